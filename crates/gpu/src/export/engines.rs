//! The real-time engines' specular, replaced: a module per engine that patches the engine's
//! own Phong shading so that its specular is the lobe (`threejs.js`, `babylon.js`, `vtk.py`,
//! their manual pages). The lobe's functions in them are the GLSL ES 3.00 export (and, for
//! three.js's node materials, the WGSL export) of the lobe's one recorded expression, with `n`
//! as an argument where the lobe's constants and the normalisation are closed forms of it.

use specula::{Geometry, Lobe, Normalisation};

use super::{functions_taking_n_where_possible, ExportError, Language};

/// A real-time engine whose Phong material the export patches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Engine {
    /// three.js: `MeshPhongMaterial` (WebGLRenderer) and `MeshPhongNodeMaterial` (TSL).
    ThreeJs,
    /// Babylon.js: a `MaterialPluginBase` for `StandardMaterial`.
    Babylon,
    /// VTK: `vtkShaderProperty` replacements of the power in its GPU ray caster's and its
    /// polydata mapper's Phong specular (3D Slicer's, ParaView's).
    Vtk,
}

impl Engine {
    /// Every engine.
    pub const ALL: [Engine; 3] = [Engine::ThreeJs, Engine::Babylon, Engine::Vtk];

    /// The name on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Engine::ThreeJs => "threejs",
            Engine::Babylon => "babylon",
            Engine::Vtk => "vtk",
        }
    }

    /// The module for `lobe`.
    pub fn write(
        self,
        lobe: &Lobe,
        geometry: Geometry,
        normalisation: Normalisation,
    ) -> Result<String, ExportError> {
        if self == Engine::Vtk && normalisation != Normalisation::None {
            return Err(ExportError {
                language: "vtk",
                message: "VTK's Phong specular has no normalisation (ks pow(t, n)), and the \
                          module replaces only the power: leave --normalisation at none"
                    .to_owned(),
            });
        }
        if self == Engine::Vtk && geometry != Geometry::Phong {
            return Err(ExportError {
                language: "vtk",
                message: "VTK forms the specular cosine itself (Phong's reflection vector; the \
                          surface headlight's N.V); the module replaces only the power: leave \
                          --geometry at phong"
                    .to_owned(),
            });
        }
        let functions =
            |language| functions_taking_n_where_possible(lobe, geometry, normalisation, language);
        let glsl = functions(Language::Glsl)?;
        let range = glsl.n_range;
        let taking_n = range.is_some();
        // The engines' shaders state their own precision.
        let glsl: String = glsl
            .text
            .lines()
            .filter(|line| !line.starts_with("precision "))
            .collect::<Vec<_>>()
            .join("\n");
        let call = |prefix: &str| {
            let n = if taking_n {
                format!("{prefix}n, ")
            } else {
                String::new()
            };
            move |normal: &str, wo: &str, wi: &str| {
                format!("specula_specular({n}{normal}, {wo}, {wi})")
            }
        };
        let template = match self {
            Engine::ThreeJs => include_str!("threejs.js")
                .replace(
                    "{glsl_call}",
                    &call("specula_")("normal", "viewDir", "lightDir"),
                )
                .replace("{tsl_call}", &call("")("normal", "wo", "wi")),
            Engine::Babylon => include_str!("babylon.js")
                .replace("{glsl_call}", &call("specula_")("normal", "wo", "wi")),
            Engine::Vtk => vtk_module(&glsl, taking_n)?,
        };
        let (n_note, n_range) = match range {
            Some(range) => (
                format!(
                    "n a uniform in {} (exported at n = {})",
                    specula_targets::code::describe_range(range),
                    lobe.exponent()
                ),
                match self {
                    Engine::Vtk => format!("({:?}, {:?})", range[0], range[1]),
                    _ => format!("[{}, {}]", range[0], range[1]),
                },
            ),
            None => (
                format!("n = {} baked in", lobe.exponent()),
                match self {
                    Engine::Vtk => "None",
                    _ => "null",
                }
                .to_owned(),
            ),
        };
        let mut module = template
            .replace("{checked_n}", include_str!("checked_n.js"))
            .replace("{key}", &format!("SPECULA_{:08X}", fnv1a(&glsl)))
            .replace("{kind}", &lobe.kind().to_string())
            .replace("{n_note}", &n_note)
            .replace("{n_range}", &n_range)
            .replace("{n}", &format!("{}", lobe.exponent().get()))
            .replace("{geometry}", geometry.id())
            .replace("{normalisation}", normalisation.id())
            .replace("{cosine}", geometry.cosine_name());
        // The code last, so that no placeholder is looked for inside it.
        if self == Engine::ThreeJs {
            module = module.replace("{wgsl}", &escaped(&functions(Language::Wgsl)?.text));
        }
        let glsl = match self {
            Engine::Vtk => glsl,
            _ => escaped(&glsl),
        };
        Ok(module.replace("{glsl}", &glsl))
    }
}

/// The VTK module's template with its call of the lobe in pow's place (`specula_vtk(t, n)`)
/// and what the exponent does; the GLSL goes in a raw Python string.
fn vtk_module(glsl: &str, taking_n: bool) -> Result<String, ExportError> {
    if glsl.contains("'''") {
        return Err(ExportError {
            language: "vtk",
            message: "the GLSL holds ''' and cannot sit in the module's raw string".to_owned(),
        });
    }
    let (call, follows) = if taking_n {
        (
            "specula_normalisation(n) * specula_lobe(n, t)",
            "changing it (SetSpecularPower) changes the lobe's n at run time, within N_RANGE \
             (the shader clamps to it).",
        )
    } else {
        (
            "SPECULA_NORMALISATION * specula_lobe(t)",
            "it must stay at the exported n, for which the lobe's constants are fitted \
             (apply_to_* sets it; the shader ignores another).",
        )
    };
    Ok(include_str!("vtk.py")
        .replace("{vtk_call}", call)
        .replace("{n_follows}", follows))
}

/// `text` inside a JavaScript template literal.
fn escaped(text: &str) -> String {
    text.replace('\\', "\\\\")
        .replace('`', "\\`")
        .replace("${", "\\${")
}

/// FNV-1a, 32 bits: a short name for a text, so that an engine's cache of compiled programs
/// keeps one per exported text.
fn fnv1a(text: &str) -> u32 {
    text.bytes().fold(0x811c_9dc5, |hash, byte| {
        (hash ^ u32::from(byte)).wrapping_mul(0x0100_0193)
    })
}
