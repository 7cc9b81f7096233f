//! specula's lobes for the renderers people ship, generated from one description.
//!
//! A prepared lobe's formula is recorded once ([`specula::expression`]); each module here
//! writes that record in one target's language, so a lobe added to specula reaches every
//! target with no code of its own:
//! - [`wgsl`]: the WGSL function behind `specula shader` (and, through naga, GLSL, HLSL, MSL
//!   and SPIR-V);
//! - [`osl`]: a Blender Cycles script node (OSL);
//! - [`materialx`]: a MaterialX document (the lobe as a node graph, and a BSDF);
//! - [`mitsuba`]: a Mitsuba 3 BSDF plugin (Python, Dr.Jit), with the lobe's sampling;
//! - [`compute`]: CUDA C and OpenCL C compute kernels, what NVIDIA's and Intel's compilers
//!   are given (`specula-isa`);
//! - [`code`]: the straight-line writer they share, and the inputs a node or plugin exposes.

pub mod code;
pub mod compute;
pub mod materialx;
pub mod mitsuba;
pub mod osl;
pub mod wgsl;

use specula::{Geometry, Lobe, Normalisation};

/// A renderer's own format, written from a lobe's description.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RendererFormat {
    /// An OSL script node for Blender Cycles.
    Osl,
    /// A MaterialX document: the lobe as a node, and a BSDF.
    MaterialX,
    /// A Mitsuba 3 BSDF plugin in Python (Dr.Jit).
    Mitsuba,
}

impl RendererFormat {
    /// Every renderer format.
    pub const ALL: [RendererFormat; 3] = [
        RendererFormat::Osl,
        RendererFormat::MaterialX,
        RendererFormat::Mitsuba,
    ];

    /// The name on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            RendererFormat::Osl => "osl",
            RendererFormat::MaterialX => "mtlx",
            RendererFormat::Mitsuba => "mitsuba",
        }
    }

    /// The file `lobe` becomes in `geometry`, its specular term scaled by `normalisation`.
    /// OSL refuses a normalisation: its exact form is the thesis's specular term, which has
    /// none, and its closure is GGX, normalised by construction.
    pub fn write(
        self,
        lobe: &Lobe,
        geometry: Geometry,
        normalisation: Normalisation,
    ) -> Result<String, String> {
        let fit = || specula::fit::microfacet(lobe, geometry);
        match self {
            RendererFormat::Osl if normalisation != Normalisation::None => Err(format!(
                "--lang osl takes no --normalisation (given {}): its Emission is the thesis's \
                    specular term, which has none, and its BSDF is GGX, normalised by \
                    construction; leave it out, or use --lang mtlx or mitsuba",
                normalisation.id()
            )),
            RendererFormat::Osl => Ok(osl::shader(lobe, geometry, &fit())),
            RendererFormat::MaterialX => {
                Ok(materialx::document(lobe, geometry, normalisation, &fit()))
            }
            RendererFormat::Mitsuba => Ok(mitsuba::plugin(lobe, geometry, normalisation)),
        }
    }
}
