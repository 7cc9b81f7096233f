//! `remove_all` in a process of its own (it ends the process's temporaries for good): every
//! registered temporary goes, and none is made afterwards.

use specula_temporaries::{dir_in, file_in, registered_under, remove_all};

#[test]
fn after_the_sweep_nothing_is_left_and_nothing_new_is_made() {
    let folder = tempfile::tempdir().expect("folder");
    let file = file_in(folder.path(), ".tmp", None).expect("made");
    let staging = dir_in(folder.path(), "series-").expect("made");
    std::fs::write(staging.path().join("slice.dcm"), b"x").expect("written");
    let (file_path, staging_path) = (file.path().to_owned(), staging.path().to_owned());
    // What the signal handler does while the work still holds its temporaries.
    remove_all();
    assert!(!file_path.exists() && !staging_path.exists());
    assert!(registered_under(folder.path()).is_empty());
    let refused = file_in(folder.path(), ".tmp", None).expect_err("the run is ending");
    assert_eq!(refused.kind(), std::io::ErrorKind::Interrupted);
    assert!(dir_in(folder.path(), "x-").is_err());
    // The work's own clean-up, after the sweep, finds nothing to remove.
    assert!(file.persist(&folder.path().join("out.txt")).is_err());
    drop(staging);
    assert_eq!(std::fs::read_dir(folder.path()).unwrap().count(), 0);
}
