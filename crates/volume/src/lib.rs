//! # specula-volume: the medical program
//!
//! The thesis's second program: the specular term in images of the body. Volumes are scalar
//! fields on a regular grid, as medical scanners write them ([`Volume`]), drawn by direct
//! volume rendering or as isosurfaces with any lobe as the specular term. It draws with the
//! renderer's images, cameras, files and (for isosurfaces) its rasterizer; the renderer knows
//! nothing of volumes.
//!
//! - [`phantom`]: the built-in volumes (the 3D Shepp-Logan head, the Marschner-Lobb signal);
//! - [`nifti`], [`dicom`] (series and enhanced multi-frame objects) and [`invesalius`]: the
//!   files scanners and research tools write ([`read()`] and [`write()`] choose by path);
//! - [`march`]: what makes the CPU ray marcher fast without changing what it computes;
//! - [`vtk`]: VTK's CPU ray caster set up as specula's, the yardstick;
//! - [`transfer`]: transfer functions (extinction and colour by value) and their presets;
//! - [`dvr`]: direct volume rendering with any lobe as the specular term;
//! - [`isosurface`]: isosurfaces by marching cubes, drawn by the rasterizer like any mesh.

pub mod dicom;
pub mod dvr;
mod files;
pub mod invesalius;
pub mod isosurface;
mod lighting;
pub mod march;
pub mod nifti;
pub mod phantom;
mod resample;
mod samples;
pub mod transfer;
mod volume;
pub mod vtk;

pub use files::{read, write};
pub use samples::{Sample, Samples};
pub use volume::{Units, Volume, VolumeError, MAX_SIDE, MAX_VOXELS};
