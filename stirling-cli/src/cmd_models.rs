//! `stirling models`: the family and its aliases.

use std::io::Write;

use stirling_models::FAMILY;

use crate::common;

/// Print the family, or JSON with `--json`.
pub fn run(json: bool) -> anyhow::Result<()> {
    if json {
        let list: Vec<_> = FAMILY
            .iter()
            .map(|e| serde_json::json!({ "name": e.name, "aliases": e.aliases, "summary": e.summary }))
            .collect();
        return common::print_json(&list);
    }
    let mut o = common::stdout();
    for e in FAMILY {
        writeln!(o, "{:<9} {:<16} {}", e.name, e.aliases.join(","), e.summary)?;
    }
    Ok(())
}
