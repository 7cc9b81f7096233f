//! A volume's file, read or written by what its path names.

use std::path::Path;

use crate::volume::{Volume, VolumeError};
use crate::{dicom, invesalius, nifti};

/// Reads the volume at `path`: a folder is a DICOM series, a `.nii` or `.nii.gz` file is
/// NIfTI-1, an `.inv3` file an InVesalius 3 project ([`invesalius`]), a `.dcm` file (or one
/// with DICOM's preamble) an enhanced, multi-frame DICOM object.
pub fn read(path: &Path) -> Result<Volume, VolumeError> {
    if path.is_dir() {
        dicom::read_series(path)
    } else if nifti::is_nifti_path(path) {
        nifti::read(path)
    } else if invesalius::is_invesalius_path(path) {
        invesalius::read(path)
    } else if dicom::is_dicom_file(path) {
        dicom::read_file(path)
    } else {
        Err(VolumeError(format!(
            "{}: not a volume; give a .nii or .nii.gz file, an InVesalius .inv3 project, a folder \
                holding a DICOM series, or a multi-frame DICOM file",
            path.display()
        )))
    }
}

/// Writes `volume` to `path`: NIfTI-1 when it ends in `.nii` or `.nii.gz`, otherwise a DICOM
/// series in the new folder `path`.
pub fn write(volume: &Volume, path: &Path) -> Result<(), VolumeError> {
    if nifti::is_nifti_path(path) {
        nifti::write(volume, path)
    } else {
        dicom::write_series(volume, path)
    }
}
