//! The tools' JSON reports: Yosys's `stat -json` and nextpnr's `--report`.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::Target;

/// Synthesized cells, classified for the target.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Cells {
    /// Every cell type and its count, as Yosys reports them.
    pub by_type: BTreeMap<String, u64>,
    /// Look-up tables (iCE40, Xilinx) or logic gates (generic).
    pub logic: u64,
    /// Carry-chain cells (SB_CARRY, CARRY4).
    pub carry: u64,
    /// Multiplier blocks (SB_MAC16, DSP48E1).
    pub dsp: u64,
    /// Flip-flops.
    pub flip_flops: u64,
    /// Block RAMs.
    pub ram: u64,
    /// Everything else (I/O buffers, wide multiplexers).
    pub other: u64,
}

/// The class of one cell type on `target`.
fn classify(cell: &str, target: Target) -> fn(&mut Cells) -> &mut u64 {
    let starts = |prefixes: &[&str]| prefixes.iter().any(|p| cell.starts_with(p));
    match target {
        Target::Generic => {
            if starts(&["$_DFF", "$_SDFF", "$_ALDFF", "$_DLATCH", "$_SR_"]) {
                |c| &mut c.flip_flops
            } else if cell.starts_with("$_") {
                |c| &mut c.logic
            } else {
                |c| &mut c.other
            }
        }
        Target::Ice40(_) => match cell {
            "SB_LUT4" => |c| &mut c.logic,
            "SB_CARRY" => |c| &mut c.carry,
            "SB_MAC16" => |c| &mut c.dsp,
            _ if cell.starts_with("SB_DFF") => |c| &mut c.flip_flops,
            _ if cell.starts_with("SB_RAM") => |c| &mut c.ram,
            _ => |c| &mut c.other,
        },
        Target::Xilinx => {
            if starts(&["LUT1", "LUT2", "LUT3", "LUT4", "LUT5", "LUT6"]) {
                |c| &mut c.logic
            } else if cell == "CARRY4" {
                |c| &mut c.carry
            } else if cell.starts_with("DSP48") {
                |c| &mut c.dsp
            } else if starts(&["FDRE", "FDSE", "FDCE", "FDPE"]) {
                |c| &mut c.flip_flops
            } else if starts(&["RAMB", "RAM32", "RAM64"]) {
                |c| &mut c.ram
            } else {
                |c| &mut c.other
            }
        }
    }
}

/// The cells of Yosys's `stat -json` output for the whole (flattened) design.
pub fn cells(stat_json: &str, target: Target) -> Result<Cells, String> {
    let stat: serde_json::Value =
        serde_json::from_str(stat_json).map_err(|e| format!("not JSON: {e}"))?;
    let by_type = stat
        .pointer("/design/num_cells_by_type")
        .and_then(serde_json::Value::as_object)
        .ok_or("no design.num_cells_by_type")?;
    let mut cells = Cells::default();
    for (cell, count) in by_type {
        let count = count
            .as_u64()
            .ok_or_else(|| format!("the count of {cell} is not a whole number"))?;
        *classify(cell, target)(&mut cells) += count;
        cells.by_type.insert(cell.clone(), count);
    }
    Ok(cells)
}

/// What nextpnr reports after routing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    /// The slowest clock's achieved Fmax, MHz.
    pub fmax_mhz: f64,
    /// Logic cells used (ICESTORM_LC).
    pub logic_cells: u64,
}

/// The figures of nextpnr's `--report` JSON.
pub fn placed(report_json: &str) -> Result<Placed, String> {
    let report: serde_json::Value =
        serde_json::from_str(report_json).map_err(|e| format!("not JSON: {e}"))?;
    let clocks = report
        .get("fmax")
        .and_then(serde_json::Value::as_object)
        .ok_or("no fmax section")?;
    let fmax_mhz = clocks
        .values()
        .filter_map(|clock| clock.get("achieved").and_then(serde_json::Value::as_f64))
        .fold(None, |slowest: Option<f64>, mhz| {
            Some(slowest.map_or(mhz, |s| s.min(mhz)))
        })
        .filter(|mhz| mhz.is_finite() && *mhz > 0.0)
        .ok_or("no clock with an achieved frequency")?;
    let logic_cells = report
        .pointer("/utilization/ICESTORM_LC/used")
        .and_then(serde_json::Value::as_u64)
        .ok_or("no utilization.ICESTORM_LC.used")?;
    Ok(Placed {
        fmax_mhz,
        logic_cells,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Ice40Device;

    /// The shape Yosys 0.23 writes (`stat -json`), abridged.
    const STAT: &str = r#"{
        "creator": "Yosys 0.23",
        "modules": { "\\top": { "num_cells": 9 } },
        "design": { "num_cells": 9, "num_cells_by_type": {
            "SB_CARRY": 3, "SB_DFF": 2, "SB_DFFSR": 1, "SB_LUT4": 2, "SB_MAC16": 1
        } }
    }"#;

    #[test]
    fn ice40_cells_are_classified() {
        let cells = cells(STAT, Target::Ice40(Ice40Device::Up5k)).expect("valid report");
        assert_eq!(
            (
                cells.logic,
                cells.carry,
                cells.flip_flops,
                cells.dsp,
                cells.other
            ),
            (2, 3, 3, 1, 0)
        );
        assert_eq!(cells.by_type.values().sum::<u64>(), 9);
    }

    #[test]
    fn generic_and_xilinx_cells_are_classified() {
        let generic = r#"{"design": {"num_cells_by_type":
            {"$_AND_": 4, "$_XOR_": 2, "$_DFF_P_": 3, "$_SDFF_PP0_": 1}}}"#;
        let cells_generic = cells(generic, Target::Generic).expect("valid");
        assert_eq!((cells_generic.logic, cells_generic.flip_flops), (6, 4));
        let xilinx = r#"{"design": {"num_cells_by_type": {"LUT2": 4, "LUT6": 1, "CARRY4": 2,
            "DSP48E1": 1, "FDRE": 7, "IBUF": 3, "MUXF7": 1}}}"#;
        let cells_xilinx = cells(xilinx, Target::Xilinx).expect("valid");
        assert_eq!(
            (
                cells_xilinx.logic,
                cells_xilinx.carry,
                cells_xilinx.dsp,
                cells_xilinx.flip_flops,
                cells_xilinx.other
            ),
            (5, 2, 1, 7, 4)
        );
    }

    #[test]
    fn the_slowest_clock_sets_fmax() {
        let report = r#"{"utilization": {"ICESTORM_LC": {"available": 7680, "used": 321}},
            "fmax": {"clk$glb": {"achieved": 61.5, "constraint": 150.0},
                     "other": {"achieved": 80.0, "constraint": 150.0}}}"#;
        assert_eq!(
            placed(report),
            Ok(Placed {
                fmax_mhz: 61.5,
                logic_cells: 321
            })
        );
    }

    #[test]
    fn malformed_reports_are_refused_with_what_is_missing() {
        assert!(cells("{}", Target::Generic)
            .unwrap_err()
            .contains("num_cells_by_type"));
        assert!(cells("not json", Target::Generic)
            .unwrap_err()
            .contains("not JSON"));
        assert!(placed(r#"{"fmax": {}}"#).unwrap_err().contains("achieved"));
        let negative = r#"{"design": {"num_cells_by_type": {"SB_LUT4": -1}}}"#;
        assert!(cells(negative, Target::Generic).is_err());
    }
}
