//! The report's longer paragraphs, kept as text beside the code (`prose/`, one file a
//! paragraph, wrapped as prose is) so that they read and change as text rather than as Rust
//! string literals. A paragraph names where a figure goes, `{name}`; [`fill`] puts the figures
//! in and refuses a placeholder left empty or a figure with no place, so a template and its
//! caller cannot drift apart unnoticed (every report runs every paragraph: the quick report's
//! test reads them all).

use core::fmt::Display;

/// What "Which lobe when" answers, and how.
pub(crate) const VERDICT: &str = include_str!("prose/verdict.txt");
/// How the real scans are drawn.
pub(crate) const REAL_SCANS: &str = include_str!("prose/real-scans.txt");
/// How the phantom is drawn.
pub(crate) const PHANTOM: &str = include_str!("prose/phantom.txt");
/// What the hardware section's datapaths are.
pub(crate) const HARDWARE: &str = include_str!("prose/hardware.txt");
/// How the environment-lit renders are made.
pub(crate) const ENVIRONMENT: &str = include_str!("prose/environment.txt");
/// How VTK and specula are set up alike on the real scans.
pub(crate) const VTK_SETUP: &str = include_str!("prose/vtk-setup.txt");
/// How the VTK comparison's figures are obtained.
pub(crate) const VTK_FIGURES: &str = include_str!("prose/vtk-figures.txt");
/// The measured materials' section.
pub(crate) const MATERIALS: &str = include_str!("prose/materials.txt");
/// The designed lobes' section.
pub(crate) const DESIGNED: &str = include_str!("prose/designed.txt");
/// How the verdict's FPGA rows are costed.
pub(crate) const FPGA_ROWS: &str = include_str!("prose/fpga-rows.txt");
/// How the lobes reach other renderers.
pub(crate) const OTHER_RENDERERS: &str = include_str!("prose/other-renderers.txt");
/// What the white furnace and reciprocity columns measure.
pub(crate) const WHITE_FURNACE: &str = include_str!("prose/white-furnace.txt");
/// A measured material's polar plot.
pub(crate) const MATERIAL_POLAR: &str = include_str!("prose/material-polar.txt");
/// How cost is stated.
pub(crate) const COST: &str = include_str!("prose/cost.txt");
/// What the gradient's error does to each lobe.
pub(crate) const GRADIENT_ERROR: &str = include_str!("prose/gradient-error.txt");

/// `template` as one paragraph (its lines joined by spaces), each `{name}` replaced by the
/// figure given for `name`; an error for a placeholder without a figure or a figure without
/// a placeholder.
pub(crate) fn fill(template: &str, figures: &[(&str, &dyn Display)]) -> Result<String, String> {
    let mut text = template.split_whitespace().collect::<Vec<_>>().join(" ");
    for (name, value) in figures {
        let placeholder = format!("{{{name}}}");
        if !text.contains(&placeholder) {
            return Err(format!("the report's prose has no place for {placeholder}"));
        }
        text = text.replace(&placeholder, &value.to_string());
    }
    if let Some(start) = text.find('{') {
        let rest = &text[start..];
        let end = rest.find('}').map_or(rest.len(), |k| k + 1);
        return Err(format!(
            "the report's prose leaves {} without a figure",
            &rest[..end]
        ));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::fill;

    #[test]
    fn placeholders_are_filled_and_checked_both_ways() {
        let template = "a {side} x {side}\nimage,   {what}";
        assert_eq!(
            fill(template, &[("side", &64), ("what", &"shaded")]),
            Ok("a 64 x 64 image, shaded".to_owned())
        );
        assert!(fill(template, &[("side", &64)])
            .unwrap_err()
            .contains("{what}"));
        let extra = fill(template, &[("side", &64), ("what", &1), ("more", &2)]);
        assert!(extra.unwrap_err().contains("{more}"));
    }

    /// Every paragraph's braces are placeholders: no stray or unclosed brace.
    #[test]
    fn every_template_has_well_formed_placeholders() {
        for template in [
            super::VERDICT,
            super::PHANTOM,
            super::HARDWARE,
            super::ENVIRONMENT,
            super::REAL_SCANS,
            super::VTK_SETUP,
            super::VTK_FIGURES,
            super::MATERIALS,
            super::DESIGNED,
            super::FPGA_ROWS,
            super::OTHER_RENDERERS,
        ] {
            let mut open = false;
            for c in template.chars() {
                match c {
                    '{' => {
                        assert!(!open, "nested brace in {template}");
                        open = true;
                    }
                    '}' => {
                        assert!(open, "stray brace in {template}");
                        open = false;
                    }
                    c if open => assert!(c.is_alphanumeric() || c == '_', "{template}"),
                    _ => {}
                }
            }
            assert!(!open, "unclosed brace in {template}");
        }
    }
}
