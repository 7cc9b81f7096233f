//! Command-line arguments: parsers that turn text into the core's validated types, so every
//! message about a bad value comes from the library's one registry.

use clap::builder::{PossibleValue, TypedValueParser};
use clap::{Arg, Command, ValueEnum};
use specula::analysis::Precision;
use specula::{Geometry, LobeKind};

/// Parses lobe ids against the registry and lists its ids as the possible values in `--help`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LobeParser;

impl TypedValueParser for LobeParser {
    type Value = LobeKind;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<LobeKind, clap::Error> {
        let text = value.to_string_lossy();
        specula_render::lobe_file::parse_lobe(&text, None)
            .map_err(|error| invalid_value(cmd, arg, &error))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(LobeKind::ALL.into_iter().map(|kind| {
            PossibleValue::new(kind.id()).help(kind.info().summary)
        })))
    }
}

/// A comma-separated list of lobes, parsed whole so that a formula's commas and a lobe's
/// parameter values stay with it (`specula_render::lobe_file::parse_lobe_list`).
#[derive(Clone, Debug, PartialEq)]
pub struct LobeList(pub Vec<LobeKind>);

/// Parses a [`LobeList`], listing the registry's ids as the possible values in `--help`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LobeListParser;

impl TypedValueParser for LobeListParser {
    type Value = LobeList;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<LobeList, clap::Error> {
        specula_render::lobe_file::parse_lobe_list(&value.to_string_lossy(), None)
            .map(LobeList)
            .map_err(|error| invalid_value(cmd, arg, &error))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        LobeParser.possible_values()
    }
}

/// Every lobe of repeated `--lobe` lists, in order.
#[must_use]
pub fn flatten(lists: &[LobeList]) -> Vec<LobeKind> {
    lists
        .iter()
        .flat_map(|list| list.0.iter().copied())
        .collect()
}

/// Parses a specular exponent in `[1, 1000]` (`N`), or one or a range (`LOW..HIGH` as
/// `steps + 1` log-spaced ones): the library's parsers, which every face shares.
pub use specula_decide::{parse_exponent, parse_exponent_range};

/// Parses a cosine in `[-1, 1]`.
pub fn parse_cosine(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number; a cosine must be in [-1, 1]"))?;
    if (-1.0..=1.0).contains(&value) {
        Ok(value)
    } else {
        Err(specula::Error::CosineOutOfRange { value }.to_string())
    }
}

/// An error bound: a percentage in `(0, 100]` (`1%` or `1`), as a fraction.
pub fn parse_percent(text: &str) -> Result<f64, String> {
    let number = text.trim().trim_end_matches('%');
    match number.parse::<f64>() {
        Ok(value) if value > 0.0 && value <= 100.0 => Ok(value / 100.0),
        _ => Err(format!(
            "'{text}' is not an error in (0, 100] %; write it as 1% or 0.5"
        )),
    }
}

/// A margin over pow's fit error: a percentage in `[0, 100]`.
pub fn parse_margin(text: &str) -> Result<f64, String> {
    let number = text.trim().trim_end_matches('%');
    match number.parse::<f64>() {
        Ok(value) if (0.0..=100.0).contains(&value) => Ok(value / 100.0),
        _ => Err(format!(
            "'{text}' is not a margin in [0, 100] %; write it as 5% or 2.5"
        )),
    }
}

/// Parses an angle in degrees (any finite value; the lobe is symmetric and 0 past 90).
pub fn parse_degrees(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|value| value.is_finite())
        .ok_or_else(|| format!("'{text}' is not a finite angle in degrees"))
}

fn invalid_value(cmd: &Command, arg: Option<&Arg>, message: &str) -> clap::Error {
    let name = arg.map_or_else(|| "value".to_owned(), |arg| arg.to_string());
    clap::Error::raw(
        clap::error::ErrorKind::ValueValidation,
        format!("invalid {name}: {message}\n"),
    )
    .with_cmd(cmd)
}

/// Output formats of the table commands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum OutputFormat {
    /// Aligned columns for reading.
    #[default]
    Table,
    /// Comma-separated values with a header row.
    Csv,
    /// JSON (an array of objects).
    Json,
}

/// `phong` or `blinn`, as a clap value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum GeometryArg {
    /// t = R.V.
    #[default]
    Phong,
    /// t = N.H.
    Blinn,
}

impl From<GeometryArg> for Geometry {
    fn from(arg: GeometryArg) -> Self {
        match arg {
            GeometryArg::Phong => Geometry::Phong,
            GeometryArg::Blinn => Geometry::Blinn,
        }
    }
}

/// Where (and in what arithmetic) the analysis evaluates lobes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum BackendArg {
    /// The f64 reference path.
    #[default]
    F64,
    /// The f32 fast path on the CPU.
    F32,
    /// The f32 batch path on the CPU (SIMD).
    Simd,
    /// f32 in a GPU compute shader (WGSL on wgpu).
    Gpu,
}

impl BackendArg {
    /// The CPU arithmetic, `None` for the GPU.
    pub fn cpu_precision(self) -> Option<Precision> {
        match self {
            BackendArg::F64 => Some(Precision::F64),
            BackendArg::F32 => Some(Precision::F32),
            BackendArg::Simd => Some(Precision::F32Simd),
            BackendArg::Gpu => None,
        }
    }
}

/// Which renderer draws.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum RendererArg {
    /// The tiled CPU rasterizer.
    #[default]
    Cpu,
    /// wgpu and WGSL (a GPU, or Mesa's lavapipe on the CPU).
    Gpu,
}

/// A value parser for a closed set of choices named by `id`, listing them in `--help` and in
/// the error for an unknown name (scenes and the command line share the ids).
pub fn choice<T: Copy + Send + Sync + 'static>(
    all: &'static [T],
    id: fn(T) -> &'static str,
) -> impl TypedValueParser<Value = T> {
    clap::builder::PossibleValuesParser::new(all.iter().map(|&value| id(value))).map(move |name| {
        *all.iter()
            .find(|&&value| id(value) == name)
            .expect("clap only passes listed names")
    })
}

/// The input-file limit: a flag of the commands that read meshes or images.
#[derive(Debug, clap::Args)]
pub struct InputLimit {
    /// The largest mesh or image file to read, in MiB (files are checked before reading; a
    /// path that is not a regular file is refused).
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u64).range(1..=65_536))]
    max_input_mib: u64,
}

impl Default for InputLimit {
    /// The flag's default, 512 MiB.
    fn default() -> Self {
        Self { max_input_mib: 512 }
    }
}

impl InputLimit {
    /// Makes it the process's limit.
    pub fn apply(&self) {
        specula_render::input::set_max_input_bytes(self.max_input_mib << 20);
    }
}

/// Refuses, before any work, a user's lobe whose formula is not a lobe at one of the
/// exponents; the library's check, which every face runs.
pub use specula_decide::check_lobes;

/// Parses one of a library's closed sets of choices (a target, a zone) through its `FromStr`,
/// so the refusal is the library's, and lists the choices with their summaries in `--help`.
#[derive(Clone, Copy)]
pub struct ChoiceParser<T: 'static> {
    all: &'static [T],
    id: fn(T) -> &'static str,
    summary: fn(T) -> &'static str,
}

/// A [`ChoiceParser`] over `all`, named by `id` and described by `summary`.
pub fn described<T: Copy>(
    all: &'static [T],
    id: fn(T) -> &'static str,
    summary: fn(T) -> &'static str,
) -> ChoiceParser<T> {
    ChoiceParser { all, id, summary }
}

impl<T> TypedValueParser for ChoiceParser<T>
where
    T: Copy + Send + Sync + std::str::FromStr<Err = String> + 'static,
{
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        value
            .to_string_lossy()
            .parse()
            .map_err(|error: String| invalid_value(cmd, arg, &error))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.all.iter().map(|&value| {
            PossibleValue::new((self.id)(value)).help((self.summary)(value))
        })))
    }
}
