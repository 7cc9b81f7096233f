//! "Real materials", the lobes as microfacet distributions: each material assessed as `specula
//! fit --model microfacet` assesses it (every lobe fitted classic and as a distribution,
//! beside Beckmann and GGX), one table of the fit errors (a row per lobe, a column per
//! material) and, per material, the verdict: the cheapest distribution within the margin of
//! GGX's fit and what it saves against the `pow` distribution.

use specula::measured::fit::{Sharing, Specular};
use specula::LobeKind;
use specula_decide::material::{verdict_line, Assessment, FitRow};

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
            format!(
                "{:.4} ({})",
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
                let microfacet = best_shared(a, |s| s == Specular::Microfacet { kind });
                let mark = a
                    .fits
                    .get(a.chosen)
                    .filter(|c| c.fit.specular == Specular::Microfacet { kind })
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
    for (name, family) in [("ggx", Specular::Ggx), ("beckmann", Specular::Beckmann)] {
        let mut row = vec![name.to_owned()];
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
         of kd / pi + K D G2 / (4 cos_o cos_i), its own normalisation and Smith masking, the \
         shape parameter after it; GGX's and Beckmann's in the same model below. Lower is \
         better; (verdict) marks each material's answer.",
    );
    html += &table(&header, &rows);
    for a in assessed {
        html += &paragraph(&format!("{}: {}", a.material, verdict_line(a)));
    }
    html
}
