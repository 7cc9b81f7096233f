//! The prepared field: its samples are the volume's trilinear values and gradients, and the
//! compact layout is the exact one within its quantisation steps.

use super::tests::padded_head;
use super::*;
use crate::dvr::{render_dvr_prepared, DvrSettings, Shading, View};
use crate::phantom::BuiltIn;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};

/// `count` points of the unit cube spread evenly by three irrational steps.
fn spread_fractions(count: usize) -> impl Iterator<Item = Vec3> {
    (0..count).map(|k| {
        Vec3::new(
            (k as f32 * 0.618_034).fract(),
            (k as f32 * 0.414_214).fract(),
            (k as f32 * 0.732_051).fract(),
        )
    })
}

#[test]
fn prepared_samples_are_the_volumes_trilinear_values_and_gradients() {
    let volume = BuiltIn::SheppLogan.make(24).unwrap();
    let prepared = PreparedVolume::new(&volume);
    let last = volume.last_index();
    for fraction in spread_fractions(500) {
        // Points at least a voxel inside the grid, where both gradients see the same
        // neighbours.
        let p = Vec3::ONE + fraction * (last - 2.0);
        let sample = prepared.sample(p);
        assert!((sample.x - volume.sample(p)).abs() < 1e-5, "{p}");
        let gradient = Vec3::new(sample.y, sample.z, sample.w);
        assert!(
            (gradient - volume.gradient(p)).length() <= 1e-4 * (1.0 + gradient.length()),
            "{p}: {gradient} against {}",
            volume.gradient(p)
        );
    }
}

/// The compact layout holds each value and gradient within half its quantisation step
/// (the Shepp-Logan head's values are not whole numbers, so both are quantised), and marches
/// the image the exact layout does within the reference test's bounds.
#[test]
fn the_compact_layout_is_the_exact_one_within_its_steps() {
    let volume = padded_head(24);
    let exact = PreparedVolume::with_layout(&volume, Layout::Exact);
    let compact = PreparedVolume::with_layout(&volume, Layout::Compact);
    assert_eq!(exact.quantisation_error(), (0.0, Vec3::ZERO));
    let (value_error, gradient_error) = compact.quantisation_error();
    assert!(value_error > 0.0 && gradient_error.min_element() > 0.0);
    let last = volume.last_index();
    for fraction in spread_fractions(500) {
        let p = fraction * last;
        let (a, b) = (exact.sample(p), compact.sample(p));
        // Half a step, plus the f32 roundings of interpolating and scaling.
        let slack = 1e-5 * (1.0 + a.abs());
        assert!((a.x - b.x).abs() <= value_error + slack.x, "{p}: {a} {b}");
        for (c, step) in gradient_error.to_array().into_iter().enumerate() {
            assert!(
                (a[c + 1] - b[c + 1]).abs() <= step + slack[c + 1],
                "{p}: {a} {b}"
            );
        }
    }
    let transfer = TransferFunction::preset("mr").unwrap().for_volume(&volume);
    let lobe = Lobe::new(LobeKind::Pow, Exponent::new(24.0));
    let settings = DvrSettings::new(
        40,
        36,
        View::Anterior,
        Some(Shading::new(lobe, Geometry::Blinn, Normalisation::None)),
    );
    let draw = |prepared: &PreparedVolume| {
        render_dvr_prepared(&volume, prepared, &transfer, &settings, &|| {}).unwrap()
    };
    let (a, b) = (draw(&exact), draw(&compact));
    let errors: Vec<f32> = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .map(|(x, y)| (*x - *y).abs().max_element())
        .collect();
    let worst = errors.iter().copied().fold(0.0, f32::max);
    let mean = errors.iter().sum::<f32>() / errors.len() as f32;
    assert!(worst < 2e-3 && mean < 2e-4, "worst {worst}, mean {mean}");
}

/// The layout follows the volume's size.
#[test]
fn large_volumes_are_prepared_compact() {
    assert_eq!(Layout::for_voxels(256 * 256 * 108), Layout::Exact);
    assert_eq!(Layout::for_voxels(512 * 512 * 432), Layout::Compact);
}

/// A volume of whole numbers keeps them: the compact layout reads the volume's own integers
/// (the same allocation, not a copy), so its values are the exact layout's bit for bit and
/// only its gradients are quantised.
#[test]
fn whole_number_volumes_share_their_integers_with_the_compact_layout() {
    let head = padded_head(24);
    let thousandths: Vec<f32> = head
        .samples()
        .iter()
        .map(|v| (v * 1000.0).round())
        .collect();
    let volume = Volume::try_new(
        head.dims(),
        head.to_world(),
        head.origin(),
        thousandths,
        head.units(),
    )
    .unwrap();
    let Samples::Whole(held) = volume.samples() else {
        panic!("whole numbers within i16 are held as i16");
    };
    let compact = PreparedVolume::with_layout(&volume, Layout::Compact);
    let Voxels::Compact { values, .. } = &compact.voxels else {
        panic!("the compact layout was asked for");
    };
    assert!(std::sync::Arc::ptr_eq(held, values));
    assert_eq!(compact.quantisation_error().0, 0.0);
    let exact = PreparedVolume::with_layout(&volume, Layout::Exact);
    let last = volume.last_index();
    for fraction in spread_fractions(500) {
        let p = fraction * last;
        assert_eq!(exact.sample(p).x, compact.sample(p).x, "{p}");
    }
}

/// The classification last asked for is kept: the same transfer function gets the same one
/// back; another gets its own (the one `Classification::new` arranges), which is then kept.
#[test]
fn the_last_classification_is_kept_for_its_transfer_function() {
    let volume = padded_head(16);
    let prepared = PreparedVolume::new(&volume);
    let mr = TransferFunction::preset("mr").unwrap().for_volume(&volume);
    let surface = TransferFunction::preset("surface")
        .unwrap()
        .for_volume(&volume);
    let first = prepared.classification(&mr);
    assert!(Arc::ptr_eq(&first, &prepared.classification(&mr)));
    let other = prepared.classification(&surface);
    assert!(!Arc::ptr_eq(&first, &other));
    assert_eq!(
        other.clearance(),
        Classification::new(&prepared, &surface).clearance()
    );
    assert!(Arc::ptr_eq(&other, &prepared.classification(&surface)));
    assert_ne!(first.clearance(), other.clearance());
}

/// A cell marked transparent has no extinction anywhere inside it: on a smooth field under a
/// function with extinction in two windows (none below, between or above them), every point
/// of a 5 x 5 x 5 lattice across each marked cell classifies to 0 by the march's own table, in
/// both layouts; and more than a tenth of the occupied bricks' cells are marked.
#[test]
fn transparent_cells_have_no_extinction_anywhere() {
    use crate::transfer::{ControlPoint, Scale};
    let n = 20;
    let samples = (0..n * n * n)
        .map(|v| {
            let [i, j, k] = [v % n, v / n % n, v / (n * n)].map(|c| c as f32);
            (0.37 * i).sin() + (0.29 * j).cos() * (0.21 * k).sin()
        })
        .collect();
    let volume = Volume::centred(
        [n; 3],
        Vec3::new(1.0, 0.8, 1.3),
        samples,
        crate::volume::Units::Arbitrary,
    )
    .unwrap();
    let point = |value, sigma| ControlPoint {
        value,
        sigma,
        colour: Vec3::ONE,
    };
    let transfer = TransferFunction::try_new(
        vec![
            point(-2.0, 0.0),
            point(-0.5, 0.0),
            point(-0.3, 2.0),
            point(0.2, 0.0),
            point(0.6, 0.0),
            point(0.7, 5.0),
            point(0.9, 5.0),
            point(1.0, 0.0),
        ],
        Scale::Absolute,
    )
    .unwrap();
    let lattice: Vec<Vec3> = (0..125)
        .map(|c| Vec3::new((c % 5) as f32, (c / 5 % 5) as f32, (c / 25) as f32) * 0.25)
        .collect();
    for layout in [Layout::Exact, Layout::Compact] {
        let prepared = PreparedVolume::with_layout(&volume, layout);
        let classification = Classification::new(&prepared, &transfer);
        let [bx, by, _] = prepared.bricks();
        let (mut marked, mut occupied_cells) = (0, 0);
        for (brick, &mask) in classification.transparent.iter().enumerate() {
            if classification.clearance[brick] == 0 {
                occupied_cells += BRICK * BRICK * BRICK;
            }
            let first =
                [brick % bx, brick / bx % by, brick / (bx * by)].map(|b| (b * BRICK) as f32);
            for bit in (0..64).filter(|bit| mask >> bit & 1 == 1) {
                marked += 1;
                let cell = Vec3::new(
                    first[0] + (bit % BRICK) as f32,
                    first[1] + (bit / BRICK % BRICK) as f32,
                    first[2] + (bit / (BRICK * BRICK)) as f32,
                );
                for &f in &lattice {
                    let value = prepared.sample(cell + f).x;
                    let sigma = classification.at(value).x;
                    assert_eq!(sigma, 0.0, "{layout:?} {cell} + {f}: {value}");
                }
            }
        }
        assert!(
            10 * marked > occupied_cells,
            "{layout:?}: {marked} of {occupied_cells} cells marked"
        );
    }
}
