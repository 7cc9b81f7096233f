//! The registry's one list. `lobes!` turns a line per lobe, `Variant => module` (with the
//! variant's parameter, `{ v: u8 = DEFAULT }`, if it has one, and `cfg` attributes if any),
//! into everything that lists the lobes: the module, the [`LobeKind`](super::LobeKind) variant
//! and its place in `LobeKind::ALL`, the prepared `Model` variant and its preparation,
//! `each_model!` (the dispatch every stated fact goes through), the registry entry and plot
//! style, and the parameter's parsing and printing. What a lobe is lives in its file: `INFO`,
//! `STYLE`, `type Prepared`, `fn prepare`, and `ModelFacts`/`ModelF32` for `Prepared`.
//!
//! The invocation starts with `$`, which the expansion needs to define `each_model!` (a
//! macro written by a macro spells its own `$` that way).

macro_rules! lobes {
    ($d:tt $(
        $(#[$attr:meta])*
        $variant:ident $({ $field:ident : $field_type:ty = $default:expr })? => $module:ident,
    )*) => {
        $( $(#[$attr])* mod $module; )*

        /// Which lobe function, with its structural parameters (but not `n`): one variant per
        /// line of the registry (`lobes!` in `lobe/mod.rs`), each described in its own file.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum LobeKind {
            $(
                $(#[$attr])*
                #[doc = concat!("The lobe of `lobe/", stringify!($module), ".rs`, its manual.")]
                $variant $({
                    #[doc = concat!("The `", stringify!($field), "` of its `INFO.params`.")]
                    $field: $field_type
                })?,
            )*
            /// A lobe of the user's, written as a formula ([`crate::formula`]).
            Formula(FormulaId),
        }

        impl LobeKind {
            /// Every lobe, with default parameters, in the order tables list them.
            pub const ALL: [LobeKind; [$($(#[$attr])* stringify!($variant),)*].len()] = [
                $( $(#[$attr])* LobeKind::$variant $({ $field: $default })?, )*
            ];

            /// The registry entry.
            #[must_use]
            pub fn info(self) -> &'static LobeInfo {
                match self {
                    $( $(#[$attr])* LobeKind::$variant { .. } => &$module::INFO, )*
                    LobeKind::Formula(id) => crate::formula::registry::get(id).info(),
                }
            }

            /// How every plot draws the lobe (the report's, the explorer's, the Python
            /// package's): its file's colour, from Kelly's set of maximum contrast and Tol's
            /// cyan (no two lobes, a user's included, closer than 25 in CIELAB: tested), a
            /// family's variants dashed as well, so that the families read apart even without
            /// colour vision.
            #[must_use]
            pub fn line_style(self) -> LineStyle {
                match self {
                    $( $(#[$attr])* LobeKind::$variant { .. } => $module::STYLE, )*
                    LobeKind::Formula(id) => kind::user_line_style(id),
                }
            }

            /// Every kind this one's registry entry names: one per value of its parameter
            /// (`cosquad:v=0` to `cosquad:v=10`), or itself for a lobe without one. A user's
            /// lobe is itself: its parameters are reals.
            #[must_use]
            pub fn variants(self) -> Vec<LobeKind> {
                match self {
                    $( $(#[$attr])* LobeKind::$variant { .. } => {
                        lobes!(@variants $variant, $module $(, $field, $field_type)?)
                    } )*
                    LobeKind::Formula(_) => vec![self],
                }
            }

            /// This built-in kind with its parameter set from `name=value` (`v=5`).
            fn with_parameter(self, text: &str) -> Result<Self> {
                match self {
                    $( $(#[$attr])* LobeKind::$variant { .. } => {
                        lobes!(@with_parameter $variant, $module, text $(, $field, $field_type)?)
                    } )*
                    LobeKind::Formula(_) => unreachable!("a user's lobe is parsed by its formula"),
                }
            }

            /// The id, with the parameter where it differs from its default; `None` for a
            /// user's lobe.
            fn built_in_text(self) -> Option<String> {
                match self {
                    $( $(#[$attr])* LobeKind::$variant $({ $field })? => {
                        Some(lobes!(@text $module $(, $field, $default)?))
                    } )*
                    LobeKind::Formula(_) => None,
                }
            }
        }

        /// The prepared state, one variant per lobe.
        #[derive(Clone, Copy, Debug, PartialEq)]
        enum Model {
            $( $(#[$attr])* $variant($module::Prepared), )*
            Formula(formula::FormulaLobe),
        }

        /// `kind`'s model prepared for `n`.
        fn prepare(kind: LobeKind, n: Exponent) -> Model {
            match kind {
                $( $(#[$attr])* LobeKind::$variant $({ $field })? => {
                    Model::$variant($module::prepare(n $(, $field)?))
                } )*
                LobeKind::Formula(id) => Model::Formula(formula::FormulaLobe::new(id, n)),
            }
        }

        /// `$body` with `$m` bound to the prepared model, whichever it is: the one dispatch
        /// of the facts each model states in its own file.
        macro_rules! each_model {
            ($d model:expr, $d m:ident => $d body:expr) => {
                match $d model {
                    $( $(#[$attr])* Model::$variant($d m) => $d body, )*
                    Model::Formula($d m) => $d body,
                }
            };
        }
    };
    (@with_parameter $variant:ident, $module:ident, $text:ident) => {
        Err(Error::InvalidLobeParameter {
            lobe: $module::INFO.id,
            message: format!("'{}' given, but this lobe takes no parameters besides n", $text),
        })
    };
    (@with_parameter $variant:ident, $module:ident, $text:ident, $field:ident, $field_type:ty) => {{
        let param = lobes!(@param $module, $field);
        let value = kind::parse_param($module::INFO.id, param, $text)?;
        Ok(LobeKind::$variant {
            $field: lobes!(@value param, value, $field_type),
        })
    }};
    (@variants $variant:ident, $module:ident) => {
        vec![LobeKind::$variant]
    };
    (@variants $variant:ident, $module:ident, $field:ident, $field_type:ty) => {{
        let param = lobes!(@param $module, $field);
        (param.min..=param.max)
            .map(|value| LobeKind::$variant {
                $field: lobes!(@value param, value, $field_type),
            })
            .collect()
    }};
    // The `ParamInfo` the lobe's entry lists for its variant's field.
    (@param $module:ident, $field:ident) => {{
        let info = &$module::INFO;
        let param = info.params.iter().find(|p| p.name == stringify!($field));
        param.unwrap_or_else(|| unreachable!("{} lists its parameter", info.id))
    }};
    // A value within the parameter's range, as its field's type.
    (@value $param:ident, $value:ident, $field_type:ty) => {
        <$field_type>::try_from($value)
            .unwrap_or_else(|_| unreachable!("{}'s range fits its type", $param.name))
    };
    (@text $module:ident) => {
        $module::INFO.id.to_owned()
    };
    (@text $module:ident, $field:ident, $default:expr) => {
        if $field == $default {
            $module::INFO.id.to_owned()
        } else {
            format!("{}:{}={}", $module::INFO.id, stringify!($field), $field)
        }
    };
}
