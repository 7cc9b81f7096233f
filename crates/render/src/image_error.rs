//! Why an image could not be read or written; `output.rs` reports a failed write of any
//! output file the same way.

use thiserror::Error;

/// Why an image could not be read or written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ImageError {
    /// The extension is none of `.png`, `.exr` and `.hdr`.
    #[error(
        "{path}: unknown image format; use a file name ending in .png (8-bit sRGB), .exr \
        (linear f32) or .hdr (Radiance RGBE)"
    )]
    UnknownFormat {
        /// The path.
        path: String,
    },
    /// The file system refused.
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The codec refused.
    #[error("{path}: {message}")]
    Codec {
        /// The path.
        path: String,
        /// The codec's message.
        message: String,
    },
}
