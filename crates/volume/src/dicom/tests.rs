//! Multi-frame objects and series built here with dicom-rs, with geometry chosen in the test:
//! every expected position is worked out from DICOM's definitions, not by the reader's code.

use std::path::Path;

use dicom_core::value::DataSetSequence;
use dicom_core::{DataElement, Length, PrimitiveValue, Tag, VR};
use dicom_dictionary_std::{tags, uids};
use dicom_object::mem::InMemElement;
use dicom_object::{FileMetaTableBuilder, InMemDicomObject};

use super::*;

const ROWS: usize = 4;
const COLUMNS: usize = 3;
/// Rows run along (cos 30, sin 30, 0), columns along -z (LPS): a tilted coronal stack whose
/// normal (row x column) is (-sin 30, cos 30, 0).
const ORIENTATION: [f64; 6] = [0.866_025_403_784_438_6, 0.5, 0.0, 0.0, 0.0, -1.0];
const NORMAL: [f64; 3] = [-0.5, 0.866_025_403_784_438_6, 0.0];
/// Between rows, then between columns.
const SPACING: [f64; 2] = [0.7, 0.5];

/// The position (LPS) of a frame `depth` millimetres along the normal.
fn at_depth(depth: f64) -> [f64; 3] {
    [
        3.0 + NORMAL[0] * depth,
        -40.0 + NORMAL[1] * depth,
        12.0 + NORMAL[2] * depth,
    ]
}

/// The stored value of pixel `(i, j)` of the file's frame `f`.
fn stored(i: usize, j: usize, f: usize) -> u16 {
    (i + 10 * j + 100 * f) as u16
}

/// A rescale as a Pixel Value Transformation says it: slope, intercept, type.
type Transform = (f64, f64, &'static str);

/// A multi-frame object to write.
struct Enhanced {
    modality: &'static str,
    /// Each frame's Plane Position (`None`: the frame has none).
    positions: Vec<Option<[f64; 3]>>,
    /// Each frame's own Pixel Value Transformation, over the shared one.
    transforms: Vec<Option<Transform>>,
    shared_transform: Option<Transform>,
    /// Each frame's own Pixel Spacing, over the shared one.
    spacings: Vec<Option<[f64; 2]>>,
    spacing_between_slices: Option<f64>,
    /// Whether the functional group sequences are written at all.
    groups: bool,
    rows: usize,
    columns: usize,
    /// Pixels left out of the end of the pixel data.
    short_by: usize,
}

impl Enhanced {
    /// `frames` frames `gap` millimetres apart, in the file's order, CT rescaled to HU.
    fn new(depths: &[f64]) -> Self {
        Self {
            modality: "CT",
            positions: depths.iter().map(|&d| Some(at_depth(d))).collect(),
            transforms: vec![None; depths.len()],
            shared_transform: Some((1.0, -1024.0, "HU")),
            spacings: vec![None; depths.len()],
            spacing_between_slices: None,
            groups: true,
            rows: ROWS,
            columns: COLUMNS,
            short_by: 0,
        }
    }

    fn write(&self, path: &Path) {
        let frames = self.positions.len();
        let numbers = |values: &[f64]| {
            values
                .iter()
                .map(f64::to_string)
                .collect::<Vec<_>>()
                .join("\\")
        };
        let ds = |tag, values: &[f64]| element(tag, VR::DS, numbers(values).into());
        let transform = |(slope, intercept, kind): Transform| {
            item(vec![
                ds(tags::RESCALE_SLOPE, &[slope]),
                ds(tags::RESCALE_INTERCEPT, &[intercept]),
                element(tags::RESCALE_TYPE, VR::LO, kind.into()),
            ])
        };
        let mut shared = vec![
            sequence(
                tags::PLANE_ORIENTATION_SEQUENCE,
                item(vec![ds(tags::IMAGE_ORIENTATION_PATIENT, &ORIENTATION)]),
            ),
            sequence(
                tags::PIXEL_MEASURES_SEQUENCE,
                item(
                    [ds(tags::PIXEL_SPACING, &SPACING)]
                        .into_iter()
                        .chain(
                            self.spacing_between_slices
                                .map(|s| ds(tags::SPACING_BETWEEN_SLICES, &[s])),
                        )
                        .collect(),
                ),
            ),
        ];
        if let Some(shared_transform) = self.shared_transform {
            shared.push(sequence(
                tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE,
                transform(shared_transform),
            ));
        }
        let per_frame: Vec<InMemDicomObject> = (0..frames)
            .map(|f| {
                let mut groups = Vec::new();
                if let Some(position) = self.positions[f] {
                    groups.push(sequence(
                        tags::PLANE_POSITION_SEQUENCE,
                        item(vec![ds(tags::IMAGE_POSITION_PATIENT, &position)]),
                    ));
                }
                if let Some(spacing) = self.spacings[f] {
                    groups.push(sequence(
                        tags::PIXEL_MEASURES_SEQUENCE,
                        item(vec![ds(tags::PIXEL_SPACING, &spacing)]),
                    ));
                }
                if let Some(own) = self.transforms[f] {
                    groups.push(sequence(
                        tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE,
                        transform(own),
                    ));
                }
                item(groups)
            })
            .collect();
        let mut pixels = Vec::new();
        for f in 0..frames {
            for j in 0..self.rows {
                for i in 0..self.columns {
                    pixels.push(stored(i, j, f));
                }
            }
        }
        pixels.truncate(pixels.len() - self.short_by);
        let short = |v: usize| PrimitiveValue::from(v as u16);
        let mut elements = vec![
            element(
                tags::SOP_CLASS_UID,
                VR::UI,
                uids::ENHANCED_CT_IMAGE_STORAGE.into(),
            ),
            element(tags::SOP_INSTANCE_UID, VR::UI, "1.2.3.4.5".into()),
            element(tags::MODALITY, VR::CS, self.modality.into()),
            element(tags::NUMBER_OF_FRAMES, VR::IS, frames.to_string().into()),
            element(tags::SAMPLES_PER_PIXEL, VR::US, short(1)),
            element(
                tags::PHOTOMETRIC_INTERPRETATION,
                VR::CS,
                "MONOCHROME2".into(),
            ),
            element(tags::ROWS, VR::US, short(self.rows)),
            element(tags::COLUMNS, VR::US, short(self.columns)),
            element(tags::BITS_ALLOCATED, VR::US, short(16)),
            element(tags::BITS_STORED, VR::US, short(16)),
            element(tags::HIGH_BIT, VR::US, short(15)),
            element(tags::PIXEL_REPRESENTATION, VR::US, short(0)),
            element(tags::PIXEL_DATA, VR::OW, PrimitiveValue::U16(pixels.into())),
        ];
        if self.groups {
            elements.push(DataElement::new(
                tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE,
                VR::SQ,
                DataSetSequence::new(vec![item(shared)], Length::UNDEFINED),
            ));
            elements.push(DataElement::new(
                tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE,
                VR::SQ,
                DataSetSequence::new(per_frame, Length::UNDEFINED),
            ));
        }
        InMemDicomObject::from_element_iter(elements)
            .with_meta(FileMetaTableBuilder::new().transfer_syntax(uids::EXPLICIT_VR_LITTLE_ENDIAN))
            .unwrap()
            .write_to_file(path)
            .unwrap();
    }

    /// Writes the object to a new folder's `enhanced.dcm` and reads it through
    /// [`crate::files::read`], as the command line does.
    fn read(&self) -> Result<Volume, String> {
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("enhanced.dcm");
        self.write(&path);
        crate::files::read(&path).map_err(|e| {
            assert!(e.0.starts_with(&path.display().to_string()), "{e}");
            assert_eq!(e.0.lines().count(), 1, "{e}");
            e.0
        })
    }
}

fn element(tag: Tag, vr: VR, value: PrimitiveValue) -> InMemElement {
    DataElement::new(tag, vr, value)
}

fn item(elements: Vec<InMemElement>) -> InMemDicomObject {
    InMemDicomObject::from_element_iter(elements)
}

fn sequence(tag: Tag, only: InMemDicomObject) -> InMemElement {
    DataElement::new(
        tag,
        VR::SQ,
        DataSetSequence::new(vec![only], Length::UNDEFINED),
    )
}

/// The RAS position of pixel `(i, j)` of a frame at `position` (LPS): `i` column spacings
/// along the row direction, `j` row spacings along the column direction, then `x` and `y`
/// negated.
fn ras(position: [f64; 3], i: usize, j: usize) -> Vec3 {
    let lps: [f64; 3] = core::array::from_fn(|a| {
        position[a]
            + i as f64 * SPACING[1] * ORIENTATION[a]
            + j as f64 * SPACING[0] * ORIENTATION[3 + a]
    });
    Vec3::new(-lps[0] as f32, -lps[1] as f32, lps[2] as f32)
}

fn assert_near(a: Vec3, b: Vec3, what: &str) {
    assert!((a - b).length() < 1e-4, "{what}: {a} != {b}");
}

#[test]
fn three_frames_are_placed_in_ras_by_their_functional_groups() {
    let volume = Enhanced::new(&[0.0, 2.5, 5.0]).read().unwrap();
    assert_eq!(volume.dims(), [COLUMNS, ROWS, 3]);
    assert_eq!(volume.units(), Units::Hounsfield);
    for (i, j, k) in [(0, 0, 0), (2, 1, 1), (1, 3, 2), (2, 3, 2)] {
        let world = volume.world(Vec3::new(i as f32, j as f32, k as f32));
        assert_near(world, ras(at_depth(2.5 * k as f64), i, j), "voxel");
        let expected = f32::from(stored(i, j, k)) - 1024.0;
        assert_eq!(volume.at(i as isize, j as isize, k as isize), expected);
    }
    assert_near(volume.spacing(), Vec3::new(0.5, 0.7, 2.5), "spacing");
    // Spacing Between Slices that agrees with the positions is accepted.
    let mut agreeing = Enhanced::new(&[0.0, 2.5, 5.0]);
    agreeing.spacing_between_slices = Some(2.5);
    assert!(agreeing.read().is_ok());
}

#[test]
fn frames_given_out_of_order_are_sorted_along_the_normal() {
    // The file holds the frames at depths 5, 0 and 2.5: slice k = 0 is the file's frame 2.
    let volume = Enhanced::new(&[5.0, 0.0, 2.5]).read().unwrap();
    for (k, frame, depth) in [(0, 1, 0.0), (1, 2, 2.5), (2, 0, 5.0)] {
        assert_near(
            volume.world(Vec3::new(1.0, 2.0, k as f32)),
            ras(at_depth(depth), 1, 2),
            "voxel",
        );
        assert_eq!(
            volume.at(1, 2, k as isize),
            f32::from(stored(1, 2, frame)) - 1024.0,
            "slice {k}"
        );
    }
}

#[test]
fn each_frame_is_rescaled_by_its_own_pixel_value_transformation() {
    let mut spec = Enhanced::new(&[0.0, 1.0, 2.0]);
    spec.modality = "MR";
    spec.shared_transform = Some((1.0, 0.0, "US"));
    spec.transforms = vec![Some((2.0, -10.0, "US")), None, Some((0.5, 7.0, "US"))];
    let volume = spec.read().unwrap();
    assert_eq!(volume.units(), Units::Arbitrary);
    for (k, slope, intercept) in [(0, 2.0, -10.0), (1, 1.0, 0.0), (2, 0.5, 7.0)] {
        let expected = f32::from(stored(2, 3, k)) * slope + intercept;
        assert_eq!(volume.at(2, 3, k as isize), expected, "frame {k}");
    }
    // A Rescale Type of HU in any frame's transformation says Hounsfield units.
    spec.transforms[1] = Some((1.0, -1024.0, "HU"));
    assert_eq!(spec.read().unwrap().units(), Units::Hounsfield);
}

#[test]
fn multi_frame_objects_without_per_frame_geometry_are_refused_in_one_line() {
    let mut spec = Enhanced::new(&[0.0, 1.0, 2.0]);
    spec.groups = false;
    let message = spec.read().unwrap_err();
    assert!(
        message.contains("3 frames without per-frame geometry")
            && message.contains("Plane Position Sequence (0020,9113)"),
        "{message}"
    );
    let mut spec = Enhanced::new(&[0.0, 1.0, 2.0]);
    spec.positions[1] = None;
    let message = spec.read().unwrap_err();
    assert!(
        message.contains("frame 2 lacks per-frame geometry: no Plane Position Sequence"),
        "{message}"
    );
    // One frame is one slice: its folder is the volume.
    let mut spec = Enhanced::new(&[0.0]);
    spec.positions = vec![Some(at_depth(0.0))];
    let message = spec.read().unwrap_err();
    assert!(message.contains("a single-frame DICOM image"), "{message}");
}

#[test]
fn unevenly_spaced_or_inconsistent_frames_are_refused_before_decoding() {
    let message = Enhanced::new(&[0.0, 1.0, 3.0, 4.0]).read().unwrap_err();
    assert!(
        message.contains(
            "uneven slice spacing: a slice seems missing between positions (2.5, \
            -39.134, 12) of frame 2 and (1.5, -37.402, 12) of frame 3"
        ) && message.contains("2.000 mm apart where the others are 1.000 mm"),
        "{message}"
    );
    let message = Enhanced::new(&[0.0, 1.0, 2.7, 4.0]).read().unwrap_err();
    assert!(
        message.contains("uneven slice spacing (1.000 to 1.700 mm"),
        "{message}"
    );
    let message = Enhanced::new(&[0.0, 1.0, 1.0]).read().unwrap_err();
    assert!(
        message.contains("frame 2 and frame 3 share one position"),
        "{message}"
    );
    let mut spec = Enhanced::new(&[0.0, 1.0, 2.0]);
    spec.spacings[2] = Some([0.7, 0.6]);
    let message = spec.read().unwrap_err();
    assert!(
        message.contains("frame 3 has Pixel Spacing 0.7\\0.6 mm where frame 1 has 0.7\\0.5 mm"),
        "{message}"
    );
    let mut spec = Enhanced::new(&[0.0, 1.0, 2.0]);
    spec.spacing_between_slices = Some(1.5);
    let message = spec.read().unwrap_err();
    assert!(
        message.contains("Spacing Between Slices says 1.5 mm"),
        "{message}"
    );
    // 17 frames of 4096 x 4096 declared with a few pixels: the grid is refused first.
    let mut spec = Enhanced::new(&(0..17).map(f64::from).collect::<Vec<_>>());
    spec.rows = 4096;
    spec.columns = 4096;
    spec.short_by = 17 * 4096 * 4096 - 10;
    let message = spec.read().unwrap_err();
    assert!(message.contains("over the limit"), "{message}");
    let mut spec = Enhanced::new(&[0.0, 1.0, 2.0]);
    spec.short_by = 5;
    let message = spec.read().unwrap_err();
    assert!(message.contains("pixel data"), "{message}");
}

/// A 4 x 3 x 6 CT volume written as a series by [`write_series`], in `dir/series`.
fn series(dir: &Path) -> std::path::PathBuf {
    let samples = (0..72).map(|v| v as f32).collect();
    let volume = Volume::centred(
        [4, 3, 6],
        Vec3::new(0.5, 0.5, 2.0),
        samples,
        Units::Hounsfield,
    )
    .unwrap();
    let path = dir.join("series");
    write_series(&volume, &path).unwrap();
    path
}

#[test]
fn a_series_missing_a_slice_names_the_gap_and_its_neighbours() {
    let directory = tempfile::tempdir().unwrap();
    let path = series(directory.path());
    std::fs::remove_file(path.join("slice-0004.dcm")).unwrap();
    let message = crate::files::read(&path).unwrap_err().0;
    assert!(
        message.contains("a slice seems missing between")
            && message.contains("slice-0003.dcm and (")
            && message.contains("slice-0005.dcm (Image Position (Patient), mm)")
            && message.contains("4.000 mm apart where the others are 2.000 mm"),
        "{message}"
    );
    assert_eq!(message.lines().count(), 1);
}

#[test]
fn a_series_with_inconsistent_pixel_spacing_names_both_files() {
    let directory = tempfile::tempdir().unwrap();
    let path = series(directory.path());
    let file = path.join("slice-0003.dcm");
    let mut object = dicom_object::open_file(&file).unwrap();
    object.put(element(tags::PIXEL_SPACING, VR::DS, "0.5\\0.6".into()));
    object.write_to_file(&file).unwrap();
    let message = crate::files::read(&path).unwrap_err().0;
    assert!(
        message.contains("slice-0003.dcm has Pixel Spacing 0.5\\0.6 mm where")
            && message.contains("slice-0001.dcm has 0.5\\0.5 mm"),
        "{message}"
    );
    // One slice alone is not a volume; the message points at its folder.
    let message = crate::files::read(&file).unwrap_err().0;
    assert!(message.contains("a single-frame DICOM image"), "{message}");
}

#[test]
fn a_multi_frame_object_in_a_series_folder_is_refused_with_where_to_pass_it() {
    let directory = tempfile::tempdir().unwrap();
    let path = series(directory.path());
    let enhanced = path.join("enhanced.dcm");
    Enhanced::new(&[0.0, 1.0, 2.0]).write(&enhanced);
    let message = crate::files::read(&path).unwrap_err().0;
    assert!(
        message.contains("a multi-frame object (3 frames) in a series folder")
            && message.contains(&format!(
                "pass the file itself (--input {})",
                enhanced.display()
            )),
        "{message}"
    );
    // A file without `.dcm` is still read as DICOM by its preamble.
    let renamed = directory.path().join("IM0001");
    std::fs::rename(&enhanced, &renamed).unwrap();
    assert!(is_dicom_file(&renamed));
    assert_eq!(
        crate::files::read(&renamed).unwrap().dims(),
        [COLUMNS, ROWS, 3]
    );
}
