//! The real-time engines' specular, replaced: an ES module per engine that patches the
//! engine's own Phong material so that its specular is the lobe (`threejs.js`, `babylon.js`,
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
}

impl Engine {
    /// Every engine.
    pub const ALL: [Engine; 2] = [Engine::ThreeJs, Engine::Babylon];

    /// The name on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Engine::ThreeJs => "threejs",
            Engine::Babylon => "babylon",
        }
    }

    /// The module for `lobe`.
    pub fn write(
        self,
        lobe: &Lobe,
        geometry: Geometry,
        normalisation: Normalisation,
    ) -> Result<String, ExportError> {
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
        };
        let (n_note, n_range) = match range {
            Some(range) => (
                format!(
                    "n a uniform in {} (exported at n = {})",
                    specula_targets::code::describe_range(range),
                    lobe.exponent()
                ),
                format!("[{}, {}]", range[0], range[1]),
            ),
            None => (
                format!("n = {} baked in", lobe.exponent()),
                "null".to_owned(),
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
        let module = module.replace("{glsl}", &escaped(&glsl));
        Ok(module)
    }
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
