//! The specular exponent `n`, validated once at the API boundary.

use serde::Serialize;

use crate::error::{Error, Result};

/// A specular exponent `n` in `[1, 1000]` (the thesis's range, SPEC section 1).
///
/// Holding an `Exponent` proves the range check happened, so models never re-check it and never
/// see a NaN exponent. Values outside the range are an error, never silently clamped.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd, Serialize)]
#[serde(transparent)]
pub struct Exponent(f64);

impl Exponent {
    /// The smallest valid exponent.
    pub const MIN: f64 = 1.0;
    /// The largest valid exponent.
    pub const MAX: f64 = 1000.0;

    /// Validates `n`, returning an error naming the valid range when it is outside.
    pub fn try_new(n: f64) -> Result<Self> {
        if (Self::MIN..=Self::MAX).contains(&n) {
            Ok(Self(n))
        } else {
            Err(Error::ExponentOutOfRange { value: n })
        }
    }

    /// Validates `n`.
    ///
    /// # Panics
    /// If `n` is not a finite number in `[1, 1000]`; use [`Exponent::try_new`] for input that
    /// comes from outside the program.
    #[must_use]
    pub fn new(n: f64) -> Self {
        match Self::try_new(n) {
            Ok(exponent) => exponent,
            Err(error) => panic!("{error}"),
        }
    }

    /// The exponent nearest `n` in `[1, 1000]` (a search's ends may round a hair outside;
    /// NaN gives the smallest).
    #[must_use]
    pub fn clamped(n: f64) -> Self {
        Self(if n.is_nan() {
            Self::MIN
        } else {
            n.clamp(Self::MIN, Self::MAX)
        })
    }

    /// The exponent's value.
    #[must_use]
    pub fn get(self) -> f64 {
        self.0
    }
}

impl core::fmt::Display for Exponent {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.0.fmt(f)
    }
}

impl core::str::FromStr for Exponent {
    type Err = Error;

    fn from_str(text: &str) -> Result<Self> {
        let value: f64 = text
            .trim()
            .parse()
            .map_err(|_| Error::ExponentOutOfRange { value: f64::NAN })?;
        Self::try_new(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_the_closed_range_and_rejects_everything_else() {
        assert!(Exponent::try_new(1.0).is_ok());
        assert!(Exponent::try_new(1000.0).is_ok());
        for bad in [0.0, 0.999, -1.0, 1000.5, 1e9, f64::NAN, f64::INFINITY] {
            assert!(Exponent::try_new(bad).is_err(), "{bad} accepted");
        }
        assert!("12.5".parse::<Exponent>().is_ok());
        assert!("twelve".parse::<Exponent>().is_err());
    }
}
