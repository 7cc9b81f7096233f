//! Sections whose page and images are functions of the code, the options and the GPU adapter
//! alone (the renders, the bundled materials' fits, the error curves, the white furnace and
//! reciprocity, the designed lobes on the GPU cost model: images, fits, integrals, searches
//! and comparisons, no timing),
//! stored beside the design searches by a first run and copied back by a later run of the
//! same build, as the claims and the datapaths' sweeps are (`specula_decide`'s analyses).
//!
//! Keyed by the section, its sizes, the lobes, the adapter and `build.rs`'s fingerprint of
//! every crate beneath the report, so a change to any of them computes again. An entry is a folder
//! (`$SPECULA_CACHE_DIR/sections/<key>/`: the section's files and `section.json`, its body
//! and notes), made under a temporary name and renamed into place, so an interrupted run
//! leaves no partial entry; one that cannot be read is computed again, and one that cannot
//! be written costs the next run. A user's lobes are never stored: their formulas are not in
//! the fingerprint.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use specula_synth::cache::{key, Cache};

use super::Context;

/// Bumped when an entry's shape changes.
const FORMAT: &str = "specula report section 1";

/// What a stored section holds besides its files.
#[derive(Serialize, Deserialize)]
struct Entry {
    key: String,
    body: String,
    notes: Vec<String>,
    files: Vec<String>,
}

/// The sections' store: `$SPECULA_CACHE_DIR/sections`, where the design searches' cache
/// would be; none when no cache location is known.
pub(crate) fn default_store() -> Option<PathBuf> {
    Cache::default_for("sections").map(|cache| cache.directory().to_owned())
}

/// `compute(context)`, or the section stored in the context's store under the key of
/// `heading`, the context's sizes and lobes, and `machine` (what else the section's output
/// depends on: the GPU adapter); `context.from_store` says which. A context showing a
/// user's lobe is never stored.
pub(crate) fn section(
    context: &mut Context,
    heading: &str,
    machine: &str,
    compute: impl FnOnce(&mut Context) -> Result<String, String>,
) -> Result<String, String> {
    let Some(store) = context.store.clone().filter(|_| context.yours().is_empty()) else {
        return compute(context);
    };
    let lobes: Vec<String> = context.lobes.iter().map(ToString::to_string).collect();
    let key = key(&[
        FORMAT,
        env!("SPECULA_REPORT_SOURCES"),
        heading,
        &format!("{:?}", context.sizes),
        &lobes.join(","),
        machine,
    ]);
    let entry = store.join(&key);
    if let Some(body) = load(&entry, &key, context) {
        context.from_store = true;
        return Ok(body);
    }
    let (files_before, notes_before) = (context.files.len(), context.notes.len());
    let body = compute(context)?;
    let _ = save(
        &store,
        &entry,
        &Entry {
            key,
            body: body.clone(),
            notes: context.notes[notes_before..].to_vec(),
            files: context.files[files_before..].to_vec(),
        },
        &context.directory,
    );
    Ok(body)
}

/// The entry at `entry` with `key`, its files written into the context's folder; none when
/// it is missing or unreadable in any part (nothing is written then).
fn load(entry: &Path, key: &str, context: &mut Context) -> Option<String> {
    let text = std::fs::read_to_string(entry.join("section.json")).ok()?;
    let stored: Entry = serde_json::from_str(&text).ok()?;
    if stored.key != key || !stored.files.iter().all(|name| plain(name)) {
        return None;
    }
    let files = stored
        .files
        .iter()
        .map(|name| {
            std::fs::read(entry.join(name))
                .ok()
                .map(|bytes| (name, bytes))
        })
        .collect::<Option<Vec<_>>>()?;
    for (name, bytes) in files {
        context.write(name, &bytes).ok()?;
    }
    context.notes.extend(stored.notes);
    Some(stored.body)
}

/// Stores `stored`'s files, read from `written_to`, and its text under `entry`.
fn save(store: &Path, entry: &Path, stored: &Entry, written_to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(store)?;
    let folder = specula_temporaries::dir_in(store, "section")?;
    for name in &stored.files {
        std::fs::copy(written_to.join(name), folder.path().join(name))?;
    }
    let text = serde_json::to_string(stored).map_err(std::io::Error::other)?;
    std::fs::write(folder.path().join("section.json"), text)?;
    // Another run may have stored the same entry meanwhile: theirs is as good.
    folder.persist(entry)?;
    prune(store, KEPT);
    Ok(())
}

/// Entries kept: every build stores new ones (a full report's Renders are about 4 MB), so
/// the oldest beyond these are removed: five sections (Renders, Real materials, the error
/// curves, reciprocity and the white furnace, Designed lobes) of a full and a quick report, of
/// three builds.
const KEPT: usize = 30;

/// Removes all but the `kept` most recently stored entries of `store` (temporary folders of
/// runs in progress are not entries and are left alone).
fn prune(store: &Path, kept: usize) {
    let Ok(listed) = std::fs::read_dir(store) else {
        return;
    };
    let mut entries: Vec<(std::time::SystemTime, PathBuf)> = listed
        .flatten()
        .map(|e| e.path())
        .filter(|path| {
            path.file_name()
                .is_some_and(|n| plain(&n.to_string_lossy()))
        })
        .filter_map(|path| {
            let stored = std::fs::metadata(path.join("section.json")).ok()?;
            Some((stored.modified().ok()?, path))
        })
        .collect();
    entries.sort_by_key(|(stored, _)| std::cmp::Reverse(*stored));
    for (_, path) in entries.into_iter().skip(kept) {
        let _ = std::fs::remove_dir_all(path);
    }
}

/// A file name the section wrote beside the page (no folder, nothing hidden).
fn plain(name: &str) -> bool {
    !name.is_empty() && !name.starts_with('.') && !name.contains(['/', '\\'])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A context storing in `store` and writing into `out`, after the section under
    /// `heading` and `machine` ran in it: a section writing two files (the PNG's first byte
    /// `pixel`) and a note, counting its runs in `runs`.
    fn run(
        (store, out): (&Path, &Path),
        (heading, machine): (&str, &str),
        runs: &mut usize,
        pixel: u8,
    ) -> Context {
        run_in(
            Context::for_tests(out),
            store,
            (heading, machine),
            runs,
            pixel,
        )
    }

    fn run_in(
        mut context: Context,
        store: &Path,
        (heading, machine): (&str, &str),
        runs: &mut usize,
        pixel: u8,
    ) -> Context {
        context.store = Some(store.to_owned());
        let body = section(&mut context, heading, machine, |context| {
            *runs += 1;
            context.write_png_file("a.png", 1, 1, &[pixel, 2, 3])?;
            context.write("b.svg", b"<svg/>")?;
            context.machine_note("no adapter");
            Ok("<p>body</p>".into())
        })
        .unwrap();
        assert_eq!(body, "<p>body</p>");
        context
    }

    /// The second run with the same key copies the first's files, bit for bit, with its body
    /// and notes, and does not compute; another key (another adapter) computes again.
    #[test]
    fn a_stored_section_is_the_computed_one() {
        let store = tempfile::tempdir().unwrap();
        let outs: Vec<_> = (0..3).map(|_| tempfile::tempdir().unwrap()).collect();
        let mut runs = 0;
        let computed = run((store.path(), outs[0].path()), ("S", "gpu A"), &mut runs, 7);
        assert_eq!((computed.from_store, runs), (false, 1));
        let copied = run(
            (store.path(), outs[1].path()),
            ("S", "gpu A"),
            &mut runs,
            99,
        );
        assert_eq!((copied.from_store, runs), (true, 1));
        assert_eq!(copied.files, computed.files);
        assert_eq!(copied.notes, ["no adapter"]);
        for name in ["a.png", "b.svg"] {
            assert_eq!(
                std::fs::read(outs[1].path().join(name)).unwrap(),
                std::fs::read(outs[0].path().join(name)).unwrap(),
                "{name}"
            );
        }
        let elsewhere = run((store.path(), outs[2].path()), ("S", "gpu B"), &mut runs, 7);
        assert_eq!((elsewhere.from_store, runs), (false, 2));
    }

    /// Storing beyond the entries kept removes the oldest, and only them.
    #[test]
    fn the_oldest_entries_are_removed() {
        let store = tempfile::tempdir().unwrap();
        let out = tempfile::tempdir().unwrap();
        let places = (store.path(), out.path());
        let mut runs = 0;
        for machine in 0..=KEPT {
            run(places, ("S", &machine.to_string()), &mut runs, 1);
            // Entries apart in time by more than a file system's clock step.
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let count = || std::fs::read_dir(store.path()).unwrap().count();
        assert_eq!(count(), KEPT);
        let newest = run(places, ("S", &KEPT.to_string()), &mut runs, 1);
        let oldest = run(places, ("S", "0"), &mut runs, 1);
        assert_eq!((newest.from_store, oldest.from_store), (true, false));
        assert_eq!(count(), KEPT);
    }

    /// An entry missing a file is computed again, and a user's lobe is never stored.
    #[test]
    fn a_damaged_entry_or_a_users_lobe_computes() {
        let store = tempfile::tempdir().unwrap();
        let out = tempfile::tempdir().unwrap();
        let places = (store.path(), out.path());
        let mut runs = 0;
        run(places, ("S", ""), &mut runs, 1);
        let entry = std::fs::read_dir(store.path())
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.join("section.json").exists())
            .expect("an entry");
        std::fs::remove_file(entry.join("b.svg")).unwrap();
        assert!(!run(places, ("S", ""), &mut runs, 1).from_store);
        assert_eq!(runs, 2);
        for _ in 0..2 {
            let mut yours = Context::for_tests(out.path());
            let kind = specula_render::lobe_file::parse_lobe("cosquad:v=5", None).unwrap();
            yours.lobes.push(kind);
            assert!(!run_in(yours, store.path(), ("Y", ""), &mut runs, 1).from_store);
        }
        assert_eq!(runs, 4);
    }
}
