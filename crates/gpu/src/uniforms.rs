//! The uniform blocks of the WGSL code, laid out as WGSL lays them out (16-byte aligned
//! `vec3`s with a 4-byte field in their padding).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use specula::{Geometry, Lobe};
use specula_render::{
    IlluminationModel, Light, Material, MicrofacetTerms, Shader, MASKING_ENTRIES,
};

use crate::lobe_library::FunctionKey;

/// `struct Lobe` of the generated lobe library (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LobeBlock {
    kind: u32,
    function: u32,
    n: f32,
    padding: u32,
    parameters: [f32; 4],
}

impl LobeBlock {
    /// The prepared lobe's function and constants, rounded to `f32`.
    #[must_use]
    pub fn new(lobe: &Lobe) -> Self {
        let FunctionKey { kind, function } = FunctionKey::of(lobe);
        Self {
            kind,
            function,
            n: lobe.exponent().get() as f32,
            padding: 0,
            parameters: crate::lobe_library::parameter_slots(lobe).map(|p| p as f32),
        }
    }

    /// The generated function that computes the lobe.
    #[must_use]
    pub fn key(&self) -> FunctionKey {
        FunctionKey {
            kind: self.kind,
            function: self.function,
        }
    }
}

/// The id geometry.wgsl's `cos_lobe` switches on.
#[must_use]
pub fn geometry_id(geometry: Geometry) -> u32 {
    match geometry {
        Geometry::Phong => 0,
        Geometry::Blinn => 1,
    }
}

/// `struct Material` of brdf.wgsl (352 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct MaterialBlock {
    ambient: [f32; 3],
    geometry: u32,
    diffuse: [f32; 3],
    model: u32,
    specular: [f32; 3],
    normaliser: f32,
    grazing: [f32; 3],
    padding: u32,
    lobe: LobeBlock,
    masking: [f32; MASKING_ENTRIES],
}

impl MaterialBlock {
    /// The material prepared for `model` by the CPU renderer's [`Shader`], so both renderers
    /// upload the same coefficients.
    #[must_use]
    pub fn new(material: &Material, model: IlluminationModel) -> Self {
        let shader = Shader::new(material, model);
        let (ambient, diffuse, specular) = shader.coefficients();
        let (geometry, model) = shader.geometry_and_model();
        Self {
            ambient: ambient.to_array(),
            geometry: geometry_id(geometry),
            diffuse: diffuse.to_array(),
            model: match model {
                IlluminationModel::Classic => 0,
                IlluminationModel::Physical => 1,
                IlluminationModel::Microfacet => 2,
            },
            specular: specular.to_array(),
            normaliser: shader.microfacet().map_or(0.0, MicrofacetTerms::normaliser),
            grazing: shader
                .microfacet()
                .map_or([0.0; 3], |m| m.grazing().to_array()),
            padding: 0,
            lobe: LobeBlock::new(shader.lobe()),
            masking: shader
                .microfacet()
                .map_or([0.0; MASKING_ENTRIES], |m| *m.masking()),
        }
    }

    /// The generated function that computes the material's lobe.
    #[must_use]
    pub fn lobe_key(&self) -> FunctionKey {
        self.lobe.key()
    }
}

/// `struct Light` of brdf.wgsl (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightBlock {
    position: [f32; 3],
    kind: u32,
    intensity: [f32; 3],
    padding: u32,
}

impl LightBlock {
    /// The light's block.
    #[must_use]
    pub fn new(light: &Light) -> Self {
        let (position, kind, intensity): (Vec3, u32, Vec3) = match *light {
            Light::Directional { towards, intensity } => (towards, 0, intensity),
            Light::Point {
                position,
                intensity,
            } => (position, 1, intensity),
        };
        Self {
            position: position.to_array(),
            kind,
            intensity: intensity.to_array(),
            padding: 0,
        }
    }
}

/// `struct Frame` of render.wgsl (112 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FrameBlock {
    /// World to clip space.
    pub view_projection: [[f32; 4]; 4],
    /// The eye.
    pub eye: [f32; 3],
    /// 1 for an orthographic camera.
    pub orthographic: u32,
    /// Unit direction from the target to the eye.
    pub backwards: [f32; 3],
    /// How many lights the light buffer holds.
    pub light_count: u32,
    /// Ambient intensity.
    pub ambient: [f32; 3],
    /// 0 flat, 1 Gouraud, 2 Phong.
    pub shading: u32,
}

/// The size WGSL's layout rules give each named struct of `source` (naga's own layout), for
/// tests that the `Pod` mirrors match.
#[cfg(test)]
pub(crate) fn wgsl_size_of(source: &str) -> impl Fn(&str) -> usize {
    let (module, _) = crate::wgsl::validate(source).unwrap();
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    move |name: &str| {
        let (handle, _) = module
            .types
            .iter()
            .find(|(_, ty)| ty.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("{name} not in the WGSL"));
        layouter[handle].size as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sizes WGSL's layout rules give the structs (checked against naga's own layout).
    #[test]
    fn blocks_match_the_wgsl_layout() {
        let size_of = wgsl_size_of(&crate::wgsl::render_module());
        assert_eq!(size_of("Lobe"), size_of_val(&LobeBlock::default()));
        assert_eq!(size_of("Material"), size_of_val(&MaterialBlock::zeroed()));
        assert_eq!(size_of("Light"), size_of_val(&LightBlock::default()));
        assert_eq!(size_of("Frame"), size_of_val(&FrameBlock::default()));
    }
}
