//! An FPGA cost estimate from a datapath's operators: how [`crate::cheapest_datapath`] picks
//! among a lobe's datapaths before one is synthesized, and the cost itself where Yosys is
//! missing. Logic cells of a LUT4 fabric without DSP blocks (an iCE40-class part, where each
//! cell is one 4-input LUT, one flip-flop and a carry link). Per operator, the textbook mapping:
//! a `b`-bit adder or comparator takes `b` cells (one per bit on the carry chain); an `a x b`
//! array multiplier `a b` cells (a partial-product AND and a full adder per bit); a `b`-bit
//! squarer half that (the product's symmetric half); an `a / b` divider `a b` cells (`a`
//! stages of a `b`-bit subtract-and-select); a leading-one detector `b` cells; a `b`-bit barrel
//! shifter `b ceil(log2 b)` cells (a 2:1 multiplexer per bit and stage); a ROM 1 cell per 16
//! bits (a LUT4 is a 16 x 1 ROM). Flip-flops pack into the cells the logic uses, so the
//! estimate is the larger of the logic cells and the register bits. Every figure from here is
//! labelled "estimated"; Yosys builds about four times as many LUTs (`specula hw synth`).

use specula_hw::Resources;

/// Estimated logic cells of `resources` on a LUT4 fabric without DSPs.
#[must_use]
pub fn logic_cells(resources: &Resources) -> u64 {
    let bits = |b: u32| u64::from(b);
    let adders: u64 = resources.adders.iter().map(|&b| bits(b)).sum();
    let multipliers: u64 = resources
        .multipliers
        .iter()
        .map(|&(a, b)| bits(a) * bits(b))
        .sum();
    let squarers: u64 = resources
        .squarers
        .iter()
        .map(|&b| bits(b) * bits(b) / 2)
        .sum();
    let dividers: u64 = resources
        .dividers
        .iter()
        .map(|&(a, b)| bits(a) * bits(b))
        .sum();
    let detectors: u64 = resources
        .leading_one_detectors
        .iter()
        .map(|&b| bits(b))
        .sum();
    let shifters: u64 = resources
        .shifters
        .iter()
        .map(|&b| bits(b) * u64::from(b.next_power_of_two().trailing_zeros()))
        .sum();
    let logic = adders
        + multipliers
        + squarers
        + dividers
        + detectors
        + shifters
        + resources.rom_bits.div_ceil(16);
    logic.max(resources.register_bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_operator_costs_its_textbook_mapping() {
        let resources = Resources {
            multipliers: vec![(16, 12)],
            squarers: vec![10],
            adders: vec![16, 8],
            dividers: vec![(16, 16)],
            leading_one_detectors: vec![16],
            shifters: vec![18],
            rom_bits: 1000,
            register_bits: 100,
            latency: 4,
        };
        // 192 + 50 + 24 + 256 + 16 + 18 * 5 + 63.
        assert_eq!(logic_cells(&resources), 691);
        // Registers bound it when they outnumber the logic.
        let registers = Resources {
            register_bits: 5000,
            ..resources
        };
        assert_eq!(logic_cells(&registers), 5000);
    }
}
