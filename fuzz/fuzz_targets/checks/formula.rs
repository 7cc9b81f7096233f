//! The formula target's check, also run by `crates/serve/tests/fuzz_regressions.rs` on the
//! seeds and every crash input kept in `fuzz/regressions/formula/`: any text is a lobe or a
//! one-line refusal, never a panic; a lobe, whether or not `Lobe::checked` accepts it at an
//! `n`, evaluates within `[0, 1]` (the range rules every lobe obeys), in `f64` and `f32`, one
//! cosine at a time and in batches.
//!
//! The library keeps every formula it compiles for the life of the process, at most
//! `specula::formula::MAX_FORMULAS`; beyond that `define` refuses (an error, not a panic), so
//! a long run fuzzes only the parser and the compiler once that many texts have compiled.
//! Each text is defined under a name of its own (`f1`, `f2`, ...): numbering one base name
//! would search every name taken before, which grows with the run.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use specula::formula::{define, instance, Definition, Naming};
use specula::{Exponent, Lobe, LobeKind};

/// Cosines at which each lobe is evaluated: the range's ends, beyond them, and between.
const COSINES: [f64; 13] = [
    -1.0,
    0.0,
    1e-30,
    1e-9,
    0.01,
    0.25,
    0.5,
    0.9,
    0.99,
    0.999_999,
    1.0,
    1.5,
    f64::NAN,
];

/// Exponents each lobe is prepared for.
const EXPONENTS: [f64; 3] = [1.0, 64.0, 1000.0];

/// Defines `data` as a formula lobe and checks it as described above.
pub fn check_formula(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Some(kind) = lobe(text) else {
        return;
    };
    for n in EXPONENTS {
        let n = Exponent::new(n);
        if let Err(error) = Lobe::checked(kind, n) {
            one_line(&error.to_string());
        }
        let lobe = Lobe::new(kind, n);
        for t in COSINES {
            let value = lobe.eval(t);
            assert!(
                (0.0..=1.0).contains(&value),
                "{text:?} at n = {n}, t = {t}: {value}"
            );
            let value = lobe.eval(t as f32);
            assert!(
                (0.0..=1.0).contains(&value),
                "{text:?} at n = {n}, t = {t} (f32): {value}"
            );
        }
        // A length that is no multiple of the vector width: the batch path's tail too.
        let ts: Vec<f32> = COSINES.iter().map(|&t| t as f32).collect();
        let mut out = vec![f32::NAN; ts.len()];
        lobe.eval_batch(&ts, &mut out);
        for (t, value) in ts.iter().zip(&out) {
            assert!(
                (0.0..=1.0).contains(value),
                "{text:?} at n = {n}, t = {t} (batch): {value}"
            );
        }
    }
}

/// The lobe `text` defines, or `None` when it is refused (with a one-line message).
pub(crate) fn lobe(text: &str) -> Option<LobeKind> {
    static DEFINED: Mutex<Option<HashMap<String, LobeKind>>> = Mutex::new(None);
    static NEXT: AtomicUsize = AtomicUsize::new(1);
    let mut defined = DEFINED
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let defined = defined.get_or_insert_with(HashMap::new);
    if let Some(&kind) = defined.get(text) {
        return Some(kind);
    }
    let definition = Definition {
        name: format!("f{}", NEXT.fetch_add(1, Ordering::Relaxed)),
        description: None,
        formula: text.to_owned(),
        tail: None,
        parameters: Default::default(),
    };
    let kind = define(definition, Naming::Unique).and_then(|formula| instance(formula, &[]));
    match kind {
        Ok(kind) => {
            defined.insert(text.to_owned(), kind);
            Some(kind)
        }
        Err(error) => {
            one_line(&error.to_string());
            None
        }
    }
}

/// A refusal is one line, of a bounded length (a long text is quoted in part).
fn one_line(message: &str) {
    assert!(
        !message.is_empty() && !message.contains('\n'),
        "{message:?}"
    );
    assert!(
        message.len() < 2048,
        "{} bytes: {}",
        message.len(),
        &message[..200]
    );
}
