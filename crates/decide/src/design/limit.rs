//! The limit of a family: the least epicentre error any member of it reaches at one `n`, from
//! Sollya's Remez algorithm and certified by its `supnorm`, beside the designed lobe's error
//! there. A design fits one set of coefficients across the whole range of `n`, its constants
//! closed forms of `n`; the optimum is fitted at that `n` alone, so the ratio says what the
//! closed forms cost against per-`n` fits, and an error below the optimum would be a bug in
//! one of the two.
//!
//! With `u = 1 - t` and the epicentre `u` in `[0, u_e]`, `u_e = 1 - 2^(-1/n)`:
//! - `poly-powM`, a lobe `p(u)^M` with `p(0) = 1` of degree `d`: its relative error is
//!   `(1 + delta)^M - 1`, `delta` the relative error of `p` against `g = (1 - u)^(n/M)`.
//!   Sollya finds `p = 1 + u q(u)` minimising `max |delta|` (`remez` of `(g - 1) / g` in the
//!   weight `u / g`, degree `d - 1`) and bounds its `delta` (`supnorm`, relative). Any `p`'s
//!   `max |delta|` is at least the minimax `D`, and `|(1 + delta)^M - 1| >= 1 - (1 - |delta|)^M`,
//!   so no member's lobe error is below `1 - (1 - D)^M`.
//! - `exp2-*`, a lobe `exp(-P(u))` with `P(0) = 0` of degree `d`: its relative error is
//!   `e^eps - 1`, `eps` the error of `P` against `-n ln(1 - u)`. Sollya finds `P = u k(u)`
//!   minimising `max |eps|` (`remez` in the weight `u`) and bounds it (`supnorm`, absolute);
//!   no member's lobe error is below `1 - e^(-D)`.
//!
//! Remez stops within [`QUALITY`] of the minimax: `D` is at least the certified bound over
//! `1 + QUALITY`, which is what [`Optimum::lower`] uses.

use std::process::Command;

use rayon::prelude::*;
use specula::Exponent;

use super::families::Family;

/// The relative distance from the true minimax at which Sollya's Remez stops.
pub const QUALITY: f64 = 1e-6;

/// How far above its family's optimum a designed lobe's error may lie at an `n` of the test's
/// design (`gpu-amd`, 16..128 at 0.5 %) where the optimum is at least [`BINDING`] of the
/// bound: there the bound makes the design work near its family's limit. Measured 1.0 to 48
/// (`quadratic-pow4` at `n = 16`, one set of closed-form constants for the whole range).
/// Where the optimum is far below the bound, the fit spends nothing on accuracy nobody asked
/// for and the ratio is unbounded: the cubic families sit near 2e-5 where their optimum is
/// 1e-10 (ratios to 4e5), `exp2-cubic` falls as `1/n` where its optimum falls as `1/n^3`.
pub const MAX_RATIO: f64 = 50.0;

/// The part of the bound from which an optimum binds a design ([`MAX_RATIO`]).
pub const BINDING: f64 = 0.01;

/// A family's best at one `n`, as the lobe's epicentre relative error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Optimum {
    /// The error Sollya's own member reaches (certified from above by `supnorm`).
    pub reached: f64,
    /// No member of the family reaches less (the certified bound over `1 + QUALITY`).
    pub lower: f64,
}

/// One row of the limit table: a designed lobe at one `n` against its family's optimum.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LimitRow {
    /// The family's id.
    pub family: String,
    /// The exponent.
    pub n: f64,
    /// The designed lobe's epicentre error at `n` (the analysis's, `f64`).
    pub designed: f64,
    /// Sollya's member's error at `n`.
    pub optimum: f64,
    /// No member of the family does better than this at `n`.
    pub lower: f64,
}

/// The Sollya script computing the family's minimax at `n` and printing its certified
/// error bound (`delta` or `eps` above).
fn script(family: Family, n: f64) -> String {
    let edge = 1.0 - (-1.0 / n).exp2();
    // What is approximated, Remez's target and weight for `q` of degree `d - 1`, and the
    // member whose error supnorm bounds.
    let (g, target, weight, member, error, degree) = match family {
        Family::PolyPow { degree, squarings } => {
            let power = n / f64::from(1u32 << squarings);
            let g = format!("(1 - x)^({power:e})");
            (g, "(g - 1) / g", "x / g", "1 + x * q", "relative", degree)
        }
        Family::Exp2Poly { degree } => {
            let g = format!("-({n:e}) * log(1 - x)");
            (g, "g", "x", "x * q", "absolute", degree)
        }
        Family::HingePow { .. } | Family::RationalPow { .. } | Family::Exp2Rational => {
            unreachable!("family_optimum refuses the non-polynomial families before a script")
        }
    };
    format!(
        "verbosity = 0;\nprec = 165;\ndisplay = decimal;\ng = {g};\n\
         q = remez({target}, {}, [{edge:e} * 2^-40; {edge:e}], {weight}, {QUALITY:e});\n\
         print(sup(supnorm({member}, g, [0; {edge:e}], {error}, 2^-40)));\nquit;\n",
        degree - 1
    )
}

/// Whether Sollya runs on this machine and computes (`print(1+1)` answers `2`; a program of
/// that name that fails, or says anything else, is not it): what a stored answer that needs
/// it is keyed by, so that installing it changes the next answer.
#[must_use]
pub fn sollya_found() -> bool {
    use std::io::Write;
    let Ok(mut child) = Command::new("sollya")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
    else {
        return false;
    };
    if let Some(mut stdin) = child.stdin.take() {
        // A broken pipe is read as "not Sollya" below.
        let _ = stdin.write_all(b"print(1+1);\nquit;\n");
    }
    child.wait_with_output().is_ok_and(|output| {
        output.status.success() && String::from_utf8_lossy(&output.stdout).trim() == "2"
    })
}

/// The family's optimum at `n`, from Sollya (`sollya` on the `PATH`); `Err` names what failed.
pub fn family_optimum(family: Family, n: Exponent) -> Result<Optimum, String> {
    if !has_optimum(family) {
        return Err(format!(
            "{} is {}, and Sollya's remez finds polynomial minimax approximations only",
            family.id(),
            if matches!(family, Family::HingePow { .. }) {
                "piecewise"
            } else {
                "rational"
            }
        ));
    }
    let n = n.get();
    // `(1 - u)^(n/M)` is itself a polynomial of the family's degree: the family holds `t^n`
    // (and Sollya's supnorm of a zero error fails).
    if let Family::PolyPow { degree, squarings } = family {
        let power = n / f64::from(1u32 << squarings);
        if power.fract() == 0.0 && power <= f64::from(degree) {
            return Ok(Optimum {
                reached: 0.0,
                lower: 0.0,
            });
        }
    }
    let output = Command::new("sollya")
        .arg("--warnonstderr")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .and_then(|mut child| {
            use std::io::Write as _;
            child.stdin.take().map_or(Ok(()), |mut input| {
                input.write_all(script(family, n).as_bytes())
            })?;
            child.wait_with_output()
        })
        .map_err(|e| format!("cannot run sollya ({e}); apt-get install sollya"))?;
    let text = String::from_utf8_lossy(&output.stdout);
    let bound: f64 = text
        .lines()
        .rev()
        .find_map(|line| line.trim().parse().ok())
        .filter(|b: &f64| b.is_finite() && *b >= 0.0)
        .ok_or_else(|| {
            format!(
                "sollya found no minimax for {} at n = {n}: {}",
                family.id(),
                String::from_utf8_lossy(&output.stderr)
                    .lines()
                    .next()
                    .unwrap_or("no output")
            )
        })?;
    let least = bound / (1.0 + QUALITY);
    Ok(match family {
        Family::PolyPow { squarings, .. } => {
            let power = f64::from(1u32 << squarings);
            Optimum {
                reached: (1.0 + bound).powf(power) - 1.0,
                lower: 1.0 - (1.0 - least).powf(power),
            }
        }
        Family::Exp2Poly { .. } => Optimum {
            reached: bound.exp_m1(),
            lower: -(-least).exp_m1(),
        },
        Family::HingePow { .. } | Family::RationalPow { .. } | Family::Exp2Rational => {
            unreachable!("refused above")
        }
    })
}

/// Whether the family's optimum is a polynomial minimax, which Sollya's `remez` finds.
#[must_use]
pub fn has_optimum(family: Family) -> bool {
    matches!(family, Family::PolyPow { .. } | Family::Exp2Poly { .. })
}

/// The limit table of `design`'s lobes over `[low, high]`: each verified design of a
/// polynomial family ([`has_optimum`]; one per family) at `steps + 1` log-spaced exponents.
pub fn limit_table(
    designed: &[super::DesignedLobe],
    (low, high): (Exponent, Exponent),
    steps: u32,
) -> Result<Vec<LimitRow>, String> {
    let exponents = crate::log_spaced(low, high, steps);
    let mut jobs = Vec::new();
    for lobe in designed.iter().filter(|d| d.verified) {
        let Some(family) = Family::all()
            .into_iter()
            .find(|f| f.id() == lobe.family)
            .filter(|&f| has_optimum(f))
        else {
            continue;
        };
        let Some(kind) = lobe.kind() else { continue };
        jobs.extend(exponents.iter().map(|&n| (lobe, family, kind, n)));
    }
    // One Sollya process a row, side by side: most of a row's time is Sollya's.
    jobs.par_iter()
        .map(|&(lobe, family, kind, n)| {
            let checked = specula::Lobe::checked(kind, n).map_err(|e| e.to_string())?;
            let designed = crate::figures::f64_figures(&checked).epicentre_max_rel;
            let optimum = family_optimum(family, n)?;
            Ok(LimitRow {
                family: lobe.family.clone(),
                n: n.get(),
                designed,
                optimum: optimum.reached,
                lower: optimum.lower,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use indicatif::ProgressBar;

    use super::*;
    use crate::design::fit::Bounds;
    use crate::design::{search, DesignRequest};
    use crate::Target;

    /// Whether `sollya` runs; under `CI=true` (where `.ci/run` installs it) its absence fails.
    fn have_sollya() -> bool {
        let found = sollya_found();
        assert!(
            found || std::env::var("CI").as_deref() != Ok("true"),
            "sollya is not installed, and CI=true requires it: apt-get install sollya"
        );
        found
    }

    /// The largest `|lobe(u) / t^n - 1|` over the epicentre, on a fine grid.
    fn epicentre_error(lobe: impl Fn(f64) -> f64, n: f64) -> f64 {
        let edge = 1.0 - (-1.0 / n).exp2();
        (0..=4000)
            .map(|k| edge * f64::from(k) / 4000.0)
            .map(|u| (lobe(u) / (1.0 - u).powf(n) - 1.0).abs())
            .fold(0.0, f64::max)
    }

    /// For a one-coefficient family, `(1 - s u)^M`, the optimum searched directly over `s`
    /// (golden sections of the grid's error, which is unimodal in `s`) lies between Sollya's
    /// lower bound and its member's error; the certification is tight; and members that are
    /// not optimal (the truncated series the fit starts from) never beat the lower bound.
    #[test]
    fn sollya_brackets_the_optimum_a_direct_search_finds() {
        if !have_sollya() {
            return;
        }
        for (squarings, n) in [(4u8, 64.0), (3, 16.0), (5, 300.0)] {
            let family = Family::PolyPow {
                degree: 1,
                squarings,
            };
            let power = f64::from(1u32 << squarings);
            let optimum = family_optimum(family, Exponent::new(n)).unwrap();
            let label = format!("{} at n = {n}", family.id());
            assert!(optimum.lower <= optimum.reached, "{label}: {optimum:?}");
            assert!(
                optimum.reached < optimum.lower * 1.05,
                "{label}: {optimum:?}"
            );
            let error = |s: f64| epicentre_error(|u| (1.0 - s * u).max(0.0).powf(power), n);
            let (mut a, mut b) = (0.5 * n / power, 1.5 * n / power);
            for _ in 0..200 {
                let (c, d) = (b - 0.618 * (b - a), a + 0.618 * (b - a));
                if error(c) < error(d) {
                    b = d;
                } else {
                    a = c;
                }
            }
            let direct = error(0.5 * (a + b));
            assert!(
                optimum.lower <= direct * (1.0 + 1e-9) && direct <= optimum.reached * 1.001,
                "{label}: direct {direct}, Sollya {optimum:?}"
            );
            let series = epicentre_error(|u| family.eval(&family.start(), n, u), n);
            assert!(series >= optimum.lower, "{label}: the series {series}");
        }
        for family in [
            Family::Exp2Poly { degree: 2 },
            Family::PolyPow {
                degree: 2,
                squarings: 3,
            },
        ] {
            for n in [8.0, 64.0, 512.0] {
                let optimum = family_optimum(family, Exponent::new(n)).unwrap();
                let series = epicentre_error(|u| family.eval(&family.start(), n, u), n);
                let label = format!("{} at n = {n}", family.id());
                assert!(optimum.lower <= optimum.reached, "{label}: {optimum:?}");
                assert!(
                    series >= optimum.lower,
                    "{label}: series {series}, {optimum:?}"
                );
            }
        }
    }

    /// A real design's lobes never beat their family's optimum at any sampled `n` (no error
    /// below the lower bound), and stay within [`MAX_RATIO`] of it where it binds.
    #[test]
    fn designed_lobes_stay_above_and_near_their_familys_optimum() {
        if !have_sollya() {
            return;
        }
        let request = DesignRequest {
            target: Target::GpuAmd,
            gpu: None,
            range: (Exponent::new(16.0), Exponent::new(128.0)),
            bounds: Bounds {
                epicentre: 0.005,
                whole: 0.01,
                energy: None,
            },
            no_transcendentals: false,
            also: Vec::new(),
            max_operations: crate::design::grammar::DEFAULT_MAX_OPERATIONS,
        };
        let designed: Vec<_> = search(&request, None, &ProgressBar::hidden())
            .into_iter()
            .filter(|lobe| lobe.verified)
            .collect();
        assert!(!designed.is_empty());
        let rows = limit_table(&designed, request.range, 3).unwrap();
        assert!(!rows.is_empty());
        for row in &rows {
            assert!(row.designed >= row.lower, "{row:?}");
            assert!(
                row.optimum < BINDING * request.bounds.epicentre
                    || row.designed <= MAX_RATIO * row.optimum,
                "{row:?}"
            );
        }
    }
}
