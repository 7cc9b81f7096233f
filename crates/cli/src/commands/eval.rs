//! `specula eval`: one lobe at one point, next to the exact `t^n`.

use serde::Serialize;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation, Zone};

use super::{print_json, CommandResult};
use crate::args::{parse_cosine, parse_degrees, parse_exponent, GeometryArg, LobeParser};
use crate::output::sig;

/// Arguments of `specula eval`.
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("point").required(true).args(["cos", "angle"])))]
pub struct Args {
    /// Lobe id, optionally with parameters (e.g. `cosquad:v=5`).
    #[arg(long, value_parser = LobeParser)]
    lobe: LobeKind,
    /// Specular exponent n, in [1, 1000].
    #[arg(long, value_parser = parse_exponent, allow_hyphen_values = true)]
    n: Exponent,
    /// The lobe's cosine t (R.V for Phong, N.H for Blinn), in [-1, 1].
    #[arg(long, value_parser = parse_cosine, allow_hyphen_values = true)]
    cos: Option<f64>,
    /// The angle from the lobe's axis, in degrees. Angle-native lobes (cheb2, cheb2-thesis,
    /// minimax2) take it directly, without an acos.
    #[arg(long, value_parser = parse_degrees, allow_hyphen_values = true)]
    angle: Option<f64>,
    /// Which cosine t is: R.V (phong) or N.H (blinn). It names the point and selects the
    /// normalisations listed.
    #[arg(long, value_enum, default_value_t)]
    geometry: GeometryArg,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct Evaluation {
    lobe: LobeKind,
    n: f64,
    geometry: Geometry,
    cosine_name: &'static str,
    t: f64,
    angle_deg: f64,
    zone: Zone,
    value: f64,
    value_f32: f32,
    reference: f64,
    abs_error: f64,
    rel_error: Option<f64>,
    normalisations: Vec<(&'static str, f64)>,
}

/// Evaluates and prints.
pub fn run(args: &Args) -> CommandResult {
    let lobe = Lobe::checked(args.lobe, args.n).map_err(|e| e.to_string())?;
    let geometry = Geometry::from(args.geometry);
    let (t, angle, value, value_f32) = match (args.cos, args.angle) {
        (Some(t), _) => (t, t.acos(), lobe.eval(t), lobe.eval(t as f32)),
        (None, Some(degrees)) => {
            let g = degrees.to_radians();
            (g.cos(), g, lobe.eval_angle(g), lobe.eval_angle(g as f32))
        }
        (None, None) => return Err("give --cos or --angle".to_owned()),
    };
    let reference = Lobe::new(LobeKind::Pow, args.n).eval(t);
    let abs_error = (value - reference).abs();
    let own = match geometry {
        Geometry::Phong => [
            Normalisation::Lobe,
            Normalisation::ThesisPhong,
            Normalisation::Lafortune,
        ],
        Geometry::Blinn => [
            Normalisation::Lobe,
            Normalisation::Blinn,
            Normalisation::BlinnApprox,
        ],
    };
    let mut normalisations: Vec<(&'static str, f64)> = own
        .iter()
        .map(|norm| (norm.id(), norm.constant_for(&lobe)))
        .collect();
    // Next to this lobe's own constant, the one of t^n: applying it to an approximation
    // scales the energy by the approximation's energy ratio.
    normalisations.insert(
        1,
        (
            "lobe, t^n's (n+1)/(2 pi)",
            Normalisation::Lobe.analytic(args.n),
        ),
    );
    let evaluation = Evaluation {
        lobe: args.lobe,
        n: args.n.get(),
        geometry,
        cosine_name: geometry.cosine_name(),
        t,
        angle_deg: angle.to_degrees(),
        zone: Zone::of_cos(t, args.n),
        value,
        value_f32,
        reference,
        abs_error,
        rel_error: (reference > 0.0).then(|| abs_error / reference),
        normalisations,
    };
    if args.json {
        return print_json(&evaluation);
    }
    let e = &evaluation;
    println!(
        "lobe        {} (n = {}, {} geometry)",
        e.lobe,
        e.n,
        geometry.id()
    );
    println!(
        "point       t = {} = {}, angle {} deg, {} zone",
        e.cosine_name,
        sig(e.t),
        sig(e.angle_deg),
        e.zone.name()
    );
    println!(
        "value       {} (f64)   {} (f32)",
        sig(e.value),
        sig(f64::from(e.value_f32))
    );
    println!("reference   t^n = {}", sig(e.reference));
    match e.rel_error {
        Some(rel) => println!(
            "error       {} absolute, {} relative",
            sig(e.abs_error),
            sig(rel)
        ),
        None => println!("error       {} absolute", sig(e.abs_error)),
    }
    for (name, constant) in &e.normalisations {
        println!(
            "N({name}) = {}   -> f = ks * {}",
            sig(*constant),
            sig(constant * e.value)
        );
    }
    Ok(())
}
