//! Figures as text, the same on the page and in the command line's tables: significant
//! digits, percentages, a datapath's resources.

use specula_hw::Resources;

/// A figure with 4 significant digits, in plain or scientific notation as fits.
#[must_use]
pub fn sig(value: f64) -> String {
    if value == 0.0 || !value.is_finite() {
        return value.to_string();
    }
    // The decimal exponent after rounding to 4 digits (0.99996 rounds to 1.000e0, not 9.9996e-1).
    let scientific = format!("{value:.3e}");
    let exponent: i32 = scientific
        .rsplit('e')
        .next()
        .and_then(|e| e.parse().ok())
        .unwrap_or(0);
    if (-3..5).contains(&exponent) {
        let decimals = (3 - exponent).max(0) as usize;
        format!("{value:.decimals$}")
    } else {
        scientific
    }
}

/// A ratio as a percentage with 4 significant digits (`1.885%`).
#[must_use]
pub fn percent(ratio: f64) -> String {
    format!("{}%", sig(ratio * 100.0))
}

/// A PSNR in dB with one decimal, or `identical` where there is no error to measure (an
/// infinite PSNR: no number stands in for it).
#[must_use]
pub fn psnr(db: f64) -> String {
    if db.is_finite() {
        format!("{db:.1}")
    } else {
        "identical".to_owned()
    }
}

/// A PSNR with its unit (`34.2 dB`), or `identical`.
#[must_use]
pub fn psnr_db(db: f64) -> String {
    if db.is_finite() {
        format!("{} dB", psnr(db))
    } else {
        psnr(db)
    }
}

/// A datapath's resources, a cell each: multipliers, squarers, adders, dividers, shifters
/// (their widths), ROM bits, register bits, latency.
#[must_use]
pub fn resource_cells(r: &Resources) -> [String; 8] {
    let list = |items: Vec<String>| {
        if items.is_empty() {
            "-".to_owned()
        } else {
            items.join(" ")
        }
    };
    [
        list(
            r.multipliers
                .iter()
                .map(|(a, b)| format!("{a}x{b}"))
                .collect(),
        ),
        list(r.squarers.iter().map(u32::to_string).collect()),
        list(r.adders.iter().map(u32::to_string).collect()),
        list(r.dividers.iter().map(|(a, b)| format!("{a}/{b}")).collect()),
        list(r.shifters.iter().map(u32::to_string).collect()),
        r.rom_bits.to_string(),
        r.register_bits.to_string(),
        r.latency.to_string(),
    ]
}

/// The columns of [`resource_numbers`].
pub const RESOURCE_NUMBER_COLUMNS: [&str; 13] = [
    "multipliers",
    "multiplier area (sum of a*b bits)",
    "squarers",
    "squarer bits (sum)",
    "adders",
    "adder bits (sum)",
    "dividers",
    "divider area (sum of dividend*divisor bits)",
    "shifters",
    "shifter bits (sum)",
    "ROM bits",
    "register bits",
    "latency (cycles)",
];

/// A datapath's resources as numbers alone, for scripts (CSV): each kind of operator's count
/// and its summed size, then ROM bits, register bits and latency ([`RESOURCE_NUMBER_COLUMNS`]).
#[must_use]
pub fn resource_numbers(r: &Resources) -> [String; 13] {
    let sum = |items: &[u32]| items.iter().map(|&b| u64::from(b)).sum::<u64>().to_string();
    let area = |pairs: &[(u32, u32)]| {
        pairs
            .iter()
            .map(|&(a, b)| u64::from(a) * u64::from(b))
            .sum::<u64>()
            .to_string()
    };
    [
        r.multipliers.len().to_string(),
        area(&r.multipliers),
        r.squarers.len().to_string(),
        sum(&r.squarers),
        r.adders.len().to_string(),
        sum(&r.adders),
        r.dividers.len().to_string(),
        area(&r.dividers),
        r.shifters.len().to_string(),
        sum(&r.shifters),
        r.rom_bits.to_string(),
        r.register_bits.to_string(),
        r.latency.to_string(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_infinite_psnr_reads_identical() {
        assert_eq!(psnr(f64::INFINITY), "identical");
        assert_eq!(psnr(41.26), "41.3");
    }

    #[test]
    fn significant_digits() {
        assert_eq!(sig(0.0123456), "0.01235");
        assert_eq!(sig(123.456), "123.5");
        assert_eq!(sig(1.5e-7), "1.500e-7");
        assert_eq!(sig(0.99996), "1.000");
        assert_eq!(sig(1.0), "1.000");
        assert_eq!(percent(0.018851), "1.885%");
    }
}
