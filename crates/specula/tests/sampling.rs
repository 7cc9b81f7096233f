//! Importance sampling, tested as pbrt-v4 and Mitsuba 3 test theirs, for every lobe, both
//! geometries, `n` in {1, 8, 64, 512} and three viewing angles:
//! - chi-square goodness of fit of the drawn directions against the integrated density
//!   (Sidak-corrected significance 0.01 over all cases); on failure the histogram and the
//!   expected counts are written as images under `target/chi2/`;
//! - the density integrates to the fraction of draws that return a direction, and to 1 when
//!   the lobe lies wholly above the surface;
//! - `sample` returns the density `pdf` gives for the same direction;
//! - white furnace: `value cos / pdf` averages to the directional albedo integrated by
//!   quadrature, and to at most 1 for Phong with the lobe's normalisation;
//! - each closed-form tail integral against quadrature, and its inverse against the tail.

use std::path::PathBuf;

use glam::DVec3;
use rayon::prelude::*;
use specula::analysis::albedo::specular_albedo_per_unit;
use specula::lobe::Warp;
use specula::quadrature::integrate;
use specula::sampling::chi2::{self, sidak, Outcome, Settings};
use specula::sampling::uniform;
use specula::sampling::SpecularSampler;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};

const EXPONENTS: [f64; 4] = [1.0, 8.0, 64.0, 512.0];
const VIEW_DEGREES: [f64; 3] = [0.0, 35.0, 70.0];

fn view(degrees: f64) -> DVec3 {
    let theta = degrees.to_radians();
    DVec3::new(theta.sin(), 0.0, theta.cos())
}

/// Every case: lobe, `n`, geometry, viewing angle.
fn cases() -> Vec<(LobeKind, f64, Geometry, f64)> {
    let mut cases = Vec::new();
    for kind in LobeKind::ALL {
        for n in EXPONENTS {
            for geometry in Geometry::ALL {
                for degrees in VIEW_DEGREES {
                    cases.push((kind, n, geometry, degrees));
                }
            }
        }
    }
    cases
}

fn sampler(
    kind: LobeKind,
    n: f64,
    geometry: Geometry,
    normalisation: Normalisation,
) -> SpecularSampler {
    SpecularSampler::new(Lobe::new(kind, Exponent::new(n)), geometry, normalisation)
}

/// Writes `values` (row-major, `columns` wide) as an 8-bit greyscale PGM scaled to its
/// maximum: readable by any image viewer, and no image library needed here.
fn write_pgm(path: &PathBuf, values: &[f64], columns: usize) -> std::io::Result<()> {
    let top = values.iter().copied().fold(f64::MIN_POSITIVE, f64::max);
    let mut bytes = format!("P5\n{} {}\n255\n", columns, values.len() / columns).into_bytes();
    bytes.extend(
        values
            .iter()
            .map(|v| (255.0 * (v / top).sqrt()).round() as u8),
    );
    std::fs::write(path, bytes)
}

fn dump(name: &str, outcome: &Outcome) -> String {
    let directory = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("chi2");
    let written = std::fs::create_dir_all(&directory).and_then(|()| {
        write_pgm(
            &directory.join(format!("{name}-histogram.pgm")),
            &outcome.histogram,
            outcome.columns,
        )?;
        write_pgm(
            &directory.join(format!("{name}-expected.pgm")),
            &outcome.expected,
            outcome.columns,
        )
    });
    match written {
        Ok(()) => format!(
            "histogram and expected counts in {}/{name}-*.pgm",
            directory.display()
        ),
        Err(e) => format!("(could not write the tables: {e})"),
    }
}

#[test]
fn every_lobe_passes_the_chi_square_test() {
    let cases = cases();
    let alpha = sidak(0.01, cases.len());
    let failures: Vec<String> = cases
        .par_iter()
        .filter_map(|&(kind, n, geometry, degrees)| {
            let sampler = sampler(kind, n, geometry, Normalisation::None);
            let wo = view(degrees);
            let outcome = chi2::run(&sampler, wo, &Settings::default());
            let name = format!("{kind}-n{n}-{}-{degrees}deg", geometry.id());
            // The density integrates to the probability of a draw: 5 binomial sigmas apart
            // at most, plus the cell integration's accuracy (1e-4: a density that jumps to 0
            // at the horizon is integrated to the deepest subdivision, not exactly).
            let p = outcome.pdf_integral;
            let sigma = (p * (1.0 - p) / 1e6).sqrt();
            let mut problems = Vec::new();
            if !outcome.passes(alpha) {
                problems.push(format!(
                    "p = {:.3e} < {alpha:.1e} (statistic {:.1}, dof {}, {} impossible)",
                    outcome.p_value, outcome.statistic, outcome.dof, outcome.impossible
                ));
            }
            if (outcome.drawn_fraction - p).abs() > 5.0 * sigma + 1e-4 || p > 1.0 + 1e-4 {
                problems.push(format!(
                    "pdf integrates to {p:.6}, draws succeed {:.6}",
                    outcome.drawn_fraction
                ));
            }
            if geometry == Geometry::Phong && degrees == 0.0 && (p - 1.0).abs() > 1e-4 {
                problems.push(format!(
                    "the lobe lies above the surface yet its pdf integrates to {p:.6}"
                ));
            }
            (!problems.is_empty())
                .then(|| format!("{name}: {}; {}", problems.join("; "), dump(&name, &outcome)))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

/// A sampler that draws one density and reports another is caught: `pow` drawn at `n = 64`
/// but its density claimed at `n = 80`.
#[test]
fn the_chi_square_test_rejects_a_wrong_density() {
    let drawn = sampler(LobeKind::Pow, 64.0, Geometry::Phong, Normalisation::None);
    let claimed = sampler(LobeKind::Pow, 80.0, Geometry::Phong, Normalisation::None);
    let wo = view(35.0);
    let settings = Settings::default();
    let honest = chi2::run(&drawn, wo, &settings);
    assert!(honest.passes(0.01), "p = {}", honest.p_value);
    // Histogram of one, expected counts of the other.
    let wrong = chi2::run(&claimed, wo, &settings);
    let (statistic, dof, _) = chi2::pearson(&honest.histogram, &wrong.expected);
    let p = chi2::chi_square_survival(statistic, dof);
    assert!(p < 1e-12, "p = {p}");
}

#[test]
fn sample_returns_the_density_pdf_gives() {
    cases()
        .par_iter()
        .for_each(|&(kind, n, geometry, degrees)| {
            let sampler = sampler(kind, n, geometry, Normalisation::None);
            let wo = view(degrees);
            for index in 0..10_000 {
                let u = [uniform(3, index, 0), uniform(3, index, 1)];
                let Some(sample) = sampler.sample(wo, u) else {
                    continue;
                };
                let pdf = sampler.pdf(wo, sample.wi);
                assert!(
                    (sample.pdf - pdf).abs() <= 1e-6 * pdf,
                    "{kind} n {n} {} {degrees}: sample says {} and pdf {pdf} at {}",
                    geometry.id(),
                    sample.pdf,
                    sample.wi
                );
                assert!((sample.wi.length() - 1.0).abs() < 1e-12 && sample.wi.z > 0.0);
            }
        });
}

/// The estimator `value cos(theta_i) / pdf` of the specular term's directional albedo
/// against the albedo integrated by quadrature (`analysis::albedo`): within 5 standard
/// errors. With Phong geometry and the lobe's own normalisation it is at most 1.
#[test]
fn the_white_furnace_holds() {
    const DRAWS: u64 = 200_000;
    let mut cases = Vec::new();
    for normalisation in [Normalisation::Lobe, Normalisation::None] {
        for case in self::cases() {
            cases.push((case, normalisation));
        }
    }
    cases
        .par_iter()
        .for_each(|&((kind, n, geometry, degrees), normalisation)| {
            let sampler = sampler(kind, n, geometry, normalisation);
            let wo = view(degrees);
            let (mut sum, mut squares) = (0.0, 0.0);
            for index in 0..DRAWS {
                let u = [uniform(11, index, 0), uniform(11, index, 1)];
                if let Some(s) = sampler.sample(wo, u) {
                    let estimate = s.value * s.wi.z / s.pdf;
                    sum += estimate;
                    squares += estimate * estimate;
                }
            }
            let mean = sum / DRAWS as f64;
            let error = ((squares / DRAWS as f64 - mean * mean).max(0.0) / DRAWS as f64).sqrt();
            let lobe = *sampler.lobe();
            let albedo = normalisation.constant_for(&lobe)
                * specular_albedo_per_unit(&lobe, geometry, degrees.to_radians());
            let name = format!(
                "{kind} n {n} {} {} {degrees}",
                geometry.id(),
                normalisation.id()
            );
            assert!(
                (mean - albedo).abs() <= 5.0 * error + 1e-6 * albedo,
                "{name}: furnace {mean} +- {error}, albedo {albedo}"
            );
            if geometry == Geometry::Phong && normalisation == Normalisation::Lobe {
                assert!(mean <= 1.0 + 5.0 * error, "{name}: albedo {mean} above 1");
            }
        });
}

/// Each closed-form tail `int_t^1 lobe` against adaptive quadrature of the lobe, and its
/// inverse: `tail(tail_inverse(u)) = u tail(0)`.
#[test]
fn closed_form_tails_and_their_inverses_are_right() {
    for kind in LobeKind::ALL {
        for n in [1.0, 1.5, 8.0, 64.0, 512.0, 1000.0] {
            let lobe = Lobe::new(kind, Exponent::new(n));
            if lobe.warp() == Warp::Table {
                assert!(lobe.tail(0.5).is_none() && lobe.tail_inverse(0.5).is_none());
                continue;
            }
            let mut points = vec![0.0, 1.0];
            if let Some(q) = lobe.angle_quadratic() {
                points.push(q.cutoff().cos());
            }
            for t in [0.0, 0.3, 0.9, 0.99, 0.999, 0.9999] {
                let tail = lobe.tail(t).unwrap();
                let mut cuts: Vec<f64> = points.iter().copied().filter(|&p| p > t).collect();
                cuts.push(t);
                let quadrature =
                    specula::quadrature::integrate_pieces(|s| lobe.eval(s), &cuts, 1e-15);
                assert!(
                    (tail - quadrature).abs() <= 1e-10 * quadrature.max(1e-300) + 1e-16,
                    "{kind} n {n} t {t}: closed form {tail}, quadrature {quadrature}"
                );
            }
            let total = lobe.tail(0.0).unwrap();
            for u in [1e-9, 1e-4, 0.1, 0.5, 0.9, 0.999999] {
                let t = lobe.tail_inverse(u).unwrap().x;
                let back = lobe.tail(t).unwrap() / total;
                // Near the peak `t` itself is only good to its spacing, eps/2, which moves the
                // tail by `lobe(t) eps/2`.
                let resolution = 8.0 * f64::EPSILON * lobe.eval(t) / total;
                assert!(
                    (back - u).abs() <= 1e-9 * u + resolution,
                    "{kind} n {n} u {u}: t {t} gives {back}"
                );
            }
        }
    }
    // Independent of the closed forms: int_0^1 t^n = 1 / (n + 1).
    let pow = Lobe::new(LobeKind::Pow, Exponent::new(7.0));
    assert!((pow.tail(0.0).unwrap() - 0.125).abs() < 1e-15);
    assert!((integrate(|t| pow.eval(t), 0.0, 1.0, 1e-15) - 0.125).abs() < 1e-14);
}
