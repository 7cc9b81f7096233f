//! The WGSL sources, embedded, and how they are put together.
//!
//! The lobe library is generated ([`lobes`], from `lobe_library`); `geometry.wgsl` computes
//! the lobe's cosine; `brdf.wgsl` adds the illumination models; `render.wgsl`,
//! `evaluate.wgsl` and `volume.wgsl` (the ray marcher) are the entry points. A module is the
//! concatenation of the parts it needs (WGSL declarations may come in any order).

use specula::LobeKind;

pub use crate::lobe_library::{lobe_function, FunctionKey};

/// The lobe's cosine from the directions (Phong or Blinn).
pub const GEOMETRY: &str = include_str!("../shaders/geometry.wgsl");
/// Materials, lights and the illumination models.
pub const BRDF: &str = include_str!("../shaders/brdf.wgsl");
/// The render pipeline's entry points.
pub const RENDER: &str = include_str!("../shaders/render.wgsl");
/// The direct-volume-rendering compute shader.
pub const VOLUME: &str = include_str!("../shaders/volume.wgsl");
/// The lobe-evaluation compute shader.
pub const EVALUATE: &str = include_str!("../shaders/evaluate.wgsl");
/// GGX's microfacet term as three.js writes it, for the cost model's comparison.
pub const GGX_COST: &str = include_str!("../shaders/ggx_cost.wgsl");

/// The lobe library, generated from every lobe's recorded expression: each built-in shape's
/// function, the user's lobes defined so far (a module built before a formula was defined
/// does not know it: its index then gives 0) and `lobe_eval`, which dispatches a material's
/// `Lobe` block to them.
#[must_use]
pub fn lobes() -> String {
    crate::lobe_library::source()
}

/// The render module's source, for every lobe.
#[must_use]
pub fn render_module() -> String {
    [lobes().as_str(), GEOMETRY, BRDF, RENDER].concat()
}

/// The render module's source for materials whose lobes are `keys`' (the renderer's
/// pipeline for a scene: `lobe_eval` switches over those lobes only).
#[must_use]
pub fn render_module_for(keys: &[FunctionKey]) -> String {
    [
        crate::lobe_library::source_for(keys).as_str(),
        GEOMETRY,
        BRDF,
        RENDER,
    ]
    .concat()
}

/// The most images (one per lobe's highlight) one march of the ray marcher draws.
pub const MAX_HIGHLIGHTS: usize = 16;

/// The ray marcher's source for images whose highlights are `keys`' lobes, in order:
/// `add_highlights` calls each lobe's generated function directly (a driver that runs every
/// case of a `switch` whose value it cannot prove uniform, as Mesa's lavapipe does, then
/// evaluates one lobe per highlight, not every lobe), and the library holds those lobes only.
///
/// # Panics
/// If there are more than [`MAX_HIGHLIGHTS`] lobes.
#[must_use]
pub fn volume_module(keys: &[FunctionKey]) -> String {
    assert!(
        keys.len() <= MAX_HIGHLIGHTS,
        "{} highlights in one march, above {MAX_HIGHLIGHTS}",
        keys.len()
    );
    let mut sums = String::new();
    for (i, key) in keys.iter().enumerate() {
        let lobe = format!("highlights[{i}u].lobe");
        let call = match LobeKind::ALL.get(key.kind as usize) {
            Some(&kind) => format!(
                "{}_f{}({lobe}.parameters, c)",
                lobe_function(kind),
                key.function
            ),
            None => format!("lobe_formula({lobe}, c)"),
        };
        sums.push_str(&format!(
            "    (*sums)[{i}u] += weight * (highlights[{i}u].scale.x * {call});\n"
        ));
    }
    let add_highlights = format!(
        "
const MAX_HIGHLIGHTS: u32 = {MAX_HIGHLIGHTS}u;

// Each image's highlight at the lobe's cosine `t` (lobe_eval's rules), weighted.
fn add_highlights(sums: ptr<function, array<f32, MAX_HIGHLIGHTS>>, weight: f32, t: f32) {{
    if !(t > 0.0) {{
        return;
    }}
    let c = min(t, 1.0);
{sums}}}
"
    );
    [
        crate::lobe_library::source_for(keys).as_str(),
        GEOMETRY,
        VOLUME,
        &add_highlights,
    ]
    .concat()
}

/// The compute module's source.
#[must_use]
pub fn evaluate_module() -> String {
    [lobes().as_str(), EVALUATE].concat()
}

/// Parses and validates WGSL with naga, as wgpu will; the error names the line.
pub fn validate(source: &str) -> Result<(naga::Module, naga::valid::ModuleInfo), String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| e.emit_to_string(source))?;
    Ok((module, info))
}
