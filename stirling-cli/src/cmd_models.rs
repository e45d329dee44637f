//! `stirling models`: the family and its aliases.

use std::io::Write;

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
    Ok(())
}
