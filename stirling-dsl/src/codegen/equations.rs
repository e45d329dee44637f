//! The assembled equations as readable text or LaTeX: named quantities first
//! (inner before outer), then one line per state block and section variant.

use super::layout::Layout;
use crate::expr::{Arena, Id, Printer, Style};
use crate::topology::{Row, VARIANTS};

/// Lines `lhs' = rhs` with the variant note, per block.
fn lines(lay: &Layout, p: &Printer, rows: &[Row]) -> Vec<(String, String, Option<String>)> {
    let mut out = Vec::new();
    for (b, row) in lay.sys.blocks.iter().zip(rows) {
        match row {
            Row::Scalar(id) => out.push((b.name.clone(), p.expr(*id), None)),
            Row::Array(ids) => {
                let lhs = format!("{}[j]", b.name);
                let mut groups: Vec<(Id, Vec<&str>)> = Vec::new();
                for (k, v) in VARIANTS.iter().enumerate() {
                    match groups.iter_mut().find(|g| g.0 == ids[k]) {
                        Some(g) => g.1.push(v.describe()),
                        None => groups.push((ids[k], vec![v.describe()])),
                    }
                }
                let single = groups.len() == 1;
                for (id, notes) in groups {
                    let note = (!single).then(|| notes.join("; "));
                    out.push((lhs.clone(), p.expr(id), note));
                }
            }
        }
    }
    out
}

/// The system as text or LaTeX.
pub fn equations(arena: &Arena, lay: &Layout, model: &str, style: Style) -> String {
    let namer = |s| lay.name(s);
    let p = Printer::new(arena, style, &namer);
    let mut roots: Vec<Id> = lay.sys.rows.iter().flat_map(|r| r.ids()).collect();
    roots.extend(&lay.sys.sums);
    let mut defs = p.definitions(&roots);
    for (k, &s) in lay.sys.sums.iter().enumerate() {
        let body = match style {
            Style::Text => format!("sum over j = 0..n-1 of {}", p.expr(s)),
            Style::Latex => format!("\\sum_{{j=0}}^{{n-1}} \\left({}\\right)", p.expr(s)),
        };
        defs.push((format!("S{k}"), body));
    }
    let eqs = lines(lay, &p, &lay.sys.rows);
    match style {
        Style::Text => text(lay, model, &defs, &eqs),
        Style::Latex => latex(&p, &defs, &eqs),
    }
}

fn header(lay: &Layout, model: &str) -> String {
    let states: Vec<String> = lay
        .sys
        .blocks
        .iter()
        .map(|b| {
            if b.array {
                format!("{}[j]", b.name)
            } else {
                b.name.clone()
            }
        })
        .collect();
    let arrays = if lay.sys.blocks.iter().any(|b| b.array) {
        " (j = 0..n-1)"
    } else {
        ""
    };
    format!(
        "model {model}, closure {}\nstates: {}{arrays}\n",
        lay.sys.closure,
        states.join(", ")
    )
}

fn text(
    lay: &Layout,
    model: &str,
    defs: &[(String, String)],
    eqs: &[(String, String, Option<String>)],
) -> String {
    let mut s = header(lay, model);
    s.push_str("\nwhere\n");
    for (name, body) in defs {
        s.push_str(&format!("  {name} = {body}\n"));
    }
    s.push_str("\nequations\n");
    for (lhs, rhs, note) in eqs {
        match note {
            Some(n) => s.push_str(&format!("  {lhs}' = {rhs}    for {n}\n")),
            None => s.push_str(&format!("  {lhs}' = {rhs}\n")),
        }
    }
    s
}

fn latex(
    p: &Printer,
    defs: &[(String, String)],
    eqs: &[(String, String, Option<String>)],
) -> String {
    let mut s = String::from("\\begin{aligned}\n");
    for (name, body) in defs {
        s.push_str(&format!("{name} &= {body} \\\\\n"));
    }
    for (lhs, rhs, note) in eqs {
        let lhs = format!("\\dot{{{}}}", p.ident(lhs));
        match note {
            Some(n) => s.push_str(&format!(
                "{lhs} &= {rhs} && \\text{{for }} {} \\\\\n",
                n.replace(">=", "\\ge")
            )),
            None => s.push_str(&format!("{lhs} &= {rhs} \\\\\n")),
        }
    }
    s.push_str("\\end{aligned}\n");
    s
}
