//! The report's real materials (those of `--materials DIR`, else the five specula carries):
//! each measured material (an RGL isotropic RGB `.bsdf` file) assessed as `specula fit
//! --material` assesses it (every lobe and GGX fitted, the verdict on a target), its
//! shared-`n` fits in a table, polar plots of the measurement against the fits in the plane
//! of incidence, and renders under the sky of the measured material beside pow's fit, the
//! verdict's lobe and GGX, each scored by FLIP against the measured render.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use specula::measured::fit::{
    plane_of_incidence, Fit, Normals, Sharing, Specular, POLAR_ANGLES_DEGREES,
};
use specula::measured::MeasuredBrdf;
use specula::LobeKind;
use specula_render::ibl::{Environment, SKY_WIDTH};
use specula_render::measured::{
    load_measured, material_name, material_scene, render_comparison, BUNDLED_MATERIALS,
};

use super::html::{escape, figure, paragraph, table};
use super::polar::{Polar, PolarCurve, PolarPanel, DASHED, DASH_DOT};
use super::prose;
use super::sections::colour;
use super::stored;
use super::{Context, MATERIALS};
use specula_decide::material::{
    assess, assess_model, lobes_to_fit, luminance, parameter_text, verdict_line, Assessment,
    FitRow, Model, DEFAULT_MARGIN,
};
use specula_decide::Target;

/// The most materials one report shows (the first, by file name).
pub const MAX_MATERIALS: usize = 16;

/// The bundled materials' render width and samples per pixel (`--quick`'s for a folder).
const BUNDLED_RENDERS: (u32, u32) = (128, 8);

/// The verdict's target (`specula fit`'s default) and margin over pow's fit error.
const TARGET: Target = Target::GpuNvidia;
const MARGIN: f64 = DEFAULT_MARGIN;

/// Light directions per polar curve (every half degree).
const POLAR_POINTS: usize = 361;

/// How far beyond the measurement's largest radius the polar plots reach (a fit's spike
/// beyond is clipped at the rim).
const POLAR_HEADROOM: f64 = 1.25;

/// GGX's colour in the polar plots: a grey lighter than fastpow's, drawn dash-dot.
const GGX_GREY: plotters::style::RGBColor = plotters::style::RGBColor(150, 150, 150);

/// The `.bsdf` files in `directory` sorted by name, at most [`MAX_MATERIALS`], and how many
/// more there were.
pub(crate) fn material_files(directory: &Path) -> Result<(Vec<PathBuf>, usize), String> {
    let refuse = |e: std::io::Error| {
        format!(
            "{}: cannot read the materials folder: {e}",
            directory.display()
        )
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(directory).map_err(refuse)? {
        let path = entry.map_err(refuse)?.path();
        if path.extension().is_some_and(|e| e == "bsdf") && path.is_file() {
            files.push(path);
        }
    }
    if files.is_empty() {
        return Err(format!(
            "{}: no .bsdf files (--materials takes a folder of RGL isotropic RGB .bsdf files)",
            directory.display()
        ));
    }
    files.sort();
    let more = files.len().saturating_sub(MAX_MATERIALS);
    files.truncate(MAX_MATERIALS);
    Ok((files, more))
}

/// Refuses a bad `--materials` before any section runs: every file shown must read as a
/// material, and the user's lobes must hold over the fits' range of `n`.
pub(crate) fn check(directory: &Path, yours: &[LobeKind]) -> Result<(), String> {
    let (files, _) = material_files(directory)?;
    for file in &files {
        load_measured(file)?;
    }
    lobes_to_fit(yours, TARGET).map(drop)
}

/// A material's name as part of a file name: letters, digits, `-` and `_` kept.
fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// The section, or a run's of this build on the same lobes: the bundled materials' fits and
/// renders are functions of those alone ([`stored`]); a folder of the user's, whose files
/// no key covers, is assessed anew.
pub fn materials(context: &mut Context) -> Result<String, String> {
    if context.materials.is_some() {
        return assessed(context);
    }
    // The verdicts' costs are NVIDIA's compiler's (or the model's where it is missing): the
    // compiler found is part of the key.
    let basis = specula_decide::gpu_basis(TARGET, None)?.unwrap_or_default();
    stored::section(context, MATERIALS, &basis, assessed)
}

/// Each material in turn (assessed in parallel, each assessment's fits in parallel too),
/// those of `--materials`, else the five specula carries (`data/rgl`, built into the binary),
/// so that a report without a folder still answers for real materials.
fn assessed(context: &mut Context) -> Result<String, String> {
    let (materials, folder, more) = match context.materials.clone() {
        Some(directory) => {
            let (files, more) = material_files(&directory)?;
            let read = files
                .into_iter()
                .map(|file| Ok((load_measured(&file)?, file)))
                .collect::<Result<Vec<_>, String>>()?;
            (read, directory.display().to_string(), more)
        }
        None => {
            // Asked for by no one, so kept cheap: the quick report's render sizes in either
            // mode (the fits, the same in both, are most of the time).
            context.sizes.materials = BUNDLED_RENDERS;
            (
                bundled()?,
                "data/rgl (the five specula carries, built into it; --materials DIR fits others)"
                    .to_owned(),
                0,
            )
        }
    };
    let yours = context.yours();
    let kinds = lobes_to_fit(&yours, TARGET)?;
    let sky = Environment::sky(SKY_WIDTH);
    let assessed = materials
        .par_iter()
        .map(|(measured, path)| assess(measured, path, &kinds, TARGET, MARGIN))
        .collect::<Result<Vec<_>, String>>()?;
    let microfacet = materials
        .par_iter()
        .map(|(measured, path)| {
            assess_model(measured, path, &kinds, TARGET, MARGIN, Model::Microfacet)
        })
        .collect::<Result<Vec<_>, String>>()?;
    let mut shown = String::new();
    let mut error_measure = String::new();
    for (index, ((measured, path), assessment)) in materials.iter().zip(&assessed).enumerate() {
        shown += &material(context, index, path, measured, assessment, &sky)?;
        error_measure.clone_from(&assessment.error_measure);
    }
    shown += &super::microfacet_table::microfacet_section(&microfacet, &kinds);
    let (width, spp) = context.sizes.materials;
    let height = material_scene(width).settings.height;
    let more = if more > 0 {
        format!("; {more} more .bsdf files not shown, as a report shows at most {MAX_MATERIALS}")
    } else {
        String::new()
    };
    let mut html = paragraph(&prose::fill(
        prose::MATERIALS,
        &[
            ("folder", &folder),
            ("count", &materials.len()),
            ("more", &more),
            ("error_measure", &error_measure),
            ("target", &TARGET),
            ("margin", &(100.0 * MARGIN)),
            ("width", &width),
            ("height", &height),
            ("spp", &spp),
        ],
    )?);
    html += &shown;
    Ok(html)
}

/// The materials specula carries, read from the binary, each named by its file in `data/rgl`.
fn bundled() -> Result<Vec<(MeasuredBrdf, PathBuf)>, String> {
    BUNDLED_MATERIALS
        .iter()
        .map(|&(name, bytes)| {
            let file = Path::new("data/rgl").join(format!("{name}.bsdf"));
            let measured =
                MeasuredBrdf::from_bytes(bytes).map_err(|e| format!("{}: {e}", file.display()))?;
            Ok((measured, file))
        })
        .collect()
}

/// The shape parameter's name: `n` for a lobe, `alpha` for GGX and Beckmann.
fn parameter_name(specular: Specular) -> &'static str {
    if specular.takes_alpha() {
        "alpha"
    } else {
        "n"
    }
}

fn triple(v: [f64; 3]) -> String {
    format!("{:.3}/{:.3}/{:.3}", v[0], v[1], v[2])
}

/// Each lobe's shared-`n` fit in its better geometry (in the fits' order), then GGX's.
fn shown_fits(a: &Assessment) -> Vec<&FitRow> {
    let mut best: Vec<&FitRow> = Vec::new();
    let mut ggx = None;
    for row in a.fits.iter().filter(|r| r.fit.sharing == Sharing::Shared) {
        match row.fit.specular {
            Specular::Lobe { kind, .. } => {
                let same = best.iter_mut().find(
                    |b| matches!(b.fit.specular, Specular::Lobe { kind: k, .. } if k == kind),
                );
                match same {
                    Some(b) if row.fit.error < b.fit.error => *b = row,
                    Some(_) => {}
                    None => best.push(row),
                }
            }
            Specular::Ggx => ggx = Some(row),
            // The microfacet model's fits are its own table's.
            Specular::Microfacet { .. } => {}
        }
    }
    best.extend(ggx);
    best
}

/// One material: what it is, the verdict, the table, the polar plots and the renders.
fn material(
    context: &mut Context,
    index: usize,
    path: &Path,
    measured: &MeasuredBrdf,
    a: &Assessment,
    sky: &Environment,
) -> Result<String, String> {
    let name = material_name(path);
    let prefix = format!("material-{}-{}", index + 1, file_safe(&name));
    let shown = shown_fits(a);
    let mut html = format!("<h3>{}</h3>\n", escape(&name));
    html += &paragraph(&format!(
        "{} ({}): measured albedo at normal incidence {} (luminance {:.3}); compared at {} \
            direction pairs. Verdict on {}: {}.",
        a.description,
        a.file,
        triple(a.measured_albedo_at_normal),
        luminance(a.measured_albedo_at_normal),
        a.pairs,
        TARGET,
        verdict_line(a),
    ));
    html += &fits_table(a, &shown);
    html += &polar(context, &prefix, &name, measured, &shown)?;
    html += &renders(context, &prefix, &name, measured, a, &shown, sky)?;
    Ok(html)
}

fn fits_table(a: &Assessment, shown: &[&FitRow]) -> String {
    let chosen = &a.fits[a.chosen].fit;
    let rows: Vec<Vec<String>> = shown
        .iter()
        .map(|row| {
            let fit = &row.fit;
            let per_channel = a
                .fits
                .iter()
                .find(|r| r.fit.specular == fit.specular && r.fit.sharing == Sharing::PerChannel)
                .map_or_else(
                    || "-".to_owned(),
                    |r| {
                        format!(
                            "{:.5} ({} {})",
                            r.fit.error,
                            parameter_name(r.fit.specular),
                            parameter_text(&r.fit)
                        )
                    },
                );
            let albedo = luminance(row.albedo_at_normal);
            vec![
                fit.specular.label(),
                parameter_text(fit),
                format!("{:.5}", fit.error),
                format!("{:.3}", row.relative_to_pow),
                format!("{:.3}", row.relative_to_ggx),
                if albedo > 1.0 {
                    format!("{albedo:.3} (creates energy)")
                } else {
                    format!("{albedo:.3}")
                },
                if fit == chosen {
                    "yes: the verdict".to_owned()
                } else if row.meets {
                    "yes".to_owned()
                } else if fit.specular == Specular::Ggx {
                    "-".to_owned()
                } else {
                    "no".to_owned()
                },
                per_channel,
            ]
        })
        .collect();
    table(
        &[
            "model",
            "n (alpha for ggx)",
            "E",
            "E vs pow (same geometry)",
            "E vs GGX",
            "albedo at normal incidence",
            "meets",
            "one n per channel: E (n or alpha r/g/b)",
        ],
        &rows,
    )
}

/// The cube root of the luminance of `f cos theta_i` (0 where it dips below).
fn radius(f_cos: glam::DVec3) -> f64 {
    luminance(f_cos.to_array()).max(0.0).cbrt()
}

/// The polar plots at [`POLAR_ANGLES_DEGREES`], one figure of three panels.
fn polar(
    context: &mut Context,
    prefix: &str,
    name: &str,
    measured: &MeasuredBrdf,
    shown: &[&FitRow],
) -> Result<String, String> {
    let curve_of = |f: &dyn Fn(glam::DVec3, glam::DVec3) -> glam::DVec3, theta_o: f64| {
        plane_of_incidence(theta_o, POLAR_POINTS)
            .into_iter()
            .map(|(elevation, wo, wi)| (elevation, radius(f(wo, wi))))
            .collect::<Vec<_>>()
    };
    let panels = POLAR_ANGLES_DEGREES
        .iter()
        .map(|&degrees| {
            let theta_o = degrees.to_radians();
            let mut curves = vec![PolarCurve {
                name: "measured".to_owned(),
                points: curve_of(&|wo, wi| measured.f_cos(wo, wi), theta_o),
                colour: plotters::style::BLACK,
                opacity: 0.4,
                width: 6,
                dash: &[],
            }];
            for row in shown {
                let fit: &Fit = &row.fit;
                let (colour, dash) = match fit.specular {
                    Specular::Lobe { kind, .. } => (
                        colour(kind),
                        if kind.line_style().dashed {
                            DASHED
                        } else {
                            &[]
                        },
                    ),
                    Specular::Microfacet {
                        normals: Normals::Lobe(kind),
                    } => (colour(kind), DASH_DOT),
                    Specular::Ggx | Specular::Microfacet { .. } => (GGX_GREY, DASH_DOT),
                };
                let model = fit.prepare();
                curves.push(PolarCurve {
                    name: fit.specular.label(),
                    points: curve_of(&|wo, wi| model.f_cos(wo, wi), theta_o),
                    colour,
                    opacity: 1.0,
                    width: 2,
                    dash,
                });
            }
            PolarPanel {
                title: format!("viewed from {degrees}°"),
                viewer: theta_o,
                curves,
            }
        })
        .collect();
    let svg = Polar {
        panels,
        headroom: POLAR_HEADROOM,
    }
    .to_svg()?;
    let file = format!("{prefix}-polar.svg");
    context.write(&file, svg.as_bytes())?;
    let angles: Vec<String> = POLAR_ANGLES_DEGREES
        .iter()
        .map(|d| format!("{d}°"))
        .collect();
    Ok(figure(
        &file,
        &prose::fill(
            prose::MATERIAL_POLAR,
            &[
                ("name", &name),
                ("angles", &angles.join(", ")),
                ("headroom", &POLAR_HEADROOM),
            ],
        )?,
    ))
}

/// The measured material rendered beside pow's fit, the verdict's lobe and GGX (each the
/// one-`n` fit), each captioned with its mean FLIP against the measured render; then every
/// model, small.
fn renders(
    context: &mut Context,
    prefix: &str,
    name: &str,
    measured: &MeasuredBrdf,
    a: &Assessment,
    shown: &[&FitRow],
    sky: &Environment,
) -> Result<String, String> {
    let pow = shown
        .iter()
        .find(|r| {
            matches!(
                r.fit.specular,
                Specular::Lobe {
                    kind: LobeKind::Pow,
                    ..
                }
            )
        })
        .ok_or("no pow fit")?;
    let ggx = shown
        .iter()
        .find(|r| r.fit.specular == Specular::Ggx)
        .ok_or("no GGX fit")?;
    let chosen = &a.fits[a.chosen];
    let mut models: Vec<(&FitRow, &str)> = vec![(pow, "pow's best fit")];
    if chosen.fit != pow.fit {
        models.push((chosen, "the verdict's lobe"));
    } else {
        models[0].1 = "pow's best fit, the verdict";
    }
    models.push((ggx, "GGX"));
    let fits: Vec<&Fit> = models.iter().map(|(row, _)| &row.fit).collect();
    let (width, spp) = context.sizes.materials;
    let images = render_comparison(measured, &fits, sky, width, spp, &|_, _| {})?;
    let scene = material_scene(width);
    let mut html = String::new();
    for (k, render) in images.iter().enumerate() {
        let file = format!("{prefix}-{}.png", file_safe(&render.label));
        let caption = if k == 0 {
            format!("{name}, measured")
        } else {
            let (row, role) = models[k - 1];
            let parameter = parameter_name(row.fit.specular);
            format!(
                "{} ({role}, {parameter} = {}): mean FLIP {:.4} against the measured render",
                render.label,
                parameter_text(&row.fit),
                render.mean_flip
            )
        };
        html += &context.png(&file, &render.image, &scene, &caption)?;
    }
    html += &every_fit(context, prefix, measured, shown, sky)?;
    Ok(html)
}

/// Every lobe's one-`n` fit (in its better geometry) and GGX rendered small beside the
/// measured material, each with its mean FLIP against the measured render at that size.
fn every_fit(
    context: &mut Context,
    prefix: &str,
    measured: &MeasuredBrdf,
    shown: &[&FitRow],
    sky: &Environment,
) -> Result<String, String> {
    let (width, spp) = context.sizes.materials;
    let (width, spp) = ((width / 2).max(16), (spp / 4).max(4));
    let fits: Vec<&Fit> = shown.iter().map(|row| &row.fit).collect();
    let images = render_comparison(measured, &fits, sky, width, spp, &|_, _| {})?;
    let scene = material_scene(width);
    let mut html = paragraph(&format!(
        "Every model beside the measurement ({width}x{}, {spp} samples per pixel), each with its \
            mean FLIP against the measured render at that size:",
        scene.settings.height
    ));
    for render in &images {
        let file = format!("{prefix}-small-{}.png", file_safe(&render.label));
        let caption = if render.label == "measured" {
            "measured".to_owned()
        } else {
            format!("{}: FLIP {:.4}", render.label, render.mean_flip)
        };
        html += &context.png(&file, &render.image, &scene, &caption)?;
    }
    Ok(html)
}
