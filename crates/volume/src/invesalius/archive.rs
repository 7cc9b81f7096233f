//! Reading the `.inv3` tar archive (gzip-compressed or not) entry by entry, within limits.

use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

use specula_render::input;

/// The largest tar long-name (GNU `L`) or PAX header entry read.
const MAX_HEADER_ENTRY_BYTES: u64 = 64 << 10;

/// The archive may inflate to this many times the input limit: room for a project's masks
/// and surfaces beside its voxels, and a stop for a gzip bomb.
const INFLATION: u64 = 4;

/// Whether [`walk`] goes on to the next entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Walk {
    On,
    Stop,
}

/// What [`walk`] calls for each regular file: its name, its size and its data.
pub(super) type Visit<'a> = dyn FnMut(&str, u64, &mut dyn Read) -> Result<Walk, String> + 'a;

/// Calls `visit(name, size, data)` for every regular file in the archive at `path`, in order,
/// until it answers [`Walk::Stop`] or the archive ends. Names are as stored, less a leading
/// `./`, with GNU long names and PAX `path` records applied.
pub(super) fn walk(path: &Path, limit: u64, visit: &mut Visit<'_>) -> Result<(), String> {
    let file = input::open_regular(path)?;
    let mut buffered = BufReader::new(file);
    let gzip = buffered
        .fill_buf()
        .map_err(|e| format!("cannot be read ({e})"))?
        .starts_with(&[0x1f, 0x8b]);
    let stream: Box<dyn Read> = if gzip {
        Box::new(flate2::read::MultiGzDecoder::new(buffered))
    } else {
        Box::new(buffered)
    };
    let cap = limit.saturating_mul(INFLATION);
    let mut archive = tar::Archive::new(Capped {
        inner: stream,
        left: cap,
        cap,
    });
    // Raw entries: long names and PAX headers are read here, within a limit, rather than by
    // the tar crate, which would read one of any declared size into memory.
    let mut entries = archive.entries().map_err(damaged)?.raw(true);
    let mut long_name: Option<Vec<u8>> = None;
    for entry in entries.by_ref() {
        let mut entry = entry.map_err(damaged)?;
        let kind = entry.header().entry_type();
        let size = entry.size();
        if kind.is_gnu_longname() || kind.is_pax_local_extensions() {
            if size > MAX_HEADER_ENTRY_BYTES {
                return Err(format!(
                    "a tar header entry (long name or PAX) of {size} bytes; the most read is \
                        {MAX_HEADER_ENTRY_BYTES}"
                ));
            }
            let mut bytes = Vec::with_capacity(size as usize);
            entry.read_to_end(&mut bytes).map_err(damaged)?;
            if kind.is_gnu_longname() {
                while bytes.last() == Some(&0) {
                    bytes.pop();
                }
                long_name = Some(bytes);
            } else {
                for extension in tar::PaxExtensions::new(&bytes) {
                    let extension = extension.map_err(damaged)?;
                    match extension.key_bytes() {
                        b"path" => long_name = Some(extension.value_bytes().to_vec()),
                        b"size" => return Err(
                            "a PAX size record (a member over 8 GiB); not an InVesalius project"
                                .into(),
                        ),
                        _ => {}
                    }
                }
            }
            continue;
        }
        let stored = long_name
            .take()
            .unwrap_or_else(|| entry.path_bytes().into_owned());
        if !(kind.is_file() || kind.is_contiguous()) {
            continue;
        }
        let stored = String::from_utf8_lossy(&stored);
        let name = stored.trim_start_matches("./");
        if visit(name, size, &mut entry)? == Walk::Stop {
            return Ok(());
        }
    }
    // What follows the end-of-archive blocks is read too, so that a gzip stream cut short or
    // damaged there (its checksum is at its very end) is refused like one damaged earlier.
    io::copy(&mut archive.into_inner(), &mut io::sink()).map_err(damaged)?;
    Ok(())
}

/// A tar or gzip failure, in a line.
pub(super) fn damaged(error: io::Error) -> String {
    let said = error.to_string().replace('\n', " ");
    if said.starts_with(CAPPED) {
        said
    } else if error.kind() == io::ErrorKind::UnexpectedEof {
        format!("the archive is truncated ({said})")
    } else {
        format!(
            "not a readable InVesalius project: the tar.gz archive is damaged or truncated \
            ({said})"
        )
    }
}

/// The start of [`Capped`]'s error.
const CAPPED: &str = "the archive inflates to more than";

/// A reader that fails once more than `cap` bytes have come through.
struct Capped<R> {
    inner: R,
    left: u64,
    cap: u64,
}

impl<R: Read> Read for Capped<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        if self.left == 0 {
            let mut probe = [0_u8; 1];
            return match self.inner.read(&mut probe)? {
                0 => Ok(0),
                _ => Err(io::Error::other(format!(
                    "{CAPPED} {} bytes ({INFLATION} x the input limit; raise it with \
                        --max-input-mib)",
                    self.cap
                ))),
            };
        }
        let most = buf
            .len()
            .min(usize::try_from(self.left).unwrap_or(usize::MAX));
        let read = self.inner.read(&mut buf[..most])?;
        self.left -= read as u64;
        Ok(read)
    }
}

/// The last component of an archive path.
pub(super) fn base_name(name: &str) -> &str {
    name.rsplit('/').next().unwrap_or(name)
}
