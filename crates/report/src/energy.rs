//! The report's sections on energy: the lobes' energy against `t^n`'s with each
//! normalisation, and reciprocity and the white furnace. Every figure is computed here.

use rayon::prelude::*;
use specula::analysis::{max_directional_albedo, max_reciprocity_error};
use specula::normalisation::lobe_constant;
use specula::{Brdf, ClassicModel, Exponent, Geometry, Lobe, LobeKind, Normalisation, Rgb};

use super::html::{paragraph, table};
use super::plot::{Chart, Series, SEQUENCE};
use super::sections::{exponents, series};
use super::{prose, Context};
use crate::format::sig;

pub fn energy(context: &mut Context) -> Result<String, String> {
    let grid = exponents(context.sizes.n_steps);
    let kinds: Vec<LobeKind> = context.lobes.clone();
    let ratios: Vec<Vec<(f64, f64)>> = kinds
        .par_iter()
        .map(|&kind| {
            grid.iter()
                .map(|&n| {
                    (
                        n.get(),
                        specula::analysis::energy_ratio(&Lobe::new(kind, n)),
                    )
                })
                .collect()
        })
        .collect();
    let finite = || ratios.iter().flatten().map(|p| p.1).filter(|r| *r > 0.0);
    let high = finite().fold(1.2, f64::max);
    let low = finite().fold(0.8, f64::min);
    // One lobe far from 1 (fasterpow's tens) would flatten the others into a line: a log
    // axis keeps a ratio of 2 the same height above 1 as a half below it.
    let log_y = high / low > 4.0;
    let chart = Chart {
        title: "energy relative to t^n".into(),
        x_label: "n".into(),
        y_label: if log_y {
            "(n + 1) int lobe(cos g) sin g dg (log scale)".into()
        } else {
            "(n + 1) int lobe(cos g) sin g dg".into()
        },
        x: (1.0, 1000.0),
        y: if log_y {
            (low / 1.2, high * 1.2)
        } else {
            (0.0, high * 1.05)
        },
        log_x: true,
        log_y,
        series: kinds
            .iter()
            .zip(ratios)
            .map(|(&k, points)| series(k, points))
            .collect(),
        ..Chart::default()
    };
    let mut html = paragraph(
        "Energy ratio 1 means the lobe reflects what t^n reflects; the \
        analytic (n+1)/(2 pi) applied to an approximation scales its energy by exactly this \
        ratio.",
    );
    html += &context.svg(
        "energy-ratio.svg",
        &chart,
        "energy ratio against n: 1 reflects what t^n \
        reflects; above 1 a lobe with t^n's normalisation creates energy, below it darkens",
    )?;
    let coef1 = Chart {
        title: "the thesis's coef1 = 1.063 n / (2 pi) against the exact (n + 1) / (2 pi)".into(),
        x_label: "n".into(),
        y_label: "coef1 / exact".into(),
        x: (1.0, 1000.0),
        y: (0.4, 1.2),
        log_x: true,
        series: vec![
            Series {
                name: "coef1 / exact".into(),
                points: grid
                    .iter()
                    .map(|n| (n.get(), 1.063 * n.get() / (n.get() + 1.0)))
                    .collect(),
                colour: SEQUENCE[1],
                width: 2,
                markers: false,
                dashed: false,
            },
            Series {
                name: "1".into(),
                points: vec![(1.0, 1.0), (1000.0, 1.0)],
                colour: plotters::style::RGBColor(0, 0, 0),
                width: 1,
                markers: false,
                dashed: true,
            },
        ],
        ..Chart::default()
    };
    html += &context.svg(
        "coef1.svg",
        &coef1,
        "coef1 against the exact normalisation: it crosses 1 \
        at a single n, so the thesis's coefficient is right only there",
    )?;
    let table_n = [1.0, 8.0, 64.0, 512.0, 1000.0].map(Exponent::new);
    let rows: Vec<Vec<String>> = kinds
        .iter()
        .map(|&kind| {
            let mut row = vec![kind.to_string()];
            row.extend(table_n.iter().map(|&n| {
                let numeric = lobe_constant(&Lobe::new(kind, n));
                format!(
                    "{} ({:+.2}%)",
                    sig(numeric),
                    100.0 * (numeric / Normalisation::Lobe.analytic(n) - 1.0)
                )
            }));
            row
        })
        .collect();
    html += &paragraph(
        "Each lobe's own normalisation constant (computed numerically), and how far \
        it is from the analytic (n+1)/(2 pi):",
    );
    html += &table(
        &["lobe", "n = 1", "n = 8", "n = 64", "n = 512", "n = 1000"],
        &rows,
    );
    Ok(html)
}

/// The section, or a run's of this build on the same sizes and lobes: its integrals and
/// seeded pairs are functions of those alone ([`stored`](super::stored)).
pub fn reciprocity(context: &mut Context) -> Result<String, String> {
    super::stored::section(context, super::RECIPROCITY, "", measured_reciprocity)
}

fn measured_reciprocity(context: &mut Context) -> Result<String, String> {
    use rand::SeedableRng;
    let pairs = context.sizes.reciprocity_pairs;
    let exponents = [8.0, 64.0, 512.0].map(Exponent::new);
    let rows: Vec<Vec<String>> = context
        .lobes
        .par_iter()
        .map(|&kind| {
            let mut row = vec![kind.to_string()];
            for n in exponents {
                let lobe = Lobe::new(kind, n);
                let brdf = Brdf::new(
                    Rgb::ZERO,
                    Rgb::ONE,
                    lobe,
                    Geometry::Phong,
                    Normalisation::Lobe,
                );
                row.push(format!("{:.5}", max_directional_albedo(&brdf).1));
            }
            let mut rng = rand_pcg::Pcg64::seed_from_u64(0x5eed);
            let worst = Geometry::ALL
                .iter()
                .map(|&geometry| {
                    let brdf = Brdf::new(
                        Rgb::splat(0.2),
                        Rgb::splat(0.8),
                        Lobe::new(kind, exponents[1]),
                        geometry,
                        Normalisation::Lobe,
                    );
                    max_reciprocity_error(|wo, wi| brdf.f(wo, wi), pairs, &mut rng)
                })
                .fold(0.0, f64::max);
            let classic = ClassicModel {
                ka: Rgb::ZERO,
                kd: Rgb::splat(0.2),
                ks: Rgb::splat(0.8),
                lobe: Lobe::new(kind, exponents[1]),
                geometry: Geometry::Phong,
            };
            let classic_error =
                max_reciprocity_error(|wo, wi| classic.implied_brdf(wo, wi), pairs, &mut rng);
            row.push(sig(worst));
            row.push(sig(classic_error));
            row
        })
        .collect();
    let loss = energy_loss(context)?;
    Ok(
        paragraph(&prose::fill(prose::WHITE_FURNACE, &[("pairs", &pairs)])?)
            + &loss
            + &table(
                &[
                    "lobe",
                    "max albedo n = 8",
                    "n = 64",
                    "n = 512",
                    "reciprocity error",
                    "classic model's \
            implied BRDF",
                ],
                &rows,
            ),
    )
}

/// Kulla and Conty's plot for the lobes as microfacet distributions: the energy a
/// distribution's single scattering loses, `1 - E_avg`, against `n`, with Beckmann's and
/// GGX's at Walter's correspondence `alpha = sqrt(2 / (n + 2))` beside them.
fn energy_loss(context: &mut Context) -> Result<String, String> {
    use specula::microfacet::energy::average_albedo;
    use specula::microfacet::tabulated::lobe_width;
    use specula::microfacet::Distribution;
    let grid = exponents(7);
    let loss = |d: &Distribution| 1.0 - average_albedo(d);
    let mut curves: Vec<Series> = context
        .lobes
        .par_iter()
        .map(|&kind| {
            let points = grid
                .iter()
                .map(|&n| (n.get(), loss(&Distribution::lobe(kind, n))))
                .collect();
            series(kind, points)
        })
        .collect();
    for (name, grey, make) in [
        (
            "ggx",
            60,
            (|alpha| Distribution::Ggx { alpha }) as fn(f64) -> Distribution,
        ),
        ("beckmann", 140, |alpha| Distribution::Beckmann { alpha }),
    ] {
        curves.push(Series {
            name: format!("{name} (Walter)"),
            points: grid
                .par_iter()
                .map(|&n| (n.get(), loss(&make(lobe_width(n.get())))))
                .collect(),
            colour: plotters::style::RGBColor(grey, grey, grey),
            width: 3,
            markers: false,
            dashed: true,
        });
    }
    let high = curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.1))
        .fold(0.05, f64::max);
    let chart = Chart {
        title: "energy the microfacet distributions lose to single scattering".into(),
        x_label: "n".into(),
        y_label: "1 - E_avg (Fresnel 1)".into(),
        x: (1.0, 1000.0),
        y: (0.0, high * 1.05),
        log_x: true,
        series: curves,
        ..Chart::default()
    };
    Ok(paragraph(
        "Each lobe as a microfacet normal distribution (normalised, with its own Smith \
         masking and the height-correlated G2; specula fit --model microfacet fits these): the \
         energy its single scattering loses, 1 - E_avg with E_avg = 2 int E(mu) mu dmu, as \
         Kulla and Conty plot it. A rough distribution loses the most, to the masking; the \
         lost energy is what a multiple-scattering term would give back.",
    ) + &context.svg(
        "microfacet-energy-loss.svg",
        &chart,
        "1 - E_avg against n for each lobe as a microfacet distribution, GGX and Beckmann at \
         Walter's correspondence dashed grey: lower keeps more energy",
    )?)
}
