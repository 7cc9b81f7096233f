//! Shader export: one lobe, prepared for one `n`, with its geometry and normalisation, as a
//! self-contained function for other pipelines, through naga.
//!
//! The exported module defines
//! - `specula_lobe(t)`: the lobe at cosine `t`, with the shared rules (`t <= 0` or NaN gives 0,
//!   `t > 1` counts as 1) and the constants `Lobe::new` prepared in `f64` baked in;
//! - `specula_cos_lobe(normal, wo, wi)`: `t` for the chosen geometry (unit vectors, pointing
//!   away from the surface);
//! - `specula_specular(normal, wo, wi)`: `N(n) lobe(t)`, the specular factor per unit `ks`;
//! - an example fragment shader `fs_main` that shows the call ([`Options::example`]; GLSL
//!   leaves it out by default, so the text is what a user pastes into a shader of their own).
//!
//! It is generated as WGSL from the lobe's recorded expression ([`specula_targets::wgsl`]):
//! straight-line code with the prepared constants folded in (the squarings written out, so a
//! GLSL driver gets no loop), validated, compacted, and written by naga's back ends.

use core::fmt::Write as _;

use specula::{Geometry, Lobe, Normalisation};
use thiserror::Error;

use crate::wgsl;

mod engines;
mod es100;
mod kernel;

pub use engines::Engine;
pub use kernel::{compute_kernel_spirv, compute_kernel_wgsl, WORKGROUP_SIZE};

/// A shading language naga writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Language {
    /// WebGPU's WGSL.
    Wgsl,
    /// GLSL 4.50 (Vulkan/OpenGL).
    Glsl,
    /// HLSL shader model 5.1 (Direct3D).
    Hlsl,
    /// Metal Shading Language 2.0.
    Msl,
    /// SPIR-V 1.0 binary.
    Spirv,
}

impl Language {
    /// Every language.
    pub const ALL: [Language; 5] = [
        Language::Wgsl,
        Language::Glsl,
        Language::Hlsl,
        Language::Msl,
        Language::Spirv,
    ];

    /// The name on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Language::Wgsl => "wgsl",
            Language::Glsl => "glsl",
            Language::Hlsl => "hlsl",
            Language::Msl => "msl",
            Language::Spirv => "spirv",
        }
    }
}

/// A GLSL dialect.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum GlslVersion {
    /// GLSL 4.50 (Vulkan, desktop OpenGL 4.5).
    #[default]
    Desktop450,
    /// GLSL ES 3.00 (OpenGL ES 3, WebGL 2).
    Es300,
    /// GLSL ES 1.00 (OpenGL ES 2, WebGL 1), for the lobes without bit operations.
    Es100,
}

impl GlslVersion {
    /// Every version, as named on the command line.
    pub const ALL: [GlslVersion; 3] = [
        GlslVersion::Desktop450,
        GlslVersion::Es300,
        GlslVersion::Es100,
    ];

    /// The name on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            GlslVersion::Desktop450 => "450",
            GlslVersion::Es300 => "300es",
            GlslVersion::Es100 => "100",
        }
    }
}

/// How an export is written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Options {
    /// Keep the example fragment shader (always kept outside GLSL, whose back ends need an
    /// entry point to write a module).
    pub example: bool,
    /// The GLSL dialect (for [`Language::Glsl`]).
    pub glsl: GlslVersion,
    /// Take `n` as the functions' first argument (`specula_specular(n, normal, wo, wi)`), the
    /// lobe's constants and normalisation computed from it in the shader, so a renderer can
    /// make `n` a uniform ([`export_wgsl_source_of_n`]); otherwise `n` is baked in.
    pub n_input: bool,
}

/// What an export produces: source text, or SPIR-V words.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ShaderCode {
    /// Source code.
    Text(String),
    /// A SPIR-V module.
    SpirV(Vec<u32>),
}

impl ShaderCode {
    /// The bytes to write to a file (SPIR-V little-endian).
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        match self {
            ShaderCode::Text(text) => text.as_bytes().to_vec(),
            ShaderCode::SpirV(words) => words.iter().flat_map(|w| w.to_le_bytes()).collect(),
        }
    }
}

/// Every format a lobe is exported to: a language naga writes, or a renderer's own format
/// (`specula_targets`). The CLI's `shader --lang` and the Python package's `Lobe.shader` both
/// list and write through it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ExportFormat {
    /// A shading language, through naga.
    Naga(Language),
    /// A renderer's file: OSL, MaterialX, Mitsuba 3.
    Renderer(specula_targets::RendererFormat),
    /// A real-time engine's module patching its Phong material: three.js, Babylon.js.
    Engine(Engine),
}

impl ExportFormat {
    /// Every format, in the order `--help` lists them.
    pub const ALL: [ExportFormat; 11] = [
        ExportFormat::Naga(Language::Wgsl),
        ExportFormat::Naga(Language::Glsl),
        ExportFormat::Naga(Language::Hlsl),
        ExportFormat::Naga(Language::Msl),
        ExportFormat::Naga(Language::Spirv),
        ExportFormat::Renderer(specula_targets::RendererFormat::Osl),
        ExportFormat::Renderer(specula_targets::RendererFormat::MaterialX),
        ExportFormat::Renderer(specula_targets::RendererFormat::Mitsuba),
        ExportFormat::Engine(Engine::ThreeJs),
        ExportFormat::Engine(Engine::Babylon),
        ExportFormat::Engine(Engine::Vtk),
    ];

    /// The name on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            ExportFormat::Naga(language) => language.id(),
            ExportFormat::Renderer(renderer) => renderer.id(),
            ExportFormat::Engine(engine) => engine.id(),
        }
    }

    /// The format named `id`, or a message naming the valid ones.
    pub fn parse(id: &str) -> Result<Self, String> {
        specula::choose(&Self::ALL, Self::id, id, "shader language", "languages")
    }

    /// `lobe` in this format (`options` apply to naga's languages).
    pub fn write(
        self,
        lobe: &Lobe,
        geometry: Geometry,
        normalisation: Normalisation,
        options: Options,
    ) -> Result<ShaderCode, String> {
        match self {
            ExportFormat::Naga(language) => {
                export(lobe, geometry, normalisation, language, options).map_err(|e| e.to_string())
            }
            ExportFormat::Renderer(_) | ExportFormat::Engine(_) if options.n_input => Err(format!(
                "--n-input is for naga's languages ({}); {} takes n as an input already \
                        where the lobe's constants follow it",
                Language::ALL.map(Language::id).join(", "),
                self.id()
            )),
            ExportFormat::Engine(engine) => engine
                .write(lobe, geometry, normalisation)
                .map(ShaderCode::Text)
                .map_err(|e| e.to_string()),
            ExportFormat::Renderer(renderer) => renderer
                .write(lobe, geometry, normalisation)
                .map(ShaderCode::Text),
        }
    }
}

/// An export naga could not complete (a bug in specula's WGSL if it ever happens).
#[derive(Clone, Debug, Error, PartialEq)]
#[error("shader export to {language} failed: {message}")]
pub struct ExportError {
    /// The target language.
    pub language: &'static str,
    /// naga's message.
    pub message: String,
}

fn float(value: f32) -> String {
    // `{:?}` prints the shortest representation that round-trips, always with a `.` or `e`.
    format!("{value:?}")
}

/// The WGSL module an export starts from, `n` baked in as the lobe's prepared constants.
#[must_use]
pub fn export_wgsl_source(lobe: &Lobe, geometry: Geometry, normalisation: Normalisation) -> String {
    let scale = normalisation.constant_for(lobe) as f32;
    let kind = lobe.kind();
    let mut source = format!(
        "// specula: {kind}, n = {}, geometry {}, normalisation {} (N = {})\n",
        lobe.exponent(),
        geometry.id(),
        normalisation.id(),
        float(scale),
    );
    source.push_str(&specula_targets::wgsl::lobe_function(
        lobe,
        "specula_lobe_unit",
    ));
    source.push_str(wgsl::GEOMETRY);
    let _ = write!(
        source,
        "
const SPECULA_NORMALISATION: f32 = {scale};
const SPECULA_GEOMETRY: u32 = {geometry}u;

// {kind} at cosine t (n = {n}): 0 for t <= 0 or NaN, t above 1 counts as 1.
fn specula_lobe(t: f32) -> f32 {{
    if !(t > 0.0) {{
        return 0.0;
    }}
    return specula_lobe_unit(min(t, 1.0));
}}
{cos_lobe}
// N(n) lobe(t): the specular BRDF term per unit ks.
fn specula_specular(normal: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>) -> f32 {{
    return SPECULA_NORMALISATION * specula_lobe(specula_cos_lobe(normal, wo, wi));
}}
{example}",
        scale = float(scale),
        geometry = geometry_code(geometry),
        n = lobe.exponent(),
        cos_lobe = cos_lobe_function(geometry),
        example = example_shader(""),
    );
    source
}

/// The WGSL module of an export that takes `n` as an argument (`Options::n_input`): the
/// lobe's constants and the normalisation computed from `n` in the shader, `n` kept within the
/// range where the lobe's operations stay the same ([`Lobe::structural_range`]). `Err` says
/// why the lobe cannot follow `n` there: its constants are fitted, or its own normalisation
/// is only a numerical integral.
pub fn export_wgsl_source_of_n(
    lobe: &Lobe,
    geometry: Geometry,
    normalisation: Normalisation,
) -> Result<String, String> {
    let lobe_of_n = specula_targets::wgsl::lobe_function_of_n(lobe, "specula_lobe_unit")
        .ok_or_else(|| {
            format!(
                "{}'s constants are fitted for n = {} and do not follow n",
                lobe.kind(),
                lobe.exponent()
            )
        })?;
    let normalisation_of_n = specula_targets::wgsl::normalisation_function_of_n(
        lobe,
        normalisation,
        "specula_normalisation",
    )?;
    let [low, high] = lobe.structural_range();
    let kind = lobe.kind();
    let mut source = format!(
        "// specula: {kind}, n an argument in {} (exported at n = {}), geometry {}, \
            normalisation {}\n",
        specula_targets::code::describe_range([low, high]),
        lobe.exponent(),
        geometry.id(),
        normalisation.id(),
    );
    if lobe.expression().has_bit_tricks() {
        source.push_str(specula_targets::wgsl::BIT_TRICKS);
    }
    source.push_str(&lobe_of_n);
    source.push_str(&normalisation_of_n);
    source.push_str(wgsl::GEOMETRY);
    let _ = write!(
        source,
        "
// The exported n, which the example passes, and the range the functions keep n within.
const SPECULA_N: f32 = {n};
const SPECULA_N_LOW: f32 = {low};
const SPECULA_N_HIGH: f32 = {high};
const SPECULA_GEOMETRY: u32 = {geometry}u;

// {kind} at cosine t for the exponent n: 0 for t <= 0 or NaN, t above 1 counts as 1.
fn specula_lobe(n: f32, t: f32) -> f32 {{
    if !(t > 0.0) {{
        return 0.0;
    }}
    return specula_lobe_unit(clamp(n, SPECULA_N_LOW, SPECULA_N_HIGH), min(t, 1.0));
}}
{cos_lobe}
// N(n) lobe(t): the specular BRDF term per unit ks, for the exponent n.
fn specula_specular(n: f32, normal: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>) -> f32 {{
    let exponent = clamp(n, SPECULA_N_LOW, SPECULA_N_HIGH);
    let t = specula_cos_lobe(normal, wo, wi);
    return specula_normalisation(exponent) * specula_lobe(exponent, t);
}}
{example}",
        n = float(lobe.exponent().get() as f32),
        low = float(low as f32),
        high = float(high as f32),
        geometry = geometry_code(geometry),
        cos_lobe = cos_lobe_function(geometry),
        example = example_shader("SPECULA_N, "),
    );
    Ok(source)
}

fn geometry_code(geometry: Geometry) -> u32 {
    match geometry {
        Geometry::Phong => 0,
        Geometry::Blinn => 1,
    }
}

fn cos_lobe_function(geometry: Geometry) -> String {
    format!(
        "
// The lobe's cosine ({}) from unit vectors pointing away from the surface.
fn specula_cos_lobe(normal: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>) -> f32 {{
    return cos_lobe(SPECULA_GEOMETRY, normal, wo, wi);
}}
",
        geometry.cosine_name()
    )
}

/// The example fragment shader, calling `specula_specular` with `arguments_before` first.
fn example_shader(arguments_before: &str) -> String {
    format!(
        "
// Example: white specular reflection of a unit light, as radiance f(wo, wi) cos(theta_i).
@fragment
fn fs_main(
    @location(0) normal: vec3<f32>,
    @location(1) wo: vec3<f32>,
    @location(2) wi: vec3<f32>,
) -> @location(0) vec4<f32> {{
    let n = normalize(normal);
    let l = normalize(wi);
    let value = specula_specular({arguments_before}n, normalize(wo), l) * max(dot(n, l), 0.0);
    return vec4<f32>(value, value, value, 1.0);
}}
"
    )
}

/// A lobe's functions for another program's shaders (the explorer's live views, the engines'
/// modules): the text and the exponents it serves.
#[derive(Clone, Debug, PartialEq)]
pub struct Functions {
    /// The functions, without the example entry point and without GLSL's `#version` line
    /// (the shader they go into has its own first).
    pub text: String,
    /// Where the functions take `n` first (`Options::n_input`), the exponents they serve,
    /// `[low, high]`; `None` where `n` is baked in.
    pub n_range: Option<[f64; 2]>,
}

/// `lobe`'s functions in `language` (WGSL or GLSL ES 3.00) with `n` as an argument where the
/// lobe's constants and the normalisation are closed forms of it, baked in otherwise.
pub fn functions_taking_n_where_possible(
    lobe: &Lobe,
    geometry: Geometry,
    normalisation: Normalisation,
    language: Language,
) -> Result<Functions, ExportError> {
    let write = |n_input: bool| {
        let options = Options {
            example: false,
            glsl: GlslVersion::Es300,
            n_input,
        };
        export(lobe, geometry, normalisation, language, options).map(|code| match code {
            ShaderCode::Text(text) => text,
            ShaderCode::SpirV(_) => unreachable!("callers ask for text languages"),
        })
    };
    let (text, n_range) = match write(true) {
        Ok(text) => (text, Some(lobe.structural_range())),
        Err(_) => (write(false)?, None),
    };
    let text = match language {
        Language::Glsl => text
            .split_once('\n')
            .map_or(text.as_str(), |(_, body)| body)
            .to_owned(),
        // naga writes the example's entry point last.
        _ => text.split("@fragment").next().unwrap_or(&text).to_owned(),
    };
    Ok(Functions { text, n_range })
}

/// naga's GLSL without the example: its stage's inputs and outputs (the globals naga names
/// `_vs2fs_*` and `_fs2p_*`) and its `void main()`, which naga writes last.
fn without_example(text: &str) -> String {
    let before_main = text.split("\nvoid main() {").next().unwrap_or(text);
    let mut kept: String = before_main
        .lines()
        .filter(|line| !line.contains("_vs2fs_") && !line.contains("_fs2p_"))
        .collect::<Vec<_>>()
        .join("\n");
    kept.push('\n');
    kept
}

/// Exports the lobe in `language`.
pub fn export(
    lobe: &Lobe,
    geometry: Geometry,
    normalisation: Normalisation,
    language: Language,
    options: Options,
) -> Result<ShaderCode, ExportError> {
    let fail = |message: String| ExportError {
        language: language.id(),
        message,
    };
    let source = if options.n_input {
        export_wgsl_source_of_n(lobe, geometry, normalisation).map_err(|message| {
            fail(format!(
                "{message}; export with n baked in (without --n-input), or choose a lobe whose \
                    constants are closed forms of n"
            ))
        })?
    } else {
        export_wgsl_source(lobe, geometry, normalisation)
    };
    let (mut module, _) = wgsl::validate(&source).map_err(fail)?;
    naga::compact::compact(&mut module, naga::compact::KeepUnused::No);
    let (module, info) = {
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .map_err(|e| fail(e.emit_to_string(&source)))?;
        (module, info)
    };
    let header = source.lines().next().unwrap_or_default();
    let commented = |comment: &str, body: String| format!("{comment} {}\n{body}", &header[3..]);
    match language {
        Language::Wgsl => {
            naga::back::wgsl::write_string(&module, &info, naga::back::wgsl::WriterFlags::empty())
                .map(|text| ShaderCode::Text(commented("//", text)))
                .map_err(|e| fail(e.to_string()))
        }
        Language::Glsl => {
            let mut text = String::new();
            let version = match options.glsl {
                // naga writes ES 3.00, from which es100 derives ES 1.00.
                GlslVersion::Es300 | GlslVersion::Es100 => naga::back::glsl::Version::Embedded {
                    version: 300,
                    is_webgl: false,
                },
                GlslVersion::Desktop450 => naga::back::glsl::Version::Desktop(450),
            };
            let glsl_options = naga::back::glsl::Options {
                version,
                ..naga::back::glsl::Options::default()
            };
            let pipeline = naga::back::glsl::PipelineOptions {
                shader_stage: naga::ShaderStage::Fragment,
                entry_point: "fs_main".to_owned(),
                multiview: None,
            };
            naga::back::glsl::Writer::new(
                &mut text,
                &module,
                &info,
                &glsl_options,
                &pipeline,
                naga::proc::BoundsCheckPolicies::default(),
            )
            .and_then(|mut writer| writer.write())
            .map_err(|e| fail(e.to_string()))?;
            if !options.example {
                text = without_example(&text);
            }
            if options.glsl == GlslVersion::Es100 {
                text = es100::from_es300(&text).map_err(|construct| ExportError {
                    language: "GLSL ES 1.00",
                    message: format!(
                        "{} uses {construct}, which GLSL ES 1.00 lacks; use --glsl-version 300es \
                            (WebGL 2) or 450, or a lobe without bit operations",
                        lobe.kind()
                    ),
                })?;
            }
            // The `#version` line must stay first.
            let (version, body) = text.split_once('\n').unwrap_or((&text, ""));
            Ok(ShaderCode::Text(format!(
                "{version}\n// {}\n{body}",
                &header[3..]
            )))
        }
        Language::Hlsl => {
            let mut text = String::new();
            let options = naga::back::hlsl::Options::default();
            let pipeline = naga::back::hlsl::PipelineOptions { entry_point: None };
            naga::back::hlsl::Writer::new(&mut text, &options, &pipeline)
                .write(&module, &info, None)
                .map_err(|e| fail(e.to_string()))?;
            Ok(ShaderCode::Text(commented("//", text)))
        }
        Language::Msl => naga::back::msl::write_string(
            &module,
            &info,
            &naga::back::msl::Options::default(),
            &naga::back::msl::PipelineOptions::default(),
        )
        .map(|(text, _)| ShaderCode::Text(commented("//", text)))
        .map_err(|e| fail(e.to_string())),
        Language::Spirv => {
            naga::back::spv::write_vec(&module, &info, &naga::back::spv::Options::default(), None)
                .map(ShaderCode::SpirV)
                .map_err(|e| fail(e.to_string()))
        }
    }
}
