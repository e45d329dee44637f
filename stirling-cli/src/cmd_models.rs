//! `stirling models`: the family and its aliases.

use stirling_models::FAMILY;

/// Print the family, or JSON with `--json`.
pub fn run(json: bool) -> anyhow::Result<()> {
    if json {
        let list: Vec<_> = FAMILY
            .iter()
            .map(|e| serde_json::json!({ "name": e.name, "aliases": e.aliases, "summary": e.summary }))
            .collect();
        println!("{}", serde_json::to_string_pretty(&list)?);
        return Ok(());
    }
    for e in FAMILY {
        println!("{:<9} {:<16} {}", e.name, e.aliases.join(","), e.summary);
    }
    Ok(())
}
