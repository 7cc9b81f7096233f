//! Lobe files: a user's lobe as TOML (`name`, `formula`, optional `description`, `tail` and
//! `[parameters.NAME]` tables with `default`, `min`, `max`), and the one parser every lobe
//! argument goes through, so that `@mylobe.toml` works wherever a lobe id does.
//!
//! ```toml
//! name = "k4-by-hand"
//! formula = """
//! let a = (n + 1) / 17;
//! max(0, a * (t - 1) + 1) ^ 16
//! """
//! ```

use std::path::Path;

use specula::formula::{define, instance, parse_values, Definition, Naming, MAX_SOURCE_BYTES};
use specula::LobeKind;

/// The largest lobe file: room for a formula and a tail at their limit, and comments.
pub const MAX_LOBE_FILE_BYTES: u64 = 4 * MAX_SOURCE_BYTES as u64;

/// A lobe argument: a built-in id (`cosquad:v=5`), `=FORMULA`, the name of a lobe defined
/// earlier in this process, or `@FILE.toml` with optional parameter values
/// (`@mine.toml:k=2,m=0.5`); relative paths are taken from `base` when given. The error is
/// one line.
pub fn parse_lobe(text: &str, base: Option<&Path>) -> Result<LobeKind, String> {
    let text = text.trim();
    let Some(file) = text.strip_prefix('@') else {
        return LobeKind::parse(text).map_err(|e| e.to_string());
    };
    // `@path:k=1,m=2`: the values follow the last ':' when it is followed by an assignment.
    let (path, values) = match file.rsplit_once(':') {
        Some((path, values)) if values.contains('=') => (path, Some(values)),
        _ => (file, None),
    };
    let path = match base {
        Some(base) if Path::new(path).is_relative() => base.join(path),
        _ => Path::new(path).to_path_buf(),
    };
    let formula = define(read_definition(&path)?, Naming::Exact).map_err(|e| e.to_string())?;
    let given = match values {
        Some(values) => parse_values(formula, values).map_err(|e| e.to_string())?,
        None => Vec::new(),
    };
    instance(formula, &given).map_err(|e| e.to_string())
}

/// A comma-separated list of lobe arguments (`pow,@mine.toml:k=2,m=1,=max(0, t - 0.5)`):
/// commas inside parentheses belong to a formula, and `NAME=VALUE` items after a lobe with
/// parameter values (`@FILE:k=2` or `id:k=2`) are more of its values.
pub fn parse_lobe_list(text: &str, base: Option<&Path>) -> Result<Vec<LobeKind>, String> {
    let mut items: Vec<String> = Vec::new();
    let mut depth = 0_i32;
    let mut current = String::new();
    for c in text.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ => {}
        }
        if c == ',' && depth <= 0 {
            items.push(core::mem::take(&mut current));
        } else {
            current.push(c);
        }
    }
    items.push(current);
    let mut merged: Vec<String> = Vec::new();
    for item in items {
        let item = item.trim();
        let is_value = !item.starts_with(['@', '=']) && item.contains('=') && !item.contains(':');
        match merged.last_mut() {
            Some(last) if is_value && last.contains(':') && last.contains('=') => {
                last.push(',');
                last.push_str(item);
            }
            _ if item.is_empty() => {}
            _ => merged.push(item.to_owned()),
        }
    }
    merged.iter().map(|item| parse_lobe(item, base)).collect()
}

/// Reads and parses a lobe file (a regular file within [`MAX_LOBE_FILE_BYTES`]).
pub fn read_definition(path: &Path) -> Result<Definition, String> {
    let shown = path.display();
    if let Ok(meta) = std::fs::metadata(path) {
        if meta.is_file() && meta.len() > MAX_LOBE_FILE_BYTES {
            return Err(format!(
                "lobe file {shown}: is {} bytes; a lobe file is at most {MAX_LOBE_FILE_BYTES} \
                 bytes (a formula at most {MAX_SOURCE_BYTES})",
                meta.len()
            ));
        }
    }
    let bytes = crate::input::read_within(path, MAX_LOBE_FILE_BYTES)
        .map_err(|e| format!("lobe file {shown}: {e}"))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| format!("lobe file {shown}: not UTF-8 text; a lobe file is TOML"))?;
    parse_definition(&text, &shown.to_string())
}

/// A lobe file's text for `definition` (no parameters), after `comments` as `#` lines: what
/// `specula design` writes, and [`parse_definition`] reads back to the same definition.
#[must_use]
pub fn lobe_file_text(definition: &Definition, comments: &[String]) -> String {
    let quoted = |text: &str| toml::Value::String(text.to_owned()).to_string();
    let mut text: String = comments.iter().map(|c| format!("# {c}\n")).collect();
    text += &format!("name = {}\n", quoted(&definition.name));
    if let Some(description) = &definition.description {
        text += &format!("description = {}\n", quoted(description));
    }
    // Literal multi-line strings: a formula has no backslash escapes and no triple quote.
    text += &format!("formula = '''\n{}'''\n", definition.formula);
    if let Some(tail) = &definition.tail {
        text += &format!("tail = '''\n{tail}'''\n");
    }
    text
}

/// Parses a lobe file's text; `label` names it in the one-line error.
pub fn parse_definition(text: &str, label: &str) -> Result<Definition, String> {
    let shown = label;
    toml::from_str(text).map_err(|e| {
        let place = e.span().map_or_else(String::new, |span| {
            let (line, column) = specula::line_column(text, span.start);
            format!(":{line}:{column}")
        });
        format!(
            "lobe file {shown}{place}: {} (a lobe file has name, formula, and optionally \
             description, tail and [parameters.NAME] tables of default, min, max)",
            e.message().trim()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_define_lobes_with_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sharp.toml");
        std::fs::write(
            &path,
            "name = \"file-sharp\"\nformula = \"t ^ (n * k)\"\n[parameters.k]\ndefault = 1\nmin = \
                1\nmax = 4\n",
        )
        .unwrap();
        let kind = parse_lobe("@sharp.toml:k=2", Some(dir.path())).unwrap();
        assert_eq!(kind.to_string(), "file-sharp:k=2");
        let lobe = specula::Lobe::new(kind, specula::Exponent::new(8.0));
        assert!((lobe.eval(0.5_f64) - 0.5_f64.powi(16)).abs() < 1e-18);
        assert_eq!(
            parse_lobe(&format!("@{}", path.display()), None)
                .unwrap()
                .to_string(),
            "file-sharp"
        );
    }

    #[test]
    fn lists_keep_formulas_and_values_whole() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("two.toml"),
            "name = \"list-two\"\nformula = \"t ^ (n * k * m)\"\n[parameters.k]\ndefault = 1\nmin \
                = 1\nmax = 4\n[parameters.m]\ndefault = 1\nmin = 1\nmax = 4\n",
        )
        .unwrap();
        let kinds = parse_lobe_list(
            "pow, @two.toml:k=2,m=3, =max(0, 1 - n * (1 - t)), cosquad:v=2",
            Some(dir.path()),
        )
        .unwrap();
        let shown: Vec<String> = kinds.iter().map(ToString::to_string).collect();
        assert_eq!(shown[0], "pow");
        assert_eq!(shown[1], "list-two:k=2,m=3");
        assert!(shown[2].starts_with("formula"), "{shown:?}");
        assert_eq!(shown[3], "cosquad:v=2");
        assert_eq!(kinds.len(), 4);
    }

    #[test]
    fn bad_files_get_one_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, "name = \"x\"\nformula = 3\n").unwrap();
        for (text, says) in [
            (format!("@{}", path.display()), "bad.toml:2:11"),
            (format!("@{}", dir.path().display()), "not a regular file"),
            (
                format!("@{}/missing.toml", dir.path().display()),
                "lobe file",
            ),
        ] {
            let message = parse_lobe(&text, None).unwrap_err();
            assert!(
                message.contains(says) && !message.contains('\n'),
                "{text}: {message}"
            );
        }
    }
}
