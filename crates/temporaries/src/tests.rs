use std::io::Write;

use super::*;

fn entries(folder: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(folder)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_file_is_registered_while_it_exists_and_named_for_its_process() {
    let folder = tempfile::tempdir().expect("folder");
    let mut file = file_in(folder.path(), ".tmp", Some(0o644)).expect("made");
    let name = file
        .path()
        .file_name()
        .unwrap()
        .to_string_lossy()
        .into_owned();
    assert!(
        name.starts_with(&format!(".specula-{}-", std::process::id())),
        "{name}"
    );
    assert!(name.ends_with(".tmp"), "{name}");
    assert_eq!(registered_under(folder.path()), [file.path().to_owned()]);
    file.as_file_mut().write_all(b"whole").expect("written");
    file.persist(&folder.path().join("out.txt"))
        .expect("renamed");
    assert!(registered_under(folder.path()).is_empty());
    assert_eq!(entries(folder.path()), ["out.txt"]);
    assert_eq!(
        std::fs::read(folder.path().join("out.txt")).unwrap(),
        b"whole"
    );

    let dropped = file_in(folder.path(), ".tmp", None).expect("made");
    let path = dropped.path().to_owned();
    drop(dropped);
    assert!(!path.exists());
    assert!(registered_under(folder.path()).is_empty());
}

#[test]
fn a_folder_is_registered_and_persisted_whole_or_removed() {
    let parent = tempfile::tempdir().expect("folder");
    let staging = dir_in(parent.path(), "series-").expect("made");
    std::fs::write(staging.path().join("slice.dcm"), b"x").expect("written");
    assert_eq!(registered_under(parent.path()), [staging.path().to_owned()]);
    staging
        .persist(&parent.path().join("series"))
        .expect("renamed");
    assert_eq!(entries(parent.path()), ["series"]);
    assert!(registered_under(parent.path()).is_empty());

    // A target that is a non-empty folder refuses the rename: the staging folder goes.
    let staging = dir_in(parent.path(), "series-").expect("made");
    assert!(staging.persist(&parent.path().join("series")).is_err());
    assert_eq!(entries(parent.path()), ["series"]);
    assert!(registered_under(parent.path()).is_empty());
}

#[test]
fn a_dead_processs_files_are_removed_and_a_live_ones_kept() {
    let folder = tempfile::tempdir().expect("folder");
    // pid_max is at most 2^22 on Linux: no process has this number.
    let dead = folder.path().join(".specula-4294967-abc.tmp");
    std::fs::write(&dead, b"x").expect("written");
    std::fs::create_dir(folder.path().join(".specula-4294967-series-abc")).expect("made");
    let live = folder.path().join(".specula-1-abc.tmp");
    std::fs::write(&live, b"x").expect("written");
    let mine = file_in(folder.path(), ".tmp", None).expect("made");
    let mut expected = vec![
        ".specula-1-abc.tmp".to_owned(),
        mine.path()
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned(),
    ];
    expected.sort();
    if Path::new("/proc/self").exists() {
        assert_eq!(entries(folder.path()), expected);
    }
}
