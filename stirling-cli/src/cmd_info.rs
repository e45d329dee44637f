//! `stirling info`: what a model is made of. States with their meaning and unit,
//! parameters with unit, value and doc, the generated equations (text or LaTeX),
//! or the model's bond graph (junctions, causal strokes, half-arrows) as Graphviz DOT.

use std::path::PathBuf;

use clap::Args;
use stirling_dsl::{EffectSite, Model, Style};

use crate::common::{self, files, ModelArgs};

/// Arguments of `stirling info`.
#[derive(Args, Debug, Clone)]
#[command(group(clap::ArgGroup::new("files").args(["out", "svg"]).multiple(true)))]
pub struct InfoArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Print the equations as LaTeX (an `aligned` block) instead of text
    #[arg(long)]
    pub latex: bool,
    /// Write the model's bond graph (0/1-junctions, causal strokes, half-arrows; see
    /// docs/bond-graphs.md) as Graphviz DOT instead of the listing
    /// (DOT has no equations: not with --latex or --json)
    #[arg(long, conflicts_with_all = ["json", "latex"])]
    pub graph: bool,
    /// With --graph: write the DOT to this file instead of stdout (folders created if missing)
    #[arg(long, requires = "graph", value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// With --graph: draw the bond graph as SVG into this file (no Graphviz needed; the DOT
    /// then goes only to --out, if given)
    #[arg(long, requires = "graph", value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// With --out or --svg: overwrite an existing file
    #[arg(long, requires = "files")]
    pub force: bool,
    /// Machine-readable output
    #[arg(long)]
    pub json: bool,
}

/// Run `stirling info`.
pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    let (model, p) = args.model.load()?;
    let model = model.as_ref();
    if args.graph {
        let graph = stirling_dsl::bond::bond_graph(model)?;
        for d in &graph.derivative {
            eprintln!("note: derivative causality at {}", d.meaning);
        }
        if let Some(path) = &args.svg {
            files::write_text(path, &graph.to_svg(), args.force, "--svg")?;
        }
        return match (&args.out, &args.svg) {
            (Some(path), _) => files::write_text(path, &graph.to_dot(), args.force, "--out"),
            (None, Some(_)) => Ok(()),
            (None, None) => Ok(common::print(&graph.to_dot())?),
        };
    }
    let style = if args.latex {
        Style::Latex
    } else {
        Style::Text
    };
    if args.json {
        common::print_json(&json(model, &p, style))
    } else {
        Ok(common::print(&listing(model, &p, style))?)
    }
}

/// The title line: name, sections, closure, state count and the declaration's doc.
fn title(model: &dyn Model) -> String {
    let n = if model.has_array() {
        format!(", n = {}", model.n())
    } else {
        String::new()
    };
    let doc = model.topology().doc.trim();
    format!(
        "model {}{n}, closure {}: {} states\n  {doc}\n",
        model.name(),
        model.closure(),
        model.n_states()
    )
}

/// The human-readable listing.
fn listing(model: &dyn Model, p: &[f64], style: Style) -> String {
    let mut s = title(model);
    s.push_str("\nstates\n");
    s.push_str(&table(
        &state_rows(model),
        &["#", "name", "unit", "meaning"],
    ));
    s.push_str("\nparameters\n");
    s.push_str(&table(
        &param_rows(model, p),
        &["name", "value", "unit", "meaning"],
    ));
    if !model.sensors().is_empty() {
        s.push_str("\nsensors (CSV columns a record may hold)\n");
        s.push_str(&table(&sensor_rows(model), &["column", "reads", "unit"]));
    }
    let (sites, member) = effect_sites(model);
    if !sites.is_empty() {
        let from = member.map_or(String::new(), |m| {
            format!(", on its augmented member `{m}`")
        });
        s.push_str(&format!(
            "\neffects at their null (what `stirling diagnose` may test{from})\n"
        ));
        s.push_str(&table(&effect_rows(sites), &["effect", "at", "parameters"]));
    }
    s.push('\n');
    s.push_str(&model.equations(style));
    s
}

fn state_rows(model: &dyn Model) -> Vec<Vec<String>> {
    let states = model.states();
    states
        .iter()
        .enumerate()
        .map(|(k, st)| {
            vec![
                k.to_string(),
                st.name.clone(),
                st.unit.into(),
                st.meaning.clone(),
            ]
        })
        .collect()
}

fn sensor_rows(model: &dyn Model) -> Vec<Vec<String>> {
    model
        .sensors()
        .iter()
        .map(|s| {
            let reads = match stirling_dsl::Observation::sensor(model, s.name) {
                Ok(_) => s.definition().to_string(),
                Err(_) => format!("{} (absent at this n and closure)", s.definition()),
            };
            vec![s.name.into(), reads, s.unit.into()]
        })
        .collect()
}

/// The effects the model names with `effect` items, or those of the augmented member a
/// registered model names for the diagnosis (with that member's name).
fn effect_sites(model: &dyn Model) -> (&'static [EffectSite], Option<&'static str>) {
    if !model.effect_sites().is_empty() {
        return (model.effect_sites(), None);
    }
    let member = stirling_models::user_models::find(model.name())
        .and_then(|u| u.augmented)
        .and_then(|build| build(model.n(), model.closure()).ok());
    match member {
        Some(m) => (m.effect_sites(), Some(m.name())),
        None => (&[], None),
    }
}

fn effect_rows(sites: &[EffectSite]) -> Vec<Vec<String>> {
    sites
        .iter()
        .map(|e| vec![e.effect.into(), e.at.into(), e.params.join(", ")])
        .collect()
}

fn param_rows(model: &dyn Model, p: &[f64]) -> Vec<Vec<String>> {
    let rows = model.params().iter().zip(p);
    rows.map(|(info, &v)| {
        let mut doc = if v == info.default {
            info.doc.to_string()
        } else {
            format!("{} (default {})", info.doc, fmt(info.default))
        };
        if let Some((lo, hi)) = info.bounds {
            doc.push_str(&format!(" [fit bounds {}..{}]", fmt(lo), fmt(hi)));
        }
        vec![info.name.into(), fmt(v), info.unit.into(), doc]
    })
    .collect()
}

/// Six significant digits (the JSON output keeps every digit), in exponent form
/// for small or large magnitudes.
fn fmt(v: f64) -> String {
    let v: f64 = format!("{v:.5e}").parse().unwrap_or(v);
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Left-aligned columns with a header; the last column is not padded.
fn table(rows: &[Vec<String>], header: &[&str]) -> String {
    let mut width: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let head: Vec<String> = header.iter().map(|h| h.to_string()).collect();
    std::iter::once(&head)
        .chain(rows)
        .map(|r| line(r, &width))
        .collect()
}

fn line(r: &[String], width: &[usize]) -> String {
    let last = r.len() - 1;
    let cells: Vec<String> = r
        .iter()
        .enumerate()
        .map(|(k, c)| {
            if k == last {
                c.clone()
            } else {
                format!("{c:<w$}", w = width[k])
            }
        })
        .collect();
    format!("  {}\n", cells.join("  ").trim_end())
}

/// The listing as JSON.
fn json(model: &dyn Model, p: &[f64], style: Style) -> serde_json::Value {
    let states: Vec<_> = model
        .states()
        .into_iter()
        .map(|s| serde_json::json!({ "name": s.name, "unit": s.unit, "meaning": s.meaning }))
        .collect();
    let params: Vec<_> = model
        .params()
        .iter()
        .zip(p)
        .map(|(i, v)| serde_json::json!({ "name": i.name, "value": v, "default": i.default, "unit": i.unit, "doc": i.doc, "bounds": i.bounds.map(|(lo, hi)| [lo, hi]) }))
        .collect();
    let effects: Vec<_> = effect_sites(model)
        .0
        .iter()
        .map(|e| serde_json::json!({ "effect": e.effect, "at": e.at, "params": e.params }))
        .collect();
    let sensors: Vec<_> = model
        .sensors()
        .iter()
        .map(|s| serde_json::json!({ "column": s.name, "state": s.state, "expr": s.expr, "reads": s.reads, "unit": s.unit, "present": stirling_dsl::Observation::sensor(model, s.name).is_ok() }))
        .collect();
    serde_json::json!({
        "model": model.name(),
        "n": model.n(),
        "has_sections": model.has_array(),
        "closure": model.closure().as_str(),
        "n_states": model.n_states(),
        "doc": model.topology().doc.trim(),
        "states": states,
        "params": params,
        "sensors": sensors,
        "effects": effects,
        "equations_style": if matches!(style, Style::Latex) { "latex" } else { "text" },
        "equations": model.equations(style),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use stirling_dsl::Closure;
    use stirling_models::effects::NSectionFx;

    /// A model that names effects lists them (text and JSON), with their parameters; a
    /// parameter without declared bounds has `bounds: null`.
    #[test]
    fn the_listing_names_the_effects() {
        let m = NSectionFx::new(1, Closure::Full).unwrap();
        let p = m.default_params();
        let text = listing(&m, &p, Style::Text);
        assert!(text.contains("effects at their null"), "{text}");
        let row = text
            .lines()
            .find(|l| l.contains("end_stops") && l.contains("piston"));
        assert!(row.is_some_and(|r| r.contains("kc, ymax")), "{text}");
        let v = json(&m, &p, Style::Text);
        let fx = v["effects"].as_array().unwrap();
        let leak = fx.iter().find(|e| e["effect"] == "leak").unwrap();
        assert_eq!(leak["at"], "cold -> bounce");
        assert_eq!(leak["params"][0], "Gleak");
        assert_eq!(v["params"][0]["bounds"], serde_json::Value::Null);
    }
}
