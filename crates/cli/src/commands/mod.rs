//! One module per subcommand: its arguments and what it prints.

pub mod analyze;
pub mod bench;
pub mod claims;
pub mod design;
pub mod diff;
pub mod eval;
pub mod fit;
pub mod hw;
pub mod isa;
pub mod lobe;
pub mod models;
pub mod recommend;
pub mod render;
pub mod report;
pub mod sample;
pub mod serve;
pub mod shader;
pub mod sky;
pub mod synth;
pub mod volume;

/// What a command reports when it fails: a one-line message.
pub type CommandResult = Result<(), String>;

/// Serialises `value` as pretty JSON followed by a newline.
pub fn print_json(value: &impl serde::Serialize) -> CommandResult {
    let text = serde_json::to_string_pretty(value).map_err(|e| e.to_string())?;
    println!("{text}");
    Ok(())
}
