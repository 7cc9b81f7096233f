//! Mitsuba 3: a Python BSDF plugin per lobe, written in Dr.Jit operations, so that one file
//! runs in the `scalar_*` variants and the JIT `llvm_*`/`cuda_*` ones.
//!
//! The BRDF is specula's, `f = kd / pi + ks N(n) lobe(t)` (Mitsuba's `eval` returns it times
//! `cos theta_i`), in either geometry, with any of specula's normalisations. What is
//! generated from the lobe's description: the lobe in Dr.Jit operations (lowered), the same
//! formula in Python's `math` for the plugin's set-up, the preparation of its constants from
//! `n`, the normalisation's formula, and for a lobe sampled in closed form its recorded tail
//! inverse and integral (for one sampled by Newton, its recorded tail, slope and cosine).
//! What the template adds, once for every lobe: the rest of the sampling, which draws the
//! cosine by that inverse, by safeguarded Newton on that tail, or from specula's tabulated
//! distribution
//! (the density linear in `t` between the lobe's values at the cosines of the angles
//! `(pi/2) (k/1024)^2`, those that coincide in `f32` merged; Mitsuba's
//! `IrregularContinuousDistribution`), places it about the mirror direction (Phong) or the
//! normal (Blinn's half vector), and mixes in cosine-weighted diffuse draws in proportion to
//! the two terms' luminance, as specula's renderer does.

use core::fmt::Write as _;

use specula::expression::{record, Expression};
use specula::{Geometry, Lobe, Normalisation};

use crate::code::{body, straight_line, Dialect, Inputs, Parameters};

/// Dr.Jit, on the plugin's arrays (or Python floats in the scalar variants).
struct DrJit;

impl Dialect for DrJit {
    fn local(&self, name: &str, value: &str) -> String {
        format!("{name} = {value}")
    }
    fn call(&self, function: &str, arguments: &[String]) -> String {
        let function = match function {
            "pow" => "power",
            "max" => "maximum",
            "min" => "minimum",
            other => other,
        };
        format!("dr.{function}({})", arguments.join(", "))
    }
    fn select_less(&self, a: &str, b: &str, then: &str, otherwise: &str) -> String {
        format!("dr.select({a} < {b}, {then}, {otherwise})")
    }
}

/// Python's `math`, in double precision, for the set-up.
struct PythonMath;

impl Dialect for PythonMath {
    fn local(&self, name: &str, value: &str) -> String {
        format!("{name} = {value}")
    }
    fn call(&self, function: &str, arguments: &[String]) -> String {
        let arguments = arguments.join(", ");
        match function {
            "exp2" => format!("math.pow(2.0, {arguments})"),
            "ceil" => format!("float(math.ceil({arguments}))"),
            "max" | "min" => format!("{function}({arguments})"),
            other => format!("math.{other}({arguments})"),
        }
    }
    fn select_less(&self, a: &str, b: &str, then: &str, otherwise: &str) -> String {
        format!("({then} if {a} < {b} else {otherwise})")
    }
    fn constant(&self, value: f64) -> String {
        format!("{value:?}")
    }
    fn log1p(&self, x: &str) -> String {
        format!("math.log1p({x})")
    }
    fn expm1(&self, x: &str) -> String {
        format!("math.expm1({x})")
    }
}

/// `def name(arguments):` computing `expression` of `arguments[0]` (its parameters by name).
fn function(
    dialect: &dyn Dialect,
    name: &str,
    arguments: &[&str],
    expression: &Expression,
) -> String {
    let (statements, result) = straight_line(expression, arguments[0], dialect, Parameters::Named);
    format!(
        "def {name}({}):\n{}",
        arguments.join(", "),
        body(&statements, &result, "    ", |r| format!("return {r}"))
    )
}

/// The plugin for `lobe`, its defaults `geometry` and `normalisation`.
#[must_use]
pub fn plugin(lobe: &Lobe, geometry: Geometry, normalisation: Normalisation) -> String {
    let inputs = Inputs::of(lobe);
    let lowered = lobe.expression().lowered();
    let mut arguments = vec!["t"];
    arguments.extend(inputs.order.iter().copied());
    let mut prepare = String::new();
    let _ = writeln!(prepare, "def _prepare(n, props):");
    let _ = writeln!(
        prepare,
        "    \"\"\"The lobe's parameters for exponent n (specula's preparation), by name.\"\"\""
    );
    match inputs.exponent {
        Some(_) => {
            let _ = writeln!(prepare, "    parameters = {{\"n\": n}}");
            for (name, expression) in &inputs.derived {
                let (statements, result) =
                    straight_line(expression, "n", &PythonMath, Parameters::Baked);
                for statement in statements {
                    let _ = writeln!(prepare, "    {statement}");
                }
                let _ = writeln!(prepare, "    parameters[\"{name}\"] = {result}");
            }
        }
        None => {
            let _ = writeln!(
                prepare,
                "    # Fitted by specula for n = {}: properties, not derived from n.",
                lobe.exponent()
            );
            let _ = writeln!(prepare, "    parameters = {{}}");
            for (name, value) in &inputs.fitted {
                let _ = writeln!(
                    prepare,
                    "    parameters[\"{name}\"] = float(props.get(\"{name}\", {value:?}))"
                );
            }
        }
    }
    let _ = writeln!(prepare, "    return parameters");
    let mut formulas = String::new();
    for candidate in Normalisation::ALL {
        if candidate == Normalisation::Lobe {
            continue;
        }
        let expression = record(|n| candidate.formula(n))
            .unwrap_or_else(|_| unreachable!("the formulas have no branch"));
        let (statements, result) = straight_line(&expression, "n", &PythonMath, Parameters::Baked);
        let _ = writeln!(formulas, "    if name == \"{}\":", candidate.id());
        for statement in statements {
            let _ = writeln!(formulas, "        {statement}");
        }
        let _ = writeln!(formulas, "        return {result}");
    }
    let [low, high] = lobe.structural_range();
    let mut sampling_functions = String::new();
    let sampling = lobe.sampling_expressions();
    let warp = match &sampling {
        Some((inverse, total)) => {
            let mut with_u = vec!["u"];
            with_u.extend(inputs.order.iter().copied());
            let _ = writeln!(
                sampling_functions,
                "\n# The cosine whose tail is the fraction u of the lobe's (specula's closed \
                    form).\n{}\n# int_0^1 lobe, in closed form (of the parameters alone).\n{}",
                function(&DrJit, "_tail_inverse", &with_u, inverse),
                function(&PythonMath, "_total_math", &with_u, total),
            );
            "its tail inverted in closed form, as specula's sampler does"
        }
        None => match lobe.newton_expressions() {
            Some([tail, slope, cosine, upper, total]) => {
                let mut with_x = vec!["x"];
                with_x.extend(inputs.order.iter().copied());
                let _ = writeln!(
                    sampling_functions,
                    "\n# The lobe's closed-form tail in the variable x Newton's method solves in, \
                        its slope,\n# and the cosine x stands for (specula's).\n{}\n{}\n{}\n# The \
                        end of x's range, and int_0^1 lobe (of the parameters alone).\n{}\n{}",
                    function(&DrJit, "_newton_tail", &with_x, &tail),
                    function(&DrJit, "_newton_slope", &with_x, &slope),
                    function(&DrJit, "_newton_cosine", &with_x, &cosine),
                    function(&PythonMath, "_newton_upper_math", &with_x, &upper),
                    function(&PythonMath, "_total_math", &with_x, &total),
                );
                "its closed-form tail inverted by Newton's method safeguarded by bisection, \
                    as\nspecula's sampler does (a fixed number of steps here, enough for float32)"
            }
            None => {
                "from specula's table of it, the density linear in t between the lobe's values \
                at\nthe cosines of the angles (pi/2) (k/1024)^2, k = 0 .. 1024 \
                (Mitsuba's\nIrregularContinuousDistribution)"
            }
        },
    };
    let sampling_kind = if sampling.is_some() {
        "closed-form"
    } else if lobe.newton_expressions().is_some() {
        "newton"
    } else {
        "table"
    };
    let exponent_property = match inputs.exponent {
        Some(range) => format!(
            "n: the exponent, in {} (where the lobe's operations stay the same)",
            crate::code::describe_range(range)
        ),
        None => format!(
            "n: {:?} only; the coefficients {} are properties too, fitted by\n  specula for that n \
                (export again for another n)",
            lobe.exponent().get(),
            inputs.order.join(", ")
        ),
    };
    let names: Vec<String> = Normalisation::ALL
        .iter()
        .map(|n| format!("\"{}\"", n.id()))
        .collect();
    TEMPLATE
        .replace("{kind}", &lobe.kind().to_string())
        .replace("{n}", &format!("{:?}", lobe.exponent().get()))
        .replace("{exponent_property}", &exponent_property)
        .replace("{low}", &format!("{low:?}"))
        .replace("{high}", &format!("{high:?}"))
        .replace("{name}", &crate::code::identifier(lobe))
        .replace("{geometry}", geometry.id())
        .replace("{normalisation}", normalisation.id())
        .replace("{normalisations}", &names.join(", "))
        .replace(
            "{lobe_drjit}",
            &function(&DrJit, "_lobe_unit", &arguments, &lowered),
        )
        .replace(
            "{lobe_math}",
            &function(&PythonMath, "_lobe_unit_math", &arguments, &lowered),
        )
        .replace("{prepare}", &prepare)
        .replace("{sampling_functions}", &sampling_functions)
        .replace("{warp}", warp)
        .replace("{sampling_kind}", sampling_kind)
        .replace("{formulas}", &formulas)
        .replace(
            "{arguments}",
            &inputs
                .order
                .iter()
                .map(|name| format!("self.parameters[\"{name}\"]"))
                .collect::<Vec<_>>()
                .join(", "),
        )
}

const TEMPLATE: &str = include_str!("mitsuba_template.py");
