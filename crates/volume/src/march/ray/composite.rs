//! A turn composited: each lane's sample made opaque, lit and added front to back, its
//! highlight gathered, and the gathered highlights' lobes evaluated together.

use glam::Vec3;
use specula::simd::{exp2_nonpositive, Lanes};

use super::{Highlight, Lane, Marched, Marching, Packet, Turn, HIGHLIGHTS, LANES};
use crate::lighting::LanesView;

/// Highlights waiting for their lobes: cosine, the light the sample carried, its fade, and
/// the ray they belong to.
pub(super) struct Highlights {
    ts: [f32; HIGHLIGHTS],
    carried: [f32; HIGHLIGHTS],
    fades: [f32; HIGHLIGHTS],
    rays: [usize; HIGHLIGHTS],
    gathered: usize,
}

impl Highlights {
    pub(super) const EMPTY: Self = Self {
        ts: [0.0; HIGHLIGHTS],
        carried: [0.0; HIGHLIGHTS],
        fades: [0.0; HIGHLIGHTS],
        rays: [0; HIGHLIGHTS],
        gathered: 0,
    };

    /// Evaluates each image's lobe at the gathered highlights and adds each, white, to its
    /// ray's colour in that image.
    #[inline(always)]
    pub(super) fn flush(&mut self, highlights: &[Highlight], out: &mut [Marched]) {
        let n = self.gathered;
        let images = highlights.len();
        let mut lobes = [0.0_f32; HIGHLIGHTS];
        for (image, highlight) in highlights.iter().enumerate() {
            highlight.lobe.eval_batch(&self.ts[..n], &mut lobes[..n]);
            for i in 0..n {
                let weight = self.carried[i] * (self.fades[i] * highlight.scale);
                out[self.rays[i] * images + image].0 += Vec3::splat(weight * lobes[i]);
            }
        }
        self.gathered = 0;
    }
}

/// The `W` lanes of `array` from `at`.
#[inline(always)]
fn load<V: Lanes>(lanes: V, array: &Lane<f32>, at: usize) -> V {
    lanes.load(&array[at..at + V::WIDTH])
}

/// [`load`] for three arrays.
#[inline(always)]
fn load3<V: Lanes>(lanes: V, arrays: &[Lane<f32>; 3], at: usize) -> [V; 3] {
    [
        load(lanes, &arrays[0], at),
        load(lanes, &arrays[1], at),
        load(lanes, &arrays[2], at),
    ]
}

impl<const FETCH: bool> Packet<'_, FETCH> {
    /// Composites each lane's sample front to back, lit, and gathers its highlight: a
    /// segment of `length` at extinction `sigma` is opaque by `1 - exp(-sigma length)`.
    #[inline(always)]
    pub(super) fn composite<V: Lanes>(
        &mut self,
        lanes: V,
        marching: &mut Marching,
        turn: &Turn,
        highlights: &mut Highlights,
    ) {
        let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
        let mut ts = [0.0_f32; LANES];
        let mut carried_light = [0.0_f32; LANES];
        let mut fades = [0.0_f32; LANES];
        for at in (0..LANES).step_by(V::WIDTH) {
            let sigma = load(lanes, &turn.sigma, at).max(zero);
            let length = load(lanes, &turn.length, at);
            let alpha =
                one - exp2_nonpositive(sigma * length * lanes.splat(-core::f32::consts::LOG2_E));
            let transmittance = load(lanes, &marching.transmittance, at);
            let carried = transmittance * alpha;
            (transmittance * (one - alpha)).store(&mut marching.transmittance[at..at + V::WIDTH]);
            let base = load3(lanes, &turn.base, at);
            let colour = load3(lanes, &marching.colour, at);
            let lit_scale = match self.lit {
                None => one,
                Some(lit) => {
                    let view = LanesView {
                        wo: load3(lanes, &marching.wo, at),
                        half: load3(lanes, &marching.half, at),
                        wi_dot_wo: load(lanes, &marching.wi_dot_wo, at),
                    };
                    let gradient = load3(lanes, &turn.gradient, at);
                    let light = lit.lighting.light_lanes(gradient, &view);
                    light.t.store(&mut ts[at..at + V::WIDTH]);
                    // Every lobe is 0 at a cosine of 0 or less; a lane that took no sample
                    // carried nothing (its weight is 0 and it is not gathered).
                    carried
                        .keep(light.t.gt(zero))
                        .store(&mut carried_light[at..at + V::WIDTH]);
                    light.fade.store(&mut fades[at..at + V::WIDTH]);
                    light.colour_scale
                }
            };
            // Written out rather than `array::map`: a closure a library function calls is
            // compiled without the level's instruction set. A lane that carried nothing adds
            // nothing, whatever its colour.
            let carrying = carried.gt(zero);
            for c in 0..3 {
                (colour[c] + (carried * (base[c] * lit_scale)).keep(carrying))
                    .store(&mut marching.colour[c][at..at + V::WIDTH]);
            }
        }
        let Some(lit) = self.lit else { return };
        for k in 0..LANES {
            let at = highlights.gathered;
            highlights.ts[at] = ts[k];
            highlights.carried[at] = carried_light[k];
            highlights.fades[at] = fades[k];
            highlights.rays[at] = marching.ray[k];
            highlights.gathered += usize::from(carried_light[k] * fades[k] > 0.0);
        }
        if highlights.gathered > HIGHLIGHTS - LANES {
            highlights.flush(lit.highlights, self.out);
        }
    }
}
