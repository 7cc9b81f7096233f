//! Error figures of a lobe against `t^n`, per zone (SPEC section 4).
//!
//! Each zone is sampled uniformly in the angle, endpoints included, with its boundaries from
//! the closed forms of [`zones`](crate::zones). The reference is `cos(g)^n` in `f64`; the lobe
//! is evaluated by an [`Evaluator`] at the cosines of the same angles: [`Precision`] on the CPU
//! (for `f32`, the cosine is rounded to `f32` first, as an `f32` pipeline would see it), or any
//! other backend (the GPU crate's compute shader) that implements the trait.

use serde::Serialize;

use crate::{Lobe, Zone};

/// The arithmetic a lobe is evaluated in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Precision {
    /// The `f64` reference path.
    #[default]
    F64,
    /// The `f32` fast path.
    F32,
    /// The `f32` batch path (SIMD, `Lobe::eval_batch`).
    F32Simd,
}

impl Precision {
    /// Every CPU precision.
    pub const ALL: [Precision; 3] = [Precision::F64, Precision::F32, Precision::F32Simd];

    /// Its name (`f64`, `f32`, `simd`), as `specula analyze --backend` takes it.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
            Precision::F32Simd => "simd",
        }
    }

    /// The precision named `id`, or a message naming the valid ones.
    pub fn parse(id: &str) -> Result<Self, String> {
        crate::choose(&Self::ALL, Self::id, id, "precision", "precisions")
    }
}

/// Evaluates a lobe at a batch of cosines: where, and in what arithmetic, error figures are
/// measured. Batches let a backend such as a GPU amortise its dispatch.
pub trait Evaluator {
    /// The name reports give it (`f64`, `f32`, `gpu`).
    fn name(&self) -> &'static str;
    /// The lobe at each cosine, widened to `f64`; one value per input, in order.
    fn evaluate(&mut self, lobe: &Lobe, cosines: &[f64]) -> Vec<f64>;
}

impl Evaluator for Precision {
    fn name(&self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
            Precision::F32Simd => "f32-simd",
        }
    }

    fn evaluate(&mut self, lobe: &Lobe, cosines: &[f64]) -> Vec<f64> {
        match self {
            Precision::F64 => lobe.eval_each(cosines),
            Precision::F32 => cosines
                .iter()
                .map(|&t| f64::from(lobe.eval(t as f32)))
                .collect(),
            Precision::F32Simd => {
                let narrow: Vec<f32> = cosines.iter().map(|&t| t as f32).collect();
                let mut values = vec![0.0; narrow.len()];
                lobe.eval_batch(&narrow, &mut values);
                values.into_iter().map(f64::from).collect()
            }
        }
    }
}

/// The error figures of one lobe at one `n`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ErrorFigures {
    /// `max |lobe - t^n| / t^n` over the epicentre.
    pub epicentre_max_rel: f64,
    /// `max |lobe - t^n|` over the epicentre.
    pub epicentre_max_abs: f64,
    /// `max |lobe - t^n|` over the bloom.
    pub bloom_max_abs: f64,
    /// `max |lobe - t^n|` over the tail.
    pub tail_max_abs: f64,
    /// Root mean square of `lobe - t^n` over the visible lobe (epicentre and bloom, uniform
    /// in the angle).
    pub rms: f64,
}

/// Samples per zone used by [`error_figures`] by default (SPEC asks for at least `10^5`).
pub const DEFAULT_SAMPLES_PER_ZONE: usize = 100_001;

/// The sample cosines of every zone at one `n`, with the reference `cos^n` at each: computed
/// once and shared by every lobe and backend measured at that `n` (the hardware sweeps measure
/// dozens of word lengths against the same samples).
#[derive(Clone, Debug, PartialEq)]
pub struct ZoneSamples {
    n: crate::Exponent,
    zones: [ZoneSample; 3],
}

/// One zone's samples.
#[derive(Clone, Debug, PartialEq)]
struct ZoneSample {
    cosines: Vec<f64>,
    /// `cos^n` at each cosine, in `f64`.
    references: Vec<f64>,
    /// The zone's width in angle (radians), for the RMS weighting.
    width: f64,
}

impl ZoneSamples {
    /// `samples_per_zone` angles per zone (at least 2), uniform, endpoints included.
    #[must_use]
    pub fn new(n: crate::Exponent, samples_per_zone: usize) -> Self {
        let samples = samples_per_zone.max(2);
        let zones = Zone::ALL.map(|zone| {
            let (from, to) = zone.angles(n);
            let cosines: Vec<f64> = (0..samples)
                .map(|i| (from + (to - from) * (i as f64 / (samples - 1) as f64)).cos())
                .collect();
            let references = cosines.iter().map(|t| t.powf(n.get())).collect();
            ZoneSample {
                cosines,
                references,
                width: to - from,
            }
        });
        Self { n, zones }
    }

    /// The exponent they were taken at.
    #[must_use]
    pub fn exponent(&self) -> crate::Exponent {
        self.n
    }

    /// Samples in each zone.
    #[must_use]
    pub fn samples_per_zone(&self) -> usize {
        self.zones[0].cosines.len()
    }
}

/// Per-zone statistics of a scan.
#[derive(Clone, Copy, Debug, Default)]
struct ZoneScan {
    max_abs: f64,
    max_rel: f64,
    mean_square: f64,
}

fn scan_zone(lobe: &Lobe, evaluator: &mut dyn Evaluator, zone: &ZoneSample) -> ZoneScan {
    let values = evaluator.evaluate(lobe, &zone.cosines);
    let mut scan = ZoneScan::default();
    let mut sum_square = 0.0;
    for (&reference, &value) in zone.references.iter().zip(&values) {
        let error = (value - reference).abs();
        scan.max_abs = scan.max_abs.max(error);
        if reference > 0.0 {
            scan.max_rel = scan.max_rel.max(error / reference);
        }
        sum_square += error * error;
    }
    scan.mean_square = sum_square / zone.cosines.len() as f64;
    scan
}

/// The error figures of `lobe` with `samples_per_zone` samples in each zone.
#[must_use]
pub fn error_figures(
    lobe: &Lobe,
    evaluator: &mut dyn Evaluator,
    samples_per_zone: usize,
) -> ErrorFigures {
    error_figures_on(
        lobe,
        evaluator,
        &ZoneSamples::new(lobe.exponent(), samples_per_zone),
    )
}

/// The error figures of `lobe` on precomputed `samples` (taken at the lobe's exponent).
///
/// # Panics
/// If `samples` were taken at another exponent.
#[must_use]
pub fn error_figures_on(
    lobe: &Lobe,
    evaluator: &mut dyn Evaluator,
    samples: &ZoneSamples,
) -> ErrorFigures {
    assert_eq!(
        samples.n,
        lobe.exponent(),
        "zone samples taken at another n"
    );
    let [epicentre, bloom, tail] = samples
        .zones
        .each_ref()
        .map(|zone| scan_zone(lobe, evaluator, zone));
    let (epicentre_width, bloom_width) = (samples.zones[0].width, samples.zones[1].width);
    let rms = ((epicentre.mean_square * epicentre_width + bloom.mean_square * bloom_width)
        / (epicentre_width + bloom_width))
        .sqrt();
    ErrorFigures {
        epicentre_max_rel: epicentre.max_rel,
        epicentre_max_abs: epicentre.max_abs,
        bloom_max_abs: bloom.max_abs,
        tail_max_abs: tail.max_abs,
        rms,
    }
}
