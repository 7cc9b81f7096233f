//! "Real materials", the lobes as microfacet distributions: each material assessed as `specula
//! fit --model microfacet` assesses it (every lobe fitted classic and as a distribution,
//! beside Beckmann and GGX), one table of the fit errors (a row per lobe, a column per
//! material) and, per material, the verdict: the cheapest distribution within the margin of
//! GGX's fit and what it saves against the `pow` distribution.

use specula::brdf::luminance;
use specula::measured::fit::{Normals, Sharing, Specular};
use specula::{Exponent, Lobe, LobeKind};
use specula_decide::material::{verdict_line, Assessment, FitRow};
use specula_decide::microfacet_cost::{ggx_microfacet_rate, microfacet_rate};
use specula_decide::Target;

use super::html::{paragraph, table};

/// The best shared-`n` fit of the families `pick` chooses (the better geometry for a classic
/// lobe), if fitted.
fn best_shared(a: &Assessment, pick: impl Fn(Specular) -> bool) -> Option<&FitRow> {
    a.fits
        .iter()
        .filter(|r| r.fit.sharing == Sharing::Shared && pick(r.fit.specular))
        .min_by(|x, y| x.fit.error.total_cmp(&y.fit.error))
}

/// The table and the verdicts for `assessed` (microfacet-model assessments, in the materials'
/// order), with `kinds` the lobes fitted.
pub(crate) fn microfacet_section(assessed: &[Assessment], kinds: &[LobeKind]) -> String {
    let mut header = vec!["lobe (classic E / microfacet E, n)".to_owned()];
    header.extend(assessed.iter().map(|a| a.material.clone()));
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let cell = |row: Option<&FitRow>| {
        row.map_or("-".to_owned(), |r| {
            let f0 = r.fit.f0.map_or(String::new(), |f0| {
                format!(", F0 {:.3}", luminance(glam::DVec3::from_array(f0)))
            });
            format!(
                "{:.4} ({}{f0})",
                r.fit.error,
                specula_decide::material::parameter_text(&r.fit)
            )
        })
    };
    let mut rows: Vec<Vec<String>> = kinds
        .iter()
        .map(|&kind| {
            let mut row = vec![kind.to_string()];
            row.extend(assessed.iter().map(|a| {
                let classic = best_shared(
                    a,
                    |s| matches!(s, Specular::Lobe { kind: k, .. } if k == kind),
                );
                let family = Specular::Microfacet {
                    normals: Normals::Lobe(kind),
                };
                let microfacet = best_shared(a, |s| s == family);
                let mark = a
                    .fits
                    .get(a.chosen)
                    .filter(|c| c.fit.specular == family)
                    .map_or("", |_| " (verdict)");
                format!(
                    "{} / {}{mark}",
                    classic.map_or("-".to_owned(), |r| format!("{:.4}", r.fit.error)),
                    cell(microfacet)
                )
            }));
            row
        })
        .collect();
    for normals in [Normals::Ggx, Normals::Beckmann] {
        let family = Specular::Microfacet { normals };
        let mut row = vec![normals.id()];
        row.extend(
            assessed
                .iter()
                .map(|a| cell(best_shared(a, |s| s == family))),
        );
        rows.push(row);
    }
    let mut html = paragraph(
        "The lobes as microfacet distributions (specula fit --model microfacet): each lobe's \
         fit error in the classic model (its better geometry) and as the normal distribution \
         of kd / pi + K F D G2 / (4 cos_o cos_i), its own normalisation and Smith masking, \
         Schlick's Fresnel F with its F0 fitted per channel; after each error, the shape \
         parameter and the F0's luminance. GGX's and Beckmann's in the same model below. \
         Lower is better; (verdict) marks each material's answer.",
    );
    html += &table(&header, &rows);
    for a in assessed {
        html += &paragraph(&format!("{}: {}", a.material, verdict_line(a)));
    }
    html += &cost_section(kinds);
    html
}

/// The exponent the cost table compares the distributions at.
const COST_EXPONENT: f64 = 64.0;

/// What each lobe's whole microfacet specular term costs on the modelled GPUs, against the
/// `pow` distribution's and GGX's (`specula_decide::microfacet_cost`); a sentence where a cost
/// cannot be had.
fn cost_section(kinds: &[LobeKind]) -> String {
    let targets = [Target::GpuNvidia, Target::GpuAmd];
    let pow = Lobe::new(LobeKind::Pow, Exponent::new(COST_EXPONENT));
    let costed = targets.map(|target| -> Result<(f64, f64, Vec<f64>), String> {
        let rates = kinds
            .iter()
            .map(|&kind| microfacet_rate(target, &Lobe::new(kind, Exponent::new(COST_EXPONENT))))
            .collect::<Result<Vec<f64>, String>>()?;
        Ok((
            microfacet_rate(target, &pow)?,
            ggx_microfacet_rate(target)?,
            rates,
        ))
    });
    let [Ok(nvidia), Ok(amd)] = &costed else {
        let why = costed
            .iter()
            .find_map(|c| c.as_ref().err())
            .cloned()
            .unwrap_or_default();
        return paragraph(&format!(
            "The microfacet terms' costs are not available: {why}"
        ));
    };
    let rows: Vec<Vec<String>> = kinds
        .iter()
        .enumerate()
        .map(|(k, kind)| {
            let mut row = vec![kind.to_string()];
            for (pow_rate, ggx_rate, rates) in [nvidia, amd] {
                row.push(format!("{:.2}", rates[k] / pow_rate));
                row.push(format!("{:.2}", rates[k] / ggx_rate));
            }
            row
        })
        .collect();
    let header = [
        "lobe as D (n = 64)",
        "gpu-nvidia: x pow's",
        "x GGX's",
        "gpu-amd: x pow's",
        "x GGX's",
    ];
    paragraph(
        "What the whole microfacet specular term costs with each lobe as the distribution \
         (the lobe, the normaliser, G2 from the 64-entry masking table, Schlick's Fresnel per \
         channel, the division by 4 N.wo: the functions the GPU renderer runs), as throughput \
         in the GPU cost model against the pow distribution's term and against GGX's (its D \
         and Smith's correlated visibility in closed form, as three.js writes them, the same \
         Fresnel). Above 1 is cheaper. The lobe is a small part of the term: what it saves \
         against pow shrinks accordingly, and the masking table's lookups cost more than \
         GGX's closed form.",
    ) + &table(&header, &rows)
}
