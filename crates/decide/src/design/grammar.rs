//! The structures `specula design` searches, enumerated from the formula language's operations
//! rather than listed by hand.
//!
//! With `u = 1 - t`, a lobe is an **outer** operation over an **inner** function of `u`:
//!
//! - `exp2` of a series of `n ln t`: a polynomial of `u` of degree 1 to 3 without constant
//!   term, or Padé's ratio `a u / (1 - b u)`;
//! - a power `2^k`, `k` in `0..=7` (squarings), of a peak-shaped function, 1 at `u = 0`: a
//!   polynomial of degree 1 to 3 cut where it stops falling, a two-piece linear function (a
//!   select at a knot), or Padé's ratio `(1 - a u) / (1 + b u)`.
//!
//! Compositions the grammar leaves out are the same lobes at more cost: a power of `exp2` is
//! `exp2` of a multiple (its coefficients absorb the power), a power of a power is one power,
//! and `exp2` of a peak-shaped function has its peak at `2^1`, not 1.
//!
//! **The cost bound** is the formula's operation count per evaluation ([`Formula::operations`]:
//! what the recorded expression runs once `n`'s constants are prepared), so the bound counts
//! what every backend is generated from. Each structure is then pruned before its fit (over
//! the bound; a transcendental where the target takes none), pruned by its fit (the coarse
//! grids' best misses the bounds, so it is never verified), or kept (verified, then costed).

use serde::Serialize;
use specula::formula::{Definition, Formula};

use super::families::Family;

/// The cost bound when none is given: every structure of the grammar up to the largest power
/// of a cubic (the costliest inner function) is within it.
pub const DEFAULT_MAX_OPERATIONS: usize = 16;

/// The cost bound on the FPGA when none is given: there every verified structure is compiled,
/// swept and synthesized at each sampled exponent (a minute or more each from an empty
/// cache), and a structure of more than 10 operations is a longer pipeline than every
/// built-in datapath but `logexp`'s; 10 admits the families searched before the grammar
/// (the linear powers to 64, the quadratic to 16, the rational to 4) and the hinge and cubic
/// powers that fit within it.
pub const DEFAULT_MAX_OPERATIONS_FPGA: usize = 10;

/// The default cost bound on `target`.
#[must_use]
pub fn default_max_operations(target: crate::Target) -> usize {
    if target == crate::Target::Fpga {
        DEFAULT_MAX_OPERATIONS_FPGA
    } else {
        DEFAULT_MAX_OPERATIONS
    }
}

/// One structure of the grammar and what became of it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Enumerated {
    /// The family's id (`cubic-pow16`).
    pub structure: String,
    /// Operations per evaluation.
    pub operations: usize,
    /// What became of it.
    pub fate: Fate,
}

/// What the search did with a structure.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "fate", content = "why", rename_all = "kebab-case")]
pub enum Fate {
    /// Pruned before its fit: why.
    Pruned(String),
    /// Fitted; its best fit on the coarse grids missed the bounds, so never verified.
    FitMissed,
    /// Fitted and verified (whether it then met every bound is the design's row).
    Kept,
}

/// Operations per evaluation of `family`'s formula (its coefficients at the fit's start: the
/// operations do not depend on their values).
#[must_use]
pub fn operations(family: Family) -> usize {
    Formula::compile(Definition {
        name: family.id(),
        description: None,
        formula: family.formula(&family.start()),
        tail: None,
        parameters: Default::default(),
    })
    .map_or(usize::MAX, |formula| formula.operations())
}

/// Every structure of the grammar with its operations: those to fit (`Fate::Kept` until the
/// fit says otherwise) and those pruned before, with why.
#[must_use]
pub fn enumerate(max_operations: usize, no_transcendentals: bool) -> Vec<(Family, Enumerated)> {
    Family::all()
        .into_iter()
        .map(|family| {
            let operations = operations(family);
            let fate = if no_transcendentals && family.transcendental() {
                Fate::Pruned("an exp2 per evaluation, which the target takes none of".to_owned())
            } else if operations > max_operations {
                Fate::Pruned(format!(
                    "{operations} operations, over the cost bound of {max_operations} \
                     (--max-operations)"
                ))
            } else {
                Fate::Kept
            };
            (
                family,
                Enumerated {
                    structure: family.id(),
                    operations,
                    fate,
                },
            )
        })
        .collect()
}

/// The counts of an enumeration: enumerated, pruned before the fit, pruned by the fit, kept.
#[must_use]
pub fn counts(enumerated: &[Enumerated]) -> [usize; 4] {
    let count = |f: fn(&Fate) -> bool| enumerated.iter().filter(|e| f(&e.fate)).count();
    [
        enumerated.len(),
        count(|f| matches!(f, Fate::Pruned(_))),
        count(|f| matches!(f, Fate::FitMissed)),
        count(|f| matches!(f, Fate::Kept)),
    ]
}
