//! What the microfacet model adds to a lobe in the renderers: the distribution's normaliser,
//! its Smith masking as a table the CPU, the GPU and the browser all read, and Schlick's
//! Fresnel split into the parts `ks F0` and `ks` scale (the model itself: `material.rs`).

use glam::Vec3;
use specula::microfacet::Distribution;
use specula::Lobe;

/// Entries of the masking table [`MicrofacetTerms`] carries.
pub const MASKING_ENTRIES: usize = 64;

/// What the microfacet model adds to a lobe: its normaliser `C(n)`, its Smith masking as a
/// table both renderers read, and the specular scale that Fresnel's grazing part takes.
///
/// The table holds `G1 = 1 / (1 + Lambda)` from the distribution's own `Lambda`
/// (`specula::microfacet`) at [`MASKING_ENTRIES`] cosines `(k / 63)^2`, closer together
/// towards the horizon where `G1` falls to 0, read with linear interpolation in `sqrt(cos)`:
/// the CPU and the GPU interpolate the same `f32` numbers, so both draw the same masking
/// (within a stated bound of the distribution's, tested).
#[derive(Clone, Debug, PartialEq)]
pub struct MicrofacetTerms {
    normaliser: f32,
    grazing: Vec3,
    masking: [f32; MASKING_ENTRIES],
}

impl MicrofacetTerms {
    /// The terms of `lobe`'s distribution with Fresnel's grazing scale `ks`.
    #[must_use]
    pub fn new(lobe: &Lobe, ks: f32) -> Self {
        let distribution = Distribution::lobe(lobe.kind(), lobe.exponent());
        let last = (MASKING_ENTRIES - 1) as f64;
        Self {
            normaliser: distribution.d(1.0) as f32,
            grazing: Vec3::splat(ks),
            masking: core::array::from_fn(|k| {
                let x = k as f64 / last;
                distribution.g1(x * x) as f32
            }),
        }
    }

    /// The distribution's normaliser `C(n)`.
    #[must_use]
    pub fn normaliser(&self) -> f32 {
        self.normaliser
    }

    /// `ks`, per channel: the scale of Fresnel's `(1 - F0) (1 - wo.h)^5`.
    #[must_use]
    pub fn grazing(&self) -> Vec3 {
        self.grazing
    }

    /// The masking table, `G1` at the cosines `(k / 63)^2`.
    #[must_use]
    pub fn masking(&self) -> &[f32; MASKING_ENTRIES] {
        &self.masking
    }

    /// Smith's `G1` at a direction of cosine `cos` to the normal, from the table.
    #[must_use]
    pub fn g1(&self, cos: f32) -> f32 {
        let x = cos.clamp(0.0, 1.0).sqrt() * (MASKING_ENTRIES - 1) as f32;
        let at = (x as usize).min(MASKING_ENTRIES - 2);
        let fraction = x - at as f32;
        self.masking[at] + fraction * (self.masking[at + 1] - self.masking[at])
    }

    /// The lobe's value at `N.h` turned into the model's specular factor per unit intensity,
    /// from `N.wo`, `N.wi` and `wo.h`, split by Schlick's grazing weight `S = (1 - wo.h)^5`:
    /// `(C(n) lobe G2 / (4 N.wo) (1 - S), the same times S)`, which `ks F0` and `ks` scale
    /// (`Shader::microfacet_contribution`); both 0 where either direction is below the
    /// horizon.
    #[must_use]
    pub fn split(&self, lobe: f32, [cos_out, cos_in, cos_half]: [f32; 3]) -> (f32, f32) {
        if cos_out <= 0.0 || cos_in <= 0.0 || lobe == 0.0 {
            return (0.0, 0.0);
        }
        let base = self.normaliser * lobe * self.g2(cos_out, cos_in) / (4.0 * cos_out);
        let s = schlick_weight(cos_half);
        (base * (1.0 - s), base * s)
    }

    /// [`MicrofacetTerms::split`] over a batch: `lobe` becomes the first factor and `grazing`
    /// the second. `Lambda` is a table lookup, so this loop is scalar.
    pub fn factors(
        &self,
        [cos_out, cos_in, cos_half]: [&[f32]; 3],
        lobe: &mut [f32],
        grazing: &mut [f32],
    ) {
        for (i, (value, grazing)) in lobe.iter_mut().zip(grazing.iter_mut()).enumerate() {
            (*value, *grazing) = self.split(*value, [cos_out[i], cos_in[i], cos_half[i]]);
        }
    }

    /// The height-correlated `G2 = 1 / (1 + Lambda_o + Lambda_i)` of directions with cosines
    /// `cos_o` and `cos_i`, from the table's `G1`s (`Lambda = 1 / G1 - 1`); 0 where either
    /// is fully masked.
    #[must_use]
    pub fn g2(&self, cos_o: f32, cos_i: f32) -> f32 {
        let (a, b) = (self.g1(cos_o), self.g1(cos_i));
        let denominator = a + b - a * b;
        if denominator > 0.0 {
            a * b / denominator
        } else {
            0.0
        }
    }
}

/// Schlick's `(1 - cos)^5`, the grazing weight of his Fresnel.
#[must_use]
fn schlick_weight(cos: f32) -> f32 {
    let m = 1.0 - cos.clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

#[cfg(test)]
mod tests {
    use specula::{Exponent, LobeKind};

    use super::*;

    /// The masking table's `G2` against the distribution's own (its `Lambda` table, built by
    /// quadrature), for every built-in lobe from rough to sharp: the bound was measured,
    /// then stated.
    #[test]
    fn the_masking_table_keeps_the_distributions_g2() {
        let mut worst = 0.0_f64;
        for kind in LobeKind::ALL {
            for n in [1.0, 8.0, 64.0, 1000.0] {
                let lobe = Lobe::new(kind, Exponent::new(n));
                let terms = MicrofacetTerms::new(&lobe, 1.0);
                let exact = specula::microfacet::Distribution::lobe(kind, Exponent::new(n));
                for i in 1..=200 {
                    for j in [1, 5, 20, 60, 120, 200] {
                        let (a, b) = (f64::from(i) / 200.0, f64::from(j) / 200.0);
                        let table = f64::from(terms.g2(a as f32, b as f32));
                        worst = worst.max((table - exact.g2(a, b)).abs());
                    }
                }
            }
        }
        // Measured: 2.6e-3 at worst over these cases.
        assert!(worst < 4e-3, "G2 off by {worst}");
    }
}
