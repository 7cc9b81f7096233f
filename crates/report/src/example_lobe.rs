//! A lobe is its file and one registry line: specula's worked example
//! (`crates/specula/src/lobe/example.rs`, compiled with the `example-lobe` feature, named in
//! `lobes!` and nowhere else) appears wherever a lobe appears: the registry, the analysis,
//! the batch path, the GPU's lobe library and its evaluation, every export, and the report's
//! tables. Each figure is checked against the closed form `(t / (h (1 - t) + t))^2`,
//! `h = n / 2`, computed here. `crates/cli/tests/suite/structure.rs` runs this module (cargo
//! test with the feature) and checks that the lobe's file and its line are all there is of it.

use specula::analysis::{analyze, Precision};
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_gpu::export::{export, GlslVersion, Language, Options, ShaderCode};
use specula_targets::RendererFormat;

use crate::{sections, Context};

fn example() -> LobeKind {
    LobeKind::ALL
        .into_iter()
        .find(|kind| kind.id() == "example")
        .expect("the example lobe is registered with the feature on")
}

/// The closed form, in `f64`.
fn closed_form(n: f64, t: f64) -> f64 {
    let h = n / 2.0;
    (t / (h * (1.0 - t) + t)).powi(2)
}

#[test]
fn the_registry_parses_and_prepares_it() {
    let kind = example();
    assert_eq!(LobeKind::parse("example"), Ok(kind));
    assert_eq!(kind.to_string(), "example");
    assert!(kind.index() < LobeKind::ALL.len() as u32);
    for n in [1.0, 7.5, 64.0, 1000.0] {
        let lobe = Lobe::new(kind, Exponent::new(n));
        for t in [1e-6, 0.1, 0.5, 0.9, 0.999, 1.0] {
            let (value, exact) = (lobe.eval(t), closed_form(n, t));
            assert!((value - exact).abs() <= 1e-15 * exact, "n = {n} t = {t}");
        }
        assert_eq!(lobe.eval(-0.5), 0.0, "the shared rules hold");
        assert_eq!(lobe.eval(f64::NAN), 0.0, "the shared rules hold");
        assert_eq!(lobe.eval(1.5), 1.0, "the shared rules hold");
        assert_eq!(lobe.preparation("h", n), Some(n / 2.0));
    }
}

/// `specula analyze`'s figures: the energy against a midpoint sum of the closed form, and the
/// largest error against the closed form's on a fine grid of angles.
#[test]
fn the_analysis_measures_it() {
    let n = 64.0;
    let report = analyze(example(), Exponent::new(n), &mut Precision::F64);
    let steps = 200_000;
    let integral: f64 = (0..steps)
        .map(|i| closed_form(n, (f64::from(i) + 0.5) / f64::from(steps)))
        .sum::<f64>()
        / f64::from(steps);
    let energy = integral * (n + 1.0);
    assert!(
        (report.energy_ratio - energy).abs() <= 1e-6 * energy,
        "energy ratio {} against {energy}",
        report.energy_ratio
    );
    let largest = (0..=100_000)
        .map(|i| (f64::from(i) / 100_000.0 * core::f64::consts::FRAC_PI_2).cos())
        .map(|t| (closed_form(n, t) - t.powf(n)).abs())
        .fold(0.0, f64::max);
    let errors = report.errors;
    let measured = errors
        .epicentre_max_abs
        .max(errors.bloom_max_abs)
        .max(errors.tail_max_abs);
    assert!(
        (0.99 * largest..=1.000_001 * largest).contains(&measured),
        "largest error {measured} against {largest}"
    );
}

/// The batch path (the lobe's own kernel) agrees with the scalar `f32` path within its
/// stated bound.
#[test]
fn the_batch_path_runs_its_kernel() {
    let lobe = Lobe::new(example(), Exponent::new(100.0));
    let ts: Vec<f32> = (0..=4096).map(|i| i as f32 / 4096.0).collect();
    let mut batch = vec![0.0; ts.len()];
    lobe.eval_batch(&ts, &mut batch);
    let bound = lobe.batch_ulp_bound() * f64::from(f32::EPSILON) / 2.0;
    for (&t, &value) in ts.iter().zip(&batch) {
        let scalar: f32 = lobe.eval(t);
        assert!(f64::from((value - scalar).abs()) <= bound, "t = {t}");
    }
}

/// The GPU's library has its generated function, and the GPU computes it within the bound
/// the lobe states (64 ULP: Schlick's 32, squared).
#[test]
fn the_gpu_library_holds_and_evaluates_it() {
    assert!(specula_gpu::wgsl::lobes().contains("fn lobe_example("));
    let gpu = match specula_gpu::Gpu::new() {
        Ok(gpu) => gpu,
        Err(error) if std::env::var("CI").as_deref() == Ok("true") => {
            panic!("CI=true but no GPU: {error}")
        }
        Err(error) => return eprintln!("skipped: {error}"),
    };
    let evaluator = specula_gpu::LobeEvaluator::new(&gpu).expect("the library compiles");
    let ts: Vec<f32> = (0..=4096)
        .map(|i| 1.0 - (i as f32 / 4096.0).powi(2))
        .collect();
    for n in [2.0, 64.0, 900.0] {
        let lobe = Lobe::new(example(), Exponent::new(n));
        let values = evaluator.eval(&lobe, &ts).expect("the GPU evaluates");
        for (&t, &value) in ts.iter().zip(&values) {
            let error = (f64::from(value) - closed_form(n, f64::from(t))).abs();
            assert!(
                error <= 64.0 * f64::from(f32::EPSILON) / 2.0,
                "n = {n} t = {t}"
            );
        }
    }
}

/// Every shader language and every renderer's format writes it; the WGSL validates.
#[test]
fn every_export_writes_it() {
    let lobe = Lobe::new(example(), Exponent::new(48.0));
    for language in Language::ALL {
        let options = Options {
            example: true,
            glsl: GlslVersion::Desktop450,
            n_input: false,
        };
        let code = export(
            &lobe,
            Geometry::Blinn,
            Normalisation::Lobe,
            language,
            options,
        )
        .unwrap_or_else(|e| panic!("{language:?}: {e}"));
        if let (Language::Wgsl, ShaderCode::Text(text)) = (language, &code) {
            specula_gpu::wgsl::validate(text).unwrap_or_else(|e| panic!("{e}"));
        }
    }
    for format in RendererFormat::ALL {
        let normalisation = match format {
            RendererFormat::Osl => Normalisation::None,
            RendererFormat::MaterialX | RendererFormat::Mitsuba => Normalisation::Lobe,
        };
        let text = format
            .write(&lobe, Geometry::Phong, normalisation)
            .unwrap_or_else(|e| panic!("{format:?}: {e}"));
        assert!(text.contains("specula_example"), "{format:?}");
    }
}

/// The report's tables list it: the models table with its formula and origin, the energy
/// section with its row.
#[test]
fn the_reports_tables_list_it() {
    let directory = specula_temporaries::dir("example-lobe-").expect("a scratch folder");
    let mut context = Context::for_tests(directory.path());
    let models = sections::models(&mut context).expect("the models section");
    assert!(models.contains("<td>example</td>"), "{models}");
    assert!(models.contains(example().info().formula), "{models}");
    let energy = crate::energy::energy(&mut context).expect("the energy section");
    assert!(energy.contains("<td>example</td>"), "{energy}");
}
