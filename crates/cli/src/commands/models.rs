//! `specula models`: the registry as a table.

use serde::Serialize;
use specula::lobe::{LobeInfo, LobeKind};
use specula::ops::OpCounts;
use specula::{Exponent, Lobe};

use super::{print_json, CommandResult};
use crate::args::{parse_exponent, OutputFormat};
use crate::output::Table;

/// Arguments of `specula models`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The exponent at which operations are counted (some lobes' cost depends on n).
    #[arg(long, allow_hyphen_values = true, default_value = "100", value_parser = parse_exponent)]
    n: Exponent,
    /// Output format.
    #[arg(long, value_enum, default_value_t)]
    format: OutputFormat,
}

#[derive(Serialize)]
struct ModelRow {
    #[serde(flatten)]
    info: &'static LobeInfo,
    ops_at_n: f64,
    ops: OpCounts,
    ops_total: u32,
}

/// Prints the registry.
pub fn run(args: &Args) -> CommandResult {
    let rows: Vec<ModelRow> = LobeKind::ALL
        .into_iter()
        .map(|kind| {
            let ops = Lobe::new(kind, args.n).ops();
            ModelRow {
                info: kind.info(),
                ops_at_n: args.n.get(),
                ops,
                ops_total: ops.total(),
            }
        })
        .collect();
    match args.format {
        OutputFormat::Json => print_json(&rows),
        OutputFormat::Csv => {
            print_csv(&rows);
            Ok(())
        }
        OutputFormat::Table => {
            let ops_header = format!("ops at n = {}", args.n);
            let mut table = Table::new(&[
                "id",
                "origin",
                "input",
                "params",
                "formula",
                &ops_header,
                "total",
            ]);
            for row in &rows {
                let params: Vec<String> = row
                    .info
                    .params
                    .iter()
                    .map(|p| format!("{}={} [{}..{}]", p.name, p.default, p.min, p.max))
                    .collect();
                let mut cells = identity(row.info).to_vec();
                cells.extend([
                    params.join(" "),
                    row.info.formula.to_owned(),
                    row.ops.to_string(),
                    row.ops_total.to_string(),
                ]);
                table.push(cells);
            }
            table.print(args.format);
            Ok(())
        }
    }
}

/// The registry as data: the ids and texts, then one column per kind of operation (at the
/// exponent asked for) and their total, numbers where the table writes a list.
fn print_csv(rows: &[ModelRow]) {
    let ops = OpCounts::default()
        .entries()
        .map(|(name, _)| format!("ops {name}"));
    let mut header = vec!["id", "origin", "input", "formula", "ops at n"];
    header.extend(ops.iter().map(String::as_str));
    header.push("ops total");
    let mut table = Table::new(&header);
    for row in rows {
        let mut cells = identity(row.info).to_vec();
        cells.extend([row.info.formula.to_owned(), row.ops_at_n.to_string()]);
        cells.extend(row.ops.entries().map(|(_, count)| count.to_string()));
        cells.push(row.ops_total.to_string());
        table.push(cells);
    }
    table.print(OutputFormat::Csv);
}

/// A model's id, origin and input (`angle` or `cosine`), as both tables begin.
fn identity(info: &LobeInfo) -> [String; 3] {
    let input = if info.takes_angle { "angle" } else { "cosine" };
    [
        info.id.to_owned(),
        info.origin.name().to_owned(),
        input.to_owned(),
    ]
}
