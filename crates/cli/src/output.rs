//! Plain-text tables and CSV for the commands' results; figures as text are the report's
//! (`specula_report::format`), so the page and the tables write them alike.

pub use specula_report::format::{percent, sig};

/// A number as data: every digit `f64` holds (the shortest text that reads back as the same
/// number), in exponent form where it is very small or large.
#[must_use]
pub fn number(value: f64) -> String {
    format!("{value:?}")
}

/// A table of strings with a header row.
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these column names.
    pub fn new(header: &[&str]) -> Self {
        Self {
            header: header.iter().map(|h| (*h).to_owned()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row (one cell per column).
    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.header.len());
        self.rows.push(row);
    }

    /// Aligned columns: text left, numbers right.
    pub fn render(&self) -> String {
        let widths: Vec<usize> = (0..self.header.len())
            .map(|c| {
                self.rows
                    .iter()
                    .map(|r| r[c].chars().count())
                    .chain([self.header[c].len()])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let numeric: Vec<bool> = (0..self.header.len())
            .map(|c| !self.rows.is_empty() && self.rows.iter().all(|r| looks_numeric(&r[c])))
            .collect();
        let line = |cells: &[String]| {
            let padded: Vec<String> = cells
                .iter()
                .zip(&widths)
                .zip(&numeric)
                .map(|((cell, &w), &right)| {
                    if right {
                        format!("{cell:>w$}")
                    } else {
                        format!("{cell:<w$}")
                    }
                })
                .collect();
            padded.join("  ").trim_end().to_owned()
        };
        let mut out = line(&self.header);
        out.push('\n');
        out.push_str(
            &widths
                .iter()
                .map(|&w| "-".repeat(w))
                .collect::<Vec<_>>()
                .join("  "),
        );
        out.push('\n');
        for row in &self.rows {
            out.push_str(&line(row));
            out.push('\n');
        }
        out
    }

    /// RFC 4180 CSV.
    pub fn csv(&self) -> String {
        let line = |cells: &[String]| {
            cells
                .iter()
                .map(|c| csv_field(c))
                .collect::<Vec<_>>()
                .join(",")
        };
        let mut out = line(&self.header);
        out.push('\n');
        for row in &self.rows {
            out.push_str(&line(row));
            out.push('\n');
        }
        out
    }
}

impl Table {
    /// Prints as CSV for `OutputFormat::Csv`, aligned columns otherwise.
    pub fn print(&self, format: crate::args::OutputFormat) {
        if format == crate::args::OutputFormat::Csv {
            print!("{}", self.csv());
        } else {
            print!("{}", self.render());
        }
    }
}

fn looks_numeric(cell: &str) -> bool {
    let trimmed = cell.trim_end_matches('%');
    trimmed.parse::<f64>().is_ok()
}

fn csv_field(cell: &str) -> String {
    if cell.contains([',', '"', '\n']) {
        format!("\"{}\"", cell.replace('"', "\"\""))
    } else {
        cell.to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_quotes_only_what_needs_it() {
        let mut table = Table::new(&["a", "b"]);
        table.push(vec!["x, y".into(), "1".into()]);
        assert_eq!(table.csv(), "a,b\n\"x, y\",1\n");
    }
}
