//! Results on disk (syntheses, designed lobes), keyed by everything that determines them.
//!
//! A key hashes the Verilog, the flow and the tool versions (FNV-1a, 64 bits), so a result is
//! reused exactly when the tools would be given the same work; the entry also stores its key,
//! checked on load. Entries are written atomically (a temporary file renamed into place), so
//! an interrupted run leaves no partial entry.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Bumped when [`crate::Synthesis`] changes shape, so old entries are not misread.
const FORMAT: &str = "specula-synth 1";

/// The key for `parts` (each separated, so `["ab", "c"]` and `["a", "bc"]` differ).
#[must_use]
pub fn key(parts: &[&str]) -> String {
    let bytes: Vec<&[u8]> = parts.iter().map(|part| part.as_bytes()).collect();
    key_of_bytes(&bytes)
}

/// [`key`] for parts that are bytes (a measurement's numbers), hashed as they are.
#[must_use]
pub fn key_of_bytes(parts: &[&[u8]]) -> String {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for part in core::iter::once(&FORMAT.as_bytes()).chain(parts) {
        for &byte in part.iter().chain(&[0xff]) {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    format!("{hash:016x}")
}

/// A directory of results.
#[derive(Clone, Debug)]
pub struct Cache {
    directory: PathBuf,
}

#[derive(Serialize, Deserialize)]
struct Entry<T> {
    key: String,
    result: T,
}

impl Cache {
    /// A cache in `directory` (created on the first store).
    #[must_use]
    pub fn new(directory: impl Into<PathBuf>) -> Self {
        Self {
            directory: directory.into(),
        }
    }

    /// `$SPECULA_CACHE_DIR/synth`, else `$XDG_CACHE_HOME/specula/synth`, else
    /// `$HOME/.cache/specula/synth`; none when no variable is set.
    #[must_use]
    pub fn default_location() -> Option<Self> {
        Self::default_for("synth")
    }

    /// The cache of `what` (`synth`, `design`) beside the synthesis's, where
    /// [`Cache::default_location`] would be.
    #[must_use]
    pub fn default_for(what: &str) -> Option<Self> {
        let var = |name: &str| std::env::var_os(name).filter(|value| !value.is_empty());
        let base = var("SPECULA_CACHE_DIR")
            .map(PathBuf::from)
            .or_else(|| var("XDG_CACHE_HOME").map(|d| Path::new(&d).join("specula")))
            .or_else(|| var("HOME").map(|d| Path::new(&d).join(".cache/specula")))?;
        Some(Self::new(base.join(what)))
    }

    /// The directory.
    #[must_use]
    pub fn directory(&self) -> &Path {
        &self.directory
    }

    fn path(&self, key: &str) -> PathBuf {
        self.directory.join(format!("{key}.json"))
    }

    /// The result stored under `key`, if there is a readable one of its type.
    #[must_use]
    pub fn load<T: DeserializeOwned>(&self, key: &str) -> Option<T> {
        let text = std::fs::read_to_string(self.path(key)).ok()?;
        let entry: Entry<T> = serde_json::from_str(&text).ok()?;
        (entry.key == key).then_some(entry.result)
    }

    /// Holds `key` until the returned file is dropped: another process (or thread) asking for
    /// the same design waits here and then finds the first one's result, rather than running
    /// the tools on the same work at the same time (tests side by side, two reports at once).
    /// The lock is the operating system's (`flock`), so a killed holder releases it. The
    /// small lock files stay: removing one another process has open would let a third lock a
    /// new file of the same name.
    pub fn hold(&self, key: &str) -> std::io::Result<std::fs::File> {
        std::fs::create_dir_all(&self.directory)?;
        let file = std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(self.directory.join(format!("{key}.lock")))?;
        file.lock()?;
        Ok(file)
    }

    /// Stores `result` under `key`, atomically.
    pub fn store<T: Serialize>(&self, key: &str, result: &T) -> std::io::Result<()> {
        std::fs::create_dir_all(&self.directory)?;
        let entry = Entry {
            key: key.to_owned(),
            result,
        };
        let text = serde_json::to_string_pretty(&entry).map_err(std::io::Error::other)?;
        let mut file = specula_temporaries::file_in(&self.directory, ".tmp", Some(0o666))?;
        file.as_file_mut().write_all(text.as_bytes())?;
        file.persist(&self.path(key))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// While one holder has a key, a second waits; once the first is dropped it proceeds.
    #[test]
    fn a_held_key_makes_the_next_holder_wait() {
        let directory = tempfile::tempdir().unwrap();
        let cache = Cache::new(directory.path());
        let first = cache.hold("k").unwrap();
        let waited = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let second = {
            let (cache, waited) = (cache.clone(), waited.clone());
            std::thread::spawn(move || {
                let _held = cache.hold("k").unwrap();
                waited.load(std::sync::atomic::Ordering::SeqCst)
            })
        };
        std::thread::sleep(std::time::Duration::from_millis(200));
        waited.store(true, std::sync::atomic::Ordering::SeqCst);
        drop(first);
        assert!(
            second.join().unwrap(),
            "the second holder did not wait for the first"
        );
    }

    #[test]
    fn keys_separate_their_parts_and_are_stable() {
        assert_ne!(key(&["ab", "c"]), key(&["a", "bc"]));
        assert_eq!(key(&["x"]), key(&["x"]));
        assert_eq!(key(&["x"]).len(), 16);
    }
}
