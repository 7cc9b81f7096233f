//! What the explorer's views show, computed from the library: lobe curves, the polar plot in
//! the plane of incidence, directional albedo, the BRDF image slice, and lit renders.
//!
//! Conventions are the library's: local frame with `z` = normal, `wi` towards the light, `wo`
//! towards the viewer, the specular BRDF term `N(n) lobe(t)` (`Brdf::specular`, `ks = 1`).

use core::f64::consts::FRAC_PI_2;

use glam::DVec3;
use serde::Serialize;
use specula::analysis::albedo::specular_albedo_per_unit;
use specula::{zones, Brdf, Exponent, Geometry, Lobe, LobeKind, Normalisation, Rgb};
use specula_render::{IlluminationModel, Scene, Shading};

use crate::scene_setup::{light_towards, tonemap_for, LIVE_SCENE};

/// Samples along each curve.
const CURVE_POINTS: usize = 361;
/// Incident angles of the albedo curve.
const ALBEDO_POINTS: usize = 31;
/// Side of the `theta_h` x `theta_d` slice.
pub const SLICE_SIZE: usize = 64;

/// One lobe's curves for the explorer's plots.
#[derive(Debug, Serialize)]
pub struct Curves {
    pub lobe: &'static str,
    pub n: f64,
    /// The zones' outer angles, degrees: `t^n = 1/2` and `t^n = 1/256`.
    pub epicentre_deg: f64,
    pub bloom_deg: f64,
    /// The angle from the lobe's axis, degrees, out to where the lobe has faded.
    pub angles_deg: Vec<f64>,
    /// The lobe (peak 1), `t^n`, and their difference, at those angles.
    pub values: Vec<f64>,
    pub reference: Vec<f64>,
    pub error: Vec<f64>,
    /// The specular BRDF term in the plane of incidence, for `wo` from -90 to 90 degrees.
    pub polar_deg: Vec<f64>,
    pub polar: Vec<f64>,
    /// Directional albedo of the specular term against the angle of incidence, degrees.
    pub albedo_deg: Vec<f64>,
    pub albedo: Vec<f64>,
    /// The specular term over `theta_h` (columns, on a square-root scale: column `i` is at
    /// `90 (i / (size - 1))^2` degrees) by `theta_d` (rows, linear), `phi_d = 90` degrees,
    /// row-major.
    pub slice: Vec<f64>,
    pub slice_size: usize,
}

/// A unit direction at polar angle `theta` in the `xz` plane (negative `theta`: `-x` side).
fn in_plane(theta: f64) -> DVec3 {
    DVec3::new(theta.sin(), 0.0, theta.cos())
}

/// The Rusinkiewicz parameterisation: the half vector at `theta_h` (in the `xz` plane), and
/// `wi`, `wo` at `theta_d` from it, at azimuth `phi_d` about it.
fn from_half_difference(theta_h: f64, theta_d: f64, phi_d: f64) -> (DVec3, DVec3) {
    let difference = DVec3::new(
        theta_d.sin() * phi_d.cos(),
        theta_d.sin() * phi_d.sin(),
        theta_d.cos(),
    );
    // Rotate the difference frame so that its z axis is the half vector.
    let rotate = |v: DVec3| {
        let (s, c) = theta_h.sin_cos();
        DVec3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z)
    };
    let wi = rotate(difference);
    let wo = rotate(DVec3::new(-difference.x, -difference.y, difference.z));
    (wi, wo)
}

/// Every view's data for `kind` at `n`, with light at `theta_in` (radians) for the polar plot.
#[must_use]
pub fn curves(
    kind: LobeKind,
    n: Exponent,
    geometry: Geometry,
    normalisation: Normalisation,
    theta_in: f64,
) -> Curves {
    let lobe = Lobe::new(kind, n);
    let reference = Lobe::new(LobeKind::Pow, n);
    let brdf = Brdf::new(Rgb::ZERO, Rgb::ONE, lobe, geometry, normalisation);
    let (epicentre, bloom) = (zones::epicentre_angle(n), zones::bloom_angle(n));
    let right = (2.0 * bloom).min(FRAC_PI_2);
    let angles: Vec<f64> = (0..CURVE_POINTS)
        .map(|i| right * i as f64 / (CURVE_POINTS - 1) as f64)
        .collect();
    let values: Vec<f64> = angles.iter().map(|&g| lobe.eval(g.cos())).collect();
    let exact: Vec<f64> = angles.iter().map(|&g| reference.eval(g.cos())).collect();
    let wi = in_plane(theta_in);
    let polar_angles: Vec<f64> = (0..CURVE_POINTS)
        .map(|i| -FRAC_PI_2 + core::f64::consts::PI * i as f64 / (CURVE_POINTS - 1) as f64)
        .collect();
    let polar = polar_angles
        .iter()
        .map(|&theta| brdf.specular(in_plane(theta), wi))
        .collect();
    let albedo_angles: Vec<f64> = (0..ALBEDO_POINTS)
        .map(|i| FRAC_PI_2 * i as f64 / (ALBEDO_POINTS - 1) as f64)
        .collect();
    let constant = brdf.normalisation_constant();
    let albedo = albedo_angles
        .iter()
        .map(|&theta| constant * specular_albedo_per_unit(&lobe, geometry, theta))
        .collect();
    let fraction = |i: usize| i as f64 / (SLICE_SIZE - 1) as f64;
    let slice = (0..SLICE_SIZE * SLICE_SIZE)
        .map(|k| {
            // theta_h on a square-root scale (BRDF Explorer's), so that a narrow lobe's few
            // degrees get columns; theta_d linear.
            let theta_h = fraction(k % SLICE_SIZE).powi(2) * FRAC_PI_2;
            let theta_d = fraction(k / SLICE_SIZE) * FRAC_PI_2;
            let (wi, wo) = from_half_difference(theta_h, theta_d, FRAC_PI_2);
            if wi.z > 0.0 && wo.z > 0.0 {
                brdf.specular(wo, wi)
            } else {
                0.0
            }
        })
        .collect();
    Curves {
        lobe: kind.id(),
        n: n.get(),
        epicentre_deg: epicentre.to_degrees(),
        bloom_deg: bloom.to_degrees(),
        error: values.iter().zip(&exact).map(|(a, b)| a - b).collect(),
        angles_deg: angles.iter().map(|g| g.to_degrees()).collect(),
        values,
        reference: exact,
        polar_deg: polar_angles.iter().map(|g| g.to_degrees()).collect(),
        polar,
        albedo_deg: albedo_angles.iter().map(|g| g.to_degrees()).collect(),
        albedo,
        slice,
        slice_size: SLICE_SIZE,
    }
}

/// What the explorer renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Object {
    Sphere,
    Teapot,
}

impl Object {
    pub const ALL: [Object; 2] = [Object::Sphere, Object::Teapot];

    pub fn id(self) -> &'static str {
        match self {
            Object::Sphere => "sphere",
            Object::Teapot => "teapot",
        }
    }
}

/// A render request, validated.
#[derive(Clone, Copy, Debug)]
pub struct RenderRequest {
    pub object: Object,
    pub kind: LobeKind,
    pub n: Exponent,
    pub geometry: Geometry,
    pub normalisation: Normalisation,
    pub shading: Shading,
    pub model: IlluminationModel,
    /// The light's direction: polar angle from the camera's axis and azimuth, radians.
    pub light_theta: f64,
    pub light_phi: f64,
    pub size: u32,
}

/// The scene of a render request, written in the scene format so that it goes through the
/// same parser and validation as a user's file.
pub fn scene(request: &RenderRequest) -> Result<Scene, String> {
    // The camera looks along -y; the light's polar angle is measured from the camera's axis.
    let towards = light_towards(request.light_theta, request.light_phi);
    let live = LIVE_SCENE;
    let sphere_eye = format!(
        "eye = [0.0, {:?}, 0.0]\ntarget = [0.0, 0.0, 0.0]",
        -live.eye_distance
    );
    let (shape, placement) = match request.object {
        Object::Sphere => (
            "shape = \"sphere\"\nradius = 1.0\nsegments = 128\nrings = 64",
            sphere_eye.as_str(),
        ),
        Object::Teapot => (
            "shape = \"teapot\"\nlevel = 10\nscale = 0.55\nrotate = [0.0, 0.0, -30.0]\ntranslate = \
                [0.0, 0.0, -0.85]",
            "eye = [0.0, -6.5, 1.8]\ntarget = [0.0, 0.0, 0.0]",
        ),
    };
    let text = format!(
        r#"ambient = {ambient:?}
[camera]
{placement}
up = [0.0, 0.0, 1.0]
fov = {fov:?}
[render]
width = {size}
height = {size}
samples = 1
shading = "{shading}"
model = "{model}"
background = {background:?}
tonemap = "{tonemap}"
[[lights]]
kind = "directional"
towards = [{x}, {y}, {z}]
intensity = [1.0, 1.0, 1.0]
[[objects]]
{shape}
[objects.material]
colour = {colour:?}
ka = {ka:?}
kd = {kd:?}
ks = {ks:?}
lobe = "{lobe}"
n = {n}
geometry = "{geometry}"
normalisation = "{normalisation}"
"#,
        size = request.size,
        ambient = live.ambient,
        fov = live.fov_y_deg,
        background = live.background,
        colour = live.colour,
        ka = live.ka,
        kd = live.kd,
        ks = live.ks,
        tonemap = tonemap_for(request.normalisation).id(),
        shading = request.shading.id(),
        model = request.model.id(),
        x = towards[0],
        y = towards[1],
        z = towards[2],
        // With its parameters (`cosquad:v=2`); a formula by the name the registry gave it
        // (`formula-3`), which the scene parser resolves to the same lobe.
        lobe = request.kind,
        n = request.n.get(),
        geometry = request.geometry.id(),
        normalisation = request.normalisation.id(),
    );
    Scene::from_toml(&text, "explorer", None)
        .map(|loaded| loaded.scene)
        .map_err(|e| e.to_string())
}

/// The render as PNG bytes.
pub fn render_png(request: &RenderRequest) -> Result<Vec<u8>, String> {
    let scene = scene(request)?;
    let image = specula_render::render(&scene, &|_, _| {}).map_err(|e| e.to_string())?;
    specula_render::encode_png_srgb8(
        image.width(),
        image.height(),
        &image.to_srgb8(scene.display),
    )
    .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The half/difference parameterisation: `h` bisects `wi` and `wo`, at `theta_h` from the
    /// normal, and `wi` is `theta_d` from `h`.
    #[test]
    fn half_difference_directions_have_their_angles() {
        for (theta_h, theta_d) in [(0.1, 0.4), (0.7, 0.2), (1.2, 1.0)] {
            let (wi, wo) = from_half_difference(theta_h, theta_d, FRAC_PI_2);
            let h = (wi + wo).normalize();
            assert!((h.z.acos() - theta_h).abs() < 1e-12);
            assert!((wi.dot(h).acos() - theta_d).abs() < 1e-12);
            assert!((wi.length() - 1.0).abs() < 1e-12 && (wo.length() - 1.0).abs() < 1e-12);
        }
    }

    /// The curves agree with closed forms: `pow`'s error is zero, its peak is 1, and the
    /// albedo at normal incidence of a `lobe`-normalised Phong lobe is `(n + 1) / (n + 2)`.
    #[test]
    fn curves_match_closed_forms() {
        let n = Exponent::new(20.0);
        let c = curves(LobeKind::Pow, n, Geometry::Phong, Normalisation::Lobe, 0.3);
        assert!(c.error.iter().all(|e| e.abs() < 1e-15));
        assert_eq!(c.values[0], 1.0);
        assert!((c.albedo[0] - 21.0 / 22.0).abs() < 1e-6, "{}", c.albedo[0]);
        assert_eq!(c.slice.len(), SLICE_SIZE * SLICE_SIZE);
        // The polar plot peaks at the mirror direction, -theta_in.
        let peak =
            c.polar.iter().enumerate().fold(
                (0, 0.0),
                |best, (k, &v)| if v > best.1 { (k, v) } else { best },
            );
        assert!(
            (c.polar_deg[peak.0] + 0.3_f64.to_degrees()).abs() < 0.6,
            "{}",
            c.polar_deg[peak.0]
        );
    }
}
