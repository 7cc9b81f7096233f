//! The formulas a process has been given, so that a [`LobeKind`] naming one stays `Copy`.
//!
//! A [`LobeKind::Formula`] holds a [`FormulaId`]: the index of an [`Instance`] (a formula
//! and its parameter values) here. Entries live as long as the process (they are leaked, so
//! that a prepared [`Lobe`](crate::Lobe) can hold a plain reference), which is bounded:
//! [`MAX_FORMULAS`] formulas and [`MAX_INSTANCES`] instances, after which defining another
//! is refused (a server asked for endless new formulas says so instead of growing).

use std::sync::RwLock;

use super::{Definition, Formula};
use crate::error::Error;
use crate::lobe::{FormulaId, LobeInfo, LobeKind, Origin};

/// The most formulas one process defines.
pub const MAX_FORMULAS: usize = 4096;
/// The most (formula, parameter values) instances one process defines.
const MAX_INSTANCES: usize = 4 * MAX_FORMULAS;

/// What to do when a definition's name is taken by a different formula.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Naming {
    /// Refuse it (two files naming their lobes alike).
    Exact,
    /// Number it: `name-2`, `name-3`, ... (inline formulas, the explorer's text box).
    Unique,
}

/// A formula with values for its parameters: what a [`FormulaId`] stands for.
#[derive(Debug)]
pub struct Instance {
    formula: &'static Formula,
    info: &'static LobeInfo,
    values: Vec<f64>,
}

impl Instance {
    /// The formula.
    #[must_use]
    pub fn formula(&self) -> &'static Formula {
        self.formula
    }

    /// The parameters' values, in declaration order.
    #[must_use]
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    pub(crate) fn info(&self) -> &'static LobeInfo {
        self.info
    }
}

struct Registry {
    formulas: Vec<(&'static Formula, &'static LobeInfo)>,
    instances: Vec<&'static Instance>,
}

static REGISTRY: RwLock<Registry> = RwLock::new(Registry {
    formulas: Vec::new(),
    instances: Vec::new(),
});

fn read() -> std::sync::RwLockReadGuard<'static, Registry> {
    REGISTRY
        .read()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn write() -> std::sync::RwLockWriteGuard<'static, Registry> {
    REGISTRY
        .write()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Whether `name` may name a lobe: the id alphabet, and not a built-in's id.
pub(crate) fn check_name(name: &str) -> Result<(), String> {
    let bytes = name.as_bytes();
    if name.is_empty()
        || name.len() > 32
        || !bytes[0].is_ascii_lowercase()
        || !bytes
            .iter()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || *b == b'-' || *b == b'_')
    {
        return Err(format!(
            "the name '{}' is not an id: a lowercase letter, then up to 31 lowercase letters, \
             digits, '-' or '_'",
            crate::excerpt(name)
        ));
    }
    if LobeKind::ALL.iter().any(|kind| kind.id() == name) {
        return Err(format!(
            "the name '{name}' is a built-in lobe's id; choose another (built-in: {})",
            LobeKind::valid_ids()
        ));
    }
    Ok(())
}

/// Compiles and registers `definition` (or finds it, defined before), with its name taken
/// as `naming` says.
pub fn define(mut definition: Definition, naming: Naming) -> Result<&'static Formula, Error> {
    check_name(&definition.name).map_err(|message| Error::Formula {
        lobe: crate::excerpt(&definition.name),
        message,
    })?;
    // One pass over the defined formulas: the same definition under this name or a
    // numbered one is found again; otherwise the name, or the next free number, is taken.
    let base = definition.name.clone();
    let numbered = |name: &str| -> Option<u64> {
        match name.strip_prefix(base.as_str()) {
            Some("") => Some(1),
            Some(rest) => rest
                .strip_prefix('-')?
                .parse::<u32>()
                .ok()
                .filter(|&k| k > 1)
                .map(u64::from),
            None => None,
        }
    };
    let same = |other: &Definition| {
        other.formula == definition.formula
            && other.tail == definition.tail
            && other.parameters == definition.parameters
            && other.description == definition.description
    };
    let mut highest = 0;
    for (formula, _) in &read().formulas {
        let Some(number) = numbered(formula.name()) else {
            continue;
        };
        if naming == Naming::Exact && number > 1 {
            continue;
        }
        if same(formula.definition()) {
            return Ok(formula);
        }
        if naming == Naming::Exact {
            return Err(Error::Formula {
                lobe: base,
                message: "a different lobe of that name is already defined; rename one".to_owned(),
            });
        }
        highest = highest.max(number);
    }
    if highest > 0 {
        definition.name = format!("{base}-{}", highest + 1);
    }
    // Refused before compiling, so that a full registry costs a request nothing it keeps.
    if read().formulas.len() >= MAX_FORMULAS {
        return Err(Error::Formula {
            lobe: definition.name,
            message: format!(
                "this process has defined its limit of {MAX_FORMULAS} lobes; restart it"
            ),
        });
    }
    let formula = Formula::compile(definition)?;
    let mut registry = write();
    if let Some((existing, _)) = registry
        .formulas
        .iter()
        .find(|(f, _)| f.name() == formula.name())
    {
        // Defined by another thread meanwhile: the same text, another number, or a refusal.
        return if existing.definition() == formula.definition() {
            Ok(existing)
        } else if naming == Naming::Unique {
            drop(registry);
            let mut again = formula.definition.clone();
            again.name = base;
            define(again, naming)
        } else {
            Err(Error::Formula {
                lobe: formula.name().to_owned(),
                message: "a different lobe of that name was defined meanwhile".to_owned(),
            })
        };
    }
    if registry.formulas.len() >= MAX_FORMULAS {
        return Err(Error::Formula {
            lobe: formula.name().to_owned(),
            message: format!(
                "this process has defined its limit of {MAX_FORMULAS} lobes; restart it"
            ),
        });
    }
    let formula: &'static Formula = Box::leak(Box::new(formula));
    let definition = formula.definition();
    let text: String = definition
        .formula
        .lines()
        .map(|line| line.split('#').next().unwrap_or_default().trim())
        .filter(|line| !line.is_empty())
        .collect::<Vec<_>>()
        .join(" ");
    let info: &'static LobeInfo = Box::leak(Box::new(LobeInfo {
        id: leak(formula.name()),
        summary: leak(
            definition
                .description
                .as_deref()
                .unwrap_or("a lobe of yours"),
        ),
        formula: leak(&crate::excerpt(&text)),
        takes_angle: false,
        params: &[],
        origin: Origin::User,
    }));
    registry.formulas.push((formula, info));
    Ok(formula)
}

fn leak(text: &str) -> &'static str {
    Box::leak(text.to_owned().into_boxed_str())
}

/// The lobe kind of `formula` with the given parameter values (the others at their
/// defaults), each checked against its declared range.
pub fn instance(formula: &'static Formula, given: &[(String, f64)]) -> Result<LobeKind, Error> {
    let refuse = |message: String| Error::Formula {
        lobe: formula.name().to_owned(),
        message,
    };
    let mut values: Vec<f64> = formula.parameters().iter().map(|p| p.default).collect();
    for (name, value) in given {
        let Some(index) = formula.parameters().iter().position(|p| p.name == *name) else {
            let names: Vec<&str> = formula
                .parameters()
                .iter()
                .map(|p| p.name.as_str())
                .collect();
            return Err(refuse(format!(
                "unknown parameter '{}'{}; its parameters: {}",
                crate::excerpt(name),
                crate::did_you_mean(name, names.iter().copied()),
                if names.is_empty() {
                    "none besides n".to_owned()
                } else {
                    names.join(", ")
                }
            )));
        };
        let [min, max] = formula.parameters()[index].range;
        if !(value.is_finite() && (min..=max).contains(value)) {
            return Err(refuse(format!(
                "parameter {name} = {value} is out of range: it must lie in [{min}, {max}]"
            )));
        }
        values[index] = *value;
    }
    let mut registry = write();
    let found = registry
        .instances
        .iter()
        .position(|i| core::ptr::eq(i.formula, formula) && i.values == values);
    let index = match found {
        Some(index) => index,
        None => {
            if registry.instances.len() >= MAX_INSTANCES {
                return Err(refuse(format!(
                    "this process has prepared its limit of {MAX_INSTANCES} parameter settings; \
                     restart it"
                )));
            }
            let info = registry
                .formulas
                .iter()
                .find(|(f, _)| core::ptr::eq(*f, formula))
                .map(|(_, info)| *info)
                .ok_or_else(|| refuse("the formula was not defined through define".to_owned()))?;
            registry.instances.push(Box::leak(Box::new(Instance {
                formula,
                info,
                values,
            })));
            registry.instances.len() - 1
        }
    };
    Ok(LobeKind::Formula(FormulaId(
        u32::try_from(index).unwrap_or(u32::MAX),
    )))
}

/// The instance `id` stands for.
pub(crate) fn get(id: FormulaId) -> &'static Instance {
    read().instances[id.0 as usize]
}

/// The formula defined under `name`.
pub(crate) fn find(name: &str) -> Option<&'static Formula> {
    read()
        .formulas
        .iter()
        .find(|(f, _)| f.name().eq_ignore_ascii_case(name))
        .map(|(f, _)| *f)
}

/// Every user lobe (formula and parameter values) defined so far, in definition order.
#[must_use]
pub fn kinds() -> Vec<LobeKind> {
    (0..read().instances.len())
        .map(|i| LobeKind::Formula(FormulaId(i as u32)))
        .collect()
}

/// Every defined formula's name.
pub(crate) fn names() -> Vec<&'static str> {
    read().formulas.iter().map(|(_, info)| info.id).collect()
}

/// Parses a user lobe's parameter values, `k=1.5,m=2`, into pairs.
pub fn parse_values(formula: &Formula, text: &str) -> Result<Vec<(String, f64)>, Error> {
    text.split(',')
        .map(|pair| {
            let (name, value) = pair.split_once('=').ok_or_else(|| Error::Formula {
                lobe: formula.name().to_owned(),
                message: format!("expected NAME=VALUE, got '{}'", crate::excerpt(pair.trim())),
            })?;
            let value: f64 = value.trim().parse().map_err(|_| Error::Formula {
                lobe: formula.name().to_owned(),
                message: format!(
                    "parameter {} = '{}' is not a number",
                    name.trim(),
                    crate::excerpt(value.trim())
                ),
            })?;
            Ok((name.trim().to_owned(), value))
        })
        .collect()
}
