//! The NIfTI and DICOM readers on files the `nifti` and dicom-rs crates write here, with
//! geometry chosen in the test: every expected position is worked out by hand from the
//! standards' definitions, not by the reader's code.

use std::path::Path;

use dicom_core::{DataElement, PrimitiveValue, VR};
use dicom_dictionary_std::{tags, uids};
use dicom_object::{FileMetaTableBuilder, InMemDicomObject};
use glam::{Mat3, Vec3};
use nifti::NiftiHeader;
use specula_volume::{self as volume, Units, Volume};

/// A value that differs at every voxel of a small grid.
fn value(i: usize, j: usize, k: usize) -> f32 {
    (i + 10 * j + 100 * k) as f32
}

fn grid(dims: [usize; 3]) -> ndarray::Array3<f32> {
    ndarray::Array3::from_shape_fn((dims[0], dims[1], dims[2]), |(i, j, k)| value(i, j, k))
}

fn write_nifti(path: &Path, header: &NiftiHeader, dims: [usize; 3]) {
    nifti::writer::WriterOptions::new(path)
        .reference_header(header)
        .write_nifti(&grid(dims))
        .expect("nifti writes");
}

fn assert_near(a: Vec3, b: Vec3, what: &str) {
    assert!((a - b).length() < 1e-3, "{what}: {a} != {b}");
}

fn assert_values(volume: &Volume, dims: [usize; 3], scale: f32, offset: f32) {
    assert_eq!(volume.dims(), dims);
    for (i, j, k) in [
        (0, 0, 0),
        (3, 1, 2),
        (dims[0] - 1, dims[1] - 1, dims[2] - 1),
    ] {
        let got = volume.at(i as isize, j as isize, k as isize);
        let expected = value(i, j, k) * scale + offset;
        assert!(
            (got - expected).abs() < 1e-3,
            "({i},{j},{k}): {got} != {expected}"
        );
    }
}

#[test]
fn nifti_qform_places_voxels_by_its_quaternion_and_handedness() {
    let directory = tempfile::tempdir().unwrap();
    let dims = [5, 4, 3];
    // A quarter turn about z (a = cos 45, d = sin 45), spacing 2, 3, 4 mm and qfac -1: the
    // third axis points down.
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let header = NiftiHeader {
        pixdim: [-1.0, 2.0, 3.0, 4.0, 1.0, 1.0, 1.0, 1.0],
        qform_code: 1,
        sform_code: 0,
        quatern_b: 0.0,
        quatern_c: 0.0,
        quatern_d: half,
        quatern_x: 10.0,
        quatern_y: 20.0,
        quatern_z: 30.0,
        xyzt_units: 2,
        ..NiftiHeader::default()
    };
    for name in ["q.nii", "q.nii.gz"] {
        let path = directory.path().join(name);
        write_nifti(&path, &header, dims);
        let volume = volume::read(&path).unwrap();
        assert_values(&volume, dims, 1.0, 0.0);
        assert_eq!(volume.units(), Units::Arbitrary);
        let offset = Vec3::new(10.0, 20.0, 30.0);
        assert_near(volume.world(Vec3::ZERO), offset, "origin");
        // i steps 2 mm along x, turned to +y; j steps 3 mm along y, turned to -x; k steps 4 mm
        // along -z.
        assert_near(
            volume.world(Vec3::X),
            offset + Vec3::new(0.0, 2.0, 0.0),
            "i",
        );
        assert_near(
            volume.world(Vec3::Y),
            offset + Vec3::new(-3.0, 0.0, 0.0),
            "j",
        );
        assert_near(
            volume.world(Vec3::Z),
            offset + Vec3::new(0.0, 0.0, -4.0),
            "k",
        );
    }
}

#[test]
fn nifti_sform_wins_and_units_and_scaling_apply() {
    let directory = tempfile::tempdir().unwrap();
    let dims = [4, 4, 4];
    let header = NiftiHeader {
        pixdim: [1.0, 9.0, 9.0, 9.0, 1.0, 1.0, 1.0, 1.0],
        qform_code: 1,
        sform_code: 1,
        srow_x: [0.0, 0.0, 0.002, -0.1],
        srow_y: [0.001, 0.0005, 0.0, 0.05],
        srow_z: [0.0, 0.0015, 0.0, 0.2],
        // Metres.
        xyzt_units: 1,
        ..NiftiHeader::default()
    };
    let path = directory.path().join("s.nii");
    write_nifti(&path, &header, dims);
    // scl_slope and scl_inter sit at bytes 112 and 116 of a NIfTI-1 header.
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[112..116].copy_from_slice(&0.5_f32.to_le_bytes());
    bytes[116..120].copy_from_slice(&(-7.0_f32).to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let volume = volume::read(&path).unwrap();
    assert_values(&volume, dims, 0.5, -7.0);
    let at = |i: f32, j: f32, k: f32| {
        Vec3::new(
            (0.002 * k - 0.1) * 1000.0,
            (0.001 * i + 0.0005 * j + 0.05) * 1000.0,
            (0.0015 * j + 0.2) * 1000.0,
        )
    };
    for index in [
        Vec3::ZERO,
        Vec3::new(3.0, 1.0, 2.0),
        Vec3::new(1.0, 3.0, 0.0),
    ] {
        assert_near(volume.world(index), at(index.x, index.y, index.z), "sform");
    }
}

#[test]
fn nifti_bad_headers_are_refused_before_the_voxels_are_read() {
    let directory = tempfile::tempdir().unwrap();
    let good = directory.path().join("good.nii");
    let header = NiftiHeader {
        pixdim: [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
        sform_code: 0,
        ..NiftiHeader::default()
    };
    write_nifti(&good, &header, [4, 4, 4]);
    let bytes = std::fs::read(&good).unwrap();
    let refused = |name: &str, edit: &dyn Fn(&mut Vec<u8>)| {
        let mut edited = bytes.clone();
        edit(&mut edited);
        let path = directory.path().join(name);
        std::fs::write(&path, &edited).unwrap();
        volume::read(&path).unwrap_err().to_string()
    };
    // dim[] is eight i16 from byte 40: a 32767^3 grid.
    let message = refused("huge.nii", &|b| {
        for axis in 1..=3 {
            b[40 + 2 * axis..42 + 2 * axis].copy_from_slice(&32767_i16.to_le_bytes());
        }
    });
    assert!(
        message.contains("every side must be 2 to 4096"),
        "{message}"
    );
    let message = refused("truncated.nii", &|b| b.truncate(b.len() - 10));
    assert!(message.contains("truncated"), "{message}");
    let message = refused("series.nii", &|b| {
        b[40..42].copy_from_slice(&4_i16.to_le_bytes());
        b[48..50].copy_from_slice(&3_i16.to_le_bytes());
    });
    assert!(message.contains("3 volumes"), "{message}");
    // pixdim[] is eight f32 from byte 76, and the header has no sform.
    let message = refused("flat.nii", &|b| {
        b[80..84].copy_from_slice(&0_f32.to_le_bytes())
    });
    assert!(message.contains("no voxel spacing"), "{message}");
    let message = refused("garbage.nii", &|b| b[..348].fill(0x5a));
    assert!(message.contains("not a NIfTI-1 header"), "{message}");
    let message = volume::read(&directory.path().join("mri.img")).unwrap_err();
    assert!(message.0.contains(".nii or .nii.gz"), "{message}");
    #[cfg(unix)]
    {
        let link = directory.path().join("zero.nii");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        let message = volume::read(&link).unwrap_err();
        assert!(message.0.contains("a device"), "{message}");
    }
}

/// One CT slice as a scanner writes it, with the fields the test wants.
struct SliceSpec<'a> {
    series: &'a str,
    position: [f64; 3],
    orientation: [f64; 6],
    pixel_spacing: Option<[f64; 2]>,
    rows: u16,
    columns: u16,
    pixels: Vec<i16>,
}

fn write_slice(path: &Path, spec: &SliceSpec, instance: usize) {
    let join = |values: &[f64]| {
        values
            .iter()
            .map(f64::to_string)
            .collect::<Vec<_>>()
            .join("\\")
    };
    let mut elements = vec![
        DataElement::new(
            tags::SOP_CLASS_UID,
            VR::UI,
            PrimitiveValue::from(uids::CT_IMAGE_STORAGE),
        ),
        DataElement::new(
            tags::SOP_INSTANCE_UID,
            VR::UI,
            PrimitiveValue::from(format!("{}.{instance}", spec.series)),
        ),
        DataElement::new(
            tags::SERIES_INSTANCE_UID,
            VR::UI,
            PrimitiveValue::from(spec.series),
        ),
        DataElement::new(tags::MODALITY, VR::CS, PrimitiveValue::from("CT")),
        DataElement::new(
            tags::IMAGE_POSITION_PATIENT,
            VR::DS,
            PrimitiveValue::from(join(&spec.position)),
        ),
        DataElement::new(
            tags::IMAGE_ORIENTATION_PATIENT,
            VR::DS,
            PrimitiveValue::from(join(&spec.orientation)),
        ),
        DataElement::new(tags::SAMPLES_PER_PIXEL, VR::US, PrimitiveValue::from(1_u16)),
        DataElement::new(
            tags::PHOTOMETRIC_INTERPRETATION,
            VR::CS,
            PrimitiveValue::from("MONOCHROME2"),
        ),
        DataElement::new(tags::ROWS, VR::US, PrimitiveValue::from(spec.rows)),
        DataElement::new(tags::COLUMNS, VR::US, PrimitiveValue::from(spec.columns)),
        DataElement::new(tags::BITS_ALLOCATED, VR::US, PrimitiveValue::from(16_u16)),
        DataElement::new(tags::BITS_STORED, VR::US, PrimitiveValue::from(16_u16)),
        DataElement::new(tags::HIGH_BIT, VR::US, PrimitiveValue::from(15_u16)),
        DataElement::new(
            tags::PIXEL_REPRESENTATION,
            VR::US,
            PrimitiveValue::from(1_u16),
        ),
        DataElement::new(tags::RESCALE_SLOPE, VR::DS, PrimitiveValue::from("2")),
        DataElement::new(
            tags::RESCALE_INTERCEPT,
            VR::DS,
            PrimitiveValue::from("-1024"),
        ),
        DataElement::new(
            tags::PIXEL_DATA,
            VR::OW,
            PrimitiveValue::U16(spec.pixels.iter().map(|&p| p as u16).collect()),
        ),
    ];
    if let Some(spacing) = spec.pixel_spacing {
        elements.push(DataElement::new(
            tags::PIXEL_SPACING,
            VR::DS,
            PrimitiveValue::from(join(&spacing)),
        ));
    }
    InMemDicomObject::from_element_iter(elements)
        .with_meta(FileMetaTableBuilder::new().transfer_syntax(uids::EXPLICIT_VR_LITTLE_ENDIAN))
        .unwrap()
        .write_to_file(path)
        .unwrap();
}

const ROWS: u16 = 6;
const COLUMNS: u16 = 5;
const SLICES: usize = 4;
/// Rows run along (cos 30, sin 30, 0), columns along -z: a tilted coronal series, in LPS.
const ORIENTATION: [f64; 6] = [0.866_025_403_784_438_6, 0.5, 0.0, 0.0, 0.0, -1.0];

/// The slice normal (row x column) is (-sin 30, cos 30, 0); slices 1.25 mm apart along it.
fn slice_position(k: usize) -> [f64; 3] {
    let step = 1.25 * k as f64;
    [
        3.0 - 0.5 * step,
        -40.0 + 0.866_025_403_784_438_6 * step,
        12.0,
    ]
}

fn stored(i: usize, j: usize, k: usize) -> i16 {
    (i + 10 * j + 100 * k) as i16
}

fn slice_spec(series: &str, k: usize) -> SliceSpec<'_> {
    let mut pixels = Vec::new();
    for j in 0..usize::from(ROWS) {
        for i in 0..usize::from(COLUMNS) {
            pixels.push(stored(i, j, k));
        }
    }
    SliceSpec {
        series,
        position: slice_position(k),
        orientation: ORIENTATION,
        pixel_spacing: Some([0.7, 0.5]),
        rows: ROWS,
        columns: COLUMNS,
        pixels,
    }
}

/// Writes the series with file names in an order unrelated to position.
fn write_series(directory: &Path, edit: &dyn Fn(usize, &mut SliceSpec)) {
    for k in 0..SLICES {
        let mut spec = slice_spec("1.2.3.4", k);
        edit(k, &mut spec);
        write_slice(
            &directory.join(format!("IM{}", (k * 3 + 1) % SLICES)),
            &spec,
            k,
        );
    }
}

#[test]
fn a_dicom_series_is_sorted_rescaled_and_placed_in_ras() {
    let directory = tempfile::tempdir().unwrap();
    write_series(directory.path(), &|_, _| {});
    std::fs::write(directory.path().join("README.txt"), "not a slice").unwrap();
    let volume = volume::read(directory.path()).unwrap();
    assert_eq!(volume.dims(), [5, 6, 4]);
    assert_eq!(volume.units(), Units::Hounsfield);
    for (i, j, k) in [(0, 0, 0), (4, 2, 1), (1, 5, 3)] {
        let expected = f32::from(stored(i, j, k)) * 2.0 - 1024.0;
        assert_eq!(volume.at(i as isize, j as isize, k as isize), expected);
        // LPS: the slice's position, plus i column spacings (0.5 mm) along the row direction
        // and j row spacings (0.7 mm) along the column direction; RAS flips x and y.
        let [x, y, z] = slice_position(k);
        let lps = Vec3::new(x as f32, y as f32, z as f32)
            + 0.5 * i as f32 * Vec3::new(0.866_025_4, 0.5, 0.0)
            + 0.7 * j as f32 * Vec3::new(0.0, 0.0, -1.0);
        let ras = lps * Vec3::new(-1.0, -1.0, 1.0);
        assert_near(
            volume.world(Vec3::new(i as f32, j as f32, k as f32)),
            ras,
            "voxel",
        );
    }
    let spacing = volume.spacing();
    assert_near(spacing, Vec3::new(0.5, 0.7, 1.25), "spacing");
}

#[test]
fn dicom_series_that_cannot_be_stacked_are_refused_with_the_reason() {
    let refused = |edit: &dyn Fn(usize, &mut SliceSpec)| {
        let directory = tempfile::tempdir().unwrap();
        write_series(directory.path(), edit);
        volume::read(directory.path()).unwrap_err().0
    };
    let message = refused(&|k, spec| {
        if k == 2 {
            spec.series = "1.2.3.5";
        }
    });
    assert!(
        message.contains("mixed series: 2 Series Instance UIDs"),
        "{message}"
    );
    let message = refused(&|k, spec| {
        if k == 1 {
            spec.pixel_spacing = None;
        }
    });
    assert!(message.contains("no Pixel Spacing"), "{message}");
    let message = refused(&|k, spec| {
        if k == 3 {
            spec.position = slice_position(5);
        }
    });
    assert!(message.contains("uneven slice spacing"), "{message}");
    let message = refused(&|k, spec| {
        if k == 3 {
            spec.position = slice_position(2);
        }
    });
    assert!(message.contains("share one position"), "{message}");
    // Seventeen slices of 4096 x 4096 declared, each with a few pixels: the grid check
    // refuses the series before any pixel is decoded.
    let directory = tempfile::tempdir().unwrap();
    for k in 0..17 {
        let mut spec = slice_spec("1.2.3.4", k);
        spec.position = slice_position(k);
        spec.rows = 4096;
        spec.columns = 4096;
        write_slice(&directory.path().join(format!("big{k}")), &spec, k);
    }
    let message = volume::read(directory.path()).unwrap_err().0;
    assert!(message.contains("over the limit"), "{message}");
    let message = refused(&|k, spec| {
        if k == 0 {
            spec.pixels.truncate(7);
        }
    });
    assert!(message.contains("pixel"), "{message}");
    let empty = tempfile::tempdir().unwrap();
    let message = volume::read(empty.path()).unwrap_err().0;
    assert!(message.contains("no DICOM files"), "{message}");
}

#[test]
fn volumes_written_as_nifti_and_dicom_read_back_in_place() {
    let directory = tempfile::tempdir().unwrap();
    let dims = [6, 5, 4];
    let mut samples = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                samples.push(value(i, j, k) - 300.0);
            }
        }
    }
    // Perpendicular rows and columns (as DICOM needs), slices sheared as by a gantry tilt.
    let to_world = Mat3::from_cols(
        Vec3::new(0.0, 0.8, 0.0),
        Vec3::new(-0.6, 0.0, 0.0),
        Vec3::new(0.3, 0.0, 2.0),
    );
    let origin = Vec3::new(-12.0, 7.5, 40.0);
    for units in [Units::Hounsfield, Units::Arbitrary] {
        let original = Volume::try_new(dims, to_world, origin, samples.clone(), units).unwrap();
        for name in ["v.nii", "v.nii.gz", "series"] {
            let path = directory.path().join(format!("{units:?}-{name}"));
            volume::write(&original, &path).unwrap();
            let read = volume::read(&path).unwrap();
            assert_eq!(read.dims(), dims);
            for corner in 0..8 {
                assert_near(read.corners()[corner], original.corners()[corner], name);
            }
            let (lo, hi) = original.range();
            let worst = read
                .samples()
                .iter()
                .zip(original.samples().iter())
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f32::max);
            // 16-bit DICOM keeps a 65000th of the range; NIfTI keeps f32 exactly.
            assert!(worst <= (hi - lo) / 65_000.0 + 1e-3, "{name}: {worst}");
        }
        // The written headers say, in DICOM's LPS, what the grid says in RAS (x and y flip):
        // rows step along RAS (0, 0.8, 0), columns along (-0.6, 0, 0), slices by (0.3, 0, 2).
        let series = directory.path().join(format!("{units:?}-series"));
        for (file, position) in [
            ("slice-0001.dcm", [12.0, -7.5, 40.0]),
            ("slice-0002.dcm", [11.7, -7.5, 42.0]),
        ] {
            let header = dicom_object::open_file(series.join(file)).unwrap();
            let numbers = |tag| header.element(tag).unwrap().to_multi_float64().unwrap();
            let close = |a: Vec<f64>, b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-4);
            assert!(
                close(numbers(tags::IMAGE_POSITION_PATIENT), &position),
                "{file}"
            );
            assert!(close(
                numbers(tags::IMAGE_ORIENTATION_PATIENT),
                &[0.0, -1.0, 0.0, 1.0, 0.0, 0.0]
            ));
            assert!(close(numbers(tags::PIXEL_SPACING), &[0.6, 0.8]));
        }
        let again = volume::write(&original, &series);
        assert!(again.unwrap_err().0.contains("not an empty folder"));
    }
}

/// NIfTI keeps a scan's whole numbers as 16-bit integers (as scanners store a CT, and as a
/// reader such as VTK then takes it) and anything else as 32-bit floats, both exactly.
#[test]
fn nifti_voxels_are_int16_when_every_sample_is_a_whole_i16() {
    use nifti::NiftiObject;
    let directory = tempfile::tempdir().unwrap();
    let dims = [4, 3, 2];
    let count = dims[0] * dims[1] * dims[2];
    let whole: Vec<f32> = (0..count).map(|v| v as f32 * 100.0 - 1024.0).collect();
    let cases = [
        ("whole", whole.clone(), 4),
        ("fraction", whole.iter().map(|v| v + 0.5).collect(), 16),
        (
            "beyond i16",
            whole.iter().map(|v| v + 40_000.0).collect(),
            16,
        ),
    ];
    for (name, samples, datatype) in cases {
        let original =
            Volume::try_new(dims, Mat3::IDENTITY, Vec3::ZERO, samples, Units::Hounsfield).unwrap();
        let path = directory.path().join(format!("{name}.nii"));
        volume::write(&original, &path).unwrap();
        let header = nifti::ReaderOptions::new().read_file(&path).unwrap();
        assert_eq!(header.header().datatype, datatype, "{name}");
        assert_eq!(
            volume::read(&path).unwrap().samples(),
            original.samples(),
            "{name}"
        );
    }
}
