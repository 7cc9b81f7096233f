//! What the registry's `LobeKind` does beyond the list (`lobes!` in `lobe/mod.rs` makes the
//! variants, `ALL`, entries and styles from each lobe's file): ids and their parsing, the
//! kinds a parameter's values make, the user's lobes' colours.

use serde::{Serialize, Serializer};

use super::info::{LineStyle, ParamInfo};
use super::LobeKind;
use crate::error::{Error, Result};

/// A user's lobe: a formula and its parameter values, defined in this process
/// ([`crate::formula::instance`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FormulaId(pub(crate) u32);

impl LobeKind {
    /// The id without parameters, e.g. `cosquad`.
    #[must_use]
    pub fn id(self) -> &'static str {
        self.info().id
    }

    /// Every registered id, comma separated (for error messages and help).
    #[must_use]
    pub fn valid_ids() -> String {
        Self::ALL.map(LobeKind::id).join(", ")
    }

    /// The model's position in [`LobeKind::ALL`], parameters aside.
    #[must_use]
    pub fn index(self) -> u32 {
        if let LobeKind::Formula(FormulaId(id)) = self {
            return LobeKind::ALL.len() as u32 + id;
        }
        let same = |k: &LobeKind| core::mem::discriminant(k) == core::mem::discriminant(&self);
        LobeKind::ALL.iter().position(same).unwrap_or_default() as u32
    }

    /// Parses `ID` or `ID:param=value`, e.g. `schlick`, `cosquad:v=5`; the name of a lobe
    /// defined from a formula earlier in this process (`mine:k=2`); or `=FORMULA`, a formula
    /// of `t` and `n` inline (`=exp2(n * (t - 1) * 1.4427)`).
    pub fn parse(text: &str) -> Result<Self> {
        let text = text.trim();
        if let Some(formula) = text.strip_prefix('=') {
            let definition = crate::formula::Definition {
                name: "formula".to_owned(),
                description: Some("a formula given inline".to_owned()),
                formula: formula.to_owned(),
                tail: None,
                parameters: std::collections::BTreeMap::new(),
            };
            let formula = crate::formula::define(definition, crate::formula::Naming::Unique)?;
            return crate::formula::instance(formula, &[]);
        }
        let (id, params) = match text.split_once(':') {
            Some((id, params)) => (id, Some(params)),
            None => (text, None),
        };
        if let Some(formula) = crate::formula::registry::find(id) {
            let values = match params {
                Some(params) => crate::formula::registry::parse_values(formula, params)?,
                None => Vec::new(),
            };
            return crate::formula::instance(formula, &values);
        }
        let kind = Self::ALL
            .into_iter()
            .find(|kind| kind.id().eq_ignore_ascii_case(id))
            .ok_or_else(|| {
                let defined = crate::formula::registry::names();
                let mut valid = Self::valid_ids();
                for name in &defined {
                    valid.push_str(", ");
                    valid.push_str(name);
                }
                valid.push_str(
                    " (or @FILE.toml for a lobe file, =FORMULA for a formula of t and n)",
                );
                Error::UnknownLobe {
                    id: crate::error::excerpt(id),
                    valid,
                    hint: crate::error::did_you_mean(
                        id,
                        Self::ALL.map(LobeKind::id).into_iter().chain(defined),
                    ),
                }
            })?;
        match params {
            None => Ok(kind),
            Some(params) => kind.with_parameter(params),
        }
    }
}

pub(super) fn parse_param(lobe: &'static str, param: &ParamInfo, text: &str) -> Result<u32> {
    let invalid = |message: String| Error::InvalidLobeParameter { lobe, message };
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| invalid(format!("expected '{}=VALUE', got '{text}'", param.name)))?;
    if name.trim() != param.name {
        return Err(invalid(format!(
            "unknown parameter '{name}'; valid: {}",
            param.name
        )));
    }
    value
        .trim()
        .parse::<u32>()
        .ok()
        .filter(|v| (param.min..=param.max).contains(v))
        .ok_or_else(|| {
            invalid(format!(
                "{} = '{value}' is not an integer in [{}, {}]",
                param.name, param.min, param.max
            ))
        })
}

impl core::fmt::Display for LobeKind {
    /// The id, with parameters only where they differ from the defaults.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match (self, self.built_in_text()) {
            (LobeKind::Formula(id), _) => {
                let instance = crate::formula::registry::get(*id);
                f.write_str(instance.info().id)
                    .and_then(|()| write_values(f, instance))
            }
            (_, text) => f.write_str(&text.unwrap_or_default()),
        }
    }
}

/// A user's lobe's line: six colours none of the built-ins has (Paul Tol's wine, indigo, teal
/// and purple, a khaki and a dark teal), so a user's lobe never looks like a built-in one; the
/// seventh user's lobe takes the first colour dashed.
pub(super) fn user_line_style(FormulaId(id): FormulaId) -> LineStyle {
    const USER: [[u8; 3]; 6] = [
        [136, 34, 85],
        [51, 34, 136],
        [68, 170, 153],
        [107, 107, 0],
        [0, 95, 95],
        [170, 68, 153],
    ];
    LineStyle {
        rgb: USER[id as usize % 6],
        dashed: (id / 6) % 2 == 1,
    }
}

/// `:k=1.5,m=2` for the parameters that differ from their defaults.
fn write_values(
    f: &mut core::fmt::Formatter<'_>,
    instance: &crate::formula::Instance,
) -> core::fmt::Result {
    let formula = instance.formula();
    let mut separator = ':';
    for (parameter, value) in formula.parameters().iter().zip(instance.values()) {
        if *value != parameter.default {
            write!(f, "{separator}{}={value}", parameter.name)?;
            separator = ',';
        }
    }
    Ok(())
}

impl core::str::FromStr for LobeKind {
    type Err = Error;
    fn from_str(text: &str) -> Result<Self> {
        Self::parse(text)
    }
}

impl Serialize for LobeKind {
    fn serialize<S: Serializer>(&self, serializer: S) -> core::result::Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A registry entry's variants are one per value of its parameter's range, stated in its
    /// `ParamInfo` (cosquad: `v` from 0 to 10), or the kind alone.
    #[test]
    fn variants_span_the_parameters_range() {
        let cosquad: Vec<LobeKind> = (0..=10).map(|v| LobeKind::CosQuad { v }).collect();
        assert_eq!(LobeKind::CosQuad { v: 2 }.variants(), cosquad);
        assert_eq!(LobeKind::Pow.variants(), [LobeKind::Pow]);
    }

    #[test]
    fn every_id_round_trips_and_is_unique() {
        for kind in LobeKind::ALL {
            assert_eq!(LobeKind::parse(&kind.to_string()), Ok(kind));
            let same_id = LobeKind::ALL.iter().filter(|k| k.id() == kind.id()).count();
            assert_eq!(same_id, 1, "{kind} registered twice");
        }
        assert_eq!(
            LobeKind::parse("cosquad:v=6"),
            Ok(LobeKind::CosQuad { v: 6 })
        );
        assert_eq!(LobeKind::CosQuad { v: 6 }.to_string(), "cosquad:v=6");
    }

    #[test]
    fn bad_ids_and_parameters_name_the_valid_choices() {
        let message = LobeKind::parse("phong").unwrap_err().to_string();
        assert!(
            message.contains("phong") && message.contains("schlick-mod"),
            "{message}"
        );
        for bad in ["cosquad:v=11", "cosquad:w=3", "cosquad:v", "schlick:v=2"] {
            assert!(LobeKind::parse(bad).is_err(), "{bad} accepted");
        }
    }

    /// A colour in CIELAB (D65), by the standard's formulas.
    fn cielab([r, g, b]: [u8; 3]) -> [f64; 3] {
        let linear = |c: u8| {
            let c = f64::from(c) / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        let (r, g, b) = (linear(r), linear(g), linear(b));
        let x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
        let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
        let z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
        let f = |t: f64| {
            if t > 216.0 / 24389.0 {
                t.cbrt()
            } else {
                (24389.0 / 27.0 * t + 16.0) / 116.0
            }
        };
        [
            116.0 * f(y) - 16.0,
            500.0 * (f(x) - f(y)),
            200.0 * (f(y) - f(z)),
        ]
    }

    /// Every lobe a colour of its own: no two, the built-ins and six users' lobes, closer
    /// than 25 in CIELAB (where about 2 is the least difference a viewer sees side by side).
    #[test]
    fn no_two_lobes_share_a_colour() {
        let lobes: Vec<LobeKind> = LobeKind::ALL
            .into_iter()
            .chain((0..6).map(|id| LobeKind::Formula(FormulaId(id))))
            .collect();
        for (i, a) in lobes.iter().enumerate() {
            for b in &lobes[i + 1..] {
                let (p, q) = (cielab(a.line_style().rgb), cielab(b.line_style().rgb));
                let distance = p
                    .iter()
                    .zip(q)
                    .map(|(x, y)| (x - y).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let (a, b) = (a.line_style().hex(), b.line_style().hex());
                assert!(distance >= 25.0, "{a} and {b}: {distance:.1} apart");
            }
        }
    }

    /// No two lobes share a colour and a dash, and every colour is dark enough to read on
    /// white (luma below 0.7, which leaves out the set's yellow).
    #[test]
    fn every_lobe_has_its_own_readable_line_style() {
        let styles: Vec<LineStyle> = LobeKind::ALL.map(LobeKind::line_style).to_vec();
        for (i, a) in styles.iter().enumerate() {
            for b in &styles[i + 1..] {
                assert_ne!(a, b, "two lobes look alike");
            }
            let [r, g, b] = a.rgb.map(|c| f64::from(c) / 255.0);
            assert!(
                0.2126 * r + 0.7152 * g + 0.0722 * b < 0.7,
                "{} too light",
                a.hex()
            );
        }
    }
}
