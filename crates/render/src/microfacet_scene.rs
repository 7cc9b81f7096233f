//! The environment-lit renderer in the microfacet model (`specula render --env sky --model
//! microfacet`): each scene material's lobe as the normal distribution of the microfacet
//! model, `kd C / pi + ks F(wo.h) D(h) G2 / (4 cos_o cos_i)` with `F0` the specular colour, as
//! the rasterizer's microfacet model draws it (`material.rs`), written as the fitted model it
//! is ([`Fit`] with [`Specular::Microfacet`]) and drawn one sample at a time in `f64` by the
//! estimator the measured materials' fits use ([`FittedReflectance`]: the cosine or the
//! distribution's normals, in proportion to the two terms' albedos).

use specula::measured::fit::{Fit, Normals, Sharing, Specular};

use crate::ibl::{render_ibl_each, Environment, IblSettings, Reflectance};
use crate::image::Image;
use crate::material::Material;
use crate::measured::FittedReflectance;
use crate::pipeline::RenderError;
use crate::scene::Scene;

/// `material` in the microfacet model, as a fit of that model (its error 0).
#[must_use]
pub fn microfacet_fit(material: &Material) -> Fit {
    let diffuse = material.kd * material.colour;
    Fit {
        specular: Specular::Microfacet {
            normals: Normals::Lobe(material.lobe.kind()),
        },
        sharing: Sharing::Shared,
        parameter: [material.lobe.exponent().get(); 3],
        kd: diffuse.as_dvec3().to_array(),
        k: [f64::from(material.ks); 3],
        f0: Some(material.specular_colour.as_dvec3().to_array()),
        error: 0.0,
        channel_error: [0.0; 3],
    }
}

/// `scene` lit by `environment` with every material in the microfacet model.
pub fn render_ibl_microfacet(
    scene: &Scene,
    environment: &Environment,
    settings: &IblSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Image, RenderError> {
    let reflectances: Vec<FittedReflectance> = scene
        .objects
        .iter()
        .map(|object| FittedReflectance::new(&microfacet_fit(&object.material)))
        .collect();
    let each: Vec<&dyn Reflectance> = reflectances.iter().map(|r| r as &dyn Reflectance).collect();
    render_ibl_each(scene, environment, settings, &each, progress)
}
