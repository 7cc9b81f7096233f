//! The camera: look-at placement, perspective or orthographic projection.
//!
//! Right-handed world, depth mapped to `[0, 1]` (near to far) as wgpu and D3D do, so the CPU and
//! GPU pipelines share one projection matrix.

use glam::{Mat4, Vec3};
use thiserror::Error;

/// The largest coordinate a camera's eye or target (and a scene's light position or object
/// translation) may have: beyond it, squared distances overflow `f32`.
pub const MAX_COORDINATE: f32 = 1e6;

/// Whether `point` is finite and within [`MAX_COORDINATE`] of the origin in each coordinate.
#[must_use]
pub fn in_scene_range(point: Vec3) -> bool {
    point.is_finite() && point.abs().max_element() <= MAX_COORDINATE
}

/// A camera description that cannot be used, and why.
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{0}")]
pub struct InvalidCamera(String);

/// How the view volume maps to the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// A pinhole with this vertical field of view, in degrees, in `(0, 180)`.
    Perspective {
        /// Vertical field of view in degrees.
        fov_y_degrees: f32,
    },
    /// Parallel rays; the image spans `height` world units vertically.
    Orthographic {
        /// Vertical extent of the view in world units.
        height: f32,
    },
}

/// A validated camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    eye: Vec3,
    target: Vec3,
    up: Vec3,
    projection: Projection,
    near: f32,
    far: f32,
}

impl Camera {
    /// A camera at `eye` looking at `target`, `up` roughly up; `near` and `far` bound the depth
    /// range. Refused when a value is not finite, `eye == target`, `up` is parallel to the view
    /// direction, `0 < near < far` fails, or the projection's parameter is out of range.
    pub fn try_new(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        projection: Projection,
        near: f32,
        far: f32,
    ) -> Result<Self, InvalidCamera> {
        let fail = |message: &str| Err(InvalidCamera(message.to_owned()));
        if !(eye.is_finite() && target.is_finite() && up.is_finite()) {
            return fail("eye, target and up must be finite");
        }
        if !(in_scene_range(eye) && in_scene_range(target)) {
            return fail(&format!(
                "eye and target must lie within {MAX_COORDINATE:e} scene units of the origin in \
                    each coordinate (squared distances must stay finite in f32)"
            ));
        }
        let Some(forward) = (target - eye).try_normalize() else {
            return fail("eye and target coincide; the camera needs a direction to look in");
        };
        if forward.cross(up).length() < 1e-6 * up.length().max(f32::MIN_POSITIVE)
            || up == Vec3::ZERO
        {
            return fail("up is zero or parallel to the view direction (target - eye)");
        }
        if !(near > 0.0 && far > near && far.is_finite()) {
            return fail("near and far must satisfy 0 < near < far < infinity");
        }
        match projection {
            Projection::Perspective { fov_y_degrees }
                if !(fov_y_degrees > 0.0 && fov_y_degrees < 180.0) =>
            {
                return fail("fov must be in (0, 180) degrees");
            }
            Projection::Orthographic { height } if !(height > 0.0 && height.is_finite()) => {
                return fail("an orthographic height must be a positive number of world units");
            }
            _ => {}
        }
        Ok(Self {
            eye,
            target,
            up,
            projection,
            near,
            far,
        })
    }

    /// The eye position.
    #[must_use]
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// The point looked at.
    #[must_use]
    pub fn target(&self) -> Vec3 {
        self.target
    }

    /// The up direction given (not necessarily orthogonal to the view).
    #[must_use]
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// The projection.
    #[must_use]
    pub fn projection(&self) -> Projection {
        self.projection
    }

    /// World to clip space for an image of `aspect = width / height`.
    #[must_use]
    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        // wgpu's clip space is D3D's: depth in [0, 1], y up.
        use glam::camera::rh::{proj::directx, view::look_at_mat4};
        let view = look_at_mat4(self.eye, self.target, self.up);
        let projection = match self.projection {
            Projection::Perspective { fov_y_degrees } => {
                directx::perspective(fov_y_degrees.to_radians(), aspect, self.near, self.far)
            }
            Projection::Orthographic { height } => {
                let (half_h, half_w) = (0.5 * height, 0.5 * height * aspect);
                directx::orthographic(-half_w, half_w, -half_h, half_h, self.near, self.far)
            }
        };
        projection * view
    }

    /// The unit direction from the target to the eye: every point's `wo` under an
    /// orthographic projection.
    #[must_use]
    pub fn backwards(&self) -> Vec3 {
        (self.eye - self.target).normalize()
    }

    /// The unit direction from `point` towards the viewer (`wo`).
    #[must_use]
    pub fn towards_viewer(&self, point: Vec3) -> Vec3 {
        // Called per sample: the fallback's normalisation is paid only where it is needed.
        match self.projection {
            Projection::Perspective { .. } => (self.eye - point)
                .try_normalize()
                .unwrap_or_else(|| self.backwards()),
            Projection::Orthographic { .. } => self.backwards(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn perspective() -> Projection {
        Projection::Perspective {
            fov_y_degrees: 60.0,
        }
    }

    #[test]
    fn the_target_projects_to_the_centre_and_near_far_to_zero_one() {
        let camera = Camera::try_new(
            Vec3::new(0.0, -5.0, 1.0),
            Vec3::Z,
            Vec3::Z,
            perspective(),
            0.5,
            50.0,
        )
        .unwrap();
        let m = camera.view_projection(1.5);
        let centre = m.project_point3(Vec3::Z);
        assert!(centre.x.abs() < 1e-6 && centre.y.abs() < 1e-6);
        let near = m.project_point3(Vec3::new(0.0, -4.5, 1.0));
        let far = m.project_point3(Vec3::new(0.0, 45.0, 1.0));
        assert!(
            near.z.abs() < 1e-5 && (far.z - 1.0).abs() < 1e-5,
            "{near} {far}"
        );
    }

    #[test]
    fn bad_cameras_are_refused_with_the_reason() {
        let error =
            Camera::try_new(Vec3::Z, Vec3::Z, Vec3::Y, perspective(), 0.1, 10.0).unwrap_err();
        assert!(error.to_string().contains("coincide"));
        assert!(Camera::try_new(Vec3::ZERO, Vec3::Z, Vec3::Z, perspective(), 0.1, 10.0).is_err());
        let wide = Projection::Perspective {
            fov_y_degrees: 180.0,
        };
        assert!(Camera::try_new(Vec3::ZERO, Vec3::X, Vec3::Z, wide, 0.1, 10.0).is_err());
        assert!(Camera::try_new(Vec3::ZERO, Vec3::X, Vec3::Z, perspective(), 0.0, 10.0).is_err());
    }
}
