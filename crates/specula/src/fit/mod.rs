//! Polynomial fitting: the thesis's Chebyshev method generalised, and a minimax alternative.
//!
//! [`ChebyshevSeries`] fits any function on any interval with any number of nodes and converts
//! to the power basis; [`minimax`] finds the best polynomial in the maximum-error sense. The
//! `cheb2` lobe uses a 3-node Chebyshev fit of `cos^n` over the epicentre, the `minimax2` lobe
//! the relative-error minimax quadratic over the same interval; both are cached per `n`
//! ([`cached_angle_quadratic`]) so that building a lobe twice never fits twice.

mod chebyshev;
mod microfacet;
mod minimax;
mod polynomial;

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

pub use chebyshev::ChebyshevSeries;
pub use microfacet::{ggx, microfacet, MicrofacetFit};
pub use minimax::{minimax, ErrorWeight, MinimaxError, MinimaxFit};
pub use polynomial::Polynomial;

/// Which quadratic-in-angle fit of `cos^n(g)` over the epicentre.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AngleFit {
    /// The thesis's 3-node Chebyshev interpolant.
    Chebyshev3,
    /// The quadratic minimising the largest relative error.
    MinimaxRelative,
}

/// `[C, B, A]`: the quadratic `C + B g + A g^2` fitted to `cos^n(g)` on `[0, g_half(n)]`,
/// computed once per `(fit, n)` and then served from a process-wide cache.
#[must_use]
pub fn cached_angle_quadratic(fit: AngleFit, n: crate::Exponent) -> [f64; 3] {
    type Coefficients = HashMap<(AngleFit, u64), [f64; 3]>;
    static CACHE: OnceLock<Mutex<Coefficients>> = OnceLock::new();
    let key = (fit, n.get().to_bits());
    let cache = CACHE.get_or_init(Default::default);
    if let Some(coeffs) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return *coeffs;
    }
    let coeffs = angle_quadratic(fit, n);
    cache
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, coeffs);
    coeffs
}

fn angle_quadratic(fit: AngleFit, n: crate::Exponent) -> [f64; 3] {
    let exponent = n.get();
    let reference = move |g: f64| g.cos().powf(exponent);
    let upper = crate::zones::epicentre_angle(n);
    let polynomial = match fit {
        AngleFit::Chebyshev3 => ChebyshevSeries::fit(reference, 0.0, upper, 3).to_power_basis(),
        AngleFit::MinimaxRelative => {
            match minimax(reference, 0.0, upper, 2, ErrorWeight::Relative) {
                Ok(fit) => fit.polynomial,
                // cos^n is positive and smooth on the epicentre, so Remez cannot meet a singular
                // system there; should it ever, the Chebyshev interpolant is the near-minimax
                // fallback.
                Err(_) => ChebyshevSeries::fit(reference, 0.0, upper, 3).to_power_basis(),
            }
        }
    };
    let c = polynomial.coeffs();
    [
        c[0],
        c.get(1).copied().unwrap_or(0.0),
        c.get(2).copied().unwrap_or(0.0),
    ]
}
