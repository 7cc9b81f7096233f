//! A small, well-formed HTML (also valid XML) page builder.

use core::fmt::Write as _;

/// Escapes text for HTML.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A table with a header row; cells are escaped.
pub fn table(header: &[&str], rows: &[Vec<String>]) -> String {
    table_with_files(header, rows, &[])
}

/// A table whose cells in `file_columns` name files beside the page, each a link to its file.
pub fn table_with_files(header: &[&str], rows: &[Vec<String>], file_columns: &[usize]) -> String {
    let mut html = String::from("<table><thead><tr>");
    for h in header {
        let _ = write!(html, "<th>{}</th>", escape(h));
    }
    html.push_str("</tr></thead><tbody>");
    for row in rows {
        html.push_str("<tr>");
        for (column, cell) in row.iter().enumerate() {
            let cell = escape(cell);
            if file_columns.contains(&column) {
                let _ = write!(html, "<td><a href=\"{cell}\">{cell}</a></td>");
            } else {
                let _ = write!(html, "<td>{cell}</td>");
            }
        }
        html.push_str("</tr>");
    }
    html.push_str("</tbody></table>\n");
    html
}

/// A large image (a diagram wider than the page) shown at its own size, so that its text stays
/// as large as it was drawn, in a frame that scrolls sideways; linked to itself.
pub fn linked_figure(file: &str, caption: &str) -> String {
    format!(
        "<figure class=\"wide\"><div class=\"scrolls\"><a href=\"{0}\"><img src=\"{0}\" \
            alt=\"{1}\"/></a></div><figcaption>{1} (select it to open it alone)</figcaption>\
            </figure>\n",
        escape(file),
        escape(caption)
    )
}

/// An image (a file beside the page) with a caption, a link to the file itself: every plot and
/// render on the page opens alone at full size in one click.
pub fn figure(file: &str, caption: &str) -> String {
    format!(
        "<figure><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"/></a><figcaption>{1}</figcaption>\
            </figure>\n",
        escape(file),
        escape(caption)
    )
}

/// Figures side by side, as many to a row as the page's width holds at `min_width` pixels
/// each (small multiples).
pub fn multiples(figures: &str, min_width: u32) -> String {
    format!(
        "<div class=\"multiples\" \
            style=\"grid-template-columns:repeat(auto-fill,minmax({min_width}px,1fr))\">\n{figures}\
            </div>\n"
    )
}

/// One image of a comparison: a lobe's render and, below it, its difference from the
/// reference, each a link to its full-size file.
#[derive(Clone, Debug)]
pub struct Tile {
    /// What the tile shows (a lobe's id).
    pub label: String,
    /// The label's colour swatch (the lobe's plot colour).
    pub colour: [u8; 3],
    /// The image's file.
    pub image: String,
    /// The difference map's file, if any (none for the reference).
    pub difference: Option<String>,
    /// The figures under the images.
    pub caption: String,
}

/// Tiles in a grid that wraps at the page's width.
pub fn tiles(tiles: &[Tile]) -> String {
    let mut html = String::from("<div class=\"tiles\">\n");
    for tile in tiles {
        let [r, g, b] = tile.colour;
        let _ = write!(
            html,
            "<figure class=\"tile\"><figcaption><span class=\"swatch\" \
                style=\"background:rgb({r},{g},{b})\"></span>{}</figcaption>",
            escape(&tile.label)
        );
        for (file, what) in std::iter::once((&tile.image, ""))
            .chain(tile.difference.iter().map(|file| (file, " difference")))
        {
            let _ = write!(
                html,
                "<a href=\"{0}\"><img src=\"{0}\" alt=\"{1}{what}\"/></a>",
                escape(file),
                escape(&tile.label)
            );
        }
        let _ = writeln!(html, "<p>{}</p></figure>", escape(&tile.caption));
    }
    html.push_str("</div>\n");
    html
}

/// A horizontal colour bar for difference maps: `stops` evenly spaced colours from 0 to
/// `scale`, labelled at both ends and the middle, with what it measures; `id` names its
/// gradient (unique on the page).
pub fn colour_bar(id: &str, stops: &[[u8; 3]], scale: f64, what: &str) -> String {
    let mut gradient = String::new();
    let last = stops.len().saturating_sub(1).max(1);
    for (k, [r, g, b]) in stops.iter().enumerate() {
        let _ = write!(
            gradient,
            "<stop offset=\"{:.3}\" stop-color=\"rgb({r},{g},{b})\"/>",
            k as f64 / last as f64
        );
    }
    format!(
        "<figure class=\"colour-bar\" id=\"{id}\" data-scale=\"{scale}\"><svg \
            xmlns=\"http://www.w3.org/2000/svg\" width=\"320\" height=\"34\" role=\"img\" \
            aria-label=\"{what}: 0 to {max}\">\
<defs><linearGradient id=\"{id}-gradient\">{gradient}</linearGradient></defs>\
<rect x=\"10\" y=\"0\" width=\"300\" height=\"14\" fill=\"url(#{id}-gradient)\" stroke=\"#888\"/>\
<text x=\"10\" y=\"30\" font-size=\"12\" text-anchor=\"start\">0</text>\
<text x=\"160\" y=\"30\" font-size=\"12\" text-anchor=\"middle\">{mid}</text>\
<text x=\"310\" y=\"30\" font-size=\"12\" text-anchor=\"end\">{max} or more</text></svg>\
<figcaption>{what}</figcaption></figure>\n",
        id = escape(id),
        what = escape(what),
        mid = scale / 2.0,
        max = scale,
    )
}

/// A paragraph of escaped text.
pub fn paragraph(text: &str) -> String {
    format!("<p>{}</p>\n", escape(text))
}

/// The answer a section leads with: short lines, set apart.
pub fn answer(lines: &[String]) -> String {
    let mut html = String::from("<div class=\"answer\"><ul>");
    for line in lines {
        let _ = write!(html, "<li>{}</li>", escape(line));
    }
    html.push_str("</ul></div>\n");
    html
}

/// The page's style sheet, beside this file.
const STYLE: &str = include_str!("report.css");

/// Reports on the browser's console any image that failed to load or decode (a moved page, a
/// broken SVG): what `.ci/browser-check` looks for. Written without `<` and `&`, so the page
/// stays well-formed XML.
const CHECK_IMAGES: &str = "window.addEventListener('load', function () { \
Array.prototype.forEach.call(document.images, function (img) { \
if (!img.complete || img.naturalWidth === 0) { console.error('image failed to load: ' + \
img.getAttribute('src')); } \
}); });";

/// The whole page: a table of contents that stays at hand beside the sections, then the
/// footer.
pub fn page(title: &str, sections: &[(String, String)], footer: &str) -> String {
    let mut html = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"/>\
         <meta name=\"viewport\" content=\"width=device-width, \
         initial-scale=1\"/><title>{0}</title>\
         <style>{STYLE}</style></head><body>\n<div class=\"layout\">\n<nav \
         class=\"toc\"><strong>{0}</strong><ol>",
        escape(title)
    );
    for (k, (heading, _)) in sections.iter().enumerate() {
        let _ = write!(
            html,
            "<li><a href=\"#s{}\">{}</a></li>",
            k + 1,
            escape(heading)
        );
    }
    let _ = write!(html, "</ol></nav>\n<main>\n<h1>{}</h1>\n", escape(title));
    for (k, (heading, body)) in sections.iter().enumerate() {
        let _ = write!(
            html,
            "<section id=\"s{}\"><h2>{}. {}</h2>\n{body}</section>\n",
            k + 1,
            k + 1,
            escape(heading)
        );
    }
    let _ = write!(
        html,
        "<footer>{footer}</footer>\n</main>\n</div>\n<script>{CHECK_IMAGES}</script>\n</body></html\
            >\n"
    );
    html
}
