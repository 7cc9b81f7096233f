//! Where a volume is seen from: views named by anatomy and the rays that frame them.

use glam::Vec3;
use specula_render::{Camera, Projection};

use crate::volume::{Volume, VolumeError};

/// Where the volume is seen from: named by anatomy, as a radiologist names the side the
/// camera stands on, with parallel rays; or a perspective eye.
///
/// Front and back views have superior up; a view from above or below has anterior up. The
/// patient's left is on the image's right from the front (anterior) and from the feet
/// (inferior), as radiology displays a patient facing the viewer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// From the front: the face, the patient's left on the image's right.
    Anterior,
    /// From behind: the back of the head, the patient's left on the image's left.
    Posterior,
    /// From the patient's left: anterior on the image's left.
    Left,
    /// From the patient's right: anterior on the image's right.
    Right,
    /// From above (the vertex), anterior up: the patient's right on the image's right.
    Superior,
    /// From the feet, anterior up: the patient's left on the image's right (an axial slice's
    /// orientation).
    Inferior,
    /// A perspective view from this world position towards the volume's centre, `z` up.
    Eye(Vec3),
}

impl View {
    /// The anatomical views, as the command line names them.
    pub const STANDARD: [View; 6] = [
        View::Anterior,
        View::Posterior,
        View::Left,
        View::Right,
        View::Superior,
        View::Inferior,
    ];

    /// The slice planes' names that earlier versions used, and the views they name.
    pub const ALIASES: [(&'static str, View); 3] = [
        ("coronal", View::Anterior),
        ("sagittal", View::Left),
        ("axial", View::Inferior),
    ];

    /// The view's name (`eye` for a perspective view).
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            View::Anterior => "anterior",
            View::Posterior => "posterior",
            View::Left => "left",
            View::Right => "right",
            View::Superior => "superior",
            View::Inferior => "inferior",
            View::Eye(_) => "eye",
        }
    }

    /// A view by name (or by an alias), or the reason naming the choices.
    pub fn parse(text: &str) -> Result<Self, String> {
        let name = text.trim().to_ascii_lowercase();
        Self::STANDARD
            .into_iter()
            .find(|view| view.id() == name)
            .or_else(|| {
                Self::ALIASES
                    .iter()
                    .find(|(alias, _)| *alias == name)
                    .map(|&(_, view)| view)
            })
            .ok_or_else(|| {
                let names = Self::STANDARD.map(View::id);
                format!(
                    "unknown view '{}'; views: {} (or coronal, sagittal, axial){}",
                    specula::excerpt(text),
                    names.join(", "),
                    specula::did_you_mean(text, names)
                )
            })
    }

    /// The direction the camera looks along and the image's up, in RAS world axes (an eye's
    /// are found from its position: [`RayCamera::new`]).
    fn axes(self) -> (Vec3, Vec3) {
        match self {
            View::Anterior => (Vec3::NEG_Y, Vec3::Z),
            View::Posterior => (Vec3::Y, Vec3::Z),
            View::Left => (Vec3::X, Vec3::Z),
            View::Right => (Vec3::NEG_X, Vec3::Z),
            View::Superior => (Vec3::NEG_Z, Vec3::Y),
            View::Inferior | View::Eye(_) => (Vec3::Z, Vec3::Y),
        }
    }
}

/// A view's rays: parallel ones from a plane, or a pinhole's from the eye.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCamera {
    /// The eye (pinhole), or the centre of the plane the parallel rays start from.
    pub eye: Vec3,
    /// The view direction.
    pub forward: Vec3,
    /// The image's `+x` in the world.
    pub right: Vec3,
    /// The image's `+y` in the world.
    pub up: Vec3,
    /// Half the view's height: in millimetres (parallel) or as `tan(fov / 2)` (pinhole).
    pub half_height: f32,
    /// Parallel rays (the standard views) or a pinhole (`--eye`).
    pub parallel: bool,
}

impl RayCamera {
    /// The rays that frame `volume` from `view`.
    pub fn new(view: View, volume: &Volume) -> Result<Self, VolumeError> {
        let corners = volume.corners();
        let centre = corners.iter().copied().sum::<Vec3>() / 8.0;
        let radius = corners
            .iter()
            .map(|c| c.distance(centre))
            .fold(0.0, f32::max);
        let (forward, up) = match view {
            View::Eye(eye) => {
                let distance = eye.distance(centre);
                if !(eye.is_finite() && distance > 1.01 * radius) {
                    return Err(VolumeError(format!(
                        "--eye must be a finite point outside the volume's bounding sphere (centre \
                            {centre}, radius {radius:.1} mm)"
                    )));
                }
                let forward = (centre - eye) / distance;
                let up = if forward.cross(Vec3::Z).length() > 1e-3 {
                    Vec3::Z
                } else {
                    Vec3::Y
                };
                let right = forward.cross(up).normalize();
                return Ok(Self {
                    eye,
                    forward,
                    right,
                    up: right.cross(forward),
                    half_height: 1.05 * (radius / distance).asin().tan(),
                    parallel: false,
                });
            }
            anatomical => anatomical.axes(),
        };
        let right = forward.cross(up);
        // The view fits the grid's projected extent (the image's aspect is applied per ray,
        // so the width is framed by the larger of the two).
        let half = |axis: Vec3| {
            corners
                .iter()
                .map(|c| (*c - centre).dot(axis).abs())
                .fold(0.0, f32::max)
        };
        Ok(Self {
            eye: centre - 2.0 * radius * forward,
            forward,
            right,
            up,
            half_height: 1.05 * half(up).max(half(right)),
            parallel: true,
        })
    }

    /// The ray through the centre of pixel `(x, y)` of a `width x height` image: its origin
    /// and unit direction in the world.
    #[must_use]
    pub fn ray(&self, x: u32, y: u32, width: u32, height: u32) -> (Vec3, Vec3) {
        let aspect = width as f32 / height as f32;
        let sx = ((x as f32 + 0.5) / width as f32 * 2.0 - 1.0) * aspect * self.half_height;
        let sy = (1.0 - (y as f32 + 0.5) / height as f32 * 2.0) * self.half_height;
        if self.parallel {
            (self.eye + sx * self.right + sy * self.up, self.forward)
        } else {
            let direction = (self.forward + sx * self.right + sy * self.up).normalize();
            (self.eye, direction)
        }
    }

    /// The light: at the eye, offset up and to the left.
    #[must_use]
    pub fn light(&self) -> Vec3 {
        (-self.forward + 0.35 * self.up - 0.35 * self.right).normalize()
    }
}

/// The rasterizer's camera for `view` of `volume`, framed as the ray marcher frames it, and
/// the direction towards the light.
pub fn surface_camera(view: View, volume: &Volume) -> Result<(Camera, Vec3), VolumeError> {
    let rays = RayCamera::new(view, volume)?;
    let corners = volume.corners();
    let reach = corners
        .iter()
        .map(|c| c.distance(rays.eye))
        .fold(0.0, f32::max);
    let projection = if rays.parallel {
        Projection::Orthographic {
            height: 2.0 * rays.half_height,
        }
    } else {
        Projection::Perspective {
            fov_y_degrees: (2.0 * rays.half_height.atan()).to_degrees(),
        }
    };
    let camera = Camera::try_new(
        rays.eye,
        rays.eye + rays.forward,
        rays.up,
        projection,
        1e-3 * reach,
        1.01 * reach,
    )
    .map_err(|e| VolumeError(e.to_string()))?;
    Ok((camera, rays.light()))
}
