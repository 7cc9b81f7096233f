//! VTK's CPU ray caster (`vtkFixedPointVolumeRayCastMapper`, what 3D Slicer and ParaView
//! build on) as the yardstick: specula's ray marcher and VTK set up alike, and the job that
//! `vtk_volume.py` (in `crates/report`, beside the module that runs it) runs.
//!
//! Alike means the same volume, view, image size, sample distance, transfer function (VTK's
//! opacity per millimetre is `1 - exp(-sigma)`, which its sample-distance correction turns
//! into specula's `1 - exp(-sigma d)`), headlight, ambient, diffuse and specular weights, and
//! VTK's Blinn-Phong power as the `pow` lobe, with every sample shaded fully and rays stopped
//! where VTK stops them (99.22 % opaque). What stays different is how each computes, not what:
//! VTK's normals are central differences of the voxels quantised to 65,280 directions, its
//! shading is interpolated between the 8 corners' lit values (a corner with an exactly zero
//! difference is lit black), its samples lie on a lattice anchored at the near plane and its
//! arithmetic is 15-bit fixed point; specula takes the gradient of the trilinear field at the
//! sample and jitters each ray's first segment.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::Serialize;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};

use crate::dvr::{DvrPlan, DvrSettings, View};
use crate::lighting::{Light, Shading};
use crate::transfer::TransferFunction;
use crate::volume::{Volume, VolumeError};

/// Where VTK stops a ray: its remaining opacity (15-bit) below 255 of 32767.
pub const VTK_OPACITY_CUTOFF: f32 = 1.0 - 255.0 / 32767.0;

/// Where VTK's GPU ray caster stops a ray (`g_opacityThreshold`, 1 - 1/255).
pub const VTK_GPU_OPACITY_CUTOFF: f32 = 1.0 - 1.0 / 255.0;

/// The weights both renderers use in a comparison (specula's defaults).
pub const AMBIENT: f32 = 0.25;
/// See [`AMBIENT`].
pub const DIFFUSE: f32 = 0.7;
/// See [`AMBIENT`].
pub const SPECULAR: f32 = 0.5;

/// specula's settings for a render VTK can match: `view` at `width x height`, samples every
/// `sample_distance` mm, the headlight, Blinn-Phong of `power` as the `pow` lobe, every
/// sample fully shaded, VTK's early termination.
pub fn alike_settings(
    volume: &Volume,
    width: u32,
    height: u32,
    view: View,
    power: Exponent,
    sample_distance: f32,
) -> Result<DvrSettings, VolumeError> {
    let pow = Lobe::new(LobeKind::Pow, power);
    let shading = alike_shading(pow, Geometry::Blinn, false);
    let mut settings = alike(volume, width, height, view, shading, sample_distance)?;
    settings.opacity_cutoff = VTK_OPACITY_CUTOFF;
    Ok(settings)
}

/// specula's settings for a render VTK's GPU ray caster can match, `lobe` in place of its
/// `pow` (the module of `specula shader --lang vtk`): as [`alike_settings`], but Phong's `R.V`
/// (that caster's cosine, where the CPU caster's is Blinn's), its early termination, and a
/// sample with no gradient lit by the ambient term alone (its normal there is 0).
pub fn alike_gpu_settings(
    volume: &Volume,
    width: u32,
    height: u32,
    view: View,
    lobe: Lobe,
    sample_distance: f32,
) -> Result<DvrSettings, VolumeError> {
    let shading = alike_shading(lobe, Geometry::Phong, true);
    let mut settings = alike(volume, width, height, view, shading, sample_distance)?;
    settings.opacity_cutoff = VTK_GPU_OPACITY_CUTOFF;
    Ok(settings)
}

/// The headlight with both renderers' weights, every sample fully shaded; a sample with no
/// gradient left unlit, or with its ambient term alone (`ambient_where_flat`).
fn alike_shading(lobe: Lobe, geometry: Geometry, ambient_where_flat: bool) -> Shading {
    Shading {
        ka: AMBIENT,
        kd: DIFFUSE,
        ks: SPECULAR,
        light: Light::Headlight,
        fade_weak_gradients: false,
        ambient_where_flat,
        ..Shading::new(lobe, geometry, Normalisation::None)
    }
}

/// The settings both casters share: the view, the sample distance (at most 4 voxels).
fn alike(
    volume: &Volume,
    width: u32,
    height: u32,
    view: View,
    shading: Shading,
    sample_distance: f32,
) -> Result<DvrSettings, VolumeError> {
    let voxel = volume.spacing().min_element();
    if !(sample_distance > 0.0 && sample_distance <= 4.0 * voxel) {
        return Err(VolumeError(format!(
            "a sample distance of {sample_distance} mm: it must be more than 0 and at most 4 \
                voxels ({} mm)",
            4.0 * voxel
        )));
    }
    let mut settings = DvrSettings::new(width, height, view, Some(shading));
    settings.step_fraction = sample_distance / voxel;
    Ok(settings)
}

/// The camera as VTK takes it (world millimetres; parallel projection).
#[derive(Clone, Debug, Serialize)]
pub struct VtkCamera {
    /// The eye.
    pub position: [f32; 3],
    /// A point on the view axis.
    pub focal_point: [f32; 3],
    /// The image's up.
    pub view_up: [f32; 3],
    /// Half the image's height in millimetres.
    pub parallel_scale: f32,
}

/// VTK's shading weights.
#[derive(Clone, Debug, Serialize)]
pub struct VtkShading {
    /// Ambient weight.
    pub ambient: f32,
    /// Diffuse weight.
    pub diffuse: f32,
    /// Specular weight.
    pub specular: f32,
    /// The specular power (Blinn-Phong's on the CPU caster, Phong's on the GPU caster).
    pub power: f32,
}

/// What `vtk_volume.py` renders (its documentation names every field).
#[derive(Clone, Debug, Serialize)]
pub struct VtkJob {
    /// The volume, a NIfTI file (VTK reads it with nibabel: world = its affine).
    pub volume: PathBuf,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The camera.
    pub camera: VtkCamera,
    /// Millimetres between samples.
    pub sample_distance: f32,
    /// `[value, sigma, r, g, b]` control points.
    pub transfer: Vec<[f32; 5]>,
    /// The shading.
    pub shading: VtkShading,
    /// `linear` (trilinear, as specula).
    pub interpolation: &'static str,
    /// Threads VTK may use.
    pub threads: usize,
    /// Untimed frames first (VTK computes its gradients in the first).
    pub warmup: u32,
    /// Timed frames.
    pub frames: u32,
    /// The PNG VTK writes.
    pub output: PathBuf,
    /// The headlight's ambient colour: white, so that the ambient weight counts as in
    /// specula (VTK's own light has none).
    pub headlight_ambient_color: [f32; 3],
    /// The background.
    pub background: [f32; 3],
    /// `cpu` (`vtkFixedPointVolumeRayCastMapper`) or `gpu` (`vtkGPUVolumeRayCastMapper`).
    pub mapper: &'static str,
    /// The module of `specula shader --lang vtk` whose lobe replaces the GPU caster's `pow`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lobe_module: Option<PathBuf>,
}

impl VtkJob {
    /// The job on VTK's GPU ray caster, shaded by `lobe_module`'s lobe (VTK's own `pow`
    /// without one); its settings should be [`alike_gpu_settings`].
    #[must_use]
    pub fn on_gpu(self, lobe_module: Option<PathBuf>) -> Self {
        Self {
            mapper: "gpu",
            lobe_module,
            ..self
        }
    }
}

/// The VTK job that renders `volume` (read from `volume_file`, a NIfTI file of the same
/// voxels and placement) as specula renders it with `settings` (from [`alike_settings`])
/// through `transfer` (in the volume's values).
pub fn job(
    volume: &Volume,
    volume_file: &Path,
    transfer: &TransferFunction,
    settings: &DvrSettings,
    output: &Path,
    threads: usize,
    frames: u32,
) -> Result<VtkJob, VolumeError> {
    let plan = DvrPlan::new(volume, settings)?;
    let (camera, lighting) = (plan.camera, plan.lighting);
    let Some(lighting) = lighting.filter(|_| camera.parallel) else {
        return Err(VolumeError(
            "VTK is compared on shaded renders from the anatomical views".into(),
        ));
    };
    let shading = lighting.shading;
    let array = |v: Vec3| v.to_array();
    Ok(VtkJob {
        volume: volume_file.to_owned(),
        width: settings.width,
        height: settings.height,
        camera: VtkCamera {
            position: array(camera.eye),
            focal_point: array(camera.eye + camera.forward),
            view_up: array(camera.up),
            parallel_scale: camera.half_height,
        },
        sample_distance: plan.step,
        transfer: transfer
            .points()
            .iter()
            .map(|p| [p.value, p.sigma, p.colour.x, p.colour.y, p.colour.z])
            .collect(),
        shading: VtkShading {
            ambient: shading.ka,
            diffuse: shading.kd,
            specular: shading.ks,
            power: shading.lobe.exponent().get() as f32,
        },
        interpolation: "linear",
        threads,
        warmup: 1,
        frames,
        output: output.to_owned(),
        headlight_ambient_color: [1.0; 3],
        background: array(settings.background),
        mapper: "cpu",
        lobe_module: None,
    })
}
