//! A compiled kernel's machine code as a list of instructions, each put in the class the GPU
//! cost model weighs (and the classes the ISA adds), and the counts by class.
//!
//! Each vendor's mnemonics are classed here by their operation, never by their text as a
//! whole: compiler versions change registers, scheduling and modifiers, not what an `FFMA`,
//! a `v_exp_f32` or a `math.exp` is.

use serde::{Deserialize, Serialize};

use specula::gpus::{Rates, Vendor};

/// What an instruction does, for costing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Class {
    /// `f32` add, multiply, multiply-add.
    Arithmetic,
    /// Compares, minimum, maximum, selects.
    Compare,
    /// The special-function unit: `exp2`, `log2`, reciprocal, square root, sine, cosine.
    Transcendental,
    /// Conversions between floats and integers, roundings.
    Conversion,
    /// Integer add, multiply-add, logic, shifts (addresses among them).
    Integer,
    /// Register moves and reads of special registers or constants.
    Move,
    /// Branches, calls, returns, the end of the program.
    Branch,
    /// Loads and stores.
    Memory,
    /// AMD's scalar unit: wave-uniform work beside the vector lanes.
    Scalar,
    /// Synchronisation, waits, no-ops.
    Other,
}

impl Class {
    /// Every class, in the order tables list them.
    pub const ALL: [Class; 10] = [
        Class::Arithmetic,
        Class::Compare,
        Class::Transcendental,
        Class::Conversion,
        Class::Integer,
        Class::Move,
        Class::Branch,
        Class::Memory,
        Class::Scalar,
        Class::Other,
    ];

    /// Its name in tables and JSON.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Class::Arithmetic => "arithmetic",
            Class::Compare => "compare",
            Class::Transcendental => "transcendental",
            Class::Conversion => "conversion",
            Class::Integer => "integer",
            Class::Move => "move",
            Class::Branch => "branch",
            Class::Memory => "memory",
            Class::Scalar => "scalar",
            Class::Other => "other",
        }
    }

    /// The rate it executes at on the vector lanes, where the cost model weighs it.
    fn rate(self, rates: &Rates) -> Option<f64> {
        match self {
            Class::Arithmetic => Some(rates.arithmetic),
            Class::Compare => Some(rates.compare),
            Class::Transcendental => Some(rates.transcendental),
            Class::Conversion => Some(rates.conversion),
            Class::Integer => Some(rates.integer),
            _ => None,
        }
    }
}

/// One instruction of a listing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Instruction {
    /// The line as the disassembler wrote it (offsets and encodings dropped).
    pub text: String,
    /// Its operation's name (`FFMA`, `v_exp_f32`, `math.exp`).
    pub mnemonic: String,
    /// Its class.
    pub class: Class,
    /// The share of one work item's operation it is: 1 for a warp- or wave-wide instruction,
    /// an Intel instruction's lanes over the kernel's SIMD width (a SIMD32 kernel splits its
    /// operations in two 16-lane halves), 0 for AMD's scalar unit, which issues beside the
    /// vector lanes.
    pub share: f64,
}

/// Instructions by class: of a listing, or a kernel's less its baseline's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Counts {
    /// Per class, in [`Class::ALL`]'s order.
    pub by_class: [i64; Class::ALL.len()],
    /// Per class, the work items' shares ([`Instruction::share`]) summed: operations per work
    /// item.
    pub per_item: [f64; Class::ALL.len()],
}

impl Counts {
    /// The counts of `instructions`.
    #[must_use]
    pub fn of(instructions: &[Instruction]) -> Self {
        let mut counts = Counts::default();
        for instruction in instructions {
            let at = index(instruction.class);
            counts.by_class[at] += 1;
            counts.per_item[at] += instruction.share;
        }
        counts
    }

    /// The count of `class`.
    #[must_use]
    pub fn get(&self, class: Class) -> i64 {
        self.by_class[index(class)]
    }

    /// Instructions in all.
    #[must_use]
    pub fn total(&self) -> i64 {
        self.by_class.iter().sum()
    }

    /// What `self` has beyond `baseline`, class by class, never below 0 (a compiler may
    /// schedule the loads and stores both kernels share a little differently).
    #[must_use]
    pub fn beyond(&self, baseline: &Counts) -> Counts {
        let mut out = Counts::default();
        for at in 0..Class::ALL.len() {
            out.by_class[at] = (self.by_class[at] - baseline.by_class[at]).max(0);
            out.per_item[at] = (self.per_item[at] - baseline.per_item[at]).max(0.0);
        }
        out
    }

    /// Evaluations per clock per multiprocessor at `rates`: the busiest resource (each class
    /// the lanes weigh at its rate, and issue, which every vector instruction takes), and its
    /// name.
    #[must_use]
    pub fn evals_per_clock(&self, rates: &Rates) -> (f64, &'static str) {
        let mut busiest = (0.0, "issue");
        let mut issued = 0.0;
        for (at, class) in Class::ALL.into_iter().enumerate() {
            let work = self.per_item[at];
            if class != Class::Scalar {
                issued += work;
            }
            if let Some(rate) = class.rate(rates) {
                if work / rate > busiest.0 {
                    busiest = (work / rate, class.id());
                }
            }
        }
        if issued / rates.issue > busiest.0 {
            busiest = (issued / rates.issue, "issue");
        }
        let evals = if busiest.0 > 0.0 {
            1.0 / busiest.0
        } else {
            f64::INFINITY
        };
        (evals, busiest.1)
    }
}

fn index(class: Class) -> usize {
    Class::ALL
        .iter()
        .position(|&c| c == class)
        .unwrap_or_else(|| unreachable!("every class is in Class::ALL"))
}

/// The class of an NVIDIA SASS operation (`FFMA.FTZ` is `FFMA` with a modifier).
#[must_use]
pub fn nvidia_class(mnemonic: &str) -> Class {
    let base = mnemonic.split('.').next().unwrap_or(mnemonic);
    // The uniform datapath's operations (`UIADD3`, `ULDC`) are their vector twins' classes.
    let operation = match base.strip_prefix('U') {
        Some(rest) if !rest.is_empty() && base != "UNDEF" => rest,
        _ => base,
    };
    // ptxas moves with the integer multiply-add (`IMAD.MOV.U32 R1, RZ, RZ, R0`), to spread
    // moves over idle pipes.
    if mnemonic.starts_with("IMAD.MOV") {
        return Class::Move;
    }
    match operation {
        "FADD" | "FMUL" | "FFMA" | "FADD32I" | "FMUL32I" | "FFMA32I" | "HADD2" | "HMUL2"
        | "HFMA2" | "FSWZADD" => Class::Arithmetic,
        "FSETP" | "FSET" | "FMNMX" | "FSEL" | "SEL" | "FCHK" => Class::Compare,
        "MUFU" => Class::Transcendental,
        "F2I" | "I2F" | "F2F" | "FRND" | "F2FP" | "I2I" | "I2FP" | "F2IP" => Class::Conversion,
        "IADD3" | "IADD" | "IADD32I" | "IMAD" | "IMUL" | "XMAD" | "LOP3" | "LOP" | "LOP32I"
        | "SHF" | "SHL" | "SHR" | "LEA" | "IABS" | "IMNMX" | "ISETP" | "POPC" | "FLO" | "BREV"
        | "BMSK" | "SGXT" | "PRMT" | "BFE" | "BFI" | "VIADD" | "VIMNMX" => Class::Integer,
        "MOV" | "MOV32I" | "S2R" | "S2UR" | "CS2R" | "LDC" | "LDCU" | "R2UR" | "SHFL" => {
            Class::Move
        }
        "BRA" | "BRX" | "JMP" | "JMX" | "EXIT" | "RET" | "CALL" | "BSSY" | "BSYNC" | "BREAK"
        | "WARPSYNC" | "BMOV" => Class::Branch,
        "LDG" | "STG" | "LD" | "ST" | "LDS" | "STS" | "LDL" | "STL" | "ATOM" | "ATOMG" | "RED"
        | "ATOMS" | "LDSM" => Class::Memory,
        _ => Class::Other,
    }
}

/// The class of an AMD GCN/RDNA operation as ACO's disassembly names it (`v_exp_f32_e32`).
#[must_use]
pub fn amd_class(mnemonic: &str) -> Class {
    let name = mnemonic
        .trim_end_matches("_e32")
        .trim_end_matches("_e64")
        .trim_end_matches("_sdwa")
        .trim_end_matches("_dpp");
    if let Some(scalar) = name.strip_prefix("s_") {
        return if scalar.starts_with("load") || scalar.starts_with("buffer_load") {
            Class::Memory
        } else if scalar.starts_with("cbranch")
            || scalar.starts_with("branch")
            || scalar == "endpgm"
            || scalar.starts_with("setpc")
            || scalar.starts_with("swappc")
        {
            Class::Branch
        } else if scalar.starts_with("waitcnt")
            || scalar.starts_with("nop")
            || scalar.starts_with("clause")
            || scalar.starts_with("delay_alu")
            || scalar.starts_with("sendmsg")
            || scalar.starts_with("barrier")
            || scalar.starts_with("inst_prefetch")
        {
            Class::Other
        } else {
            Class::Scalar
        };
    }
    let Some(vector) = name.strip_prefix("v_") else {
        // buffer_, global_, flat_, ds_, image_, scratch_ are the memory instructions.
        return Class::Memory;
    };
    let vector = vector.strip_prefix("dual_").unwrap_or(vector);
    let operation = vector.split("_f").next().unwrap_or(vector);
    let float = vector.contains("_f32") || vector.contains("_f16") || vector.contains("_legacy");
    if vector.starts_with("cmp") || vector.starts_with("cndmask") {
        return Class::Compare;
    }
    if vector.starts_with("cvt") || vector.starts_with("frexp") {
        return Class::Conversion;
    }
    if vector.starts_with("mov")
        || vector.starts_with("readfirstlane")
        || vector.starts_with("readlane")
        || vector.starts_with("writelane")
    {
        return Class::Move;
    }
    match operation {
        "exp" | "log" | "rcp" | "rsq" | "sqrt" | "sin" | "cos" | "rcp_iflag" => {
            Class::Transcendental
        }
        "floor" | "ceil" | "trunc" | "rndne" | "fract" => Class::Conversion,
        "max" | "min" | "med3" | "max3" | "min3" if float => Class::Compare,
        "add" | "sub" | "subrev" | "mul" | "fma" | "fmac" | "mac" | "mad" | "fmaak" | "fmamk"
        | "madak" | "madmk" | "ldexp" | "mul_legacy" | "fma_legacy" | "fmac_legacy"
        | "mac_legacy" | "mad_legacy"
            if float =>
        {
            Class::Arithmetic
        }
        _ => Class::Integer,
    }
}

/// The class of an Intel GEN operation as IGC writes it (`math.exp`, `mad`, `send.dc1`), its
/// destination's type (`:f`, `:d`) deciding between float and integer arithmetic, and a `mov`
/// between types a conversion.
#[must_use]
pub fn intel_class(mnemonic: &str, destination_type: &str, source_type: Option<&str>) -> Class {
    let base = mnemonic.split('.').next().unwrap_or(mnemonic);
    let float = matches!(destination_type, "f" | "hf" | "df" | "bf");
    match base {
        "math" => Class::Transcendental,
        "send" | "sends" | "sendc" | "sendsc" | "load" | "store" | "lsc_load" | "lsc_store" => {
            Class::Memory
        }
        "cmp" | "cmpn" | "sel" | "csel" => Class::Compare,
        "rndd" | "rnde" | "rndu" | "rndz" | "frc" => Class::Conversion,
        "mov" | "movi" => match source_type {
            Some(source) if source != destination_type && !source.is_empty() => Class::Conversion,
            _ => Class::Move,
        },
        "add" | "mul" | "mad" | "madm" | "mac" | "lrp" | "dp4" | "dp3" | "dp2" | "line" | "pln"
            if float =>
        {
            Class::Arithmetic
        }
        "add" | "add3" | "addc" | "mul" | "mach" | "mad" | "mac" | "and" | "or" | "xor" | "not"
        | "shl" | "shr" | "asr" | "bfe" | "bfi1" | "bfi2" | "bfrev" | "cbit" | "fbh" | "fbl"
        | "lzd" | "subb" | "rol" | "ror" | "avg" | "bfn" | "dp4a" => Class::Integer,
        "jmpi" | "if" | "else" | "endif" | "while" | "break" | "cont" | "brc" | "brd" | "goto"
        | "join" | "ret" | "call" | "calla" | "halt" => Class::Branch,
        _ => Class::Other,
    }
}

/// A vendor's listing line read into an instruction, or `None` for a label, a directive or a
/// comment. `simd` is the kernel's SIMD width (Intel) or its wave size (AMD).
#[must_use]
pub fn instruction(vendor: Vendor, line: &str, simd: u32) -> Option<Instruction> {
    match vendor {
        Vendor::Nvidia => nvidia_instruction(line),
        Vendor::Amd => amd_instruction(line),
        Vendor::Intel => intel_instruction(line, simd),
    }
}

/// `/*0090*/                   MUFU.LG2 R0, R2 ;` (nvdisasm).
fn nvidia_instruction(line: &str) -> Option<Instruction> {
    let code = line.trim_start().strip_prefix("/*")?;
    let (_, code) = code.split_once("*/")?;
    let code = code.trim().trim_end_matches(';').trim();
    let without_predicate = match code.strip_prefix('@') {
        Some(rest) => rest.split_once(char::is_whitespace)?.1.trim_start(),
        None => code,
    };
    let mnemonic = without_predicate.split_whitespace().next()?.to_owned();
    let operands = without_predicate[mnemonic.len()..].trim_start();
    // ptxas materialises constants with a half-precision multiply-add of zeros
    // (`HFMA2.MMA R7, -RZ, RZ, 0, 0`): a move on an idle pipe.
    let class = if mnemonic.starts_with("HFMA2") && operands.contains("-RZ, RZ, ") {
        Class::Move
    } else {
        nvidia_class(&mnemonic)
    };
    Some(Instruction {
        text: code.to_owned(),
        class,
        mnemonic,
        share: 1.0,
    })
}

/// ACO's assembly read into instructions: its disassembler writes a run of identical
/// instructions once, followed by `(then repeated 3 times)`, which is expanded here.
#[must_use]
pub fn amd_listing(text: &str, wave: u32) -> Vec<Instruction> {
    let mut instructions: Vec<Instruction> = Vec::new();
    for line in text.lines() {
        let repeats = line
            .trim()
            .strip_prefix("(then repeated ")
            .and_then(|rest| rest.split_whitespace().next())
            .and_then(|count| count.parse::<usize>().ok());
        match (repeats, instructions.last().cloned()) {
            (Some(count), Some(previous)) => {
                instructions.extend(std::iter::repeat_n(previous, count));
            }
            _ => instructions.extend(instruction(Vendor::Amd, line, wave)),
        }
    }
    instructions
}

/// `v_log_f32_e32 v1, v1     ; 7e024f01` (ACO, indented by a tab).
fn amd_instruction(line: &str) -> Option<Instruction> {
    let code = line.split(';').next()?.trim();
    if code.is_empty() || code.ends_with(':') || code.starts_with("BB") || code.starts_with('/') {
        return None;
    }
    let mnemonic = code.split_whitespace().next()?.to_owned();
    if !mnemonic
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || c == '_')
    {
        return None;
    }
    let class = amd_class(&mnemonic);
    Some(Instruction {
        text: code.to_owned(),
        share: if mnemonic.starts_with("s_") { 0.0 } else { 1.0 },
        class,
        mnemonic,
    })
}

/// `(f1.0)  sel (16|M0)   r27.0<1>:f  r19.0<8;8,1>:f  -r19.0<8;8,1>:f  {Compacted,$2.dst} // $5`
/// (IGC's dump).
fn intel_instruction(line: &str, simd: u32) -> Option<Instruction> {
    let code = line.split("//").next()?.trim();
    if code.is_empty() || code.ends_with(':') || code.starts_with('.') {
        return None;
    }
    let mut rest = code;
    // Predicates and the no-mask flag: `(W)`, `(f1.0)`, `(~f0.0)`, `(W&f0.0)`.
    while let Some(after) = rest.strip_prefix('(') {
        rest = after.split_once(')')?.1.trim_start();
    }
    let mnemonic = rest.split_whitespace().next()?.to_owned();
    let after_mnemonic = rest[mnemonic.len()..].trim_start();
    // `(16|M0)`, possibly after a conditional modifier such as `(lt)f0.0`.
    let lanes = after_mnemonic
        .split('(')
        .filter_map(|part| part.split_once('|'))
        .find_map(|(width, _)| width.trim().parse::<u32>().ok())
        .unwrap_or(1);
    let operands: Vec<&str> = after_mnemonic
        .split_whitespace()
        .filter(|word| word.contains(':') && !word.starts_with('{'))
        .collect();
    let type_of = |operand: &str| operand.rsplit(':').next().unwrap_or("").to_owned();
    let destination = operands.first().map(|o| type_of(o)).unwrap_or_default();
    let source = operands.get(1).map(|o| type_of(o));
    let class = intel_class(&mnemonic, &destination, source.as_deref());
    Some(Instruction {
        text: code.to_owned(),
        class,
        share: f64::from(lanes) / f64::from(simd.max(1)),
        mnemonic,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_vendors_operations_fall_in_their_classes() {
        assert_eq!(nvidia_class("MUFU.EX2"), Class::Transcendental);
        assert_eq!(nvidia_class("FFMA.FTZ"), Class::Arithmetic);
        assert_eq!(nvidia_class("FMNMX.FTZ"), Class::Compare);
        assert_eq!(nvidia_class("IMAD.MOV.U32"), Class::Move);
        assert_eq!(nvidia_class("IMAD.WIDE"), Class::Integer);
        assert_eq!(nvidia_class("ULDC.64"), Class::Move);
        assert_eq!(amd_class("v_exp_f32_e32"), Class::Transcendental);
        assert_eq!(amd_class("v_fmac_f32_e32"), Class::Arithmetic);
        assert_eq!(amd_class("v_cndmask_b32_e64"), Class::Compare);
        assert_eq!(amd_class("v_max_f32_e32"), Class::Compare);
        assert_eq!(amd_class("v_max_u32_e32"), Class::Integer);
        assert_eq!(amd_class("v_lshl_add_u32"), Class::Integer);
        assert_eq!(amd_class("s_load_b128"), Class::Memory);
        assert_eq!(amd_class("s_mov_b32"), Class::Scalar);
        assert_eq!(amd_class("buffer_store_b32"), Class::Memory);
        assert_eq!(
            intel_class("math.exp", "f", Some("f")),
            Class::Transcendental
        );
        assert_eq!(intel_class("mad", "f", Some("f")), Class::Arithmetic);
        assert_eq!(intel_class("add", "d", Some("d")), Class::Integer);
        assert_eq!(intel_class("mov", "d", Some("f")), Class::Conversion);
        assert_eq!(intel_class("mov", "f", Some("f")), Class::Move);
    }

    #[test]
    fn listing_lines_are_read_with_their_lanes() {
        let nvidia = instruction(
            Vendor::Nvidia,
            "        /*0090*/                   MUFU.LG2 R0, R2 ;",
            32,
        )
        .unwrap();
        assert_eq!(
            (nvidia.mnemonic.as_str(), nvidia.class),
            ("MUFU.LG2", Class::Transcendental)
        );
        let zero = instruction(Vendor::Nvidia, "/*0050*/ HFMA2.MMA R7, -RZ, RZ, 0, 0 ;", 32);
        assert_eq!(zero.unwrap().class, Class::Move);
        let predicated = instruction(Vendor::Nvidia, "/*00e0*/ @!P0 BRA `(.L_x_0) ;", 32).unwrap();
        assert_eq!(predicated.class, Class::Branch);
        let amd = instruction(
            Vendor::Amd,
            "\tv_log_f32_e32 v1, v1                                        ; 7e024f01",
            32,
        )
        .unwrap();
        assert_eq!(amd.class, Class::Transcendental);
        assert!(instruction(Vendor::Amd, "BB0:", 32).is_none());
        let squarings = amd_listing(
            "\tv_max_f32_e32 v1, 0, v1   ; 20020280\n\tv_mul_f32_e32 v1, v1, v1   ; 10020301\n\
             \t(then repeated 3 times)\n\ts_endpgm   ; bfb00000\n",
            32,
        );
        let mnemonics: Vec<&str> = squarings.iter().map(|i| i.mnemonic.as_str()).collect();
        assert_eq!(
            mnemonics,
            [
                "v_max_f32_e32",
                "v_mul_f32_e32",
                "v_mul_f32_e32",
                "v_mul_f32_e32",
                "v_mul_f32_e32",
                "s_endpgm"
            ]
        );
        let intel = instruction(
            Vendor::Intel,
            "(f1.0)  sel (16|M0)              r27.0<1>:f    r19.0<8;8,1>:f    -r19.0<8;8,1>:f  \
             {Compacted,$2.dst} // $9",
            32,
        )
        .unwrap();
        assert_eq!((intel.class, intel.share), (Class::Compare, 0.5));
        let compare = instruction(
            Vendor::Intel,
            "        cmp (16|M0)   (lt)f0.0   null<1>:d     r15.0<8;8,1>:d    0:w  {Compacted}",
            32,
        )
        .unwrap();
        assert_eq!((compare.class, compare.share), (Class::Compare, 0.5));
    }

    #[test]
    fn the_busiest_resource_bounds_the_rate() {
        // pow on an SM: log2, multiply, exp2 per work item.
        let pow = [
            ("MUFU.LG2", Class::Transcendental),
            ("FMUL", Class::Arithmetic),
            ("MUFU.EX2", Class::Transcendental),
        ]
        .map(|(mnemonic, class)| Instruction {
            text: mnemonic.to_owned(),
            mnemonic: mnemonic.to_owned(),
            class,
            share: 1.0,
        });
        let rates = specula::gpus::Gpu::find("sm_89").unwrap().rates;
        // Two special-function results at 16 per clock: 8 evaluations per clock.
        assert_eq!(
            Counts::of(&pow).evals_per_clock(&rates),
            (8.0, "transcendental")
        );
    }
}
