//! The WGSL sources, embedded, and how they are put together.
//!
//! `lobes.wgsl` is the library (one function per lobe, `lobe_eval` dispatching on the kind's
//! index); `geometry.wgsl` computes the lobe's cosine; `brdf.wgsl` adds the illumination
//! models; `render.wgsl`, `evaluate.wgsl` and `volume.wgsl` (the ray marcher) are the entry
//! points. A module is the concatenation of the files it needs
//! (WGSL declarations may come in any order).

use specula::LobeKind;

/// The lobe library's built-in lobes (`lobe_eval`'s default case calls `lobe_formula`,
/// which [`lobes`] appends).
pub const LOBES: &str = include_str!("../shaders/lobes.wgsl");
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

/// The WGSL function that implements `kind`: `lobe_` and the id with `-` as `_`.
#[must_use]
pub fn lobe_function(kind: LobeKind) -> String {
    format!("lobe_{}", kind.id().replace('-', "_"))
}

/// The lobe library with every user lobe defined so far ([`specula::formula::kinds`]): each
/// formula's generated function of `n` and `t`, dispatched from `lobe_eval`'s default case
/// by the kind's index, so that a user's lobe renders as the built-in ones do. A module
/// built before a formula was defined does not know it (its index then gives 0).
#[must_use]
pub fn lobes() -> String {
    let mut cases = String::new();
    let mut functions = String::new();
    for kind in specula::formula::kinds() {
        let lobe = specula::Lobe::new(kind, specula::Exponent::new(1.0));
        let name = format!("lobe_formula_{}", kind.index());
        if let Some(function) = specula_targets::wgsl::lobe_function_of_n(&lobe, &name) {
            functions.push_str(&function);
            cases.push_str(&format!(
                "        case {}u: {{ return {name}(lobe.n, t); }}\n",
                kind.index()
            ));
        }
    }
    let dispatch = format!(
        "
// The user's lobes, by kind index (specula::formula).
fn lobe_formula(lobe: Lobe, t: f32) -> f32 {{
    switch lobe.kind {{
{cases}        default: {{ return 0.0; }}
    }}
}}
"
    );
    [LOBES, &functions, &dispatch].concat()
}

/// The render module's source.
#[must_use]
pub fn render_module() -> String {
    [lobes().as_str(), GEOMETRY, BRDF, RENDER].concat()
}

/// The most images (one per lobe's highlight) one march of the ray marcher draws.
pub const MAX_HIGHLIGHTS: usize = 16;

/// The ray marcher's source for images whose highlights are `kinds`' lobes, in order:
/// `add_highlights` calls each lobe's function directly (a driver that runs every case of a
/// `switch` whose value it cannot prove uniform, as Mesa's lavapipe does, then evaluates one
/// lobe per highlight, not every lobe).
///
/// # Panics
/// If there are more than [`MAX_HIGHLIGHTS`] kinds.
#[must_use]
pub fn volume_module(kinds: &[LobeKind]) -> String {
    assert!(
        kinds.len() <= MAX_HIGHLIGHTS,
        "{} highlights in one march, above {MAX_HIGHLIGHTS}",
        kinds.len()
    );
    let mut sums = String::new();
    for (i, &kind) in kinds.iter().enumerate() {
        let call = if LobeKind::ALL.contains(&kind) {
            format!("{}(highlights[{i}u].lobe, c)", lobe_function(kind))
        } else {
            format!("lobe_formula(highlights[{i}u].lobe, c)")
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
    [lobes().as_str(), GEOMETRY, VOLUME, &add_highlights].concat()
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
