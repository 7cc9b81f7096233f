//! Image comparisons as the report shows them: every lobe's image in a grid that wraps at the
//! page's width, each with its FLIP map against the reference below it, the maps on one shared
//! scale that a colour bar states, every image a link to its full-size file.
//!
//! FLIP's own maps run from 0 to 1, and the lobes' differences from `pow` are mostly below a
//! tenth: drawn on FLIP's scale they are nearly black. So the maps here share a scale set by
//! the differences themselves (the largest of their 99th percentiles, rounded up to 1, 2 or 5
//! times a power of ten), said on the colour bar, and still comparable with each other.

use specula::LobeKind;
use specula_render::metrics::{magma_srgb8, Difference};

use super::html::{colour_bar, tiles, Tile};
use super::Context;
use crate::format::psnr_db;

/// One image of a comparison.
pub(crate) struct Compared<'a> {
    /// Whose image.
    pub lobe: LobeKind,
    /// Its file beside the page.
    pub file: String,
    /// How it differs from the reference; `None` for the reference itself.
    pub difference: Option<&'a Difference>,
    /// The figures under it.
    pub caption: String,
}

impl<'a> Compared<'a> {
    /// `lobe`'s image in `file` and how it differs from the reference's, its caption the
    /// PSNR and mean FLIP, or, for the reference itself, "the reference".
    #[must_use]
    pub(crate) fn new(
        lobe: LobeKind,
        file: &str,
        difference: &'a Difference,
        reference: bool,
    ) -> Self {
        Self {
            lobe,
            file: file.to_owned(),
            difference: (!reference).then_some(difference),
            caption: if reference {
                "the reference".to_owned()
            } else {
                format!(
                    "PSNR {}, mean FLIP {:.4}",
                    psnr_db(difference.psnr_db),
                    difference.mean_flip
                )
            },
        }
    }
}

/// The scale every map of a comparison shares: the largest 99th percentile of the maps' FLIP
/// values, rounded up to 1, 2 or 5 times a power of ten, from 0.01 to 1.
#[must_use]
pub(crate) fn shared_scale(maps: &[&[f32]]) -> f64 {
    let largest = maps
        .iter()
        .filter(|map| !map.is_empty())
        .map(|map| {
            // The 99th percentile without sorting the whole map.
            let mut values = map.to_vec();
            let rank = (values.len() - 1) * 99 / 100;
            f64::from(*values.select_nth_unstable_by(rank, f32::total_cmp).1)
        })
        .fold(0.0, f64::max);
    // A power of ten at or below the percentile, as 1 / 10^k so that the steps print short.
    let below = (-largest.max(1e-2).log10().floor()) as i32;
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|step| step / 10f64.powi(below))
        .find(|&scale| scale >= largest * (1.0 - 1e-9))
        .unwrap_or(1.0)
        .clamp(1e-2, 1.0)
}

/// Writes each difference map (`<prefix>-flip-<lobe>.png`, FLIP over the shared scale in
/// FLIP's magma colour map) and returns the colour bar and the grid.
pub(crate) fn grid(
    context: &mut Context,
    prefix: &str,
    reference: &str,
    images: &[Compared],
) -> Result<String, String> {
    let maps: Vec<&[f32]> = images
        .iter()
        .filter_map(|image| image.difference.map(|d| d.flip_map.as_slice()))
        .collect();
    let scale = shared_scale(&maps);
    let mut shown = Vec::with_capacity(images.len());
    for image in images {
        let difference = match image.difference {
            Some(d) => {
                let name = format!("{prefix}-flip-{}.png", image.lobe.id());
                let map = d.heatmap_srgb8_scaled(scale as f32);
                context.write_png_file(&name, d.width, d.height, &map)?;
                Some(name)
            }
            None => None,
        };
        shown.push(Tile {
            label: image.lobe.to_string(),
            colour: image.lobe.line_style().rgb,
            image: image.file.clone(),
            difference,
            caption: image.caption.clone(),
        });
    }
    let stops: Vec<[u8; 3]> = magma_srgb8(&(0..=16).map(|k| k as f32 / 16.0).collect::<Vec<_>>())
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    Ok(colour_bar(
        &format!("{prefix}-scale"),
        &stops,
        scale,
        &format!(
            "Below each image: its FLIP error against {reference}'s, black where they agree, on \
                one scale for every map here (0 to {scale}; FLIP's own runs to 1; specula diff \
                --heatmap-scale draws the same). Select an image for its full size.",
        ),
    ) + &tiles(&shown))
}

#[cfg(test)]
mod tests {
    use super::shared_scale;

    #[test]
    fn the_scale_is_the_next_one_two_five_step_above_the_99th_percentile() {
        // 1000 values: the 99th percentile is the 990th smallest.
        let map: Vec<f32> = (0..1000).map(|k| k as f32 / 10_000.0).collect();
        // 989 / 10000 = 0.0989: the next step is 0.1.
        assert!((shared_scale(&[&map]) - 0.1).abs() < 1e-12);
        let doubled: Vec<f32> = map.iter().map(|v| v * 2.0).collect();
        // 0.1978 -> 0.2, the larger of the two maps.
        assert!((shared_scale(&[&map, &doubled]) - 0.2).abs() < 1e-12);
        // Nothing to show: the smallest scale; everything: FLIP's own.
        assert!((shared_scale(&[&[0.0; 10]]) - 0.01).abs() < 1e-12);
        assert!((shared_scale(&[&[1.0; 10]]) - 1.0).abs() < 1e-12);
        assert!((shared_scale(&[]) - 0.01).abs() < 1e-12);
    }
}
