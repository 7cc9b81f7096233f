//! A scatter chart's dots and their names, written as SVG after plotters' drawing: each dot a
//! circle titled with its name (a tooltip where the chart is opened on its own), each name
//! placed where the nearest dot to it is its own, so that a reader pairs every name with the
//! right dot (`.ci/explorer/report.mjs` measures it from these coordinates).
//!
//! Every length here is in the drawing's (supersampled) units.

use core::fmt::Write as _;

use super::{offset, px};
use crate::html::escape;

/// A dot's radius, displayed pixels.
pub(super) const DOT_RADIUS: u32 = 5;

/// The names' size, displayed pixels.
pub(crate) const NAME_SIZE: u32 = 11;

/// How much nearer a name must be to its own dot than to any other (2 displayed pixels): the
/// margin that keeps it so whatever the reader's font.
const NEARER_BY: i32 = offset(2);

/// One dot: its series' name, colour (`#RRGGBB`) and centre.
pub(super) struct Dot {
    pub name: String,
    pub colour: String,
    pub at: (i32, i32),
}

/// The gaps between a dot and its name tried, nearest first (displayed pixels), and the
/// directions tried at each.
const GAPS: [i32; 10] = [2, 4, 7, 11, 16, 23, 32, 44, 60, 80];
const DIRECTIONS: u32 = 24;

/// A box: left, top, right, bottom.
type Box = (i32, i32, i32, i32);

/// How a place breaks the rules: how many it breaks (weighted), how much it overlaps names
/// already placed, and how far it stands from its dot; the least is the best.
type Score = (i64, i64, f64);

/// A name as placed: the text, its box and how the text is anchored in it.
#[derive(Debug)]
pub(super) struct Placed {
    pub text: String,
    pub area: Box,
    pub anchor: Anchor,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Anchor {
    Start,
    Middle,
    End,
}

/// The width of `text` at [`NAME_SIZE`], generous: DejaVu Sans's advances (the widest of
/// the usual sans-serif faces, Chromium's on Debian) rounded up per class of character, so
/// that the text drawn stays inside its box in any of them.
fn text_width(text: &str) -> i32 {
    let ems: f64 = text
        .chars()
        .map(|c| match c {
            'i' | 'j' | 'l' | '.' | ',' | ':' | ' ' | '\'' | '|' => 0.33,
            'f' | 't' | 'r' | '-' | '(' | ')' => 0.42,
            'm' | 'w' | 'M' | 'W' => 1.0,
            'A'..='Z' => 0.78,
            _ => 0.65,
        })
        .sum();
    (ems * f64::from(px(NAME_SIZE))).ceil() as i32
}

/// Names sharing one name: joined by commas, and a run of one stem and a number (the quadratic
/// family: `quadratic-pow8`, `-pow16`, `-pow32`) as the stem once and the numbers by slashes
/// (`quadratic-pow8/16/32`), short enough to find room beside a crowded cluster.
fn joined(names: &[&str]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut run: Option<&str> = None;
    for &name in names {
        match (run, numbered(name)) {
            (Some(current), Some(own)) if current == own => {
                let last = parts.last_mut().expect("a run has its first part");
                last.push('/');
                last.push_str(&name[own.len()..]);
            }
            (_, own) => {
                parts.push(name.to_owned());
                run = own;
            }
        }
    }
    parts.join(", ")
}

/// `name` without the number it ends in, where it ends in one.
fn numbered(name: &str) -> Option<&str> {
    let stem = name.trim_end_matches(|c: char| c.is_ascii_digit());
    (stem.len() < name.len()).then_some(stem)
}

/// The distance from `point` to the nearest point of `area` (0 inside).
fn distance(point: (i32, i32), area: Box) -> f64 {
    let dx = (area.0 - point.0).max(point.0 - area.2).max(0);
    let dy = (area.1 - point.1).max(point.1 - area.3).max(0);
    f64::from(dx).hypot(f64::from(dy))
}

/// The distance between two points.
fn apart(a: (i32, i32), b: (i32, i32)) -> f64 {
    f64::from(a.0 - b.0).hypot(f64::from(a.1 - b.1))
}

fn overlap(a: Box, b: Box) -> i64 {
    let width = (a.2.min(b.2) - a.0.max(b.0)).max(0);
    let height = (a.3.min(b.3) - a.1.max(b.1)).max(0);
    i64::from(width) * i64::from(height)
}

/// Where each dot's name goes, inside `area`. Dots closer than a radius (one hides the other)
/// share one name. Each name tries places around its dots, nearest first, in [`DIRECTIONS`]
/// directions at widening gaps, and takes the nearest where its box covers no dot and no name
/// already placed and its own dot is nearer to it than any other dot (by [`NEARER_BY`]); where
/// no place is free it takes the one that breaks the fewest of those. The most crowded dots
/// choose first, while the room around them is still free. A name that found no place nearer
/// its own dot than another's is joined with the name of the dot it stands nearest, and one
/// that found no place free at all with a neighbour within six radii; then every name is
/// placed again: the joined name stands nearest one of its dots and lists them left to right.
pub(super) fn place(dots: &[Dot], area: Box) -> Vec<Placed> {
    let radius = f64::from(offset(DOT_RADIUS as i32));
    // Groups of dots that hide one another, by index.
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (k, dot) in dots.iter().enumerate() {
        let close = |j: &usize| apart(dots[*j].at, dot.at) < radius;
        match groups.iter_mut().find(|g| g.iter().any(close)) {
            Some(group) => group.push(k),
            None => groups.push(vec![k]),
        }
    }
    loop {
        let (placed, nearer) = place_groups(dots, &mut groups, area);
        // Each pass joins two groups, so this ends, at worst with one name for every dot.
        match nearer {
            Some((group, other)) if groups.len() > 1 => {
                let with = groups
                    .iter()
                    .position(|g| g.contains(&other))
                    .expect("every dot is in a group");
                let joined = groups[with].clone();
                groups[group].extend(joined);
                groups.remove(with);
            }
            _ => return placed,
        }
    }
}

/// Each group's name placed, the most crowded first (`groups` left in that order), and the
/// first group, if any, to be joined with a neighbour (see [`place`]), with that neighbour.
fn place_groups(
    dots: &[Dot],
    groups: &mut [Vec<usize>],
    area: Box,
) -> (Vec<Placed>, Option<(usize, usize)>) {
    let radius = offset(DOT_RADIUS as i32);
    let crowd = |group: &[usize]| {
        let (at, near) = (dots[group[0]].at, 8.0 * f64::from(radius));
        dots.iter().filter(|d| apart(d.at, at) < near).count()
    };
    groups.sort_by_key(|g| core::cmp::Reverse(crowd(g)));
    let height = offset(14);
    let mut placed: Vec<Placed> = Vec::new();
    let mut nearer = None;
    for (index, group) in groups.iter_mut().enumerate() {
        // Left to right, so that a joined name reads in the dots' order.
        group.sort_by_key(|&k| dots[k].at.0);
        let mut names: Vec<&str> = Vec::new();
        for &k in group.iter() {
            if !names.contains(&dots[k].name.as_str()) {
                names.push(&dots[k].name);
            }
        }
        let text = joined(&names);
        let width = text_width(&text);
        let mut best: Option<(Score, Box, Anchor, Option<usize>)> = None;
        // Around each of the group's dots, so that a joined name can stand beside the
        // outermost.
        let around = group.iter().flat_map(|&k| {
            GAPS.iter()
                .flat_map(move |&gap| (0..DIRECTIONS).map(move |step| (dots[k].at, gap, step)))
        });
        for (centre, gap, step) in around {
            let angle = f64::from(step) * core::f64::consts::TAU / f64::from(DIRECTIONS);
            let reach = f64::from(radius + offset(gap));
            let (cos, sin) = (angle.cos(), angle.sin());
            let point = (
                centre.0 + (reach * cos).round() as i32,
                centre.1 + (reach * sin).round() as i32,
            );
            // The box's side facing the dot touches `point`; text anchored on that side.
            let (left, anchor) = if cos > 0.38 {
                (point.0, Anchor::Start)
            } else if cos < -0.38 {
                (point.0 - width, Anchor::End)
            } else {
                (point.0 - width / 2, Anchor::Middle)
            };
            let top = if sin > 0.38 {
                point.1
            } else if sin < -0.38 {
                point.1 - height
            } else {
                point.1 - height / 2
            };
            let candidate = (left, top, left + width, top + height);
            let own = group
                .iter()
                .map(|&k| distance(dots[k].at, candidate))
                .fold(f64::INFINITY, f64::min);
            let other = dots
                .iter()
                .enumerate()
                .filter(|(k, _)| !group.contains(k))
                .map(|(k, d)| (k, distance(d.at, candidate)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let closer = other
                .filter(|&(_, d)| own + f64::from(NEARER_BY) > d)
                .map(|(k, _)| k);
            let inside = candidate.0 >= area.0
                && candidate.1 >= area.1
                && candidate.2 <= area.2
                && candidate.3 <= area.3;
            let covers_dot = dots
                .iter()
                .any(|d| distance(d.at, candidate) <= f64::from(radius + offset(1)));
            // Names kept 2 pixels apart.
            let pad = offset(2);
            let covered: i64 = placed
                .iter()
                .map(|p| {
                    (
                        p.area.0 - pad,
                        p.area.1 - pad,
                        p.area.2 + pad,
                        p.area.3 + pad,
                    )
                })
                .map(|other| overlap(candidate, other))
                .sum();
            let broken = i64::from(!inside) * 4
                + i64::from(closer.is_some()) * 2
                + i64::from(covers_dot) * 2
                + i64::from(covered > 0);
            // Fewest broken rules, then the least overlap, then the nearest.
            let score = (broken, covered, own);
            if best.as_ref().is_none_or(|(s, ..)| score < *s) {
                best = Some((score, candidate, anchor, closer));
            }
        }
        if let Some(((broken, ..), area, anchor, closer)) = best {
            // Where no place is nearer this dot than another, the name is joined with the dot
            // its best place stands nearest (a reader would pair them), however far; where
            // every place broke another rule (crowded), with a neighbour within six radii, so
            // that one name serves both.
            let reach = if broken == 0 { 0.0 } else { 6.0 };
            let neighbour = closer.map(|k| (k, 0.0)).or_else(|| {
                dots.iter()
                    .enumerate()
                    .filter(|(k, _)| !group.contains(k))
                    .map(|(k, d)| {
                        let gap = group.iter().map(|&j| apart(dots[j].at, d.at));
                        (k, gap.fold(f64::INFINITY, f64::min))
                    })
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .filter(|&(_, gap)| gap < reach * f64::from(radius))
            });
            if let (None, Some((other, _))) = (nearer, neighbour) {
                nearer = Some((index, other));
            }
            placed.push(Placed { text, area, anchor });
        }
    }
    (placed, nearer)
}

/// The dots and their names as SVG elements (a group of each), to go before the drawing's
/// `</svg>`.
pub(super) fn svg(dots: &[Dot], placed: &[Placed]) -> String {
    let mut svg = String::from("<g class=\"dots\">");
    for dot in dots {
        let _ = write!(
            svg,
            "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{}\"><title>{}</title></circle>",
            dot.at.0,
            dot.at.1,
            px(DOT_RADIUS),
            dot.colour,
            escape(&dot.name)
        );
    }
    svg.push_str("</g>\n<g class=\"dot-labels\" font-family=\"sans-serif\">");
    for label in placed {
        let (x, anchor) = match label.anchor {
            Anchor::Start => (label.area.0, "start"),
            Anchor::Middle => ((label.area.0 + label.area.2) / 2, "middle"),
            Anchor::End => (label.area.2, "end"),
        };
        let _ = write!(
            svg,
            "<text x=\"{x}\" y=\"{}\" font-size=\"{}\" text-anchor=\"{anchor}\" \
                dominant-baseline=\"central\">{}</text>",
            (label.area.1 + label.area.3) / 2,
            px(NAME_SIZE),
            escape(&label.text)
        );
    }
    svg.push_str("</g>\n");
    svg
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dots(at: &[(&str, (i32, i32))]) -> Vec<Dot> {
        at.iter()
            .map(|&(name, (x, y))| Dot {
                name: name.to_owned(),
                colour: "#000000".to_owned(),
                at: (x * 4, y * 4),
            })
            .collect()
    }

    /// The names a label gives, read as `.ci/explorer/report.mjs` reads them: parts between
    /// commas, a part ending in numbers between slashes one name per number.
    fn names_in(text: &str) -> Vec<String> {
        text.split(", ")
            .flat_map(|part| match part.split_once('/') {
                Some((first, rest)) => {
                    let stem = first.trim_end_matches(|c: char| c.is_ascii_digit());
                    std::iter::once(first.to_owned())
                        .chain(rest.split('/').map(|n| format!("{stem}{n}")))
                        .collect::<Vec<_>>()
                }
                None => vec![part.to_owned()],
            })
            .collect()
    }

    #[test]
    fn a_family_shares_its_stem() {
        assert_eq!(
            joined(&["quadratic-pow8", "quadratic-pow16"]),
            "quadratic-pow8/16"
        );
        assert_eq!(joined(&["sg", "sg-karis"]), "sg, sg-karis");
        assert_eq!(joined(&["cheb2", "cheb2-thesis"]), "cheb2, cheb2-thesis");
        assert_eq!(
            names_in("quadratic-pow8/16/32"),
            ["quadratic-pow8", "quadratic-pow16", "quadratic-pow32"]
        );
    }

    /// The nearest dot to a box, by the distance from its centre to the box's nearest point,
    /// computed apart from the placement's own helper.
    fn nearest(dots: &[Dot], b: Box) -> &str {
        let gap = |d: &Dot| {
            let x = f64::from(d.at.0.clamp(b.0, b.2) - d.at.0);
            let y = f64::from(d.at.1.clamp(b.1, b.3) - d.at.1);
            x.hypot(y)
        };
        &dots
            .iter()
            .min_by(|a, c| gap(a).total_cmp(&gap(c)))
            .unwrap()
            .name
    }

    /// The clusters of the report's Pareto plots (the quadratics nearly on one point, minimax2
    /// and the cheb2 pair a few pixels apart, sg and sg-karis on one point, fasterpow at the
    /// edge): every dot named once, every name nearest one of its own dots, inside the plot,
    /// clear of every dot and of every other name; the two dots on one point share one name.
    #[test]
    fn every_name_stands_nearest_its_own_dot() {
        let dots = dots(&[
            ("sg", (400, 300)),
            ("sg-karis", (400, 301)),
            ("quadratic-pow8", (160, 262)),
            ("quadratic-pow16", (166, 266)),
            ("quadratic-pow32", (172, 270)),
            ("exp2-cubic", (100, 245)),
            ("minimax2", (480, 380)),
            ("cheb2", (490, 380)),
            ("cheb2-thesis", (510, 380)),
            ("logexp", (470, 360)),
            ("pow", (30, 300)),
            ("fasterpow", (595, 385)),
        ]);
        let area = (0, 0, 600 * 4, 480 * 4);
        let placed = place(&dots, area);
        let texts: Vec<&str> = placed.iter().map(|p| p.text.as_str()).collect();
        // The two on one point share a name; every dot is named once.
        assert!(texts.contains(&"sg, sg-karis"), "{texts:?}");
        let mut named: Vec<String> = texts.iter().flat_map(|t| names_in(t)).collect();
        named.sort_unstable();
        let mut all: Vec<String> = dots.iter().map(|d| d.name.clone()).collect();
        all.sort_unstable();
        assert_eq!(named, all);
        for (k, label) in placed.iter().enumerate() {
            let own = nearest(&dots, label.area);
            assert!(
                names_in(&label.text).iter().any(|name| name == own),
                "'{}' stands nearest {own}",
                label.text
            );
            let b = label.area;
            assert!(b.0 >= area.0 && b.1 >= area.1 && b.2 <= area.2 && b.3 <= area.3);
            for dot in &dots {
                let (x, y) = dot.at;
                let gap = f64::from(x.clamp(b.0, b.2) - x).hypot(f64::from(y.clamp(b.1, b.3) - y));
                assert!(gap > 20.0, "'{}' covers {}", label.text, dot.name);
            }
            for other in &placed[k + 1..] {
                assert_eq!(
                    overlap(b, other.area),
                    0,
                    "'{}' and '{}'",
                    label.text,
                    other.text
                );
            }
        }
    }

    /// A name placed left of its dot ends at the box's right side, the side facing the dot,
    /// so a narrower face than the estimate moves only its far end.
    #[test]
    fn a_name_is_anchored_on_the_side_facing_its_dot() {
        let dots = dots(&[("fasterpow", (595, 200))]);
        let placed = place(&dots, (0, 0, 600 * 4, 400 * 4));
        assert_eq!(placed[0].anchor, Anchor::End);
        assert!(placed[0].area.2 < 595 * 4);
        let svg = svg(&dots, &placed);
        assert!(svg.contains("text-anchor=\"end\""), "{svg}");
        assert!(svg.contains("<title>fasterpow</title>"), "{svg}");
    }
}
