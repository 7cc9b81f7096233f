//! The structural scheme as an SVG block diagram, drawn from the datapath description:
//! one column per pipeline stage, one box per node (its name, operation and format), an arrow
//! from each operand to its reader. Constants are small tags under their readers; wiring-only
//! shifts are dashed boxes under the node they rewire.

use core::fmt::Write as _;

use crate::datapath::{operands, Datapath, NodeId, Op};
use crate::verilog::describe;

const BOX_WIDTH: f64 = 190.0;
const BOX_HEIGHT: f64 = 46.0;
const COLUMN: f64 = 240.0;
const ROW: f64 = 70.0;
const MARGIN: f64 = 30.0;

/// Escapes text for XML.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The diagram of `datapath`, titled `title`.
#[must_use]
pub fn svg(datapath: &Datapath, title: &str) -> String {
    let stages = datapath.stages();
    let nodes = datapath.nodes();
    let columns = stages.iter().copied().max().unwrap_or(0) as usize + 1;
    let mut rows_used = vec![0_usize; columns];
    let mut position = vec![(0.0, 0.0); nodes.len()];
    for (k, node) in nodes.iter().enumerate() {
        if matches!(node.op, Op::Const(_)) {
            continue;
        }
        let column = stages[k] as usize;
        let row = rows_used[column];
        rows_used[column] += 1;
        position[k] = (
            MARGIN + column as f64 * COLUMN,
            MARGIN + 40.0 + row as f64 * ROW,
        );
    }
    let height = MARGIN * 2.0 + 40.0 + rows_used.iter().copied().max().unwrap_or(1) as f64 * ROW;
    let width = MARGIN * 2.0 + columns as f64 * COLUMN;
    let mut v = String::new();
    let _ = writeln!(
        v,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}"
 viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="12">
<defs><marker id="arrow" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="7" markerHeight="7"
 orient="auto"><path d="M0,0 L10,5 L0,10 z" fill="#555"/></marker></defs>
<rect width="100%" height="100%" fill="white"/>
<text x="{MARGIN}" y="{}" font-size="15" font-weight="bold">{}</text>"##,
        MARGIN + 8.0,
        escape(title)
    );
    for column in 0..columns {
        let _ = writeln!(
            v,
            r##"<text x="{}" y="{}" fill="#888">{}</text>"##,
            MARGIN + column as f64 * COLUMN,
            MARGIN + 28.0,
            if column == 0 {
                "inputs (stage 0)".to_owned()
            } else {
                format!("stage {column}")
            }
        );
    }
    for (k, node) in nodes.iter().enumerate() {
        let (x, y) = position[k];
        let mut constants = Vec::new();
        for operand in operands(&node.op) {
            if let Op::Const(raw) = datapath.node(operand).op {
                let format = datapath.node(operand).format;
                constants.push(format!(
                    "{} = {}",
                    datapath.node(operand).name,
                    format.to_f64(raw)
                ));
                continue;
            }
            let (ox, oy) = position[operand.0];
            // Wiring in the same stage (a shift) hangs below its operand.
            let (x1, y1, x2, y2) = if ox == x {
                (
                    ox + BOX_WIDTH / 2.0,
                    oy + BOX_HEIGHT,
                    x + BOX_WIDTH / 2.0,
                    y,
                )
            } else {
                (
                    ox + BOX_WIDTH,
                    oy + BOX_HEIGHT / 2.0,
                    x,
                    y + BOX_HEIGHT / 2.0,
                )
            };
            let _ = writeln!(
                v,
                r##"<line x1="{x1}" y1="{y1}" x2="{x2}" y2="{y2}" stroke="#555"
 marker-end="url(#arrow)"/>"##
            );
        }
        if matches!(node.op, Op::Const(_)) {
            continue;
        }
        let dashed = if matches!(node.op, Op::Shift(..)) {
            r#" stroke-dasharray="4 3""#
        } else {
            ""
        };
        let fill = match node.op {
            Op::Input => "#e8f0fe",
            Op::Rom { .. } => "#fdf2e0",
            Op::Log2(..) | Op::Exp2Neg(..) => "#e9f7ec",
            _ => "#f4f4f4",
        };
        let output =
            datapath.wired_source(datapath.output()) == NodeId(k) || datapath.output() == NodeId(k);
        let stroke = if output { "#c0392b" } else { "#333" };
        let _ = writeln!(
            v,
            r##"<rect x="{x}" y="{y}" width="{BOX_WIDTH}" height="{BOX_HEIGHT}" rx="6" fill="{fill}"
 stroke="{stroke}"{dashed}/>
<text x="{}" y="{}" font-weight="bold">{} <tspan font-weight="normal" fill="#666">{}</tspan></text>
<text x="{}" y="{}">{}</text>"##,
            x + 8.0,
            y + 17.0,
            escape(&node.name),
            node.format.name(),
            x + 8.0,
            y + 35.0,
            escape(&shorten(&describe(datapath, &node.op)))
        );
        if !constants.is_empty() {
            let _ = writeln!(
                v,
                r##"<text x="{}" y="{}" fill="#888" font-size="10">{}</text>"##,
                x + 4.0,
                y + BOX_HEIGHT + 12.0,
                escape(&constants.join(", "))
            );
        }
    }
    v.push_str("</svg>\n");
    v
}

/// Long descriptions (a multiplexer's eight inputs) cut to fit the box.
fn shorten(text: &str) -> String {
    const MAX: usize = 28;
    if text.chars().count() <= MAX {
        text.to_owned()
    } else {
        format!("{}...", text.chars().take(MAX - 3).collect::<String>())
    }
}
