//! The report's renderers section: every lobe leaves specula for Blender Cycles (OSL),
//! MaterialX and Mitsuba 3 from one recorded description. Computed here, on every run: that
//! the record and its lowering (no bit tricks) give the lobe's own `f32` bits, and the GGX
//! roughness each lobe is given where a renderer only has microfacet closures. What the test
//! suite verifies in the real renderers is not run here: the last table states it, naming
//! the tests that do it.

use rayon::prelude::*;
use specula::expression::Expression;
use specula::fit::microfacet;
use specula::{Geometry, Lobe, LobeKind};

use super::html::{paragraph, table};
use super::prose;
use super::Context;

const FIT_EXPONENTS: [f64; 3] = [8.0, 64.0, 512.0];
const DESCRIPTION_EXPONENT: f64 = 64.0;

/// How many of `cosines` `expression` (the lobe's record) and its lowering evaluate to the
/// lobe's `f32` bits.
fn bit_exact(lobe: &Lobe, expression: &Expression, cosines: &[f32]) -> (usize, usize) {
    let lowered = expression.lowered();
    let same = |e: &Expression| {
        cosines
            .iter()
            .filter(|&&t| e.eval(t).to_bits() == lobe.eval(t).to_bits())
            .count()
    };
    (same(expression), same(&lowered))
}

pub fn other_renderers(context: &mut Context) -> Result<String, String> {
    let cosines: Vec<f32> = (1..=20_000).map(|k| k as f32 / 20_000.0).collect();
    let lobe = |kind: LobeKind, n: f64| Lobe::try_new(kind, n).map_err(|e| e.to_string());
    let description = context
        .lobes
        .par_iter()
        .map(|&kind| {
            let lobe = lobe(kind, DESCRIPTION_EXPONENT)?;
            let expression = lobe.expression();
            let (record, lowered) = bit_exact(&lobe, &expression, &cosines);
            let described = specula_targets::code::Inputs::of(&lobe);
            let inputs = match described.exponent {
                Some(range) => format!("n in {}", specula_targets::code::describe_range(range)),
                None => format!("{} (fitted for n)", described.order.join(", ")),
            };
            Ok(vec![
                kind.id().to_owned(),
                expression.nodes().len().to_string(),
                inputs,
                format!("{record} / {}", cosines.len()),
                format!("{lowered} / {}", cosines.len()),
            ])
        })
        .collect::<Result<Vec<_>, String>>()?;
    let fits = context
        .lobes
        .par_iter()
        .map(|&kind| {
            let mut row = vec![kind.id().to_owned()];
            for geometry in Geometry::ALL {
                for n in FIT_EXPONENTS {
                    let fit = microfacet(&lobe(kind, n)?, geometry);
                    row.push(format!(
                        "{:.4} ({:.0} %)",
                        fit.alpha,
                        100.0 * fit.relative_error
                    ));
                }
            }
            Ok(row)
        })
        .collect::<Result<Vec<_>, String>>()?;
    let mut fit_header = vec!["lobe"];
    let labels: Vec<String> = Geometry::ALL
        .iter()
        .flat_map(|g| FIT_EXPONENTS.map(|n| format!("{} n = {n}", g.id())))
        .collect();
    fit_header.extend(labels.iter().map(String::as_str));
    let mut html = paragraph(&prose::fill(
        prose::OTHER_RENDERERS,
        &[("n", &DESCRIPTION_EXPONENT), ("count", &cosines.len())],
    )?);
    html.push_str(&table(
        &[
            "lobe",
            "nodes",
            "inputs of a target",
            "record = lobe",
            "lowered = lobe",
        ],
        &description,
    ));
    html.push_str(&paragraph(
        "Where a renderer's only glossy closures are microfacet models (Cycles' OSL, MaterialX's \
            OSL and MDL back ends), the lobe becomes GGX with the alpha closest to it read as a \
            distribution of normals (relative L2 distance in brackets; Phong's lobe at normal \
            incidence).",
    ));
    html.push_str(&table(&fit_header, &fits));
    html.push_str(&table(
        &[
            "target",
            "what the file holds",
            "verified in the real renderer by the test suite",
        ],
        &[
            vec![
                "Blender Cycles (OSL)".into(),
                "script node: Lobe output, the exact specular term as emission, GGX closure at the \
                    fitted alpha; n an input".into(),
                "every lobe's node compiles in Blender 5.0's OSL compiler; Cycles renders every \
                    lobe on a sphere within 1 % of specula's render of the same scene \
                    (crates/cli/tests/suite/blender.rs)".into(),
            ],
            vec![
                "MaterialX".into(),
                "the lobe as a node graph of standard nodes; a BSDF exact under each light in \
                    GLSL, ESSL and MSL, GGX at the fitted roughness in OSL and MDL".into(),
                "every lobe's document validates and MaterialX 1.39 generates GLSL, ESSL, MSL, OSL \
                    and MDL; glslangValidator accepts the GLSL and ESSL, an OSL compiler the OSL \
                    (MSL and MDL are generated, not compiled); the lobe's node graph, evaluated as \
                    MaterialX defines its nodes, is the lobe within 1e-4 \
                    (crates/cli/tests/suite/materialx.rs)".into(),
            ],
            vec![
                "Mitsuba 3".into(),
                "Python BSDF plugin in Dr.Jit: eval, pdf, sample, eval_pdf, specula's \
                    normalisations; the cosine drawn as specula draws it: the recorded closed-form \
                    inverse (pow, sg, sg-karis, cosquad), safeguarded Newton on the recorded tail \
                    (schlick, cheb2-thesis), specula's table (the rest)"
                    .into(),
                "Mitsuba's chi-square test passes for every lobe at n = 8, 64, 512, both \
                    geometries, three angles; Mitsuba's direct integrator renders the environment \
                    scene's sphere within the noise of specula's \
                    (crates/cli/tests/suite/mitsuba.rs)"
                    .into(),
            ],
        ],
    ));
    Ok(html)
}
