//! What the registry states of a lobe ([`LobeInfo`], [`ParamInfo`], [`Origin`]) and how its
//! curves are drawn ([`LineStyle`]): the types each model's file fills in for its lobes, and
//! `kind.rs` reads.

use serde::Serialize;

/// A lobe parameter other than `n`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ParamInfo {
    /// Its name in ids such as `cosquad:v=5`.
    pub name: &'static str,
    /// What it does.
    pub description: &'static str,
    /// The default value.
    pub default: u32,
    /// The smallest valid value.
    pub min: u32,
    /// The largest valid value.
    pub max: u32,
}

/// Where a lobe comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Origin {
    /// The classic lobe every approximation is measured against.
    Reference,
    /// Published before the thesis.
    Literature,
    /// Proposed in the thesis.
    Thesis,
    /// A variant added by specula, measured the same way.
    Specula,
    /// Written by the user as a formula.
    User,
}

impl Origin {
    /// The origin in words, as tables show it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Origin::Reference => "reference",
            Origin::Literature => "literature",
            Origin::Thesis => "thesis",
            Origin::Specula => "specula",
            Origin::User => "user",
        }
    }
}

/// A registry entry.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LobeInfo {
    /// The id used on the command line and in scenes.
    pub id: &'static str,
    /// One line on what the lobe is.
    pub summary: &'static str,
    /// The formula, in plain text.
    pub formula: &'static str,
    /// Whether the lobe's native input is the angle `g` rather than the cosine `t`.
    pub takes_angle: bool,
    /// Parameters other than `n`.
    pub params: &'static [ParamInfo],
    /// Where it comes from.
    pub origin: Origin,
}

/// How a lobe's curves are drawn: [`LobeKind::line_style`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LineStyle {
    /// Red, green, blue.
    pub rgb: [u8; 3],
    /// Dashed rather than solid.
    pub dashed: bool,
}

impl LineStyle {
    /// The colour as `#rrggbb`.
    #[must_use]
    pub fn hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.rgb[0], self.rgb[1], self.rgb[2])
    }
}
