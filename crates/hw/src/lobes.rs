//! The datapaths, one per lobe (SPEC section 8), built for a word length `W`.
//!
//! **What `W` means.** Every signal in `[0, 1]` (the input `t` or angle `g`, the lobe's value
//! and the intermediate values of that range) is `UQ1.(W-1)`: one integer bit, so that `t = 1`
//! is exact, and `W - 1` fraction bits. Signals of a wider range (`n (1 - t)`, the `cheb2`
//! coefficients, the first logarithm) keep the same least significant bit, `2^-(W-1)`, and as
//! many integer bits as their range needs. The exponent `n` is an integer `UQ10.0` in
//! `[1, 1000]`: hardware takes the thesis's integer exponents. Per-material constants are
//! prepared on the host, as [`specula::Lobe`] prepares them: `cosquad`'s `a = (n + 1) / 17`
//! (`v = 4`, the thesis's `K_4`), `schlick-mod`'s squaring count, `cheb2`'s ROM address.
//!
//! Every node rounds half to even and saturates.

use serde::Serialize;
use specula::lobe::FormulaId;
use specula::{Exponent, Lobe, LobeKind};

use crate::compiled;
use crate::datapath::{Builder, Datapath, Op};
use crate::exp2::Exp2Unit;
use crate::fixed::{FixedPoint, Rounding};
use crate::log2::Log2Unit;

/// The word lengths the models are built for.
pub const BITS: core::ops::RangeInclusive<u32> = 8..=24;

/// `cosquad`'s squaring count in hardware: the thesis's `K_4`.
pub const COSQUAD_V: u32 = 4;

/// `logexp`'s log2 unit: 64 segments. The first logarithm's error is multiplied by `n`, so
/// the table must be fine: 16 segments (error 3.5e-4) cost 25 % in the epicentre at `n = 512`.
pub const LOGEXP_TABLE: Log2Unit = Log2Unit::Table { segments_log2: 6 };

/// `pow`'s log2 unit: as fine as `logexp`'s, for the same reason (its error is multiplied by
/// `n`).
pub const POW_LOG2_TABLE: Log2Unit = LOGEXP_TABLE;

/// The exp2 unit of `pow` and `sg`: 64 segments, relative interpolation error `1.8e-5`, below
/// a 16-bit result's rounding.
pub const POW_EXP2_TABLE: Exp2Unit = Exp2Unit { segments_log2: 6 };

/// Integer bits of `sg`'s rate `log2(e) n`: up to 1443 at `n = 1000`.
const SG_RATE_INT_BITS: u32 = 11;

/// The squarings `schlick-mod` can select: `a = 2^k` with `k <= 7` covers `n <= 1000`.
const SCHLICK_MOD_MAX_SQUARINGS: u32 = 7;

/// A hardware datapath: the lobe it implements and, for `logexp`, its log2 unit; or a lobe of
/// yours compiled from its formula ([`HwLobe::Formula`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HwLobe {
    /// `t / (n (1 - t) + t)`: one multiply, two adds, a divider.
    Schlick,
    /// `t^a / (n (1 - t) + t)`: adds seven squarers, a multiplexer choosing `t^(2^k)` and a
    /// clamp to 1 (for `t > 1`).
    SchlickMod,
    /// `C + g (B + A g)` with `[A, B, C]` from a ROM indexed by `n`: two multiplies, two adds.
    Cheb2,
    /// `1 - log2(1 - n log2 t) / 2` with the log2 unit's table ([`LOGEXP_TABLE`]).
    LogExp,
    /// The same with Mitchell's log2 (no table, no multiplier in the unit).
    LogExpMitchell,
    /// `max(0, a (t - 1) + 1)^16`: one multiply, two adds, four squarers (and 0 at `t = 0`).
    CosQuad,
    /// The baseline: `t^n = 2^-(n (-log2 t))`, a log2 unit, a multiply by `n` and an exp2
    /// unit, both units table-interpolated ([`POW_LOG2_TABLE`], [`POW_EXP2_TABLE`]).
    Pow,
    /// The engines' spherical Gaussian `2^-(r (1 - t))`, `r = log2(e) n` per material: a
    /// subtract, a multiply and an exp2 unit (and 0 at `t = 0`).
    Sg,
    /// A lobe of yours (a lobe file, a designed lobe), compiled from its recorded expression
    /// one stage per operation (`compiled.rs`): transcendental-free formulas only.
    Formula(FormulaId),
}

impl Serialize for HwLobe {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.id())
    }
}

/// An unknown datapath id.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum HwError {
    /// Not a datapath id.
    #[error(
        "unknown hardware datapath `{0}`; valid: {valid}{hint}",
        valid = HwLobe::valid_ids(),
        hint = specula::did_you_mean(.0, HwLobe::ALL.map(HwLobe::id))
    )]
    UnknownLobe(String),
    /// A lobe of yours whose formula does not compile to a datapath.
    #[error(
        "`{lobe}` has no datapath: {why}; valid: a transcendental-free formula, or {valid}",
        valid = HwLobe::valid_ids()
    )]
    NotCompiled {
        /// The lobe.
        lobe: String,
        /// Why: the operation no stage computes, or the width it would need.
        why: String,
    },
    /// A built-in lobe that has no datapath.
    #[error(
        "`{0}` has no hardware datapath; valid: {valid}, or a lobe of yours whose formula is \
         transcendental-free (@FILE.toml)",
        valid = HwLobe::valid_ids()
    )]
    NoDatapath(String),
    /// A word length outside [`BITS`].
    #[error("word length {0} is out of range; valid: 8 to 24 bits")]
    Bits(u32),
    /// An exponent the hardware cannot take.
    #[error("n = {0} is not an integer in [1, 1000], which the hardware datapaths take")]
    Exponent(f64),
}

impl HwLobe {
    /// Every datapath.
    pub const ALL: [HwLobe; 8] = [
        HwLobe::Schlick,
        HwLobe::SchlickMod,
        HwLobe::Cheb2,
        HwLobe::LogExp,
        HwLobe::LogExpMitchell,
        HwLobe::CosQuad,
        HwLobe::Pow,
        HwLobe::Sg,
    ];

    /// The id on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            HwLobe::Schlick => "schlick",
            HwLobe::SchlickMod => "schlick-mod",
            HwLobe::Cheb2 => "cheb2",
            HwLobe::LogExp => "logexp",
            HwLobe::LogExpMitchell => "logexp-mitchell",
            HwLobe::CosQuad => "cosquad",
            HwLobe::Pow => "pow",
            HwLobe::Sg => "sg",
            HwLobe::Formula(id) => LobeKind::Formula(id).id(),
        }
    }

    /// Every id, comma-separated.
    #[must_use]
    pub fn valid_ids() -> String {
        Self::ALL.map(HwLobe::id).join(", ")
    }

    /// The datapath with id `text`: a built-in's, or a lobe of yours named or written as
    /// `=FORMULA` (a lobe file is read by the caller, who hands the lobe to
    /// [`HwLobe::of_kind`]).
    pub fn parse(text: &str) -> Result<Self, HwError> {
        let text = text.trim();
        if let Some(lobe) = Self::ALL.into_iter().find(|lobe| lobe.id() == text) {
            return Ok(lobe);
        }
        match LobeKind::parse(text) {
            Ok(kind @ LobeKind::Formula(_)) => Self::of_kind(kind),
            _ => Err(HwError::UnknownLobe(specula::excerpt(text))),
        }
    }

    /// The datapath of `kind`: its built-in one (`logexp`'s table unit, not Mitchell's), or a
    /// lobe of yours compiled from its formula, or why it has none.
    pub fn of_kind(kind: LobeKind) -> Result<Self, HwError> {
        if let LobeKind::Formula(id) = kind {
            compiled::layout(id).map_err(|why| HwError::NotCompiled {
                lobe: kind.to_string(),
                why,
            })?;
            return Ok(HwLobe::Formula(id));
        }
        Self::ALL
            .into_iter()
            .find(|lobe| lobe.float_kind() == kind)
            .ok_or_else(|| HwError::NoDatapath(kind.to_string()))
    }

    /// The float model it implements.
    #[must_use]
    pub fn float_kind(self) -> LobeKind {
        match self {
            HwLobe::Schlick => LobeKind::Schlick,
            HwLobe::SchlickMod => LobeKind::SchlickMod,
            HwLobe::Cheb2 => LobeKind::Cheb2,
            HwLobe::LogExp | HwLobe::LogExpMitchell => LobeKind::LogExp,
            HwLobe::CosQuad => LobeKind::CosQuad { v: COSQUAD_V as u8 },
            HwLobe::Pow => LobeKind::Pow,
            HwLobe::Sg => LobeKind::Sg,
            HwLobe::Formula(id) => LobeKind::Formula(id),
        }
    }

    /// Whether the input is the angle `g` rather than the cosine `t`.
    #[must_use]
    pub fn takes_angle(self) -> bool {
        self == HwLobe::Cheb2
    }

    /// The input format of `t` (or `g`) and of the output.
    #[must_use]
    pub fn unit_format(bits: u32) -> FixedPoint {
        FixedPoint::unsigned(1, bits - 1)
    }

    /// The datapath at word length `bits`.
    pub fn build(self, bits: u32) -> Result<Datapath, HwError> {
        if !BITS.contains(&bits) {
            return Err(HwError::Bits(bits));
        }
        let frac = bits - 1;
        let unit = Self::unit_format(bits);
        let mut b = Builder::new(Rounding::HalfEven);
        // A formula's name may hold what a Verilog identifier cannot.
        let id: String = self
            .id()
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        let name = format!("specula_{id}_w{bits}");
        let output = match self {
            HwLobe::Formula(id) => {
                return compiled::layout(id)
                    .and_then(|layout| layout.build(&name, bits))
                    .map_err(|why| HwError::NotCompiled {
                        lobe: self.id().to_owned(),
                        why,
                    });
            }
            HwLobe::Schlick | HwLobe::SchlickMod => {
                let t = b.input("t", unit);
                let n = b.input("n", FixedPoint::unsigned(10, 0));
                let numerator = if self == HwLobe::SchlickMod {
                    let k = b.input("k", FixedPoint::unsigned(3, 0));
                    let mut powers = vec![t];
                    for i in 1..=SCHLICK_MOD_MAX_SQUARINGS {
                        let previous = powers[powers.len() - 1];
                        powers.push(b.node(&format!("t_{}", 1 << i), Op::Square(previous), unit));
                    }
                    b.node(
                        "t_a",
                        Op::Select {
                            index: k,
                            options: powers,
                        },
                        unit,
                    )
                } else {
                    t
                };
                let one = b.node("one", Op::Const(1 << frac), unit);
                let u = b.node("u", Op::Sub(one, t), unit);
                let n_u = b.node("n_u", Op::Mul(n, u), FixedPoint::unsigned(10, frac));
                let denominator = b.node("d", Op::Add(n_u, t), FixedPoint::unsigned(10, frac));
                if self == HwLobe::SchlickMod {
                    // Above t = 1 the quotient is t^(a-1) > 1; the float model clamps t to 1.
                    let quotient = b.node("quotient", Op::Div(numerator, denominator), unit);
                    b.node("value", Op::Min(quotient, one), unit)
                } else {
                    b.node("value", Op::Div(numerator, denominator), unit)
                }
            }
            HwLobe::Cheb2 => {
                let g = b.input("g", unit);
                let n = b.input("n", FixedPoint::unsigned(10, 0));
                let [c, b_coef, a] = cheb2_roms(frac);
                let rom = |b: &mut Builder, name: &str, (table, format): (Vec<i64>, FixedPoint)| {
                    b.node(name, Op::Rom { index: n, table }, format)
                };
                let (fa, fb, fc) = (a.1, b_coef.1, c.1);
                let a = rom(&mut b, "rom_a", a);
                let b_node = rom(&mut b, "rom_b", b_coef);
                let c = rom(&mut b, "rom_c", c);
                let a_g = b.node(
                    "a_g",
                    Op::Mul(a, g),
                    FixedPoint::signed(fa.int_bits + 1, frac),
                );
                let inner_int = fa.int_bits.max(fb.int_bits) + 2;
                let inner = b.node(
                    "inner",
                    Op::Add(a_g, b_node),
                    FixedPoint::signed(inner_int, frac),
                );
                // The result is clamped to [0, 1] and C is near 1, so these two may saturate
                // at +-8 and +-4: any value beyond clamps to the same 0 or 1.
                let times_g = b.node("inner_g", Op::Mul(inner, g), FixedPoint::signed(3, frac));
                let sum = b.node(
                    "sum",
                    Op::Add(times_g, c),
                    FixedPoint::signed(fc.int_bits.max(2), frac),
                );
                let one = b.node("one", Op::Const(1 << frac), unit);
                // min(sum, 1), and negatives saturate to 0 in the unsigned output.
                b.node("value", Op::Min(sum, one), unit)
            }
            HwLobe::LogExp | HwLobe::LogExpMitchell => {
                let log2_unit = if self == HwLobe::LogExp {
                    LOGEXP_TABLE
                } else {
                    Log2Unit::Mitchell
                };
                let t = b.input("t", unit);
                let n = b.input("n", FixedPoint::unsigned(10, 0));
                let log_t = b.node(
                    "log2_t",
                    Op::Log2(t, log2_unit),
                    FixedPoint::signed(5, frac),
                );
                let zero = b.node("zero", Op::Const(0), FixedPoint::unsigned(1, frac));
                let minus_log = b.node(
                    "minus_log2_t",
                    Op::Sub(zero, log_t),
                    FixedPoint::unsigned(5, frac),
                );
                // -y = -n log2 t; at 3 and above the lobe is 0, so 2 integer bits suffice.
                let minus_y = b.node(
                    "minus_y",
                    Op::Mul(n, minus_log),
                    FixedPoint::unsigned(2, frac),
                );
                let one = b.node("one", Op::Const(1 << frac), unit);
                let s = b.node(
                    "one_minus_y",
                    Op::Add(one, minus_y),
                    FixedPoint::unsigned(3, frac),
                );
                let log_s = b.node(
                    "log2_s",
                    Op::Log2(s, log2_unit),
                    FixedPoint::unsigned(2, frac),
                );
                let half = b.node(
                    "half_log2_s",
                    Op::Shift(log_s, -1),
                    FixedPoint::unsigned(1, frac + 1),
                );
                b.node("value", Op::Sub(one, half), unit)
            }
            HwLobe::CosQuad => {
                let t = b.input("t", unit);
                let a = b.input("a", FixedPoint::unsigned(6, frac));
                let one = b.node("one", Op::Const(1 << frac), unit);
                let u = b.node("u", Op::Sub(one, t), unit);
                let a_u = b.node("a_u", Op::Mul(a, u), FixedPoint::unsigned(6, frac));
                let mut value = b.node("base", Op::Sub(one, a_u), unit);
                for i in 1..=COSQUAD_V {
                    value = b.node(&format!("power_{}", 1 << i), Op::Square(value), unit);
                }
                // The formula gives (1 - a)^16 at t = 0 for n < 16.
                b.zero_at_t_zero(t, value, unit)
            }
            HwLobe::Pow => {
                let t = b.input("t", unit);
                let n = b.input("n", FixedPoint::unsigned(10, 0));
                // Six integer bits: log2 0 saturates to -32, and 2^-32 is 0 at every width.
                let log_t = b.node(
                    "log2_t",
                    Op::Log2(t, POW_LOG2_TABLE),
                    FixedPoint::signed(6, frac),
                );
                let zero = b.node("zero", Op::Const(0), FixedPoint::unsigned(1, frac));
                // Above t = 1 the logarithm is positive and this saturates to 0: t^n = 1.
                let minus_log = b.node(
                    "minus_log2_t",
                    Op::Sub(zero, log_t),
                    FixedPoint::unsigned(6, frac),
                );
                let minus_y = b.node(
                    "minus_y",
                    Op::Mul(n, minus_log),
                    FixedPoint::unsigned(6, frac),
                );
                b.node("value", Op::Exp2Neg(minus_y, POW_EXP2_TABLE), unit)
            }
            HwLobe::Sg => {
                let t = b.input("t", unit);
                let rate = b.input("rate", FixedPoint::unsigned(SG_RATE_INT_BITS, frac));
                let one = b.node("one", Op::Const(1 << frac), unit);
                let u = b.node("u", Op::Sub(one, t), unit);
                let minus_y = b.node("minus_y", Op::Mul(rate, u), FixedPoint::unsigned(6, frac));
                let value = b.node("gaussian", Op::Exp2Neg(minus_y, POW_EXP2_TABLE), unit);
                // The Gaussian is exp(-n) at t = 0.
                b.zero_at_t_zero(t, value, unit)
            }
        };
        Ok(b.finish(&name, output))
    }

    /// The per-material inputs for integer exponent `n`: `n` itself and the constants the
    /// library prepares for it (`Lobe::preparation`, `Lobe::squarings`), in the datapath's
    /// formats. What a renderer uploads once per material.
    #[must_use]
    pub fn material_inputs(self, bits: u32, n: u32) -> Vec<i64> {
        let n_raw = i64::from(n);
        let lobe = || Lobe::new(self.float_kind(), Exponent::new(f64::from(n)));
        // The named constant, as the library prepares it from n.
        let prepared = |name: &str| {
            lobe()
                .preparation(name, f64::from(n))
                .unwrap_or_else(|| unreachable!("{} prepares {name} from n", self.float_kind()))
        };
        match self {
            HwLobe::Schlick
            | HwLobe::LogExp
            | HwLobe::LogExpMitchell
            | HwLobe::Cheb2
            | HwLobe::Pow => vec![n_raw],
            HwLobe::Sg => vec![FixedPoint::unsigned(SG_RATE_INT_BITS, bits - 1)
                .quantize(prepared("rate"), Rounding::HalfEven)],
            HwLobe::SchlickMod => {
                let squarings = lobe()
                    .squarings()
                    .unwrap_or_else(|| unreachable!("schlick-mod squares"));
                let squarings = i64::from(squarings).min(SCHLICK_MOD_MAX_SQUARINGS.into());
                vec![n_raw, squarings]
            }
            HwLobe::CosQuad => {
                vec![FixedPoint::unsigned(6, bits - 1)
                    .quantize(prepared("slope"), Rounding::HalfEven)]
            }
            HwLobe::Formula(id) => compiled::layout(id)
                .map(|layout| layout.material_inputs(self.float_kind(), bits, n))
                .unwrap_or_default(),
        }
    }

    /// The raw inputs for cosine `t` (or angle `g`, for [`HwLobe::takes_angle`]) and integer
    /// exponent `n`: the quantised input followed by [`HwLobe::material_inputs`].
    #[must_use]
    pub fn inputs(self, bits: u32, t_or_g: f64, n: u32) -> Vec<i64> {
        let x = Self::unit_format(bits).quantize(t_or_g, Rounding::HalfEven);
        core::iter::once(x)
            .chain(self.material_inputs(bits, n))
            .collect()
    }

    /// The lobe's value from the datapath's raw output.
    #[must_use]
    pub fn value(bits: u32, raw: i64) -> f64 {
        Self::unit_format(bits).to_f64(raw)
    }
}

/// The integer exponent the hardware takes, or why `n` is not one.
pub fn integer_exponent(n: f64) -> Result<u32, HwError> {
    if n.fract() == 0.0 && (1.0..=1000.0).contains(&n) {
        Ok(n as u32)
    } else {
        Err(HwError::Exponent(n))
    }
}

/// The `cheb2` ROMs `[C, B, A]` for `n = 0..=1000` (address 0 repeats `n = 1`), each with the
/// signed format its largest magnitude needs and `frac` fraction bits.
fn cheb2_roms(frac: u32) -> [(Vec<i64>, FixedPoint); 3] {
    let coefficients: Vec<[f64; 3]> = (0..=1000)
        .map(|n: u32| {
            let lobe = Lobe::new(LobeKind::Cheb2, Exponent::new(f64::from(n.max(1))));
            lobe.angle_quadratic()
                .unwrap_or_else(|| unreachable!("cheb2 is quadratic in the angle"))
                .coeffs()
        })
        .collect();
    core::array::from_fn(|k| {
        let largest = coefficients.iter().map(|c| c[k].abs()).fold(0.0, f64::max);
        let int_bits = (largest + 1.0).log2().ceil() as u32;
        let format = FixedPoint::signed(int_bits, frac);
        let table = coefficients
            .iter()
            .map(|c| format.quantize(c[k], Rounding::HalfEven))
            .collect();
        (table, format)
    })
}
