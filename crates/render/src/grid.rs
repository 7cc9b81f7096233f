//! A comparison grid: the scene rendered once per lobe, side by side, each with its label, and
//! below each its FLIP heatmap against the reference lobe (`pow`, the exact `t^n`) with the mean
//! FLIP written on it.

use font8x8::UnicodeFonts;
use rayon::prelude::*;
use specula::LobeKind;
use thiserror::Error;

use crate::image::Image;
use crate::metrics::{compare_srgb8, Difference};
use crate::pipeline::MAX_PIXELS;
use crate::pipeline::{render, RenderError};
use crate::scene::{Overrides, Scene};

/// What a grid shows.
#[derive(Clone, Debug, PartialEq)]
pub struct GridOptions {
    /// One column per lobe, in this order.
    pub lobes: Vec<LobeKind>,
    /// What every column is compared with.
    pub reference: LobeKind,
}

/// A grid that cannot be made.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum GridError {
    /// No lobe was named.
    #[error("a grid needs at least one lobe, e.g. --grid lobes=pow,schlick,cheb2")]
    Empty,
    /// A render failed.
    #[error("{0}")]
    Render(String),
    /// The grid would exceed the renderer's pixel limit.
    #[error(
        "a grid of {lobes} lobes at {width}x{height} is {pixels} pixels (two rows of renders \
        and FLIP maps), above the limit of {MAX_PIXELS}; use fewer lobes or a smaller \
        --width/--height"
    )]
    TooLarge {
        /// Lobes asked for.
        lobes: usize,
        /// Render width.
        width: u32,
        /// Render height.
        height: u32,
        /// The grid's pixels.
        pixels: u64,
    },
}

/// An 8-bit sRGB image (three bytes per pixel).
#[derive(Clone, Debug, PartialEq)]
pub struct Srgb8Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major bytes.
    pub bytes: Vec<u8>,
}

impl Srgb8Image {
    fn blit(&mut self, x0: u32, y0: u32, width: u32, bytes: &[u8]) {
        for (row, line) in bytes.chunks_exact(3 * width as usize).enumerate() {
            let start = 3 * ((y0 + row as u32) * self.width + x0) as usize;
            self.bytes[start..start + line.len()].copy_from_slice(line);
        }
    }

    /// Writes `text` at `(x, y)` in white on a dark box, with 8x8 glyphs scaled twice.
    fn label(&mut self, x: u32, y: u32, text: &str) {
        const SCALE: u32 = 2;
        let glyph_size = 8 * SCALE;
        let box_width = (text.chars().count() as u32 * glyph_size + 8).min(self.width - x);
        let box_height = (glyph_size + 8).min(self.height - y);
        for yy in y..y + box_height {
            for xx in x..x + box_width {
                let k = 3 * (yy * self.width + xx) as usize;
                self.bytes[k..k + 3].iter_mut().for_each(|b| *b /= 4);
            }
        }
        for (index, c) in text.chars().enumerate() {
            let glyph = font8x8::BASIC_FONTS.get(c).unwrap_or([0; 8]);
            for (row, bits) in glyph.iter().enumerate() {
                for column in 0..8 {
                    if bits >> column & 1 == 0 {
                        continue;
                    }
                    for (dy, dx) in (0..SCALE).flat_map(|dy| (0..SCALE).map(move |dx| (dy, dx))) {
                        let px = x + 4 + index as u32 * glyph_size + column * SCALE + dx;
                        let py = y + 4 + row as u32 * SCALE + dy;
                        if px < self.width && py < self.height {
                            let k = 3 * (py * self.width + px) as usize;
                            self.bytes[k..k + 3].fill(255);
                        }
                    }
                }
            }
        }
    }
}

/// Renders the grid with the CPU renderer: row one the lobes, row two their FLIP against
/// `options.reference`. `progress(done, total)` counts tiles over all renders.
pub fn render_grid(
    scene: &Scene,
    options: &GridOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Srgb8Image, GridError> {
    let renders = 1 + options.lobes.len();
    render_grid_with(scene, options, &mut |variant, index| {
        render(variant, &|done, total| {
            progress(index * total + done, renders * total)
        })
        .map_err(|e: RenderError| e.to_string())
    })
}

/// Refuses a grid of no lobes, or one too large to hold, before anything is rendered.
pub fn check_grid(scene: &Scene, options: &GridOptions) -> Result<(), GridError> {
    if options.lobes.is_empty() {
        return Err(GridError::Empty);
    }
    let (width, height) = (scene.settings.width, scene.settings.height);
    let pixels = 2 * options.lobes.len() as u64 * u64::from(width) * u64::from(height);
    if pixels > MAX_PIXELS {
        return Err(GridError::TooLarge {
            lobes: options.lobes.len(),
            width,
            height,
            pixels,
        });
    }
    Ok(())
}

/// [`render_grid_with`]'s renderer over renders made beforehand, by index as
/// [`grid_renders`] lists them: hands each out once.
pub fn made_renders(
    renders: &mut [Option<Image>],
) -> impl FnMut(&Scene, usize) -> Result<Image, String> + '_ {
    |_, index| {
        renders
            .get_mut(index)
            .and_then(Option::take)
            .ok_or_else(|| format!("no render {index} for the grid"))
    }
}

/// The lobe of each render [`render_grid_with`] asks for, by index: the reference at 0,
/// each other lobe at its column + 1 (`None` at the reference's own column, which the grid
/// fills from render 0).
#[must_use]
pub fn grid_renders(options: &GridOptions) -> Vec<Option<LobeKind>> {
    std::iter::once(Some(options.reference))
        .chain(
            options
                .lobes
                .iter()
                .map(|&kind| (kind != options.reference).then_some(kind)),
        )
        .collect()
}

/// [`render_grid`] with any renderer: `render(scene, index)` draws the `index`-th of the
/// `1 + lobes` renders (the reference first).
pub fn render_grid_with(
    scene: &Scene,
    options: &GridOptions,
    render: &mut dyn FnMut(&Scene, usize) -> Result<Image, String>,
) -> Result<Srgb8Image, GridError> {
    render_grid_columns(scene, options, render).map(|grid| grid.image)
}

/// One column of a grid: its lobe's render as displayed and its difference from the
/// reference's, both computed from those bytes.
#[derive(Clone, Debug)]
pub struct GridColumn {
    /// The column's lobe.
    pub lobe: LobeKind,
    /// The render as displayed: 8-bit sRGB, three bytes per pixel (what a PNG of it holds).
    pub srgb8: Vec<u8>,
    /// PSNR, largest error and FLIP against the reference's bytes.
    pub difference: Difference,
}

/// A grid and the columns it was made of.
#[derive(Clone, Debug)]
pub struct Grid {
    /// The grid's image.
    pub image: Srgb8Image,
    /// The columns in `options.lobes`' order.
    pub columns: Vec<GridColumn>,
}

/// [`render_grid_with`], keeping each column's bytes and its difference, so that a caller
/// writing each lobe's image and its figures compares nothing twice.
pub fn render_grid_columns(
    scene: &Scene,
    options: &GridOptions,
    render: &mut dyn FnMut(&Scene, usize) -> Result<Image, String>,
) -> Result<Grid, GridError> {
    check_grid(scene, options)?;
    let mut with_lobe = |kind: LobeKind, index: usize| {
        let mut variant = scene.clone();
        variant.apply(&Overrides {
            lobe: Some(kind),
            ..Overrides::default()
        });
        render(&variant, index).map_err(GridError::Render)
    };
    let reference = with_lobe(options.reference, 0)?;
    let (width, height) = (reference.width(), reference.height());
    let reference_srgb8 = reference.to_srgb8(scene.display);
    drop(reference);
    // Each render kept as displayed (a quarter of its floats' memory), then compared.
    let mut displayed = Vec::with_capacity(options.lobes.len());
    for (column, &lobe) in options.lobes.iter().enumerate() {
        let srgb8 = if lobe == options.reference {
            reference_srgb8.clone()
        } else {
            let image = with_lobe(lobe, column + 1)?;
            if (image.width(), image.height()) != (width, height) {
                return Err(GridError::Render(format!(
                    "the {lobe} render is {}x{}, the {} render {width}x{height}",
                    image.width(),
                    image.height(),
                    options.reference
                )));
            }
            image.to_srgb8(scene.display)
        };
        displayed.push((lobe, srgb8));
    }
    // FLIP (the reference implementation, one thread) dominates; the columns in parallel.
    let columns: Vec<GridColumn> = displayed
        .into_par_iter()
        .map(|(lobe, srgb8)| GridColumn {
            lobe,
            difference: compare_srgb8(width, height, &reference_srgb8, &srgb8),
            srgb8,
        })
        .collect();
    let mut grid = Srgb8Image {
        width: width * options.lobes.len() as u32,
        height: 2 * height,
        bytes: vec![0; 3 * (width * options.lobes.len() as u32 * 2 * height) as usize],
    };
    for (index, column) in columns.iter().enumerate() {
        let x0 = index as u32 * width;
        grid.blit(x0, 0, width, &column.srgb8);
        grid.blit(x0, height, width, &column.difference.heatmap_srgb8());
        grid.label(x0, 0, &column.lobe.to_string());
        let caption = if column.lobe == options.reference {
            "reference".to_owned()
        } else {
            format!(
                "FLIP {:.4} vs {}",
                column.difference.mean_flip,
                options.reference.id()
            )
        };
        grid.label(x0, height, &caption);
    }
    Ok(Grid {
        image: grid,
        columns,
    })
}
