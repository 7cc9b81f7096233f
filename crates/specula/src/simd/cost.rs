//! The throughput bound of a kernel: from its [`Instructions`] per vector and the machine's
//! measured [`Peaks`], the fastest it could possibly run on one thread.
//!
//! Each resource gives a lower bound on the time per vector, and the largest wins:
//! - each instruction class alone, at its measured peak (`count / peak`);
//! - the FMA pipes, shared by `fma` and `mul` (multiplies run on the FMA units on every x86
//!   core since Haswell and Zen): `fma / peak(fma) + mul / peak(mul)`;
//! - the divider, shared by `div` and `sqrt`: `div / peak(div) + sqrt / peak(sqrt)`;
//! - dispatch: every vector instruction at the measured peak of an independent mix;
//! - memory: one load and one store per vector, at the driver's measured L1 copy rate.
//!
//! The peaks are measured, never typed, so a kernel measured above 100 % of its bound means a
//! peak was measured too low or a resource is missing here: the model is wrong, not the kernel
//! fast. `specula bench lobes` says so when it happens.

use serde::Serialize;

use super::tally::{Class, Instructions};
use super::Level;

/// Measured single-thread throughputs at one [`Level`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Peaks {
    /// Where they were measured.
    pub level: Level,
    /// Vector instructions per second of each class alone, `None` where not measured
    /// (serialised as an object keyed by the class's name, as a kernel's instruction counts
    /// are: `{"fma": ..., "mul": ..., "min/max": ...}`).
    #[serde(serialize_with = "by_class_name")]
    pub per_class: [Option<f64>; Class::ALL.len()],
    /// Vector instructions per second of an independent mix of `fma`, `add` and `and`.
    pub dispatch: f64,
    /// Vectors per second the driver loads and stores with nothing in between (L1).
    pub copy: f64,
}

/// `per_class` as an object keyed by each class's name ([`Class::name`], the keys of a
/// kernel's [`crate::simd::tally::Instructions`]), in [`Class::ALL`]'s order.
fn by_class_name<S: serde::Serializer>(
    per_class: &[Option<f64>; Class::ALL.len()],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut map = serializer.serialize_map(Some(per_class.len()))?;
    for (class, rate) in Class::ALL.iter().zip(per_class) {
        map.serialize_entry(class.name(), rate)?;
    }
    map.end()
}

/// The resource that bounds a kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Limit {
    /// One instruction class.
    Class(Class),
    /// The FMA pipes (`fma` + `mul`).
    FmaPipes,
    /// The divider (`div` + `sqrt`).
    Divider,
    /// Instruction dispatch.
    Dispatch,
    /// Loads and stores.
    Memory,
}

impl core::fmt::Display for Limit {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Limit::Class(class) => f.write_str(class.name()),
            Limit::FmaPipes => f.write_str("fma pipes"),
            Limit::Divider => f.write_str("divider"),
            Limit::Dispatch => f.write_str("dispatch"),
            Limit::Memory => f.write_str("load/store"),
        }
    }
}

/// A kernel's throughput bound.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bound {
    /// Evaluations (lanes) per second, at most.
    pub evals_per_second: f64,
    /// What sets it.
    pub limit: Limit,
}

impl Peaks {
    /// The larger of two measurements of every peak: a clock that drifts between measuring
    /// the peaks and the kernels (turbo, a neighbour on a shared host) only ever makes a
    /// measured peak too low, so the best seen is the closest to the machine's.
    #[must_use]
    pub fn best_of(&self, other: &Peaks) -> Peaks {
        let mut per_class = self.per_class;
        for (mine, theirs) in per_class.iter_mut().zip(other.per_class) {
            *mine = match (*mine, theirs) {
                (Some(a), Some(b)) => Some(a.max(b)),
                (a, b) => a.or(b),
            };
        }
        Peaks {
            level: self.level,
            per_class,
            dispatch: self.dispatch.max(other.dispatch),
            copy: self.copy.max(other.copy),
        }
    }

    /// The peak of `class`, if measured.
    #[must_use]
    pub fn of(&self, class: Class) -> Option<f64> {
        self.per_class[class as usize]
    }

    /// The bound of a kernel executing `instructions` per vector of `level.lanes()` lanes.
    #[must_use]
    pub fn bound(&self, instructions: &Instructions) -> Bound {
        let count = |class: Class| f64::from(instructions.get(class));
        let time = |class: Class| self.of(class).map_or(0.0, |peak| count(class) / peak);
        let mut candidates: Vec<(f64, Limit)> = Class::ALL
            .iter()
            .map(|&class| (time(class), Limit::Class(class)))
            .collect();
        candidates.extend([
            (time(Class::Fma) + time(Class::Mul), Limit::FmaPipes),
            (time(Class::Div) + time(Class::Sqrt), Limit::Divider),
            (
                f64::from(instructions.total()) / self.dispatch,
                Limit::Dispatch,
            ),
            (1.0 / self.copy, Limit::Memory),
        ]);
        // Strictly greater: on a tie, the simplest explanation (listed first) is kept.
        let (seconds, limit) =
            candidates.into_iter().fold(
                (0.0, Limit::Memory),
                |best, c| if c.0 > best.0 { c } else { best },
            );
        Bound {
            evals_per_second: self.level.lanes() as f64 / seconds,
            limit,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Round numbers for a hypothetical 8-lane machine at 1 GHz: 2 FMAs or multiplies, 2 adds, 1
    /// shift per
    /// cycle, a divide every 4 cycles, 4 instructions dispatched and 1 vector copied per cycle.
    fn peaks() -> Peaks {
        let mut per_class = [None; Class::ALL.len()];
        per_class[Class::Fma as usize] = Some(2e9);
        per_class[Class::Mul as usize] = Some(2e9);
        per_class[Class::Add as usize] = Some(2e9);
        per_class[Class::Shift as usize] = Some(1e9);
        per_class[Class::Div as usize] = Some(0.25e9);
        per_class[Class::Sqrt as usize] = Some(0.25e9);
        Peaks {
            level: Level::Avx2,
            per_class,
            dispatch: 4e9,
            copy: 1e9,
        }
    }

    #[test]
    fn each_peak_is_named_by_its_class_in_json() {
        let json = serde_json::to_value(peaks()).expect("serialises");
        let per_class = json["per_class"]
            .as_object()
            .expect("an object, not an array");
        assert_eq!(per_class.len(), Class::ALL.len());
        assert_eq!(per_class["fma"], 2e9);
        assert_eq!(per_class["div"], 0.25e9);
        assert!(per_class["cvt"].is_null() && per_class["min/max"].is_null());
        let names: Vec<&str> = per_class.keys().map(String::as_str).collect();
        let expected: Vec<&str> = Class::ALL.iter().map(|class| class.name()).collect();
        assert_eq!(names.len(), expected.len());
        assert!(expected.iter().all(|name| names.contains(name)));
    }

    #[test]
    fn the_best_of_two_measurements_keeps_every_higher_peak() {
        let low = peaks();
        let mut high = peaks();
        high.per_class[Class::Div as usize] = Some(0.5e9);
        high.per_class[Class::Fma as usize] = Some(1e9);
        high.per_class[Class::Convert as usize] = Some(3e9);
        high.dispatch = 5e9;
        let best = low.best_of(&high);
        assert_eq!(best.of(Class::Div), Some(0.5e9));
        assert_eq!(best.of(Class::Fma), Some(2e9));
        assert_eq!(best.of(Class::Convert), Some(3e9));
        assert_eq!(best.of(Class::Compare), None);
        assert_eq!((best.dispatch, best.copy), (5e9, 1e9));
    }

    #[test]
    fn a_known_loop_is_bounded_by_the_resource_it_saturates() {
        // 8 FMAs + 2 multiplies: 10 on 2 pipes, 5 cycles per vector of 8 -> 1.6 G/s.
        let horner = Instructions::of(&[(Class::Fma, 8), (Class::Mul, 2)]);
        let bound = peaks().bound(&horner);
        assert_eq!(bound.limit, Limit::FmaPipes);
        assert!((bound.evals_per_second - 1.6e9).abs() < 1.0);
        // One divide and one square root share the divider: 8 cycles -> 1 G/s.
        let root = Instructions::of(&[(Class::Div, 1), (Class::Sqrt, 1), (Class::Add, 1)]);
        let bound = peaks().bound(&root);
        assert_eq!(bound.limit, Limit::Divider);
        assert!((bound.evals_per_second - 1e9).abs() < 1.0);
        // 3 fma + 3 add + 6 logic: no pipe full, 12 dispatched at 4 a cycle -> 3 cycles.
        let mix = Instructions::of(&[(Class::Fma, 3), (Class::Add, 3), (Class::Logic, 6)]);
        let bound = peaks().bound(&mix);
        assert_eq!(bound.limit, Limit::Dispatch);
        assert!((bound.evals_per_second - 8e9 / 3.0).abs() < 1.0);
        // Nothing to compute: the copy.
        let bound = peaks().bound(&Instructions::NONE);
        assert_eq!(bound.limit, Limit::Memory);
        assert!((bound.evals_per_second - 8e9).abs() < 1.0);
        // Three shifts at one a cycle.
        let shifts = Instructions::of(&[(Class::Shift, 3)]);
        assert_eq!(peaks().bound(&shifts).limit, Limit::Class(Class::Shift));
    }
}
