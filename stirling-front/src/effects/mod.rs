//! `effect` items: an effect the nominal model leaves out, applied where the model names it,
//! at its null (docs/custom-topologies.md, "Effects"):
//!
//! ```text
//! effect coulomb on piston;              // force -Fc_piston tanh(w / v_eps) on the piston
//! effect end_stops on displacer;         // -kc_displacer relu(|x| - xmax) sign(x)
//! effect leak cold -> bounce;            // link cold -> bounce { conductance: Gleak_cold_bounce }
//! effect orifice_leak cold -> bounce;    // link cold -> bounce { orifice: Co_cold_bounce, dp0: dP0 }
//! effect quadratic on link hot -> regen[0];  // that link gains quadratic: Rq_hot_regen
//! effect heater_input on port hot.hot;   // the port's fixed wall becomes wall `hot_hot`:
//!                                        // capacity 1/kh_hot_hot, fed through Gh_hot_hot
//! effect matrix_capacity on port regen.wall; // walls regen_wall[n], capacity 1/km_regen_wall
//! effect lag on sensor p_bounce;        // its reading lagged, time constant tau_p_bounce
//! effect gain on sensor x;               // its reading (1 + gain_x) times the position
//! effect coulomb on piston as Fcp;       // the strength named `Fcp` (then the shape, `as Fcp, v_eps`)
//! ```
//!
//! Each declares its parameters at their null (a strength of 0: the effect is absent) unless
//! the model declares them already, adds its term, and is listed with its parameters in
//! `Model::effect_sites`, which the diagnosis reads to know what it may test. Applied to the
//! parsed model before the check, so a term is checked like one written by hand.

mod kinds;
mod ports;

use stirling_dsl::topology::EffectSiteDecl;
use syn::{Expr, Ident};

use crate::ast::{
    ends, BodyAst, EffectAst, EndAst, Field, Item, LinkAst, ModelAst, ParamAst, Site,
};
use kinds::{Kind, Where, KINDS};

/// Apply every `effect` item of `ast` and return the sites. A link an effect adds takes the
/// item's place (so a model's links keep the order they are written in); the parameters the
/// effects add come last.
pub fn apply(ast: &mut ModelAst) -> syn::Result<Vec<EffectSiteDecl>> {
    let mut effects: Vec<(usize, EffectAst)> = Vec::new();
    for it in std::mem::take(&mut ast.items) {
        match it {
            Item::Effect(e) => effects.push((ast.items.len(), e)),
            other => ast.items.push(other),
        }
    }
    let mut sites: Vec<EffectSiteDecl> = Vec::new();
    let mut added: Vec<ParamAst> = Vec::new();
    let mut links: Vec<(usize, Item)> = Vec::new();
    let mut errors: Option<syn::Error> = None;
    for (at, e) in effects {
        match one(ast, &e, &mut added, &mut |item| links.push((at, item))) {
            Ok(site)
                if sites
                    .iter()
                    .any(|s| s.effect == site.effect && s.at == site.at) =>
            {
                let msg = format!("`effect {} on {}` twice", site.effect, site.at);
                push(&mut errors, syn::Error::new(e.span, msg));
            }
            Ok(site) => sites.push(site),
            Err(err) => push(&mut errors, err),
        }
    }
    if let Some(err) = errors {
        return Err(err);
    }
    for (at, item) in links.into_iter().rev() {
        ast.items.insert(at, item);
    }
    if !added.is_empty() {
        ast.items.push(Item::Params(added));
    }
    Ok(sites)
}

fn push(errors: &mut Option<syn::Error>, e: syn::Error) {
    match errors {
        Some(all) => all.combine(e),
        None => *errors = Some(e),
    }
}

/// Apply one effect: its parameters (those the model lacks into `added`) and its term (a
/// force term in place; a link, or a port's wall with its items, given to `link`).
fn one(
    ast: &mut ModelAst,
    e: &EffectAst,
    added: &mut Vec<ParamAst>,
    link: &mut dyn FnMut(Item),
) -> syn::Result<EffectSiteDecl> {
    let name = e.kind.to_string();
    let Some(kind) = KINDS.iter().find(|k| k.name == name) else {
        let known: Vec<&str> = KINDS.iter().map(|k| k.name).collect();
        let msg = format!(
            "unknown effect `{name}`: expected one of {}",
            known.join(", ")
        );
        return Err(syn::Error::new(e.span, msg));
    };
    if e.names.len() > kind.params.len() {
        let msg = format!(
            "effect `{name}` has {} parameter(s), {} named after `as`",
            kind.params.len(),
            e.names.len()
        );
        return Err(syn::Error::new(e.span, msg));
    }
    let names = match (&kind.site, &e.site) {
        (Where::Body(term), Site::Body(b)) => on_body(ast, kind, *term, e, b)?,
        (Where::Between(fields), Site::Between(from, to)) => {
            let names = param_names(kind, e, &[&from.name.to_string(), &to.name.to_string()]);
            link(between(e, (from, to), fields(&names)));
            names
        }
        (Where::Link(fields), Site::Link(from, to)) => on_link(ast, kind, *fields, e, (from, to))?,
        (Where::Port(shape), Site::Port(cv, port)) => {
            let names = param_names(kind, e, &[&cv.to_string(), &port.to_string()]);
            let pair = (&names[0], &names[1]);
            for item in ports::on_port(ast, kind.name, *shape, (cv, port), pair)? {
                link(item);
            }
            names
        }
        (Where::Sensor, Site::Sensor(sensor)) => {
            // a sensor's parameter is the rig's and the diagnosis's, not the model's: none
            // is declared
            let names = on_sensor(ast, kind, e, sensor)?;
            return Ok(site_decl(e, names));
        }
        (site, _) => return Err(wrong_site(&name, site, e.span)),
    };
    declare(ast, kind, &names, &e.site.describe(), added);
    Ok(site_decl(e, names))
}

fn site_decl(e: &EffectAst, names: Vec<Ident>) -> EffectSiteDecl {
    EffectSiteDecl {
        effect: e.kind.to_string(),
        at: e.site.describe(),
        params: names.iter().map(Ident::to_string).collect(),
    }
}

/// An effect named at a place of the wrong kind: how to name it.
fn wrong_site(name: &str, site: &Where, span: proc_macro2::Span) -> syn::Error {
    let (what, how) = match site {
        Where::Body(_) => ("on a body", format!("effect {name} on <body>;")),
        Where::Between(_) => (
            "between two volumes",
            format!("effect {name} <from> -> <to>;"),
        ),
        Where::Link(_) => (
            "on a link",
            format!("effect {name} on link <from> -> <to>;"),
        ),
        Where::Port(_) => (
            "on a CV's heat port",
            format!("effect {name} on port <cv>.<port>;"),
        ),
        Where::Sensor => (
            "on a sensor's reading",
            format!("effect {name} on sensor <name>;"),
        ),
    };
    syn::Error::new(span, format!("effect `{name}` acts {what}: write `{how}`"))
}

/// The link a leak adds between two volumes, with its fields.
fn between(e: &EffectAst, (from, to): (&EndAst, &EndAst), fields: Vec<(&str, Expr)>) -> Item {
    Item::Link(LinkAst {
        span: e.span,
        from: from.clone(),
        to: to.clone(),
        range: None,
        fields: fields
            .into_iter()
            .map(|(name, value)| Field {
                name: Ident::new(name, e.span),
                value,
            })
            .collect(),
    })
}

/// A distortion of a declared sensor's reading: its parameter named after the sensor.
fn on_sensor(
    ast: &ModelAst,
    kind: &Kind,
    e: &EffectAst,
    sensor: &Ident,
) -> syn::Result<Vec<Ident>> {
    let name = kind.name;
    let declared = ast
        .items
        .iter()
        .any(|it| matches!(it, Item::Sensor(s) if s.name == *sensor));
    if !declared {
        let msg = format!("effect `{name}` on sensor `{sensor}`: no sensor `{sensor}`; it acts on a declared sensor");
        return Err(syn::Error::new(sensor.span(), msg));
    }
    if !e.names.is_empty() {
        let own = fill(kind.params[0].name, &[&sensor.to_string()]);
        let msg = format!("effect `{name}` on a sensor takes no `as`: its parameter is named after the sensor (`{own}`)");
        return Err(syn::Error::new(e.span, msg));
    }
    Ok(param_names(kind, e, &[&sensor.to_string()]))
}

/// The effect's term appended to the body's `force`.
fn on_body(
    ast: &mut ModelAst,
    kind: &Kind,
    term: fn(&[Ident], &Ident, &Ident) -> Expr,
    e: &EffectAst,
    b: &Ident,
) -> syn::Result<Vec<Ident>> {
    let body = ast.items.iter_mut().find_map(|it| match it {
        Item::Body(x) if x.name == *b => Some(x),
        _ => None,
    });
    let Some(body) = body else {
        let msg = format!(
            "effect `{}` on `{b}`: no body `{b}`; it acts on a declared body",
            kind.name
        );
        return Err(syn::Error::new(b.span(), msg));
    };
    let names = param_names(kind, e, &[&b.to_string(), &body.pos.to_string()]);
    add_force(body, term(&names, &body.pos, &body.vel));
    Ok(names)
}

/// The effect's fields added to the declared link `from -> to` (its ends as written).
fn on_link(
    ast: &mut ModelAst,
    kind: &Kind,
    fields: fn(&[Ident]) -> Vec<(&'static str, Expr)>,
    e: &EffectAst,
    (from, to): (&EndAst, &EndAst),
) -> syn::Result<Vec<Ident>> {
    let link = ast.items.iter_mut().find_map(|it| match it {
        Item::Link(l) if l.from.text() == from.text() && l.to.text() == to.text() => Some(l),
        _ => None,
    });
    let site = ends(from, to);
    let Some(link) = link else {
        let msg = format!("effect `{}` on link `{site}`: no link `{site}` (its ends as the link item writes them)", kind.name);
        return Err(syn::Error::new(from.name.span(), msg));
    };
    let names = param_names(kind, e, &[&from.name.to_string(), &to.name.to_string()]);
    for (name, value) in fields(&names) {
        if link.fields.iter().any(|f| f.name == name) {
            let msg = format!(
                "effect `{}` on link `{site}`: the link has its `{name}` already",
                kind.name
            );
            return Err(syn::Error::new(e.span, msg));
        }
        link.fields.push(Field {
            name: Ident::new(name, e.span),
            value,
        });
    }
    Ok(names)
}

/// `force: F` becomes `force: F - term` (`force: -term` when there was none).
fn add_force(body: &mut BodyAst, term: Expr) {
    match body.fields.iter_mut().find(|f| f.name == "force") {
        Some(f) => {
            let old = &f.value;
            f.value = syn::parse_quote!(#old - #term);
        }
        None => body.fields.push(Field {
            name: Ident::new("force", body.name.span()),
            value: syn::parse_quote!(-#term),
        }),
    }
}

/// The parameter names: those after `as`, then the defaults (`{0}`, `{1}`: the site's names).
fn param_names(kind: &Kind, e: &EffectAst, site: &[&str]) -> Vec<Ident> {
    kind.params
        .iter()
        .enumerate()
        .map(|(k, p)| match e.names.get(k) {
            Some(n) => n.clone(),
            None => Ident::new(&fill(p.name, site), e.span),
        })
        .collect()
}

fn fill(pattern: &str, site: &[&str]) -> String {
    site.iter()
        .enumerate()
        .fold(pattern.to_string(), |s, (k, v)| {
            s.replace(&format!("{{{k}}}"), v)
        })
}

/// Declare the parameters the model does not declare, at their defaults.
fn declare(ast: &ModelAst, kind: &Kind, names: &[Ident], site: &str, added: &mut Vec<ParamAst>) {
    let in_model = |n: &str| {
        ast.items
            .iter()
            .any(|it| matches!(it, Item::Params(ps) if ps.iter().any(|p| p.name == n)))
    };
    for (p, name) in kind.params.iter().zip(names) {
        let n = name.to_string();
        if in_model(&n) || added.iter().any(|q| q.name == n) {
            continue;
        }
        let default = p.default;
        added.push(ParamAst {
            doc: p.doc.replace("{site}", site),
            name: name.clone(),
            default: syn::parse_quote!(#default),
            unit: p.unit.to_string(),
            bounds: None,
        });
    }
}
