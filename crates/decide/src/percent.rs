//! Fractions written as percentages, as every face shows errors and bounds: `0.1 %`,
//! `0.03115 %`; and a figure beside the bound it breaks, never `2 % exceeds 2 %`.

/// A fraction as a percentage with four significant digits (`0.1 %`, `0.03115 %`).
#[must_use]
pub fn percent(fraction: f64) -> String {
    percent_to(fraction, 4)
}

/// A figure that exceeds its bound and the bound, as percentages with four significant digits,
/// or as many more as it takes for the two to read apart (`2.0001 %` and `2 %`).
#[must_use]
pub fn percents_apart(figure: f64, bound: f64) -> (String, String) {
    (4..=16)
        .map(|digits| (percent_to(figure, digits), percent_to(bound, digits)))
        .find(|(a, b)| a != b)
        .unwrap_or_else(|| (percent(figure), percent(bound)))
}

/// "`figure` exceeds `bound`" in percentages that read apart.
#[must_use]
pub fn exceeds(figure: f64, bound: f64) -> String {
    let (figure, bound) = percents_apart(figure, bound);
    format!("{figure} exceeds {bound}")
}

/// A percentage as a command line takes it (`1.1%`): the fraction rounded up to two
/// significant digits of a percent, so the flag it is printed in admits the figure.
#[must_use]
pub fn flag_percent_above(fraction: f64) -> String {
    let value = fraction * 100.0;
    if !(value.is_finite() && value > 0.0) {
        return format!("{value}%");
    }
    let digits = (1 - value.log10().floor() as i32).max(0);
    let scale = 10f64.powi(digits);
    let up = (value * scale).ceil() / scale;
    let up = if up * 0.01 < fraction {
        up + 1.0 / scale
    } else {
        up
    };
    format!("{up:.prec$}%", prec = digits as usize)
}

fn percent_to(fraction: f64, significant: i32) -> String {
    if !fraction.is_finite() || fraction == 0.0 {
        return format!("{} %", fraction * 100.0);
    }
    let digits =
        (significant - 1 - (fraction * 100.0).abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{:.digits$}", fraction * 100.0);
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    format!("{text} %")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentages_keep_four_significant_digits() {
        assert_eq!(percent(0.001), "0.1 %");
        assert_eq!(percent(0.000_311_5), "0.03115 %");
        assert_eq!(percent(0.02), "2 %");
        assert_eq!(percent(0.0), "0 %");
    }

    /// A figure over its bound never reads as the bound, however close.
    #[test]
    fn a_broken_bound_reads_apart_from_its_figure() {
        assert_eq!(exceeds(0.020_001, 0.02), "2.0001 % exceeds 2 %");
        assert_eq!(exceeds(0.030, 0.02), "3 % exceeds 2 %");
        for excess in [1e-3, 1e-6, 1e-9, 1e-12] {
            let (figure, bound) = percents_apart(0.01 * (1.0 + excess), 0.01);
            assert_ne!(figure, bound, "excess {excess}");
        }
    }

    /// The flag's value parses back to at least the figure, within a step of two digits.
    #[test]
    fn the_admitting_flag_is_at_least_the_figure() {
        for fraction in [0.010_52, 0.01, 0.000_49, 0.123_4, 0.0199] {
            let flag = flag_percent_above(fraction);
            let value: f64 = flag.trim_end_matches('%').parse().unwrap();
            assert!(value / 100.0 >= fraction, "{flag} for {fraction}");
            assert!(value / 100.0 <= fraction * 1.1, "{flag} for {fraction}");
        }
        assert_eq!(flag_percent_above(0.010_52), "1.1%");
    }
}
