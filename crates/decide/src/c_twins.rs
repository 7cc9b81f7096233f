//! The C twins: each lobe that a C programmer would write as a one-line loop (`pow` as
//! `exp2f(n*log2f(t))`, `logexp` and `sg` through glibc's libmvec, `schlick`, `cosquad` with
//! its clamp at 0), in `c_twins.c`, compiled here with [`FLAGS`] and measured over the same
//! cosines, the same way and in the same run as specula's kernels ([`crate::rates`]). Their
//! values are a second opinion on specula's: each twin's largest relative difference from
//! the lobe's batch path is reported beside its speed.

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

use serde::Serialize;
use specula::simd::Level;
use specula::{Exponent, Lobe, LobeKind};

use crate::rates::{cosines, L1_SIZE, MIN_SECONDS, ROUNDS_PER_CLOCK};

/// The twins' source.
const SOURCE: &str = include_str!("c_twins.c");

/// What the twins are compiled with: the flags a C programmer tunes a loop with on x86-64.
pub const FLAGS: [&str; 4] = ["-O3", "-ffast-math", "-mavx2", "-mfma"];

/// One twin's figures.
#[derive(Clone, Debug, Serialize)]
pub struct CTwin {
    /// The lobe's id.
    pub lobe: String,
    /// Evaluations per second of the C loop, L1, one thread (best of 3).
    pub rate: f64,
    /// The largest `|c - specula| / max(|c|, |specula|)` over the cosines.
    pub max_rel_difference: f64,
}

/// Every twin, and what compiled them.
#[derive(Clone, Debug, Serialize)]
pub struct CTwins {
    /// The compiler's first line of `--version`.
    pub compiler: String,
    /// [`FLAGS`], joined.
    pub flags: String,
    /// One per twin, in `c_twins.c`'s order.
    pub twins: Vec<CTwin>,
}

/// Compiles and runs the twins at `n` with the C compiler `cc` (`gcc` or `clang`).
///
/// # Errors
/// When `cc` is missing or fails, the CPU lacks AVX2 and FMA, or the twins' output cannot be
/// read: the message names which.
pub fn measure(n: Exponent, cc: &str) -> Result<CTwins, String> {
    if Level::detect() != Level::Avx2 {
        return Err("the C twins are compiled for AVX2 and FMA, which this CPU lacks".into());
    }
    let compiler = Command::new(cc)
        .arg("--version")
        .output()
        .ok()
        .filter(|output| output.status.success())
        .and_then(|output| {
            String::from_utf8_lossy(&output.stdout)
                .lines()
                .next()
                .map(str::to_owned)
        })
        .ok_or_else(|| {
            format!("no C compiler `{cc}` (install gcc: apt-get install gcc, or set CC)")
        })?;
    let dir = specula_temporaries::dir("c-twins-")
        .map_err(|e| format!("C twins: a temporary folder: {e}"))?;
    let source = dir.path().join("c_twins.c");
    std::fs::write(&source, SOURCE).map_err(|e| format!("C twins: {e}"))?;
    let program = dir.path().join("c_twins");
    compile(cc, &source, &program)?;
    let running = |e: std::io::Error| format!("C twins: running them: {e}");
    let mut child = Command::new(&program)
        .args([
            n.get().to_string(),
            MIN_SECONDS.to_string(),
            ROUNDS_PER_CLOCK.to_string(),
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(running)?;
    // The cosines go in as text, shortest round-trip decimals, which `scanf` reads exactly.
    let cosines: String = cosines(L1_SIZE)
        .iter()
        .map(|t| format!("{t:?}\n"))
        .collect();
    child
        .stdin
        .take()
        .ok_or("C twins: no standard input")?
        .write_all(cosines.as_bytes())
        .map_err(running)?;
    let output = child.wait_with_output().map_err(running)?;
    if !output.status.success() {
        return Err(format!("C twins: exited with {}", output.status));
    }
    let twins = String::from_utf8_lossy(&output.stdout)
        .lines()
        .map(|line| twin(line, n))
        .collect::<Result<_, _>>()?;
    Ok(CTwins {
        compiler,
        flags: FLAGS.join(" "),
        twins,
    })
}

fn compile(cc: &str, source: &Path, program: &Path) -> Result<(), String> {
    let output = Command::new(cc)
        .args(FLAGS)
        .arg("-o")
        .arg(program)
        .arg(source)
        .arg("-lm")
        .output()
        .map_err(|e| format!("C twins: running {cc}: {e}"))?;
    if output.status.success() {
        Ok(())
    } else {
        Err(format!(
            "C twins: {cc} failed: {}",
            String::from_utf8_lossy(&output.stderr).trim()
        ))
    }
}

/// One line of the twins' output: the id, the rate, then the values at [`cosines`].
fn twin(line: &str, n: Exponent) -> Result<CTwin, String> {
    let unreadable = || format!("C twins: an unreadable line: {:.60}", line);
    let mut fields = line.split_ascii_whitespace();
    let id = fields.next().ok_or_else(unreadable)?;
    let kind: LobeKind = id
        .parse()
        .map_err(|_| format!("C twins: `{id}` is no lobe"))?;
    let rate: f64 = fields
        .next()
        .and_then(|f| f.parse().ok())
        .ok_or_else(unreadable)?;
    let theirs: Vec<f32> = fields
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| unreadable())?;
    if theirs.len() != L1_SIZE {
        return Err(unreadable());
    }
    let ts = cosines(L1_SIZE);
    let mut mine = vec![0.0; L1_SIZE];
    Lobe::new(kind, n).eval_batch(&ts, &mut mine);
    let max_rel_difference = mine
        .iter()
        .zip(&theirs)
        .map(|(&a, &b)| {
            let scale = a.abs().max(b.abs());
            if !(a.is_finite() && b.is_finite()) {
                f64::INFINITY
            } else if scale == 0.0 {
                0.0
            } else {
                f64::from((a - b).abs() / scale)
            }
        })
        .fold(0.0, f64::max);
    Ok(CTwin {
        lobe: kind.to_string(),
        rate,
        max_rel_difference,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The twins compile and run, and their independently written formulas agree with
    /// specula's kernels: to a few `f32` roundings where both compute the same expression
    /// (`cosquad`, `schlick`), within the fast pow's and fast `exp2`'s stated errors where
    /// specula approximates what libm computes (`pow`, `sg`), and within `logexp`'s own
    /// `log2` approximation (its kernel's, not the formula's, error) against libmvec's.
    #[test]
    fn the_twins_agree_with_the_kernels() {
        let twins = match measure(Exponent::new(64.0), "gcc") {
            Ok(twins) => twins,
            Err(error) if std::env::var("CI").as_deref() != Ok("true") => {
                eprintln!("skipped: {error}");
                return;
            }
            Err(error) => panic!("CI=true requires the C twins: {error}"),
        };
        let ids: Vec<&str> = twins.twins.iter().map(|t| t.lobe.as_str()).collect();
        assert_eq!(ids, ["pow", "schlick", "logexp", "cosquad", "sg"]);
        for twin in &twins.twins {
            let bound = if twin.lobe == "logexp" { 1e-3 } else { 2e-5 };
            assert!(
                twin.max_rel_difference <= bound,
                "{}: {} above {bound}",
                twin.lobe,
                twin.max_rel_difference
            );
            assert!(twin.rate.is_finite() && twin.rate > 0.0, "{twin:?}");
        }
    }
}
