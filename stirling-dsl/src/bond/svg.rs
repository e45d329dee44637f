//! The bond graph drawn as SVG by this crate (no Graphviz): the layered layout of
//! [`super::layout`], each bond a straight line with its half-arrow (positive power) at its
//! `to` end and its causal stroke across the end whose node takes the effort. Labels are SVG
//! text (`0`, `1`, `I: md`, `TF: -A`), so a screen reader or a test can read them; each bond
//! and node carries a `<title>` (its variables, its meaning).

use std::fmt::Write;

use super::causality::Derivative;
use super::graph::{BondGraph, Domain, Kind};
use super::layout::{layered, Layout};

/// Length of the half-arrow's barb and half length of the stroke (px).
const BARB: f64 = 9.0;
const STROKE: f64 = 6.0;

/// The SVG text of `g`.
pub fn to_svg(g: &BondGraph, derivative: &[Derivative]) -> String {
    let lay = layered(g);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" \
         viewBox=\"0 0 {w:.0} {h:.0}\" font-family=\"Helvetica, Arial, sans-serif\" \
         font-size=\"13\">",
        w = lay.width,
        h = lay.height
    );
    let _ = writeln!(s, "<title>bond graph of {}</title>", esc(&g.name));
    s.push_str("<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n");
    for (k, b) in g.bonds.iter().enumerate() {
        bond(&mut s, &lay, k, b);
    }
    for (n, node) in g.nodes.iter().enumerate() {
        let (x, y) = lay.centre[n];
        let red = derivative.iter().any(|d| d.node == n);
        let fill = if red { "red" } else { "black" };
        let ring = if node.kind == Kind::C && node.states.len() > 1 {
            let (hx, hy) = lay.half[n];
            format!(
                "<ellipse cx=\"{x:.1}\" cy=\"{y:.1}\" rx=\"{:.1}\" ry=\"{:.1}\" fill=\"none\" stroke=\"black\"/>",
                hx + 2.0,
                hy + 1.0
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            "<g class=\"node\" data-kind=\"{}\"><title>{}</title>{ring}<text x=\"{x:.1}\" y=\"{:.1}\" \
             text-anchor=\"middle\" fill=\"{fill}\" stroke=\"white\" stroke-width=\"4\" \
             paint-order=\"stroke\">{}</text></g>",
            node.kind.symbol(),
            esc(&node.label),
            y + 4.5,
            esc(&node.text())
        );
    }
    s.push_str("</svg>\n");
    s
}

/// One bond: the line, the half-arrow at `to`, the stroke at the effort's end.
fn bond(s: &mut String, lay: &Layout, k: usize, b: &super::graph::Bond) {
    let (a, z) = (lay.centre[b.from], lay.centre[b.to]);
    let (dx, dy) = (z.0 - a.0, z.1 - a.1);
    let len = (dx * dx + dy * dy).sqrt().max(1e-9);
    let u = (dx / len, dy / len);
    let normal = (-u.1, u.0);
    let p = exit(a, u, lay.half[b.from]);
    let q = exit(z, (-u.0, -u.1), lay.half[b.to]);
    let colour = colour(b.domain);
    let barb = (
        q.0 - BARB * u.0 + 0.6 * BARB * normal.0,
        q.1 - BARB * u.1 + 0.6 * BARB * normal.1,
    );
    let end = match b.effort_to {
        Some(e) if e == b.from => Some(p),
        Some(_) => Some(q),
        None => None,
    };
    let stroke = end.map_or(String::new(), |e| {
        format!(
            "<line class=\"stroke\" x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke-width=\"2\"/>",
            e.0 + STROKE * normal.0,
            e.1 + STROKE * normal.1,
            e.0 - STROKE * normal.0,
            e.1 - STROKE * normal.1
        )
    });
    let _ = writeln!(
        s,
        "<g class=\"bond\" stroke=\"{colour}\" fill=\"none\"><title>bond {}: {}</title>\
         <line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\"/>\
         <polyline class=\"half-arrow\" points=\"{:.1},{:.1} {:.1},{:.1}\"/>{stroke}</g>",
        k + 1,
        b.domain.variables(),
        p.0,
        p.1,
        q.0,
        q.1,
        q.0,
        q.1,
        barb.0,
        barb.1
    );
}

/// Where the ray from `c` along unit `u` leaves the box of half sizes `half` (plus a gap).
fn exit(c: (f64, f64), u: (f64, f64), half: (f64, f64)) -> (f64, f64) {
    let (hx, hy) = (half.0 + 3.0, half.1 + 3.0);
    let tx = if u.0.abs() > 1e-12 {
        hx / u.0.abs()
    } else {
        f64::INFINITY
    };
    let ty = if u.1.abs() > 1e-12 {
        hy / u.1.abs()
    } else {
        f64::INFINITY
    };
    let t = tx.min(ty);
    (c.0 + t * u.0, c.1 + t * u.1)
}

/// The colour of a domain's bonds (as in the DOT).
fn colour(d: Domain) -> &'static str {
    match d {
        Domain::Mechanical => "black",
        Domain::Volume => "blue",
        Domain::Heat => "red",
        Domain::MassFlow => "darkgreen",
    }
}

/// `s` escaped for SVG text.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
