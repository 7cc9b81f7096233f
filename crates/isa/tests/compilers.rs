//! Facts of the machine code the vendors' compilers write, not its text (versions change the
//! text): under fast math `pow` is two transcendental instructions and a multiply on every
//! NVIDIA and AMD generation listed, and two per work item on Intel's; a lobe whose recorded
//! expression has no transcendental operation compiles to none; the compiler's estimates are
//! there where it makes them. Without a compiler these tests print `skipped: ...` and pass,
//! except under `CI=true`, where `.ci/run` installs them all.

use specula::expression::Node;
use specula::{Exponent, Lobe, LobeKind};
use specula_isa::{compile, Class, Compiled, Gpu, IsaError, Vendor, Work};

/// `lobe` compiled for `gpu`, or `None` (printed) where its compiler is missing outside CI.
fn compiled(lobe: &Lobe, gpu: Gpu, work: Work) -> Option<Compiled> {
    match compile(lobe, gpu, work) {
        Ok(compiled) => Some(compiled),
        Err(IsaError::Missing { tool, install })
            if std::env::var("CI").as_deref() != Ok("true") =>
        {
            eprintln!("skipped on {}: {tool} is missing ({install})", gpu.id);
            None
        }
        Err(error) => panic!("{} on {}: {error}", lobe.kind(), gpu.id),
    }
}

#[test]
fn pow_is_two_transcendentals_and_a_multiply_on_every_generation() {
    let pow = Lobe::new(LobeKind::Pow, Exponent::new(64.0));
    for gpu in Gpu::ALL {
        let Some(compiled) = compiled(&pow, gpu, Work::Lobe) else {
            continue;
        };
        let counts = compiled.counts();
        let per_item =
            |class: Class| counts.per_item[Class::ALL.iter().position(|&c| c == class).unwrap()];
        assert_eq!(
            (per_item(Class::Transcendental), per_item(Class::Arithmetic)),
            (2.0, 1.0),
            "{}: pow is log2, a multiply and exp2 per work item; compiled:\n{}",
            gpu.id,
            listing(&compiled)
        );
        if gpu.vendor != Vendor::Intel {
            // One instruction a warp or wave on NVIDIA and AMD.
            assert_eq!(counts.get(Class::Transcendental), 2, "{}", gpu.id);
        }
    }
}

/// Whether a recorded expression has an operation a GPU runs on its special-function unit.
fn transcendental_free(lobe: &Lobe) -> bool {
    lobe.expression().nodes().iter().all(|node| {
        !matches!(
            node,
            Node::Div(..)
                | Node::Sqrt(_)
                | Node::Log2(_)
                | Node::Exp2(_)
                | Node::Acos(_)
                | Node::Cos(_)
                | Node::Sin(_)
                | Node::Exp(_)
                | Node::Ln1p(_)
                | Node::ExpM1(_)
                | Node::Pow(..)
        )
    })
}

#[test]
fn a_transcendental_free_lobe_compiles_to_none() {
    let free: Vec<Lobe> = LobeKind::ALL
        .into_iter()
        .map(|kind| Lobe::new(kind, Exponent::new(64.0)))
        .filter(transcendental_free)
        .collect();
    assert!(
        free.len() >= 2,
        "the built-ins have transcendental-free lobes (cosquad, cheb2)"
    );
    for lobe in &free {
        for gpu in Gpu::ALL {
            let Some(compiled) = compiled(lobe, gpu, Work::Lobe) else {
                continue;
            };
            assert_eq!(
                compiled.counts().get(Class::Transcendental),
                0,
                "{} on {}:\n{}",
                lobe.kind(),
                gpu.id,
                listing(&compiled)
            );
        }
    }
}

#[test]
fn aco_states_its_estimates_and_registers_for_every_amd_chip() {
    // cosquad's squarings are a run of identical multiplies, which ACO's listing writes once
    // and says how often it repeats.
    let lobes =
        [LobeKind::Sg, LobeKind::CosQuad { v: 4 }].map(|kind| Lobe::new(kind, Exponent::new(64.0)));
    for (gpu, lobe) in
        Gpu::of(Vendor::Amd).flat_map(|gpu| lobes.iter().map(move |lobe| (gpu, lobe)))
    {
        let Some(compiled) = compiled(lobe, gpu, Work::Lobe) else {
            continue;
        };
        assert!(
            compiled.kernel.registers.is_some_and(|r| r > 0),
            "{}",
            gpu.id
        );
        assert!(
            compiled
                .kernel
                .estimate("ACO's estimated latency")
                .is_some(),
            "{}",
            gpu.id
        );
        assert!(compiled.aco_inverse_throughput().is_some(), "{}", gpu.id);
        // LLVM's analyser beside ACO's own estimate, where it is installed (CI installs it).
        let mca = compiled
            .kernel
            .estimate("llvm-mca's block reciprocal throughput");
        assert!(
            mca.is_some_and(|cycles| cycles > 0.0) || std::env::var("CI").as_deref() != Ok("true"),
            "{}: no llvm-mca estimate",
            gpu.id
        );
        // ACO's own instruction count is the listing's.
        assert_eq!(
            compiled.kernel.estimate("ACO's instruction count"),
            Some(compiled.kernel.instructions.len() as f64),
            "{}:\n{}",
            gpu.id,
            listing(&compiled)
        );
    }
}

#[test]
fn the_shading_context_holds_the_lobe_and_more() {
    let lobe = Lobe::new(LobeKind::Pow, Exponent::new(64.0));
    let work = Work::Shading(specula::Geometry::Blinn, specula::Normalisation::Lobe);
    for gpu in [
        Vendor::Nvidia.default_gpu(),
        Vendor::Amd.default_gpu(),
        Vendor::Intel.default_gpu(),
    ] {
        let (Some(alone), Some(shading)) =
            (compiled(&lobe, gpu, Work::Lobe), compiled(&lobe, gpu, work))
        else {
            continue;
        };
        // Blinn's half vector adds a square root (or reciprocal square root) to pow's two.
        assert!(
            shading.counts().get(Class::Transcendental) > alone.counts().get(Class::Transcendental),
            "{}",
            gpu.id
        );
        assert!(
            shading.counts().total() > alone.counts().total(),
            "{}",
            gpu.id
        );
    }
}

/// Kernels compiled together in one run are the kernels compiled alone: the batch renames
/// them apart and reads each back, and nothing of one leaks into another.
#[test]
fn a_batch_compiles_each_kernel_as_it_compiles_alone() {
    // schlick branches on Intel, so its listing names labels.
    let lobes: Vec<Lobe> = [
        LobeKind::Pow,
        LobeKind::Schlick,
        LobeKind::Sg,
        LobeKind::FastPow,
    ]
    .into_iter()
    .map(|kind| Lobe::new(kind, Exponent::new(32.0)))
    .collect();
    for vendor in Vendor::ALL {
        let gpu = vendor.default_gpu();
        let batch_cache = tempfile::tempdir().unwrap();
        let batch = match specula_isa::compile_all_in(
            &lobes,
            gpu,
            Work::Lobe,
            Some(&specula_isa::Cache::new(batch_cache.path())),
        ) {
            Ok(batch) => batch,
            Err(IsaError::Missing { tool, .. }) if std::env::var("CI").as_deref() != Ok("true") => {
                eprintln!("skipped on {}: {tool} is missing", gpu.id);
                continue;
            }
            Err(error) => panic!("{}: {error}", gpu.id),
        };
        for (lobe, batched) in lobes.iter().zip(&batch) {
            let alone =
                specula_isa::compile_all_in(std::slice::from_ref(lobe), gpu, Work::Lobe, None)
                    .unwrap()
                    .remove(0);
            let texts = |c: &Compiled| {
                c.kernel
                    .instructions
                    .iter()
                    .map(|i| i.text.clone())
                    .collect::<Vec<_>>()
            };
            assert_eq!(
                texts(batched),
                texts(&alone),
                "{} on {}",
                lobe.kind(),
                gpu.id
            );
            assert_eq!(
                batched.kernel.registers, alone.kernel.registers,
                "{}",
                gpu.id
            );
        }
    }
}

fn listing(compiled: &Compiled) -> String {
    compiled
        .kernel
        .instructions
        .iter()
        .map(|i| format!("  {:<15} {}", i.class.id(), i.text))
        .collect::<Vec<_>>()
        .join("\n")
}
