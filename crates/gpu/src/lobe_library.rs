//! The lobe library in WGSL, generated from each lobe's recorded expression, as the exports
//! are: no lobe is typed twice.
//!
//! A built-in lobe's formula changes with its parameters (`cosquad`'s `v`) and, for a few
//! models, with `n` (`schlick-mod` squares once more at each power of two: its shapes,
//! `Lobe::shape`): each combination is one straight-line function ([`Generated`]) written by
//! `specula_targets::wgsl` with the lobe's named parameters read from the material's
//! `parameters` (four slots; everything else baked in). `lobe_<id>` picks the function the
//! material's block names, `lobe_eval` the kind: both `switch`es generated from the registry.
//! The user's lobes are functions of `n` ([`specula_targets::wgsl::lobe_function_of_n`]),
//! as they were defined when the module was built.

use std::fmt::Write as _;
use std::sync::OnceLock;

use specula::{Exponent, Lobe, LobeKind};
use specula_targets::wgsl::{lobe_function_of_n, lobe_function_of_slots, BIT_TRICKS, SLOTS};

/// `struct Lobe`: what a material uploads of its lobe (`LobeBlock`, in uniforms.rs).
const LOBE_STRUCT: &str = "
// A prepared lobe: which function computes it and the constants specula prepared in f64.
struct Lobe {
    // The kind's position in specula's registry (LobeKind::index); a user's lobe's follow.
    kind: u32,
    // Which of the kind's functions (its parameters and its range of n): lobe_<id> switches on it.
    function: u32,
    // The exponent, from which a user's lobe computes its constants.
    n: f32,
    padding: u32,
    // The named parameters of the lobe's expression, in order of first use.
    parameters: vec4<f32>,
}
";

/// One of a built-in kind's generated functions: the lobes of `kind` (one variant: its
/// parameters set) from `exponents[0]` up to (not including) `exponents[1]`, which record the
/// same operations (one of the variant's shapes, `Lobe::shape`).
#[derive(Clone, Debug)]
struct Generated {
    kind: LobeKind,
    shape: u32,
    /// The lobe recorded for the function (at the shape's least exponent).
    representative: Lobe,
    exponents: [f64; 2],
}

/// Every built-in kind's generated functions, by the kind's index.
fn generated() -> &'static [Vec<Generated>] {
    static SHAPES: OnceLock<Vec<Vec<Generated>>> = OnceLock::new();
    SHAPES.get_or_init(|| {
        LobeKind::ALL
            .into_iter()
            .map(|kind| {
                kind.variants()
                    .into_iter()
                    .flat_map(|variant| {
                        let starts =
                            Lobe::new(variant, Exponent::new(Exponent::MIN)).shape_exponents();
                        (0..starts.len()).map(move |shape| {
                            let low = starts[shape];
                            let high = starts.get(shape + 1).copied().unwrap_or(Exponent::MAX);
                            Generated {
                                kind: variant,
                                shape: shape as u32,
                                representative: Lobe::new(variant, Exponent::new(low)),
                                exponents: [low, high],
                            }
                        })
                    })
                    .collect()
            })
            .collect()
    })
}

/// Which generated function computes a lobe: its kind's index and the function's position
/// among the kind's (0 for a user's lobe, which has one). What a material's block uploads,
/// and what a module generated for some lobes only is keyed by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FunctionKey {
    /// `LobeKind::index`.
    pub kind: u32,
    /// The function's position among the kind's generated functions.
    pub function: u32,
}

impl FunctionKey {
    /// `lobe`'s function.
    #[must_use]
    pub fn of(lobe: &Lobe) -> Self {
        let kind = lobe.kind().index();
        let Some(functions) = generated().get(kind as usize) else {
            return Self { kind, function: 0 };
        };
        let found = functions
            .iter()
            .position(|g| g.kind == lobe.kind() && g.shape == lobe.shape())
            // A parameter beyond its range (`cosquad` with `v` above 10, which the model
            // clamps) records the operations of a generated function all the same.
            .or_else(|| {
                let mine = lobe.expression().operations();
                functions
                    .iter()
                    .position(|g| g.representative.expression().operations() == mine)
            });
        let function = found.unwrap_or_else(|| {
            unreachable!(
                "{}: every prepared model's operations are generated",
                lobe.kind()
            )
        });
        Self {
            kind,
            function: function as u32,
        }
    }
}

/// The values of `lobe`'s named parameters in the order its generated function reads them
/// (a user's lobe's function computes its own from `n` and reads none).
#[must_use]
pub fn parameter_slots(lobe: &Lobe) -> [f64; SLOTS] {
    let mut slots = [0.0; SLOTS];
    for (slot, (_, value)) in slots.iter_mut().zip(lobe.expression().parameters()) {
        *slot = value;
    }
    slots
}

/// The WGSL function that implements `kind` from a `Lobe` block: `lobe_` and the id with
/// `-` as `_`.
#[must_use]
pub fn lobe_function(kind: LobeKind) -> String {
    format!("lobe_{}", kind.id().replace('-', "_"))
}

/// The library: `struct Lobe`, the bit-trick helpers, every built-in lobe's generated
/// functions, each kind's `switch` on the material's function, the user's lobes defined so far
/// and `lobe_eval`.
#[must_use]
pub fn source() -> String {
    library(|_| true)
}

/// The library for `keys`' lobes only (and the user's): a material's module, in which
/// `lobe_eval` switches over the lobes the scene holds, not every lobe (a driver that cannot
/// prove the switch's value uniform runs every case, as Mesa's lavapipe does). A lobe
/// outside `keys` gives 0 in it.
#[must_use]
pub fn source_for(keys: &[FunctionKey]) -> String {
    library(|key| keys.contains(&key))
}

fn library(keep: impl Fn(FunctionKey) -> bool) -> String {
    let mut out = [LOBE_STRUCT, BIT_TRICKS].concat();
    let mut kind_cases = String::new();
    for (index, kind_functions) in generated().iter().enumerate() {
        let kind = LobeKind::ALL[index];
        let name = lobe_function(kind);
        let mut cases = String::new();
        for (position, generated) in kind_functions.iter().enumerate() {
            let key = FunctionKey {
                kind: index as u32,
                function: position as u32,
            };
            if !keep(key) {
                continue;
            }
            let function = format!("{name}_f{position}");
            let text =
                lobe_function_of_slots(&generated.representative, &function).unwrap_or_else(|| {
                    unreachable!(
                        "{} has more named parameters than struct Lobe's {SLOTS} slots: widen \
                            `parameters` there and in LobeBlock",
                        generated.kind
                    )
                });
            let [low, high] = generated.exponents;
            let closing = if high == Exponent::MAX { ']' } else { ')' };
            let _ = write!(
                out,
                "\n// Function {position} of {kind}: {}, n in [{low}, {high}{closing}.{text}",
                generated.kind
            );
            let _ = writeln!(
                cases,
                "        case {position}u: {{ return {function}(lobe.parameters, t); }}"
            );
        }
        if cases.is_empty() {
            continue;
        }
        let body = if kind_functions.len() == 1 {
            format!("    return {name}_f0(lobe.parameters, t);\n")
        } else {
            let default = "        default: { return 0.0; }\n";
            format!("    switch lobe.function {{\n{cases}{default}    }}\n")
        };
        let _ = write!(
            out,
            "
// {kind}: the material's function.
fn {name}(lobe: Lobe, t: f32) -> f32 {{
{body}}}
"
        );
        let _ = writeln!(
            kind_cases,
            "        case {index}u: {{ return {name}(lobe, c); }}"
        );
    }
    out.push_str(&user_lobes());
    let _ = write!(
        out,
        "
// Any lobe at cosine t: the rules every lobe shares (t <= 0 or NaN gives 0, t > 1 counts
// as 1), then the kind's function.
fn lobe_eval(lobe: Lobe, t: f32) -> f32 {{
    // `!(t > 0)` is also true for NaN.
    if !(t > 0.0) {{
        return 0.0;
    }}
    let c = min(t, 1.0);
    switch lobe.kind {{
{kind_cases}        default: {{ return lobe_formula(lobe, c); }}
    }}
}}
"
    );
    out
}

/// Every user lobe defined so far ([`specula::formula::kinds`]): each formula's function of
/// `n` and `t`, and `lobe_formula`, which dispatches on the kind's index. A module built
/// before a formula was defined does not know it (its index then gives 0).
fn user_lobes() -> String {
    let mut cases = String::new();
    let mut functions = String::new();
    for kind in specula::formula::kinds() {
        let lobe = Lobe::new(kind, Exponent::new(1.0));
        let name = format!("lobe_formula_{}", kind.index());
        if let Some(function) = lobe_function_of_n(&lobe, &name) {
            functions.push_str(&function);
            let _ = writeln!(
                cases,
                "        case {}u: {{ return {name}(lobe.n, t); }}",
                kind.index()
            );
        }
    }
    format!(
        "{functions}
// The user's lobes, by kind index (specula::formula).
fn lobe_formula(lobe: Lobe, t: f32) -> f32 {{
    switch lobe.kind {{
{cases}        default: {{ return 0.0; }}
    }}
}}
"
    )
}
