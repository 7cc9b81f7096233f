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
    let mut html = String::from("<table><thead><tr>");
    for h in header {
        let _ = write!(html, "<th>{}</th>", escape(h));
    }
    html.push_str("</tr></thead><tbody>");
    for row in rows {
        html.push_str("<tr>");
        for cell in row {
            let _ = write!(html, "<td>{}</td>", escape(cell));
        }
        html.push_str("</tr>");
    }
    html.push_str("</tbody></table>\n");
    html
}

/// A large image shown at page width, linked to itself at full size.
pub fn linked_figure(file: &str, caption: &str) -> String {
    format!(
        "<figure><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"/></a><figcaption>{1} (select it for full size)</figcaption></figure>\n",
        escape(file),
        escape(caption)
    )
}

/// An image (a file beside the page) with a caption.
pub fn figure(file: &str, caption: &str) -> String {
    format!(
        "<figure><img src=\"{}\" alt=\"{}\"/><figcaption>{}</figcaption></figure>\n",
        escape(file),
        escape(caption),
        escape(caption)
    )
}

/// A paragraph of escaped text.
pub fn paragraph(text: &str) -> String {
    format!("<p>{}</p>\n", escape(text))
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}\
table{border-collapse:collapse;margin:1em 0;font-size:0.9em}\
th,td{border:1px solid #ccc;padding:0.25em 0.6em;text-align:left}\
th{background:#f2f2f2}figure{display:inline-block;margin:0.5em;vertical-align:top}\
img{max-width:100%}figcaption{font-size:0.85em;color:#555}code{background:#f5f5f5}\
.holds{color:#1a7f37}.qualified{color:#9a6700}.fails{color:#cf222e}footer{margin-top:3em;font-size:0.85em;color:#666}";

/// Reports on the browser's console any image that failed to load or decode (a moved page, a
/// broken SVG): what `.ci/browser-check` looks for. Written without `<` and `&`, so the page
/// stays well-formed XML.
const CHECK_IMAGES: &str = "window.addEventListener('load', function () { \
Array.prototype.forEach.call(document.images, function (img) { \
if (!img.complete || img.naturalWidth === 0) { console.error('image failed to load: ' + img.getAttribute('src')); } \
}); });";

/// The whole page.
pub fn page(title: &str, sections: &[(String, String)], footer: &str) -> String {
    let mut html = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"/><title>{}</title>\
         <style>{STYLE}</style></head><body>\n<h1>{}</h1>\n<nav><ol>",
        escape(title),
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
    html.push_str("</ol></nav>\n");
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
        "<footer>{footer}</footer>\n<script>{CHECK_IMAGES}</script>\n</body></html>\n"
    );
    html
}
