//! Images: linear radiance in memory, tone mapping and sRGB encoding only at write time.
//!
//! PNG files hold 8-bit sRGB (exposure and tone map applied, then the sRGB curve); OpenEXR files
//! hold the linear `f32` radiance untouched. Every file is written to a temporary file in the
//! destination's directory and renamed into place, so a failed or interrupted write never
//! leaves a partial image behind.

use std::path::Path;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::image_error::ImageError;
use crate::output::write_atomically;
use crate::srgb8;

/// A linear RGB image, row-major from the top-left pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
}

/// How radiance above 1 is brought into the displayable range before sRGB encoding.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ToneMap {
    /// Clip each channel to `[0, 1]` (the classic model's intensities are meant this way).
    #[default]
    Clamp,
    /// `x / (1 + x)` per channel (keeps the peaks of normalised lobes visible).
    Reinhard,
}

impl ToneMap {
    /// Both tone maps.
    pub const ALL: [ToneMap; 2] = [ToneMap::Clamp, ToneMap::Reinhard];

    /// The name in scenes and on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            ToneMap::Clamp => "clamp",
            ToneMap::Reinhard => "reinhard",
        }
    }

    fn apply(self, value: f32) -> f32 {
        match self {
            ToneMap::Clamp => value.clamp(0.0, 1.0),
            ToneMap::Reinhard => {
                let v = value.max(0.0);
                v / (1.0 + v)
            }
        }
    }
}

/// What turns radiance into display values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Display {
    /// Radiance is multiplied by this before tone mapping.
    pub exposure: f32,
    /// The tone map.
    pub tonemap: ToneMap,
}

impl Default for Display {
    fn default() -> Self {
        Self {
            exposure: 1.0,
            tonemap: ToneMap::Clamp,
        }
    }
}

impl Image {
    /// A `width x height` image filled with `colour`.
    #[must_use]
    pub fn new(width: u32, height: u32, colour: Vec3) -> Self {
        Self {
            width,
            height,
            pixels: vec![colour; width as usize * height as usize],
        }
    }

    /// An image from its pixels; `None` unless `pixels.len() == width * height`.
    #[must_use]
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<Vec3>) -> Option<Self> {
        (pixels.len() == width as usize * height as usize).then_some(Self {
            width,
            height,
            pixels,
        })
    }

    /// Width in pixels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pixels, row-major.
    #[must_use]
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// The pixels, row-major, to write.
    pub fn pixels_mut(&mut self) -> &mut [Vec3] {
        &mut self.pixels
    }

    /// The pixel at column `x`, row `y`.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Sets the pixel at column `x`, row `y`.
    pub fn set(&mut self, x: u32, y: u32, colour: Vec3) {
        self.pixels[(y * self.width + x) as usize] = colour;
    }

    /// 8-bit sRGB values, three per pixel, after exposure and tone mapping.
    #[must_use]
    pub fn to_srgb8(&self, display: Display) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| p.to_array())
            .map(|c| {
                let mapped = display.tonemap.apply(c * display.exposure);
                // NaN cannot reach here (the renderer never writes one), but a NaN would
                // encode as 0 rather than poison the file.
                srgb8::encode(mapped)
            })
            .collect()
    }

    /// The image from 8-bit sRGB values, decoded to linear.
    #[must_use]
    pub fn from_srgb8(width: u32, height: u32, bytes: &[u8]) -> Option<Self> {
        let decode = srgb8::decode;
        let pixels = bytes
            .chunks_exact(3)
            .map(|c| Vec3::new(decode(c[0]), decode(c[1]), decode(c[2])))
            .collect();
        Self::from_pixels(width, height, pixels)
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum ImageFileFormat {
    Png,
    Exr,
    Hdr,
}

fn format_of(path: &Path) -> Result<ImageFileFormat, ImageError> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => Ok(ImageFileFormat::Png),
        Some("exr") => Ok(ImageFileFormat::Exr),
        Some("hdr") => Ok(ImageFileFormat::Hdr),
        _ => Err(ImageError::UnknownFormat {
            path: path.display().to_string(),
        }),
    }
}

/// Checks that `path` names a format this module writes (before any long work starts).
pub fn check_output_path(path: &Path) -> Result<(), ImageError> {
    format_of(path).map(|_| ())
}

/// Whether `path` names a format that keeps linear radiance above 1 (EXR, HDR; not PNG's
/// 8-bit display values), or why it names no format this module writes.
pub fn is_linear_output(path: &Path) -> Result<bool, ImageError> {
    format_of(path).map(|format| format != ImageFileFormat::Png)
}

/// Writes 8-bit sRGB bytes (three per pixel) as a PNG, atomically.
pub fn write_png_srgb8(
    path: &Path,
    width: u32,
    height: u32,
    bytes: &[u8],
) -> Result<(), ImageError> {
    write_atomically(path, |writer| png_into(writer, width, height, bytes))
}

/// 8-bit sRGB bytes (three per pixel) as PNG file contents in memory.
pub fn encode_png_srgb8(width: u32, height: u32, bytes: &[u8]) -> Result<Vec<u8>, String> {
    let mut png = Vec::new();
    png_into(&mut png, width, height, bytes)?;
    Ok(png)
}

fn png_into(
    writer: impl std::io::Write,
    width: u32,
    height: u32,
    bytes: &[u8],
) -> Result<(), String> {
    use image::ImageEncoder;
    image::codecs::png::PngEncoder::new(writer)
        .write_image(bytes, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| e.to_string())
}

/// Writes `image` to `path`: `.png` as 8-bit sRGB through `display`, `.exr` as linear `f32`
/// (run-length coded), `.hdr` as linear Radiance RGBE (negative and non-finite values are
/// written as 0).
pub fn write_image(path: &Path, image: &Image, display: Display) -> Result<(), ImageError> {
    use exr::prelude::{
        Encoding, Image as ExrImage, Layer, LayerAttributes, SpecificChannels, WritableImage,
    };
    match format_of(path)? {
        ImageFileFormat::Png => {
            write_png_srgb8(path, image.width, image.height, &image.to_srgb8(display))
        }
        ImageFileFormat::Exr => write_atomically(path, |writer| {
            let layer = Layer::new(
                (image.width as usize, image.height as usize),
                LayerAttributes::named("radiance"),
                // Run-length coded in 64 x 64 tiles: a render's noise leaves ZIP little to find
                // (a 512 x 512 close-up: 3.05 MB in ZIP, 3.15 in RLE, 3.15 raw), a volume's
                // background RLE finds as well (0.88 against 0.91 MB), and ZIP's deflate took
                // 35 ms of a 0.21 s `specula render` on 2 threads.
                Encoding::FAST_LOSSLESS,
                SpecificChannels::rgb(|position: exr::math::Vec2<usize>| {
                    let p = image.get(position.x() as u32, position.y() as u32);
                    (p.x, p.y, p.z)
                }),
            );
            ExrImage::from_layer(layer)
                .write()
                .to_buffered(writer)
                .map_err(|e| e.to_string())
        }),
        ImageFileFormat::Hdr => write_atomically(path, |writer| {
            let finite = |v: f32| if v.is_finite() { v.max(0.0) } else { 0.0 };
            let pixels: Vec<image::Rgb<f32>> = image
                .pixels()
                .iter()
                .map(|p| image::Rgb([finite(p.x), finite(p.y), finite(p.z)]))
                .collect();
            image::codecs::hdr::HdrEncoder::new(writer)
                .encode(&pixels, image.width as usize, image.height as usize)
                .map_err(|e| e.to_string())
        }),
    }
}

/// The most pixels an image read from a file may have: 16,777,216 (4096 x 4096). What the
/// file declares is checked before any pixel is decoded, and FLIP (`specula diff`) needs
/// about 60 bytes per pixel beside the two images.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 24;

/// Reads a PNG (decoded from sRGB to linear), an OpenEXR file (its first RGB(A) layer) or a
/// Radiance HDR file (RGBE, linear): a
/// regular file within the input limit, whose declared size is at most [`MAX_IMAGE_PIXELS`].
pub fn read_image(path: &Path) -> Result<Image, ImageError> {
    let codec = |message: String| ImageError::Codec {
        path: path.display().to_string(),
        message,
    };
    let format = format_of(path)?;
    let bytes = crate::input::read_regular(path).map_err(codec)?;
    let check = |width: u64, height: u64| {
        if width * height > MAX_IMAGE_PIXELS {
            Err(codec(format!(
                "declares {width}x{height} pixels, above the limit of {MAX_IMAGE_PIXELS} (4096 x \
                    4096)"
            )))
        } else {
            Ok(())
        }
    };
    match format {
        ImageFileFormat::Png => {
            let reader = || {
                image::ImageReader::with_format(
                    std::io::Cursor::new(bytes.as_slice()),
                    image::ImageFormat::Png,
                )
            };
            let (width, height) = reader()
                .into_dimensions()
                .map_err(|e| codec(e.to_string()))?;
            check(u64::from(width), u64::from(height))?;
            let mut limits = image::Limits::default();
            limits.max_alloc = Some(16 * MAX_IMAGE_PIXELS);
            let mut limited = reader();
            limited.limits(limits);
            let decoded = limited.decode().map_err(|e| codec(e.to_string()))?;
            let rgb = decoded.to_rgb8();
            Image::from_srgb8(rgb.width(), rgb.height(), rgb.as_raw())
                .ok_or_else(|| codec("inconsistent image size".into()))
        }
        ImageFileFormat::Hdr => {
            let decoder =
                image::codecs::hdr::HdrDecoder::new(std::io::Cursor::new(bytes.as_slice()))
                    .map_err(|e| codec(e.to_string()))?;
            let meta = decoder.metadata();
            check(u64::from(meta.width), u64::from(meta.height))?;
            let decoded = image::DynamicImage::from_decoder(decoder)
                .map_err(|e| codec(e.to_string()))?
                .to_rgb32f();
            let pixels = decoded
                .pixels()
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect();
            Image::from_pixels(decoded.width(), decoded.height(), pixels)
                .ok_or_else(|| codec("inconsistent image size".into()))
        }
        ImageFileFormat::Exr => {
            use exr::prelude::{ReadChannels as _, ReadLayers as _};
            let meta = exr::meta::MetaData::read_from_buffered(
                std::io::Cursor::new(bytes.as_slice()),
                false,
            )
            .map_err(|e| codec(e.to_string()))?;
            for header in meta.headers.iter() {
                let size = header.layer_size;
                check(size.width() as u64, size.height() as u64)?;
            }
            let read = exr::prelude::read()
                .no_deep_data()
                .largest_resolution_level()
                .rgba_channels(
                    |resolution, _| {
                        Image::new(
                            resolution.width() as u32,
                            resolution.height() as u32,
                            Vec3::ZERO,
                        )
                    },
                    |image: &mut Image, position, (r, g, b, _a): (f32, f32, f32, f32)| {
                        image.set(position.x() as u32, position.y() as u32, Vec3::new(r, g, b));
                    },
                )
                .first_valid_layer()
                .all_attributes()
                .from_buffered(std::io::Cursor::new(bytes.as_slice()))
                .map_err(|e| codec(e.to_string()))?;
            Ok(read.layer_data.channel_data.pixels)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::srgb8::srgb_encode;

    #[test]
    fn tone_maps_and_exposure_apply_before_encoding() {
        let image =
            Image::from_pixels(2, 1, vec![Vec3::new(3.0, 1.0, -1.0), Vec3::splat(0.25)]).unwrap();
        let clamp = image.to_srgb8(Display::default());
        assert_eq!(&clamp[..3], &[255, 255, 0]);
        let reinhard = image.to_srgb8(Display {
            exposure: 2.0,
            tonemap: ToneMap::Reinhard,
        });
        // 0.25 * 2 = 0.5 -> 0.5 / 1.5 = 1/3 -> sRGB 0.6132 -> 156.
        assert_eq!(reinhard[3], (srgb_encode(1.0 / 3.0) * 255.0).round() as u8);
        assert_eq!(reinhard[3], 156);
    }

    #[test]
    fn files_round_trip_and_unknown_extensions_are_refused() {
        let directory = tempfile::tempdir().unwrap();
        let pixels = (0..12)
            .map(|k| Vec3::new(k as f32 * 0.7, 0.1, 1e-3 * k as f32))
            .collect();
        let image = Image::from_pixels(4, 3, pixels).unwrap();
        let exr = directory.path().join("a.exr");
        write_image(&exr, &image, Display::default()).unwrap();
        assert_eq!(read_image(&exr).unwrap(), image);

        let png = directory.path().join("a.png");
        write_image(&png, &image, Display::default()).unwrap();
        let back = read_image(&png).unwrap();
        assert_eq!(
            back.to_srgb8(Display::default()),
            image.to_srgb8(Display::default())
        );

        let error = write_image(&directory.path().join("a.jpg"), &image, Display::default());
        assert!(error.unwrap_err().to_string().contains(".png"));
        // Only the two images: no temporary file left behind.
        assert_eq!(std::fs::read_dir(directory.path()).unwrap().count(), 2);
    }
}
