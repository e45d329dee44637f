//! `stirling models`: the family and its aliases, registered engines, the bases an engine
//! file may extend by name, and the engine files that come with stirling.

use std::io::Write;

use stirling_models::model::files::{BASES, SHIPPED};
use stirling_models::{user_models, FAMILY};

use crate::common;

/// Print the family, or JSON with `--json`.
pub fn run(json: bool) -> anyhow::Result<()> {
    let user = user_models::registered();
    if json {
        let list: Vec<_> = FAMILY
            .iter()
            .map(|e| serde_json::json!({ "name": e.name, "aliases": e.aliases, "summary": e.summary }))
            .chain(user.iter().map(|u| serde_json::json!({ "name": u.name, "aliases": [], "summary": u.summary, "registered": true })))
            .chain(BASES.iter().map(|b| serde_json::json!({ "name": b.name, "aliases": [], "summary": base_summary(b.text), "base": true })))
            .chain(SHIPPED.iter().map(|f| serde_json::json!({ "name": f.path, "aliases": [], "summary": base_summary(f.text), "file": true })))
            .collect();
        return common::print_json(&list);
    }
    let mut o = common::stdout();
    for e in FAMILY {
        writeln!(o, "{:<9} {:<16} {}", e.name, e.aliases.join(","), e.summary)?;
    }
    for u in &user {
        writeln!(o, "{:<9} {:<16} {} (registered)", u.name, "", u.summary)?;
    }
    writeln!(
        o,
        "\nbases an engine file extends by name (`model Mine extends NAME {{ .. }}`):"
    )?;
    for b in BASES {
        writeln!(o, "  {:<17} {}", b.name, base_summary(b.text))?;
    }
    writeln!(
        o,
        "\nengine files in the source tree (run one by its path, e.g. `stirling info examples/engines/gamma_ltd.stirling`):"
    )?;
    for f in SHIPPED {
        writeln!(o, "  {:<42} {}", f.path, base_summary(f.text))?;
    }
    Ok(())
}

/// A base's summary: the first sentence of the doc comment on its declaration.
fn base_summary(text: &str) -> String {
    let doc = text
        .lines()
        .map(str::trim)
        .skip_while(|l| !l.starts_with("///"))
        .map_while(|l| l.strip_prefix("///"))
        .map(str::trim)
        .collect::<Vec<_>>()
        .join(" ");
    match doc.find(". ") {
        Some(end) => doc[..=end].to_string(),
        None => doc,
    }
}
