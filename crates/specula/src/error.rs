//! The errors of the library's API boundary.
//!
//! Every message names the offending value and the valid choices, because it is shown to
//! users verbatim by the CLI and the server.

use thiserror::Error;

/// A request the library cannot serve.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// A specular exponent outside `[1, 1000]`, or not a finite number.
    #[error("specular exponent n = {value} is out of range: n must be a finite number in [{min}, {max}]", min = crate::Exponent::MIN, max = crate::Exponent::MAX)]
    ExponentOutOfRange {
        /// The rejected value.
        value: f64,
    },
    /// A lobe id the registry does not know.
    #[error("unknown lobe '{id}'; valid lobes: {valid}")]
    UnknownLobe {
        /// The rejected id.
        id: String,
        /// The registry's ids, comma separated.
        valid: String,
    },
    /// A lobe parameter that is unknown, malformed or out of range.
    #[error("invalid parameter for lobe '{lobe}': {message}")]
    InvalidLobeParameter {
        /// The lobe the parameter was given to.
        lobe: &'static str,
        /// What is wrong, and what is valid.
        message: String,
    },
    /// A cosine outside `[-1, 1]`.
    #[error("cosine {value} is out of range: a cosine must be a finite number in [-1, 1]")]
    CosineOutOfRange {
        /// The rejected value.
        value: f64,
    },
    /// A name (geometry, normalisation, ...) that is not one of the valid choices.
    #[error("unknown {what} '{name}'; valid choices: {valid}")]
    UnknownName {
        /// What kind of name it was meant to be.
        what: &'static str,
        /// The rejected name.
        name: String,
        /// The valid names, comma separated.
        valid: String,
    },
}

/// Shorthand for results of this crate.
pub type Result<T, E = Error> = core::result::Result<T, E>;

/// The most characters of a user's text a message quotes.
pub const QUOTED_CHARACTERS: usize = 80;

/// `text` as a message quotes it: whole up to [`QUOTED_CHARACTERS`], else its start and its
/// length (a 50 MB typo is not echoed back).
#[must_use]
pub fn excerpt(text: &str) -> String {
    let count = text.chars().count();
    if count <= QUOTED_CHARACTERS {
        text.to_owned()
    } else {
        let start: String = text.chars().take(QUOTED_CHARACTERS - 20).collect();
        format!("{start}... ({count} characters)")
    }
}

/// Finds `text` (case-insensitively, trimmed) among `choices` by their names, or says which
/// names are valid.
pub(crate) fn parse_choice<T: Copy>(
    what: &'static str,
    text: &str,
    choices: &[T],
    name: fn(T) -> &'static str,
) -> Result<T> {
    choices
        .iter()
        .copied()
        .find(|&c| name(c).eq_ignore_ascii_case(text.trim()))
        .ok_or_else(|| Error::UnknownName {
            what,
            name: excerpt(text),
            valid: choices
                .iter()
                .map(|&c| name(c))
                .collect::<Vec<_>>()
                .join(", "),
        })
}
