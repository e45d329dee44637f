//! The endpoints of the engine editor: a family member's declaration to start from, the
//! compile of an edited one, and a model's equations and parameters.

use serde_json::json;
use stirling_dsl::{Model, Style};
use stirling_models::files::BASES;

use super::engines::{self, Refused};
use super::query::{self, Query};
use super::Reply;

/// The family members as engine files (the same files `tests/files_family.rs` holds to the
/// macro's models), by name.
const SOURCES: &[(&str, &str)] = &[
    (
        "schmidt",
        include_str!("../../../examples/engines/schmidt.stirling"),
    ),
    (
        "cv1",
        include_str!("../../../examples/engines/cv1.stirling"),
    ),
    (
        "cv2",
        include_str!("../../../examples/engines/cv2.stirling"),
    ),
    (
        "nsection",
        include_str!("../../../examples/engines/nsection.stirling"),
    ),
];

/// `GET /api/source?model=cv2`: the member's declaration and the bases it may extend.
pub fn source(q: &str) -> Reply {
    let name = q
        .split('&')
        .find_map(|kv| kv.strip_prefix("model="))
        .unwrap_or("");
    let Some((_, text)) = SOURCES.iter().find(|(m, _)| *m == name) else {
        let names: Vec<&str> = SOURCES.iter().map(|(m, _)| *m).collect();
        return Reply::error(
            400,
            format!(
                "no declaration of `{name}`: the page starts from {}",
                names.join(", ")
            ),
        );
    };
    let bases: serde_json::Map<String, serde_json::Value> = BASES
        .iter()
        .map(|b| (b.name.to_string(), b.text.into()))
        .collect();
    super::api::json_reply(&json!({ "source": text, "bases": bases }))
}

/// `POST /api/compile?n=N` with the declaration as the body: its id (`model=@ID` in the
/// other endpoints), or the diagnostics at their line and column. Writes no file.
pub fn compile(q: &str, body: &str) -> Reply {
    let n = match q
        .split('&')
        .find_map(|kv| kv.strip_prefix("n="))
        .map(query::parse_n)
    {
        None => 1,
        Some(Ok(n)) => n,
        Some(Err(e)) => return Reply::error(400, e),
    };
    match engines::compile(body, n) {
        Ok((id, def)) => super::api::json_reply(&json!({
            "id": id,
            "name": def.name(),
            "has_array": def.has_array(),
        })),
        Err(Refused { status, body }) => Reply {
            status,
            content_type: "application/json",
            body: body.to_string(),
        },
    }
}

/// `GET /api/equations`: the model's equations (as `stirling info` prints them), its states
/// and its parameters with their defaults.
pub fn equations(q: &Query) -> Reply {
    let (model, _) = match q.load() {
        Ok(m) => m,
        Err(e) => return Reply::error(400, e),
    };
    let m: &dyn Model = model.as_ref();
    let params: Vec<_> = m
        .params()
        .iter()
        .map(|p| json!({ "name": p.name, "default": p.default, "unit": p.unit, "doc": p.doc }))
        .collect();
    let states: Vec<String> = m.states().iter().map(|s| s.name.clone()).collect();
    super::api::json_reply(&json!({
        "name": m.name(),
        "equations": m.equations(Style::Text),
        "states": states,
        "params": params,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every member's declaration compiles to the member: same name and parameters.
    #[test]
    fn each_source_is_its_member() {
        for (name, text) in SOURCES {
            let (_, def) = engines::compile(text, 1).unwrap_or_else(|r| panic!("{}", r.body));
            assert_eq!(def.name(), *name);
            let member = stirling_models::build(name, None, stirling_dsl::Closure::Full).unwrap();
            let file = engines::model(&def, 1).unwrap();
            let names = |m: &dyn Model| m.params().iter().map(|p| p.name).collect::<Vec<_>>();
            assert_eq!(names(member.as_ref()), names(file.as_ref()));
            assert_eq!(member.n_states(), file.n_states());
        }
    }
}
