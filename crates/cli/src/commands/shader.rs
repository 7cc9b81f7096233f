//! `specula shader`: one lobe as a self-contained shader function for another pipeline.

use std::path::PathBuf;

use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_gpu::export::{ExportFormat, GlslVersion, Language, Options, ShaderCode};

use super::CommandResult;
use crate::args::{choice, parse_exponent, LobeParser};

/// Arguments of `specula shader`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The lobe.
    #[arg(long, value_parser = LobeParser)]
    lobe: LobeKind,
    /// The exponent, in [1, 1000]; the lobe's constants are prepared for it.
    #[arg(long, value_parser = parse_exponent, allow_hyphen_values = true)]
    n: Exponent,
    /// How the lobe's cosine is formed.
    #[arg(long, value_parser = choice(&Geometry::ALL, Geometry::id), default_value = "phong")]
    geometry: Geometry,
    /// The normalisation N(n) of the specular term (`specula_specular`, MaterialX's BSDF, the
    /// Mitsuba plugin's default); OSL takes none.
    #[arg(
        long,
        value_parser = choice(&Normalisation::ALL, Normalisation::id),
        default_value = "none",
    )]
    normalisation: Normalisation,
    /// The shading language: wgsl, glsl, hlsl, msl, spirv (a function for one's own
    /// shader), osl (a Blender Cycles script node), mtlx (a MaterialX
    /// document), mitsuba (a Mitsuba 3 BSDF plugin in Python), threejs (an ES module patching
    /// a MeshPhongMaterial or MeshPhongNodeMaterial), babylon (an ES module with a
    /// MaterialPluginBase for StandardMaterial) or vtk (a Python module putting the lobe in
    /// VTK's GPU ray caster and surface shading).
    #[arg(long, value_parser = choice(&ExportFormat::ALL, ExportFormat::id))]
    lang: ExportFormat,
    /// The GLSL dialect (with --lang glsl): 450 (Vulkan, OpenGL 4.5), 300es (OpenGL ES 3,
    /// WebGL 2) or 100 (OpenGL ES 2, WebGL 1; lobes that read a float's bits are refused).
    #[arg(long, value_parser = choice(&GlslVersion::ALL, GlslVersion::id), default_value = "450")]
    glsl_version: GlslVersion,
    /// Include the example fragment shader that calls the functions (GLSL leaves it out by
    /// default, so the text pastes into a shader of one's own; the other languages keep it).
    #[arg(long)]
    example: bool,
    /// Take n as the functions' first argument (`specula_specular(n, normal, wo, wi)`), the
    /// lobe's constants and N(n) computed from it in the shader, so that n can be a uniform;
    /// naga's languages only, for lobes whose constants are closed forms of n (kept within the
    /// range where the lobe's operations stay the same, stated in the header).
    #[arg(long)]
    n_input: bool,
    /// Write to this file instead of standard output (required for SPIR-V, a binary).
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// Exports and writes.
pub fn run(args: &Args) -> CommandResult {
    if args.lang == ExportFormat::Naga(Language::Spirv) && args.output.is_none() {
        return Err("SPIR-V is binary; give an output file with -o (e.g. -o lobe.spv)".into());
    }
    let lobe = Lobe::checked(args.lobe, args.n).map_err(|e| e.to_string())?;
    let options = Options {
        example: args.example,
        glsl: args.glsl_version,
        n_input: args.n_input,
    };
    let code = args
        .lang
        .write(&lobe, args.geometry, args.normalisation, options)?;
    match &args.output {
        Some(path) => specula_render::write_atomically(path, |writer| {
            writer
                .write_all(&code.to_bytes())
                .map_err(|e| e.to_string())
        })
        .map_err(|e| e.to_string()),
        None => {
            if let ShaderCode::Text(text) = code {
                print!("{text}");
            }
            Ok(())
        }
    }
}
