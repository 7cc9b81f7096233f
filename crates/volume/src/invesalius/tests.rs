//! The reader's unit tests: small projects built in memory, good and bad.

use super::*;
use std::io::Write as _;

/// A `main.plist` for a `[z, y, x]` grid.
fn plist(shape: [i64; 3], dtype: &str, spacing: [f64; 3], extra: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE plist PUBLIC "-//Apple Computer//DTD PLIST 1.0//EN"
 "http://www.apple.com/DTDs/PropertyList-1.0.dtd">
<plist version="1.0">
<dict>
	<key>matrix</key>
	<dict>
		<key>dtype</key>
		<string>{dtype}</string>
		<key>filename</key>
		<string>matrix.dat</string>
		<key>shape</key>
		<array>
			<integer>{}</integer>
			<integer>{}</integer>
			<integer>{}</integer>
		</array>
	</dict>
	<key>spacing</key>
	<array>
		<real>{}</real>
		<real>{}</real>
		<real>{}</real>
	</array>
	<key>window_level</key>
	<real>-18.0</real>
	{extra}
</dict>
</plist>
"#,
        shape[0], shape[1], shape[2], spacing[0], spacing[1], spacing[2]
    )
}

/// A tar archive of `entries` (name, bytes), gzip-compressed when `gzip`.
fn archive(entries: &[(&str, &[u8])], gzip: bool) -> Vec<u8> {
    let mut builder = tar::Builder::new(Vec::new());
    for (name, bytes) in entries {
        let mut header = tar::Header::new_gnu();
        header.set_size(bytes.len() as u64);
        header.set_mode(0o644);
        builder
            .append_data(&mut header, name, *bytes)
            .expect("append");
    }
    let tar = builder.into_inner().expect("tar");
    if !gzip {
        return tar;
    }
    let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    encoder.write_all(&tar).expect("gzip");
    encoder.finish().expect("gzip")
}

/// `bytes` in a temporary `.inv3` file.
fn file(bytes: &[u8]) -> tempfile::NamedTempFile {
    let mut file = tempfile::Builder::new()
        .suffix(".inv3")
        .tempfile()
        .expect("temporary file");
    file.write_all(bytes).expect("write");
    file
}

/// A 4 x 3 x 2 (x, y, z) int16 grid whose voxel `(i, j, k)` holds `100 k + 10 j + i - 1000`.
fn small_matrix() -> Vec<u8> {
    let mut raw = Vec::new();
    for k in 0..2_i16 {
        for j in 0..3_i16 {
            for i in 0..4_i16 {
                raw.extend_from_slice(&(100 * k + 10 * j + i - 1000).to_le_bytes());
            }
        }
    }
    raw
}

const CT: &str = "<key>modality</key><string>CT</string><key>orientation</key><integer>1</integer>";

fn small_plist() -> String {
    plist([2, 3, 4], "int16", [0.5, 0.75, 1.5], CT)
}

fn read_bytes(bytes: &[u8]) -> Result<Volume, VolumeError> {
    let file = file(bytes);
    read(file.path())
}

fn refusal(bytes: &[u8]) -> String {
    let file = file(bytes);
    let error = read(file.path()).expect_err("refused").0;
    assert!(!error.contains('\n'), "one line: {error}");
    assert!(
        error.starts_with(&file.path().display().to_string()),
        "names the file: {error}"
    );
    error
}

fn check_small(volume: &Volume) {
    assert_eq!(volume.dims(), [4, 3, 2]);
    assert_eq!(volume.units(), Units::Hounsfield);
    for (k, j, i) in [(0, 0, 0), (1, 2, 3), (0, 1, 2), (1, 0, 1)] {
        assert_eq!(
            volume.at(i, j, k),
            (100 * k + 10 * j + i - 1000) as f32,
            "voxel {i} {j} {k}"
        );
    }
    assert_eq!(
        volume.to_world(),
        Mat3::from_diagonal(Vec3::new(-0.5, 0.75, 1.5))
    );
    // The grid is centred on the world origin.
    let centre = volume.world(0.5 * volume.last_index());
    assert!(centre.length() < 1e-6, "{centre}");
}

#[test]
fn a_project_reads_with_its_placement_and_units() {
    let plist = small_plist();
    let matrix = small_matrix();
    let entries: [(&str, &[u8]); 4] = [
        ("tmpabc/main.plist", plist.as_bytes()),
        ("tmpabc/mask_0.dat", &[7; 100]),
        ("tmpabc/matrix.dat", &matrix),
        ("tmpabc/surface_0.vtp", b"<VTKFile/>"),
    ];
    check_small(&read_bytes(&archive(&entries, true)).expect("gzip'd"));
    // Uncompressed, as InVesalius 3.1 writes with compression off.
    check_small(&read_bytes(&archive(&entries, false)).expect("plain tar"));
    // The voxel file before main.plist: a second pass finds it.
    let reversed: Vec<_> = entries.iter().rev().copied().collect();
    check_small(&read_bytes(&archive(&reversed, true)).expect("reversed"));
    // A folder name over tar's 100 bytes: a GNU long-name entry.
    let folder = format!("./{}", "d".repeat(150));
    let (plist_name, matrix_name) = (
        format!("{folder}/main.plist"),
        format!("{folder}/matrix.dat"),
    );
    let long = [
        (plist_name.as_str(), plist.as_bytes()),
        (matrix_name.as_str(), matrix.as_slice()),
    ];
    check_small(&read_bytes(&archive(&long, true)).expect("long names"));
}

#[test]
fn the_units_follow_the_modality_then_the_values() {
    let matrix = small_matrix();
    let project = |extra: &str| {
        let plist = plist([2, 3, 4], "int16", [1.0, 1.0, 1.0], extra);
        read_bytes(&archive(
            &[
                ("p/main.plist", plist.as_bytes()),
                ("p/matrix.dat", &matrix),
            ],
            true,
        ))
        .expect("reads")
        .units()
    };
    assert_eq!(project(CT), Units::Hounsfield);
    assert_eq!(
        project("<key>modality</key><string>MRI</string>"),
        Units::Arbitrary
    );
    // Nothing said: every value here is air (-1000 to -879), so CT by the values.
    assert_eq!(project(""), Units::Hounsfield);
    // Every dtype is read as little-endian values.
    let bytes: Vec<u8> = (0..24_u16).flat_map(|v| v.to_le_bytes()).collect();
    let plist = plist([2, 3, 4], "uint16", [1.0, 1.0, 1.0], "");
    let volume = read_bytes(&archive(
        &[("p/main.plist", plist.as_bytes()), ("p/matrix.dat", &bytes)],
        true,
    ))
    .expect("uint16");
    assert_eq!(
        volume.samples().iter().collect::<Vec<_>>(),
        (0..24).map(|v| v as f32).collect::<Vec<_>>()
    );
    assert_eq!(volume.units(), Units::Arbitrary);
    let bytes: Vec<u8> = (0..24)
        .flat_map(|v| (f64::from(v) * 0.5).to_le_bytes())
        .collect();
    let plist = self::plist([2, 3, 4], "float64", [1.0, 1.0, 1.0], "");
    let volume = read_bytes(&archive(
        &[("p/main.plist", plist.as_bytes()), ("p/matrix.dat", &bytes)],
        false,
    ))
    .expect("float64");
    assert_eq!(volume.at(3, 2, 1), 11.5);
}

#[test]
fn bad_projects_are_refused_in_one_line_naming_the_problem() {
    let matrix = small_matrix();
    let good = small_plist();
    let with = |plist: &str, matrix: &[u8]| {
        archive(
            &[("p/main.plist", plist.as_bytes()), ("p/matrix.dat", matrix)],
            true,
        )
    };
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (archive(&[("p/matrix.dat", &matrix)], true), "no main.plist"),
        (
            archive(
                &[
                    ("p/main.plist", good.as_bytes()),
                    ("q/main.plist", good.as_bytes()),
                ],
                true,
            ),
            "two main.plist files (p/main.plist and q/main.plist)",
        ),
        (
            archive(&[("p/main.plist", good.as_bytes())], true),
            "p/matrix.dat, the voxel file main.plist names, is not in the archive",
        ),
        (
            with(&good, &matrix[..46]),
            "p/matrix.dat holds 46 bytes; main.plist's 4 x 3 x 2 int16 grid needs 48",
        ),
        (
            with(&plist([2, 3, 1], "int16", [1.0; 3], CT), &matrix),
            "every side must be 2 to 4096",
        ),
        (
            with(
                &plist([100_000, 100_000, 100_000], "int16", [1.0; 3], CT),
                &matrix,
            ),
            "every side must be 2 to 4096",
        ),
        (
            with(&plist([2, -3, 4], "int16", [1.0; 3], CT), &matrix),
            "matrix.shape holds -3",
        ),
        (
            // 2^28 voxels of 8 bytes: 2 GiB, over the 512 MiB limit, refused before reading.
            with(&plist([1024, 512, 512], "float64", [1.0; 3], CT), &matrix),
            "take 2147483648 bytes, above the input limit",
        ),
        (
            with(&plist([2, 3, 4], "complex64", [1.0; 3], CT), &matrix),
            "matrix.dtype `complex64`: specula reads int8, uint8, int16",
        ),
        (
            with(&plist([2, 3, 4], "int16", [1.0, 0.0, 1.0], CT), &matrix),
            "every spacing must be positive",
        ),
        (
            with(
                &plist(
                    [2, 3, 4],
                    "int16",
                    [1.0; 3],
                    "<key>orientation</key><string>CORONAL</string>",
                ),
                &matrix,
            ),
            "orientation CORONAL: specula reads axial projects",
        ),
        (
            with(
                &plist(
                    [2, 3, 4],
                    "int16",
                    [1.0; 3],
                    "<key>orientation</key><integer>3</integer>",
                ),
                &matrix,
            ),
            "orientation 3 (sagittal)",
        ),
        (
            with(&good.replace("matrix.dat", "../matrix.dat"), &matrix),
            "is not a file name beside main.plist",
        ),
        (
            with(
                &good.replace("<key>matrix</key>", "<key>matrices</key>"),
                &matrix,
            ),
            "no `matrix` dictionary",
        ),
        (
            with("<plist><array></array></plist>", &matrix),
            "not a dictionary",
        ),
        (
            with("{ not a plist", &matrix),
            "p/main.plist: not a property list",
        ),
        (
            with(&"x".repeat(70_000), &matrix),
            "p/main.plist is 70000 bytes; a project's main.plist is at most 65536",
        ),
        (
            b"just some text, not an archive".to_vec(),
            "damaged or truncated",
        ),
    ];
    for (bytes, expected) in cases {
        let error = refusal(&bytes);
        assert!(error.contains(expected), "{expected:?} not in {error}");
    }
}

/// A deeply nested property list within the size limit is refused or read, never a crash
/// (the plist crate builds and drops values without recursion up to this depth).
#[test]
fn a_deeply_nested_plist_is_no_crash() {
    let depth = (MAX_PLIST_BYTES as usize - 64) / "<array></array>".len();
    let nested = format!(
        "<plist>{}{}</plist>",
        "<array>".repeat(depth),
        "</array>".repeat(depth)
    );
    assert!(nested.len() as u64 <= MAX_PLIST_BYTES);
    let bytes = archive(
        &[
            ("p/main.plist", nested.as_bytes()),
            ("p/matrix.dat", &[0; 8]),
        ],
        true,
    );
    assert!(refusal(&bytes).contains("not a dictionary"));
}

/// Every truncation of a gzip'd project, and many garbled copies of it, is refused in one
/// line (or, for a byte changed where nothing checks it, read); none panics.
#[test]
fn truncated_and_garbled_archives_are_refused_without_a_panic() {
    let plist = small_plist();
    let matrix = small_matrix();
    let entries: [(&str, &[u8]); 3] = [
        ("tmpabc/main.plist", plist.as_bytes()),
        ("tmpabc/matrix.dat", &matrix),
        ("tmpabc/surface_0.vtp", &[1; 700]),
    ];
    for gzip in [true, false] {
        let whole = archive(&entries, gzip);
        let full = read_bytes(&whole).expect("whole");
        let step = if gzip { 1 } else { 97 };
        for cut in (0..whole.len()).step_by(step) {
            match read_bytes(&whole[..cut]) {
                Err(error) => assert!(!error.0.contains('\n'), "{error}"),
                // A tar cut after its last member, before the end-of-archive blocks,
                // still holds the whole project (as Python's tarfile reads it).
                Ok(volume) => {
                    assert!(!gzip, "a gzip stream cut at {cut} was read");
                    assert_eq!(volume, full, "cut at {cut}");
                }
            }
        }
        // Bytes changed at pseudo-random places (a fixed sequence).
        let mut state = 0x2545_f491_u64;
        for _ in 0..400 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let at = (state >> 33) as usize % whole.len();
            let mut garbled = whole.clone();
            garbled[at] ^= 1 << ((state >> 20) % 8);
            if let Err(error) = read_bytes(&garbled) {
                assert!(!error.0.contains('\n'), "{error}");
            }
        }
    }
}

/// A long-name entry declaring more than 64 KiB is refused before it is read, and an
/// archive that inflates past four times the input limit stops there.
#[test]
fn header_entries_and_inflation_are_bounded() {
    let plist = small_plist();
    let matrix = small_matrix();
    let mut tar = Vec::new();
    {
        let mut header = tar::Header::new_gnu();
        header.set_entry_type(tar::EntryType::GNULongName);
        header.set_path("././@LongLink").expect("path");
        header.set_size(1 << 30);
        header.set_mode(0o644);
        header.set_cksum();
        tar.extend_from_slice(header.as_bytes());
        tar.extend_from_slice(&[b'a'; 512]);
    }
    let error = refusal(&tar);
    assert!(
        error.contains("a tar header entry (long name or PAX) of 1073741824 bytes"),
        "{error}"
    );

    let padding = vec![0_u8; 40_000];
    let bytes = archive(
        &[
            ("p/main.plist", plist.as_bytes()),
            ("p/mask_0.dat", &padding),
            ("p/matrix.dat", &matrix),
        ],
        true,
    );
    let file = file(&bytes);
    let error = read_within(file.path(), 8_000).expect_err("capped").0;
    assert!(
        error.contains("the archive inflates to more than 32000 bytes"),
        "{error}"
    );
    assert!(read_within(file.path(), 20_000).is_ok());
}

#[test]
fn inv3_paths_are_recognised() {
    assert!(is_invesalius_path(Path::new("/a/Cranium.inv3")));
    assert!(is_invesalius_path(Path::new("X.INV3")));
    assert!(!is_invesalius_path(Path::new("x.nii.gz")));
    assert!(!is_invesalius_path(Path::new("inv3")));
}
