//! Error against `t^n` as a function of word length, measured with the core's zone scan.
//!
//! A datapath is an [`Evaluator`]: the core's [`error_figures_on`] samples each zone densely in
//! the angle (closed-form boundaries, at least `samples_per_zone` points), hands the cosines
//! here, and compares with `cos(g)^n` in `f64`. The datapath sees its inputs as hardware
//! would: `t` (or `g = acos t`) rounded to `UQ1.(W-1)`, so input quantisation is part of the
//! error, as it is on silicon. At `W <= 16` the scan's points outnumber the representable
//! inputs of each zone, so every representable input is visited (exhaustive in effect).

use serde::Serialize;
use specula::analysis::{error_figures_on, ErrorFigures, Evaluator, Precision, ZoneSamples};
use specula::{Exponent, Lobe};

use crate::datapath::{Datapath, Resources};
use crate::fixed::Rounding;
use crate::lobes::{HwError, HwLobe};

/// A datapath at one word length as an [`Evaluator`].
pub struct HwEvaluator {
    lobe: HwLobe,
    bits: u32,
    datapath: Datapath,
    /// The input slot for `t` (or `g`) followed by the material's inputs, prepared once.
    inputs: Vec<i64>,
    /// Every node's value, reused across evaluations.
    values: Vec<i64>,
}

impl HwEvaluator {
    /// The datapath for `lobe` at `bits`, evaluating with integer exponent `n`.
    pub fn new(lobe: HwLobe, bits: u32, n: u32) -> Result<Self, HwError> {
        Ok(Self {
            lobe,
            bits,
            datapath: lobe.build(bits)?,
            inputs: core::iter::once(0)
                .chain(lobe.material_inputs(bits, n))
                .collect(),
            values: Vec::new(),
        })
    }
}

impl Evaluator for HwEvaluator {
    fn name(&self) -> &'static str {
        "fixed-point"
    }

    fn evaluate(&mut self, _lobe: &Lobe, cosines: &[f64]) -> Vec<f64> {
        let unit = HwLobe::unit_format(self.bits);
        // The samples are sorted, and at narrow widths runs of them quantise to the same
        // input: the datapath is a pure function of it, so a run is evaluated once.
        let mut last: Option<(i64, f64)> = None;
        cosines
            .iter()
            .map(|&t| {
                let input = if self.lobe.takes_angle() {
                    t.clamp(-1.0, 1.0).acos()
                } else {
                    t
                };
                let raw = unit.quantize(input, Rounding::HalfEven);
                match last {
                    Some((previous, value)) if previous == raw => value,
                    _ => {
                        self.inputs[0] = raw;
                        let value = HwLobe::value(
                            self.bits,
                            self.datapath.eval_in(&self.inputs, &mut self.values),
                        );
                        last = Some((raw, value));
                        value
                    }
                }
            })
            .collect()
    }
}

/// One row of the error-against-width table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WidthRow {
    /// The word length.
    pub bits: u32,
    /// The datapath's error figures.
    pub errors: ErrorFigures,
    /// What it costs.
    pub resources: Resources,
}

/// A datapath's errors and resources over a range of word lengths, beside its float model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WidthSweep {
    /// The datapath.
    pub lobe: HwLobe,
    /// The exponent.
    pub n: u32,
    /// The float model's figures (`f64`): what the hardware is held to.
    pub float: ErrorFigures,
    /// One row per word length.
    pub rows: Vec<WidthRow>,
}

/// How far above the float model's epicentre error a datapath may be and still "meet" it.
pub const MEETS_TOLERANCE: f64 = 1.1;

impl WidthSweep {
    /// The smallest word length whose epicentre max relative error is within
    /// [`MEETS_TOLERANCE`] times the float model's, if any in the sweep.
    #[must_use]
    pub fn minimum_width(&self) -> Option<u32> {
        let bound = self.float.epicentre_max_rel * MEETS_TOLERANCE;
        self.rows
            .iter()
            .find(|row| row.errors.epicentre_max_rel <= bound)
            .map(|row| row.bits)
    }
}

/// Errors and resources of `lobe` for every word length in `bits`, at integer exponent `n`,
/// sampling each zone at `samples_per_zone` angles; `progress` is called after each width.
pub fn sweep(
    lobe: HwLobe,
    n: u32,
    bits: impl IntoIterator<Item = u32>,
    samples_per_zone: usize,
    progress: &mut dyn FnMut(u32),
) -> Result<WidthSweep, HwError> {
    let exponent = Exponent::try_new(f64::from(n)).map_err(|_| HwError::Exponent(f64::from(n)))?;
    let float_lobe = Lobe::new(lobe.float_kind(), exponent);
    let samples = ZoneSamples::new(exponent, samples_per_zone);
    let float = error_figures_on(&float_lobe, &mut Precision::F64, &samples);
    let mut rows = Vec::new();
    for bits in bits {
        let mut evaluator = HwEvaluator::new(lobe, bits, n)?;
        let errors = error_figures_on(&float_lobe, &mut evaluator, &samples);
        rows.push(WidthRow {
            bits,
            errors,
            resources: evaluator.datapath.resources(),
        });
        progress(bits);
    }
    Ok(WidthSweep {
        lobe,
        n,
        float,
        rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Evaluating a run of samples that quantise alike once gives what evaluating each gives.
    #[test]
    fn batches_agree_with_one_evaluation_per_sample() {
        let n = 64;
        let lobe_n = Exponent::new(f64::from(n));
        for lobe in HwLobe::ALL {
            let bits = 8;
            let mut evaluator = HwEvaluator::new(lobe, bits, n).unwrap();
            // Sorted, dense enough that neighbours share an 8-bit input, plus a lone repeat.
            let cosines: Vec<f64> = (0..=400)
                .map(|i| 0.9 + 0.1 * f64::from(i) / 400.0)
                .chain([0.5, 0.5, 0.95])
                .collect();
            let batch = evaluator.evaluate(&Lobe::new(lobe.float_kind(), lobe_n), &cosines);
            let datapath = lobe.build(bits).unwrap();
            for (&t, &value) in cosines.iter().zip(&batch) {
                let input = if lobe.takes_angle() { t.acos() } else { t };
                let alone = HwLobe::value(bits, datapath.eval(&lobe.inputs(bits, input, n)));
                assert_eq!(value, alone, "{} at t = {t}", lobe.id());
            }
        }
    }
}
