//! `specula serve`: the BRDF explorer (`crates/serve`), served by the binary itself.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;

use std::collections::HashMap;
use std::sync::Mutex;

use indicatif::ProgressBar;
use specula::{Exponent, Lobe};
use specula_decide::design::{default_whole_error, design, Bounds, DesignRequest};
use specula_decide::Target;
use specula_serve::{cpu_cost, DesignModel, DesignQuery, Materials, TargetRate};

use super::CommandResult;

/// Arguments of `specula serve`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The port to listen on (0 picks a free one).
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// The address to listen on; anything but loopback exposes the explorer to the network.
    #[arg(long, default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    bind: IpAddr,
    /// Open the explorer in the default browser.
    #[arg(long)]
    open: bool,
    /// A folder of measured materials (RGL isotropic RGB `.bsdf` files) that the explorer's
    /// measured-materials view offers beside the five bundled ones: the files directly in it,
    /// listed at start-up (at most 64), offered by name (a file named like a bundled material
    /// takes its place); each is fitted at its first request (seconds) and kept.
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
}

/// Serves until Ctrl-C.
pub fn run(args: &Args) -> CommandResult {
    let materials = match &args.data {
        Some(folder) => {
            let (materials, notes) = Materials::bundled().with_folder(folder)?;
            for line in notes {
                eprintln!("note: {line}");
            }
            materials
        }
        None => Materials::bundled(),
    };
    let names: Vec<&str> = materials.names().collect();
    println!(
        "{} measured materials (the bundled ones{}): {}",
        names.len(),
        args.data
            .as_ref()
            .map(|folder| format!(" and {}", folder.display()))
            .unwrap_or_default(),
        names.join(", ")
    );
    specula_serve::serve(
        SocketAddr::new(args.bind, args.port),
        args.open,
        Arc::new(costs),
        designer(),
        Arc::new(|lobe: &Lobe, gpu| {
            let answer = specula_isa::compare(lobe, gpu, specula_isa::Work::Lobe)
                .map_err(|e| e.to_string())?;
            serde_json::to_value(answer).map_err(|e| e.to_string())
        }),
        materials,
    )
}

/// The most designs a server runs: each registers its families' formulas for the life of
/// the process (the formula registry is bounded), so a design asked again is answered from
/// memory, and new ones beyond this are refused.
const MAX_DESIGNS: usize = 64;

/// `specula design`'s answer as JSON for the explorer, each query designed once.
fn designer() -> DesignModel {
    let answered: Mutex<HashMap<String, serde_json::Value>> = Mutex::new(HashMap::new());
    Arc::new(move |query: &DesignQuery| {
        let key = format!("{query:?}");
        if let Some(answer) = answered.lock().map_err(|e| e.to_string())?.get(&key) {
            return Ok(answer.clone());
        }
        if answered.lock().map_err(|e| e.to_string())?.len() >= MAX_DESIGNS {
            return Err(format!(
                "this server has designed {MAX_DESIGNS} lobes, its limit; ask one of those again, \
                    or restart specula serve"
            ));
        }
        let target: Target = query.target.parse().map_err(|e: String| e)?;
        let n = |value: f64| Exponent::try_new(value).map_err(|e| e.to_string());
        let request = DesignRequest {
            target,
            gpu: None,
            range: (n(query.range.0)?, n(query.range.1)?),
            bounds: Bounds {
                epicentre: query.max_error,
                whole: default_whole_error(query.max_error),
                energy: None,
            },
            no_transcendentals: false,
            also: Vec::new(),
            max_operations: specula_decide::design::grammar::default_max_operations(target),
        };
        let answer = design(&request, &ProgressBar::hidden())?;
        let value = serde_json::to_value(&answer).map_err(|e| e.to_string())?;
        answered
            .lock()
            .map_err(|e| e.to_string())?
            .insert(key, value.clone());
        Ok(value)
    })
}

/// A lobe's costs: the CPU's counted SIMD instructions and each GPU vendor's current
/// generation as `recommend` costs it (the machine code its compiler writes, or the model
/// where the compiler is missing, which the unit says).
pub fn costs(lobe: &Lobe) -> Result<Vec<TargetRate>, String> {
    let gpus = Target::GPUS.into_iter().map(|target| {
        let gpu = target.gpu(None)?.map_or("", |gpu| gpu.id);
        Ok(TargetRate {
            target: target.id().to_owned(),
            value: specula_decide::lobe_rate(target, lobe)?,
            unit: format!(
                "{gpu}: {} (higher is better)",
                specula_decide::rate_unit(target)
            ),
        })
    });
    std::iter::once(Ok(cpu_cost(lobe))).chain(gpus).collect()
}
