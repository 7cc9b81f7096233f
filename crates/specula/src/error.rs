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
    #[error("specular exponent n = {value} is out of range: n must be a finite number in [{min}, \
        {max}]", min = crate::Exponent::MIN, max = crate::Exponent::MAX)]
    ExponentOutOfRange {
        /// The rejected value.
        value: f64,
    },
    /// A lobe id the registry does not know.
    #[error("unknown lobe '{id}'; valid lobes: {valid}{hint}")]
    UnknownLobe {
        /// The rejected id.
        id: String,
        /// The registry's ids, comma separated.
        valid: String,
        /// `; did you mean 'x'?` when a valid id is close, else empty.
        hint: String,
    },
    /// A lobe parameter that is unknown, malformed or out of range.
    #[error("invalid parameter for lobe '{lobe}': {message}")]
    InvalidLobeParameter {
        /// The lobe the parameter was given to.
        lobe: &'static str,
        /// What is wrong, and what is valid.
        message: String,
    },
    /// A user's lobe refused: its formula, its parameters, or its values at an `n`.
    #[error("lobe '{lobe}': {message}")]
    Formula {
        /// The lobe's name.
        lobe: String,
        /// Where and what is wrong (one line).
        message: String,
    },
    /// A cosine outside `[-1, 1]`.
    #[error("cosine {value} is out of range: a cosine must be a finite number in [-1, 1]")]
    CosineOutOfRange {
        /// The rejected value.
        value: f64,
    },
    /// A name (geometry, normalisation, ...) that is not one of the valid choices.
    #[error("unknown {what} '{name}'; valid choices: {valid}{hint}")]
    UnknownName {
        /// What kind of name it was meant to be.
        what: &'static str,
        /// The rejected name.
        name: String,
        /// The valid names, comma separated.
        valid: String,
        /// `; did you mean 'x'?` when a valid name is close, else empty.
        hint: String,
    },
}

/// Shorthand for results of this crate.
pub type Result<T, E = Error> = core::result::Result<T, E>;

/// The most characters of a user's text a message quotes.
pub const QUOTED_CHARACTERS: usize = 80;

/// `text` as a message quotes it: whole up to [`QUOTED_CHARACTERS`], else its start and its
/// length (a 50 MB typo is not echoed back); control characters escaped (`\n`, `\u{7}`), so
/// a message stays one line whatever the user typed.
#[must_use]
pub fn excerpt(text: &str) -> String {
    let count = text.chars().count();
    let shown = if count <= QUOTED_CHARACTERS {
        QUOTED_CHARACTERS
    } else {
        QUOTED_CHARACTERS - 20
    };
    let mut quoted = String::new();
    for c in text.chars().take(shown) {
        if c.is_control() {
            quoted.extend(c.escape_default());
        } else {
            quoted.push(c);
        }
    }
    if count > QUOTED_CHARACTERS {
        quoted += &format!("... ({count} characters)");
    }
    quoted
}

/// The 1-based line and column (in characters) of byte offset `at` in `text`, as messages
/// about a file or a formula name a position.
#[must_use]
pub fn line_column(text: &str, at: usize) -> (usize, usize) {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let column = before.chars().rev().take_while(|&c| c != '\n').count() + 1;
    (line, column)
}

/// The longest text a "did you mean" is computed for: identifiers, not pasted files.
const SUGGESTED_UP_TO: usize = 40;

/// Of `choices`, the one nearest `typed` when it is close enough to be a typo: at most a third
/// of its length in edits (and at least 2 allowed). Only for short text.
#[must_use]
pub fn nearest<'a>(typed: &str, choices: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let typed = typed.trim().to_ascii_lowercase();
    if typed.chars().count() > SUGGESTED_UP_TO {
        return None;
    }
    choices
        .into_iter()
        .map(|choice| (edit_distance(&typed, choice), choice))
        .min()
        .filter(|&(distance, choice)| distance > 0 && distance <= (choice.len() / 3).max(2))
        .map(|(_, choice)| choice)
}

/// The one of `all` whose `id` is `text`, or the one-line refusal every face prints:
/// `unknown {what} '{text}'; valid {plural}: a, b, c` (the text excerpted).
pub fn choose<T: Copy>(
    all: &[T],
    id: fn(T) -> &'static str,
    text: &str,
    what: &str,
    plural: &str,
) -> core::result::Result<T, String> {
    all.iter()
        .copied()
        .find(|&value| id(value) == text)
        .ok_or_else(|| {
            let names: Vec<&str> = all.iter().map(|&value| id(value)).collect();
            format!(
                "unknown {what} '{}'; valid {plural}: {}",
                excerpt(text),
                names.join(", ")
            )
        })
}

/// `; did you mean 'x'?` for [`nearest`], or nothing.
#[must_use]
pub fn did_you_mean<'a>(typed: &str, choices: impl IntoIterator<Item = &'a str>) -> String {
    nearest(typed, choices).map_or_else(String::new, |c| format!("; did you mean '{c}'?"))
}

/// Levenshtein distance between `a` and `b` (characters inserted, deleted or replaced).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut previous: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut current = vec![i + 1];
        for (j, &cb) in b.iter().enumerate() {
            let replace = previous[j] + usize::from(ca != cb);
            current.push(replace.min(previous[j + 1] + 1).min(current[j] + 1));
        }
        previous = current;
    }
    previous[b.len()]
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
            hint: did_you_mean(text, choices.iter().map(|&c| name(c))),
        })
}

#[cfg(test)]
mod tests {
    use super::{choose, excerpt, QUOTED_CHARACTERS};

    #[test]
    fn choose_finds_by_id_or_names_every_valid_one() {
        let id = |n: u8| ["one", "two", "three"][usize::from(n)];
        assert_eq!(choose(&[0, 1, 2], id, "two", "digit", "digits"), Ok(1));
        assert_eq!(
            choose(&[0, 1, 2], id, "four", "digit", "digits"),
            Err("unknown digit 'four'; valid digits: one, two, three".to_owned())
        );
        assert_eq!(
            choose(&[0, 1, 2], id, "fo\nur\u{7}", "digit", "digits"),
            Err(r"unknown digit 'fo\nur\u{7}'; valid digits: one, two, three".to_owned())
        );
    }

    #[test]
    fn an_excerpt_is_one_line_and_bounded() {
        assert_eq!(excerpt("a\tb\r\nc é"), r"a\tb\r\nc é");
        let long = "x".repeat(1000);
        assert_eq!(
            excerpt(&long),
            format!(
                "{}... (1000 characters)",
                "x".repeat(QUOTED_CHARACTERS - 20)
            )
        );
        assert_eq!(
            excerpt(&"y".repeat(QUOTED_CHARACTERS)),
            "y".repeat(QUOTED_CHARACTERS)
        );
    }
}
