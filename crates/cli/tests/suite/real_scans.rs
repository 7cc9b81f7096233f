//! `specula volume` on real scans (issue 32): InVesalius' head CT (Debian's
//! `invesalius-examples`, converted to a NIfTI file and to a DICOM CT series by
//! `tests/volumes/real_scans.py` with numpy, nibabel and pydicom), Colin27's T1 MRI with skull
//! (Debian's `mricron-data`, read as shipped) and pydicom-data's enhanced (multi-frame) CT.
//!
//! Every expected value comes from outside specula: silhouettes and marker positions from
//! `real_scans.py` (numpy over the voxels), the views' orientations from their definitions
//! (closed form), and VTK's CPU ray caster (`vtkFixedPointVolumeRayCastMapper`) through
//! `specula bench volume`. Nothing is downloaded: without the packages a test prints
//! `skipped: ...`, and under `CI=true` it fails.

mod setup;

mod peers;
mod presets;
mod refusals;
mod views;
