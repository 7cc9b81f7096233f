use super::ray::{march_rays, Highlight, Lit, Marched, Ray};
use super::*;
use crate::dvr::{
    inside_grid, pixel_jitter, render_dvr, DvrPlan, DvrSettings, Light, Lighting, RayView, Shading,
    View,
};
use crate::phantom::BuiltIn;
use specula::simd::Level;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};

/// The classic model as the module states it, written here apart from
/// `Lighting::light_lanes`'s rearranged arithmetic: the gradient's opposite, turned to the viewer,
/// as the normal; the
/// geometry's own cosine; lit blended with unlit by the gradient's strength.
fn classic(lighting: &Lighting, gradient: Vec3, base: Vec3, wo: Vec3) -> Vec3 {
    let strength = gradient.length();
    if strength == 0.0 {
        return base;
    }
    let mut normal = -gradient / strength;
    if normal.dot(wo) < 0.0 {
        normal = -normal;
    }
    let (shading, wi) = (&lighting.shading, lighting.light);
    let t = shading.geometry.cos_lobe_f32(normal, wo, wi);
    let specular = lighting.highlight_scale(&shading.lobe) * shading.lobe.eval(t);
    let lit = base * (shading.ka + shading.kd * normal.dot(wi).max(0.0)) + Vec3::splat(specular);
    base.lerp(lit, (strength / lighting.gradient_reference).min(1.0))
}

/// The march as the model states it, sample by sample from the volume and the transfer
/// function themselves (no table, no bricks, gradients from six trilinear samples).
fn reference(volume: &Volume, transfer: &TransferFunction, settings: &DvrSettings) -> Vec<Vec3> {
    let plan = DvrPlan::new(volume, settings).unwrap();
    let (width, height) = (settings.width, settings.height);
    let mut pixels = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let (origin, direction) = plan.camera.ray(x, y, width, height);
            let (o, d) = (volume.index(origin), volume.index_direction(direction));
            let Some((start, end)) = inside_grid(volume, o, d) else {
                pixels.push(settings.background);
                continue;
            };
            let (mut colour, mut transmittance) = (Vec3::ZERO, 1.0_f32);
            // The segments' ends: the first a fraction of a step in, then whole steps.
            let first = start + plan.step * pixel_jitter(x, y);
            let ends = std::iter::once(first)
                .chain((1..).map(|j| first - plan.step + (j + 1) as f32 * plan.step));
            let mut t = start;
            for next in ends {
                if !(t < end && 1.0 - transmittance < settings.opacity_cutoff) {
                    break;
                }
                let segment = next.min(end) - t;
                let index = o + d * (t + 0.5 * segment);
                t = next;
                let (sigma, base) = transfer.at(volume.sample(index));
                let alpha = 1.0 - (-sigma * segment).exp();
                let shaded = plan.lighting.as_ref().map_or(base, |lighting| {
                    classic(lighting, volume.gradient(index), base, -direction)
                });
                colour += transmittance * alpha * shaded;
                transmittance *= 1.0 - alpha;
            }
            pixels.push(colour + transmittance * settings.background);
        }
    }
    pixels
}

/// The reference march's image, and per pixel the largest difference in a channel between
/// `render_dvr` and it (infinite where either is NaN).
fn against_the_reference(
    volume: &Volume,
    transfer: &TransferFunction,
    settings: &DvrSettings,
) -> (Vec<Vec3>, Vec<f32>) {
    let fast = render_dvr(volume, transfer, settings, &|| {}).unwrap();
    let expected = reference(volume, transfer, settings);
    let errors = expected
        .iter()
        .enumerate()
        .map(|(p, e)| {
            let error = (fast.get(p as u32 % settings.width, p as u32 / settings.width) - *e)
                .abs()
                .max_element();
            if error.is_nan() {
                f32::INFINITY
            } else {
                error
            }
        })
        .collect();
    (expected, errors)
}

/// The Shepp-Logan head of `side` voxels inside a margin of 4 empty voxels, so that the
/// last layer (where the two gradients differ by definition) is uniform.
pub(super) fn padded_head(side: usize) -> Volume {
    let head = BuiltIn::SheppLogan.make(side).unwrap();
    let n = side + 8;
    let samples = (0..n * n * n)
        .map(|v| {
            let [i, j, k] = [v % n, v / n % n, v / (n * n)].map(|c| c as isize - 4);
            head.at(i, j, k)
                * f32::from(u8::from(
                    [i, j, k].iter().all(|&c| (0..side as isize).contains(&c)),
                ))
        })
        .collect();
    Volume::centred(
        [n; 3],
        head.spacing(),
        samples,
        crate::volume::Units::Arbitrary,
    )
    .unwrap()
}

#[test]
fn the_prepared_march_is_the_reference_march() {
    let volume = padded_head(36);
    let lobe = Lobe::new(LobeKind::Pow, Exponent::new(24.0));
    for (view, transfer, light, geometry, fade) in [
        (View::Anterior, "mr", Light::Key, Geometry::Blinn, true),
        (
            View::Left,
            "surface",
            Light::Headlight,
            Geometry::Phong,
            true,
        ),
        (
            View::Eye(Vec3::new(400.0, -300.0, 200.0)),
            "mr",
            Light::Headlight,
            Geometry::Blinn,
            false,
        ),
        (View::Superior, "mr", Light::Key, Geometry::Phong, false),
    ] {
        let transfer = TransferFunction::preset(transfer)
            .unwrap()
            .for_volume(&volume);
        let shading = Shading {
            light,
            fade_weak_gradients: fade,
            ..Shading::new(lobe, geometry, Normalisation::None)
        };
        let mut settings = DvrSettings::new(48, 40, view, Some(shading));
        settings.background = Vec3::new(0.1, 0.2, 0.3);
        let (_, errors) = against_the_reference(&volume, &transfer, &settings);
        let worst = errors.iter().copied().fold(0.0, f32::max);
        let mean = errors.iter().sum::<f32>() / errors.len() as f32;
        assert!(
            worst < 2e-3 && mean < 2e-4,
            "{view:?}: worst {worst}, mean {mean}"
        );
    }
}

/// A ball in a large empty grid: most bricks are empty, and the image with bricks and
/// transparent cells is the image without them (every brick occupied, no cell marked) bit for
/// bit; in both layouts, the compact one on values that are not whole numbers (stored scaled,
/// and its voxels fetched ahead).
#[test]
fn empty_bricks_are_skipped_without_changing_a_pixel() {
    skipping_changes_no_pixel(Layout::Exact, 1.0);
    skipping_changes_no_pixel(Layout::Compact, 0.6);
}

/// [`empty_bricks_are_skipped_without_changing_a_pixel`] with the voxels in `layout` and the
/// ball's value `inside`.
fn skipping_changes_no_pixel(layout: Layout, inside: f32) {
    let n = 64;
    let samples = (0..n * n * n)
        .map(|v| {
            let p = Vec3::new((v % n) as f32, (v / n % n) as f32, (v / (n * n)) as f32);
            if p.distance(Vec3::new(40.0, 30.0, 25.0)) < 9.0 {
                inside
            } else {
                0.0
            }
        })
        .collect();
    let volume =
        Volume::centred([n; 3], Vec3::ONE, samples, crate::volume::Units::Arbitrary).unwrap();
    let prepared = PreparedVolume::with_layout(&volume, layout);
    let transfer = TransferFunction::preset("surface")
        .unwrap()
        .for_volume(&volume);
    let step = 0.37;
    let skipping = Classification::new(&prepared, &transfer);
    let occupied = skipping.clearance.iter().filter(|&&c| c == 0).count();
    assert!(
        occupied * 4 < skipping.clearance.len(),
        "{occupied} bricks occupied"
    );
    assert!(
        skipping.clearance.iter().any(|&c| c > 4),
        "some empty space reaches beyond 4 bricks"
    );
    assert!(
        skipping.transparent.iter().any(|&mask| mask != 0),
        "some cells of occupied bricks are transparent"
    );
    let mut everything = skipping.clone();
    everything.clearance.iter_mut().for_each(|c| *c = 0);
    everything.transparent.fill(0);
    let direction = Vec3::new(0.3, 0.8, 0.52).normalize();
    let mut rays = Vec::new();
    for (k, first) in [0.1_f32, 0.5, 1.0].into_iter().enumerate() {
        for start in 0..16 {
            let origin = Vec3::new(2.0 + start as f32 * 3.0, 0.5 * k as f32, 0.0);
            if let Some((start, end)) = inside_grid(&volume, origin, direction) {
                rays.push(Ray {
                    origin,
                    direction,
                    start,
                    end,
                    first: step * first,
                });
            }
        }
    }
    let march_with = |c: &Classification, rays: &[Ray]| {
        let mut out = vec![(Vec3::ZERO, 1.0); rays.len()];
        march_rays(
            specula::simd::Level::detect(),
            &prepared,
            c,
            None,
            rays,
            step,
            0.99,
            &mut out,
        );
        out
    };
    // More rays than a packet has lanes, so lanes take new rays as theirs end; each ray's
    // result is its march on its own.
    assert!(rays.len() > 2 * super::ray::LANES, "{} rays", rays.len());
    let together = march_with(&skipping, &rays);
    assert_eq!(together, march_with(&everything, &rays));
    for (ray, marched) in rays.iter().zip(&together) {
        let alone: Marched = march_with(&skipping, std::slice::from_ref(ray))[0];
        assert_eq!(alone, *marched);
    }
    assert!(
        together.iter().any(|(colour, _)| colour.x > 0.1),
        "some rays cross the ball"
    );
}

/// The packet on one lane (the baseline, which every CPU runs) and on the best instruction
/// set here march the same lit rays to the same results, within the rounding of fused
/// multiply-adds.
#[test]
fn every_instruction_set_marches_the_same_rays() {
    let volume = padded_head(24);
    let prepared = PreparedVolume::new(&volume);
    let transfer = TransferFunction::preset("mr").unwrap().for_volume(&volume);
    let classification = Classification::new(&prepared, &transfer);
    let lobe = Lobe::new(LobeKind::Pow, Exponent::new(24.0));
    for geometry in Geometry::ALL {
        let shading = Shading::new(lobe, geometry, Normalisation::None);
        let settings = DvrSettings::new(20, 14, View::Anterior, Some(shading));
        let (plan, rays, views) = lit_rays(&volume, &settings, |_, _| true);
        let lighting = plan.lighting.unwrap();
        let march = |level: Level| {
            let mut out = vec![(Vec3::ZERO, 1.0); rays.len()];
            let highlights = [Highlight::of(&lighting)];
            let lit = Lit {
                lighting: &lighting,
                views: &views,
                highlights: &highlights,
            };
            march_rays(
                level,
                &prepared,
                &classification,
                Some(lit),
                &rays,
                plan.step,
                0.99,
                &mut out,
            );
            out
        };
        let baseline = march(Level::Baseline);
        assert!(
            baseline
                .iter()
                .any(|(colour, _)| colour.max_element() > 0.05),
            "the rays cross the head"
        );
        for level in Level::available() {
            for (got, expected) in march(level).iter().zip(&baseline) {
                assert!(
                    (got.0 - expected.0).abs().max_element() < 1e-5
                        && (got.1 - expected.1).abs() < 1e-5,
                    "{level:?}, {geometry:?}: {got:?} against {expected:?}"
                );
            }
        }
    }
}

/// The clearance is the chessboard distance to the nearest occupied brick, as a search over
/// every pair of bricks finds it.
#[test]
fn clearance_is_the_chessboard_distance_to_the_nearest_occupied_brick() {
    // Random grids, and a long one with a single occupied brick at its end, whose far bricks
    // lie beyond the cap.
    let long = [22, 3, 2];
    for (dims, seed, density) in [
        ([9, 7, 6], 1_u32, 0.02_f32),
        ([9, 7, 6], 7, 0.1),
        ([9, 7, 6], 11, 0.0),
        ([9, 7, 6], 13, 0.5),
        (long, 0, 0.0),
    ] {
        let count = dims.iter().product::<usize>();
        let mut occupied: Vec<bool> = (0..count as u32)
            .map(|b| pixel_jitter(b, seed) < density)
            .collect();
        if dims == long {
            occupied[0] = true;
        }
        let position = |b: usize| [b % dims[0], b / dims[0] % dims[1], b / (dims[0] * dims[1])];
        let expected: Vec<u8> = (0..count)
            .map(|b| {
                let here = position(b);
                (0..count)
                    .filter(|&o| occupied[o])
                    .map(|o| {
                        let there = position(o);
                        (0..3).map(|a| here[a].abs_diff(there[a])).max().unwrap()
                    })
                    .min()
                    .map_or(super::MOST_CLEARANCE, |d| {
                        (d as u8).min(super::MOST_CLEARANCE)
                    })
            })
            .collect();
        assert_eq!(
            super::chessboard_distance(&occupied, dims),
            expected,
            "{dims:?}, seed {seed}"
        );
    }
}

/// The rays of a render, lit, that cross the grid (in grid units), with their views.
fn lit_rays(
    volume: &Volume,
    settings: &DvrSettings,
    keep: impl Fn(u32, u32) -> bool,
) -> (DvrPlan, Vec<Ray>, Vec<RayView>) {
    let plan = DvrPlan::new(volume, settings).unwrap();
    let lighting = plan.lighting.unwrap();
    let (width, height) = (settings.width, settings.height);
    let (mut rays, mut views) = (Vec::new(), Vec::new());
    for y in 0..height {
        for x in (0..width).filter(|&x| keep(x, y)) {
            let (origin, direction) = plan.camera.ray(x, y, width, height);
            let (o, d) = (volume.index(origin), volume.index_direction(direction));
            if let Some((start, end)) = inside_grid(volume, o, d) {
                rays.push(Ray {
                    origin: o,
                    direction: d,
                    start,
                    end,
                    first: plan.step * pixel_jitter(x, y),
                });
                views.push(RayView::new(&lighting, -direction));
            }
        }
    }
    (plan, rays, views)
}

/// Lit rays marched in lists of a tile's size (so that lanes run out of rays and idle again
/// and again) give each ray what it gets marched alone, up to the order its highlights are
/// summed in, whether rays end by their opacity or at the grid.
#[test]
fn lit_rays_marched_together_are_each_ray_marched_alone() {
    let volume = padded_head(24);
    let prepared = PreparedVolume::new(&volume);
    // n = 1: broad highlights, so that a highlight added to the wrong ray shows.
    let lobe = Lobe::new(LobeKind::Pow, Exponent::new(1.0));
    for (preset, cutoff) in [
        ("mr", 0.99),
        ("mr", 0.3),
        ("surface", 0.99),
        ("surface", 0.3),
    ] {
        let transfer = TransferFunction::preset(preset)
            .unwrap()
            .for_volume(&volume);
        let classification = Classification::new(&prepared, &transfer);
        let shading = Shading::new(lobe, Geometry::Blinn, Normalisation::None);
        let settings = DvrSettings::new(20, 14, View::Anterior, Some(shading));
        // The middle of the image, where every ray crosses the head.
        let (plan, rays, views) = lit_rays(&volume, &settings, |x, y| {
            (6..14).contains(&x) && (4..10).contains(&y)
        });
        let lighting = plan.lighting.unwrap();
        let march = |rays: &[Ray], views: &[RayView]| {
            let mut out = vec![(Vec3::ZERO, 1.0); rays.len()];
            let highlights = [Highlight::of(&lighting)];
            let lit = Lit {
                lighting: &lighting,
                views,
                highlights: &highlights,
            };
            march_rays(
                Level::detect(),
                &prepared,
                &classification,
                Some(lit),
                rays,
                plan.step,
                cutoff,
                &mut out,
            );
            out
        };
        for tile in (0..rays.len()).step_by(13) {
            let end = (tile + 13).min(rays.len());
            let together = march(&rays[tile..end], &views[tile..end]);
            for (r, got) in (tile..end).zip(&together) {
                let alone = march(&rays[r..=r], &views[r..=r])[0];
                assert!(
                    (got.0 - alone.0).abs().max_element() < 1e-5 && got.1 == alone.1,
                    "{preset}, cutoff {cutoff}, ray {r}: {got:?} together, {alone:?} alone"
                );
            }
        }
    }
}

/// A dense layer on the grid's far face, behind empty space: rays end at the grid a step
/// after crossing it, in every tile, and the march is the reference's.
#[test]
fn rays_ending_on_a_dense_far_face_are_the_reference() {
    use crate::transfer::{ControlPoint, Scale};
    let n = 16;
    let samples = (0..n * n * n)
        .map(|v| if v / (n * n) == n - 1 { 1.0 } else { 0.0 })
        .collect();
    let volume =
        Volume::centred([n; 3], Vec3::ONE, samples, crate::volume::Units::Arbitrary).unwrap();
    let point = |value, sigma| ControlPoint {
        value,
        sigma,
        colour: Vec3::ONE,
    };
    let transfer = TransferFunction::try_new(
        vec![point(0.0, 0.0), point(0.95, 0.0), point(1.0, 1000.0)],
        Scale::Absolute,
    )
    .unwrap();
    let lobe = Lobe::new(LobeKind::Pow, Exponent::new(24.0));
    let shading = Shading::new(lobe, Geometry::Blinn, Normalisation::None);
    let settings = DvrSettings::new(48, 48, View::Inferior, Some(shading));
    let (expected, errors) = against_the_reference(&volume, &transfer, &settings);
    let worst = errors.iter().copied().fold(0.0, f32::max);
    assert!(worst < 2e-3, "worst {worst}");
    assert!(
        expected.iter().any(|e| e.max_element() > 0.5),
        "the far face is seen"
    );
}

#[test]
fn classification_is_the_transfer_function() {
    let volume = BuiltIn::SheppLogan.make(16).unwrap();
    let prepared = PreparedVolume::new(&volume);
    for name in crate::transfer::PRESETS {
        let transfer = TransferFunction::preset(name).unwrap().for_volume(&volume);
        let classification = Classification::new(&prepared, &transfer);
        let (lo, hi) = volume.range();
        for k in 0..=20_000 {
            let value = lo - 0.1 + (hi - lo + 0.2) * k as f32 / 20_000.0;
            let (sigma, colour) = transfer.at(value);
            let got = classification.at(value);
            assert!(
                (got.x - sigma).abs() <= 1e-4 * (1.0 + sigma)
                    && (Vec3::new(got.y, got.z, got.w) - colour)
                        .abs()
                        .max_element()
                        < 1e-5,
                "{name} at {value}: {got} against {sigma} {colour}"
            );
        }
    }
}

/// Every lobe's image from one march is, bit for bit, the image marched for that lobe alone:
/// the samples, their colours and opacities are the lobe's no more than the light is.
#[test]
fn lobes_marched_together_are_each_marched_alone() {
    let volume = BuiltIn::SheppLogan.make(40).unwrap();
    let prepared = PreparedVolume::new(&volume);
    let transfer = TransferFunction::default_for(&volume).for_volume(&volume);
    let n = Exponent::new(32.0);
    let lobes: Vec<Lobe> = LobeKind::ALL
        .iter()
        .map(|&kind| Lobe::new(kind, n))
        .collect();
    for (geometry, normalisation, view) in [
        (Geometry::Blinn, Normalisation::ThesisPhong, View::Anterior),
        (Geometry::Phong, Normalisation::None, View::Left),
    ] {
        let shading = Shading::new(lobes[0], geometry, normalisation);
        let settings = DvrSettings::new(36, 28, view, Some(shading));
        let together =
            crate::dvr::render_dvr_lobes(&volume, &prepared, &transfer, &settings, &lobes, &|| {})
                .unwrap();
        assert_eq!(together.len(), lobes.len());
        let mut differ = 0;
        for (lobe, image) in lobes.iter().zip(&together) {
            let alone = DvrSettings {
                shading: Some(Shading::new(*lobe, geometry, normalisation)),
                ..settings
            };
            let alone = render_dvr(&volume, &transfer, &alone, &|| {}).unwrap();
            assert!(
                alone.pixels() == image.pixels(),
                "{lobe:?} {geometry:?}: marched with the others it differs"
            );
            differ += usize::from(image.pixels() != together[0].pixels());
        }
        // Not vacuous: the lobes' highlights differ.
        assert!(
            differ >= lobes.len() - 2,
            "{differ} images differ from pow's"
        );
    }
    let unshaded = DvrSettings::new(8, 8, View::Anterior, None);
    let refused =
        crate::dvr::render_dvr_lobes(&volume, &prepared, &transfer, &unshaded, &lobes, &|| {});
    assert!(refused.unwrap_err().0.contains("no lobe"));
}
