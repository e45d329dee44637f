//! Parsing: the token syntax of `stirling_model!` into a spanned AST (after `compose` has
//! merged a declaration that `extends` a base with the base's items).
//!
//! ```text
//! /// docs
//! pub model Name {
//!     name "name";                                   // optional display name
//!     params { /// doc
//!              p: 1.0 "unit", ... }
//!     let D = sqrt(4.0 * A / pi);
//!     gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
//!     body displacer(x, v) { mass: md, spring: kd, damper: bd, quad_damper: bqd, force: .. }
//!     coupling displacer, piston { damper: b }
//!     flywheel wheel(theta, omega) { inertia: J, damper: c, friction: Tc, omega_eps: w0, load: Tl }
//!     crank piston(y) on wheel { radius: r, rod: L, phase: phi }   // y = s(theta), no state
//!     linkage displacer(x) on wheel { position: r * sin(theta) }     // any s(theta)
//!     space bounce { pressure: Pb, volume: Vb0, temperature: Tk, faces { displacer: Ar } }
//!     cv hot { volume: Vh0, faces { displacer: -A }, port hot { h: hh, area: Awh, wall: Th } }
//!     cv regen[n] { volume: Vr / n, port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n } }
//!     link hot -> regen[0] { resistance: Rf / (2.0 * n) }
//!     link regen[j] -> regen[j + 1] for j in 0..n - 1 { resistance: Rf / n, quadratic: Rq / n }
//!     link cold -> bounce { conductance: Gleak }            // mdot = G dP, exact zero at G = 0
//!     link cold -> bounce { orifice: Co, dp0: dP0 }         // mdot = Co dP / (dP^2 + dP0^2)^(1/4)
//!     link regen[j] -> bounce for j in 0..n { resistance: Rl * n }  // every section to one CV
//!     wall head { capacity: Ch, rest: Th, input: Qin }      // a thermal mass: Tw_head is a state
//!     wall matrix[n] { capacity: Cm / n, rest: Th - (j + 0.5) * (Th - Tk) / n }
//!     // a CV port names a wall instead of a fixed temperature: `wall: head`, `wall: matrix[j]`;
//!     // a port of an array naming a single wall (`wall: shell`) is every section's port to it
//!     link matrix[j] -> matrix[j + 1] for j in 0..n - 1 { conductance: Gm * n }  // conduction
//!     link head -> matrix[0] { conductance: 2.0 * Gm * n }  // between walls ...
//!     link matrix[n - 1] -> Tk { conductance: 2.0 * Gm * n } // ... or to a fixed temperature
//!     link matrix[j] -> shell for j in 0..n { conductance: Gms / n } // every section to one wall
//!     sensor p: P_cold "Pa";       // a measured channel: a CSV column named `p` observes state `P_cold`
//!     sensor T3: Tw_matrix[3] "K"; // an element of an array (checked against `n` at run time)
//!     sensor dp: P_cold - P_bounce "Pa"; // an expression of states and parameters
//!     free kd, kp, hh;             // the parameters a fit frees by default
//! }
//! ```

mod effect;

pub use effect::{EffectAst, Site};

use proc_macro2::Span;
use quote::ToTokens;
use syn::parse::{Parse, ParseStream};
use syn::punctuated::Punctuated;
use syn::{braced, bracketed, parenthesized, Attribute, Expr, Ident, LitStr, Token, Visibility};

/// `name: expr`.
pub struct Field {
    pub name: Ident,
    pub value: Expr,
}

impl Parse for Field {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let name = input.parse()?;
        input.parse::<Token![:]>()?;
        let value = input.parse()?;
        Ok(Field { name, value })
    }
}

fn fields(input: ParseStream) -> syn::Result<Vec<Field>> {
    let content;
    braced!(content in input);
    let list = Punctuated::<Field, Token![,]>::parse_terminated(&content)?;
    Ok(list.into_iter().collect())
}

/// One parameter: `/// doc` then `name: default "unit"`.
pub struct ParamAst {
    pub doc: String,
    pub name: Ident,
    pub default: Expr,
    pub unit: String,
    /// `in lo..hi`: the range a fit keeps it in.
    pub bounds: Option<syn::ExprRange>,
}

impl Parse for ParamAst {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let doc = docs(&input.call(Attribute::parse_outer)?);
        let name = input.parse()?;
        input.parse::<Token![:]>()?;
        let default = input.parse()?;
        let unit = if input.peek(LitStr) {
            input.parse::<LitStr>()?.value()
        } else {
            "-".to_string()
        };
        let bounds = if input.peek(Token![in]) {
            let kw = input.parse::<Token![in]>()?;
            match input.parse::<Expr>()? {
                Expr::Range(r) if r.start.is_some() && r.end.is_some() => Some(r),
                _ => {
                    let msg =
                        "expected the range a fit keeps the parameter in, e.g. `in 100.0..2000.0`";
                    return Err(syn::Error::new(kw.span, msg));
                }
            }
        } else {
            None
        };
        Ok(ParamAst {
            doc,
            name,
            default,
            unit,
            bounds,
        })
    }
}

/// Concatenated `///` lines.
pub fn docs(attrs: &[Attribute]) -> String {
    let mut lines = Vec::new();
    for a in attrs {
        if let syn::Meta::NameValue(nv) = &a.meta {
            if let Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) = &nv.value
            {
                lines.push(s.value().trim().to_string());
            }
        }
    }
    lines.join(" ")
}

pub struct BodyAst {
    pub name: Ident,
    pub pos: Ident,
    pub vel: Ident,
    pub fields: Vec<Field>,
    /// Declared with `flywheel` (an angle, an inertia, torques) rather than `body`.
    pub rotary: bool,
}

/// A position driven by a flywheel's angle (docs/physics.md section 12):
/// `crank piston(y) on wheel { radius: r, rod: L, phase: phi }` or
/// `linkage displacer(x) on wheel { position: <expression of the angle> }`.
pub struct MechanismAst {
    /// `crank` or `linkage`.
    pub kind: Ident,
    pub name: Ident,
    pub pos: Ident,
    /// The flywheel.
    pub on: Ident,
    pub fields: Vec<Field>,
}

pub struct CouplingAst {
    pub a: Ident,
    pub b: Ident,
    pub fields: Vec<Field>,
}

/// A space or a CV: fields, faces and ports.
pub struct VesselAst {
    pub name: Ident,
    /// `[n]` for an array of CVs.
    pub array: Option<Ident>,
    pub fields: Vec<Field>,
    pub faces: Vec<Field>,
    pub ports: Vec<PortAst>,
}

pub struct PortAst {
    pub name: Ident,
    pub fields: Vec<Field>,
}

/// `name` or `name[index]`.
#[derive(Clone)]
pub struct EndAst {
    pub name: Ident,
    pub index: Option<Expr>,
}

impl EndAst {
    /// As written: `hot`, `regen[j + 1]` (the key of a link and of an effect's site).
    pub fn text(&self) -> String {
        match &self.index {
            Some(i) => format!("{}[{}]", self.name, i.to_token_stream()),
            None => self.name.to_string(),
        }
    }
}

/// `from -> to` with the ends as written.
pub fn ends(from: &EndAst, to: &EndAst) -> String {
    format!("{} -> {}", from.text(), to.text())
}

impl Parse for EndAst {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let name = input.parse()?;
        let index = if input.peek(syn::token::Bracket) {
            let content;
            bracketed!(content in input);
            Some(content.parse()?)
        } else {
            None
        };
        Ok(EndAst { name, index })
    }
}

pub struct RangeAst {
    pub var: Ident,
    pub start: Expr,
    pub end: Expr,
    pub span: Span,
}

pub struct LinkAst {
    pub span: Span,
    pub from: EndAst,
    pub to: EndAst,
    pub range: Option<RangeAst>,
    pub fields: Vec<Field>,
}

#[allow(clippy::large_enum_variant)] // parsed once per item, at compile time
pub enum Item {
    Name(LitStr),
    Params(Vec<ParamAst>),
    Let(Ident, Box<Expr>),
    Gas(Span, Vec<Field>),
    Body(BodyAst),
    /// A crank or linkage on a flywheel.
    Mechanism(MechanismAst),
    Coupling(CouplingAst),
    Space(VesselAst),
    Cv(VesselAst),
    /// A wall with a temperature state (its fields; faces and ports are refused).
    Wall(VesselAst),
    Link(LinkAst),
    /// A measured channel: a CSV column observing one state.
    Sensor(SensorAst),
    /// `free a, b, c;`: the parameters a fit frees by default.
    Free(Span, Vec<Ident>),
    /// `effect coulomb on piston;`: an effect at its null (applied before the check).
    Effect(EffectAst),
}

/// `sensor name: STATE "unit";`, `sensor name: STATE[k] "unit";` (unit optional: the
/// state's own) or `sensor name: EXPR "unit";` (an expression of states and parameters,
/// unit required).
pub struct SensorAst {
    pub name: Ident,
    /// What the sensor reads: a state's name as [`stirling_dsl::Model::states`] lists it (`x`, `P_cold`,
    /// `Tw_head`), an array element (`P_regen[2]`) or an expression of states and parameters.
    pub expr: syn::Expr,
    pub unit: Option<LitStr>,
}

fn sensor(input: ParseStream) -> syn::Result<SensorAst> {
    let name = input.parse()?;
    input.parse::<Token![:]>()?;
    let expr = syn::Expr::parse_without_eager_brace(input)?;
    let unit = if input.peek(LitStr) {
        Some(input.parse()?)
    } else {
        None
    };
    input.parse::<Token![;]>()?;
    Ok(SensorAst { name, expr, unit })
}

pub struct ModelAst {
    pub doc: String,
    pub vis: Visibility,
    pub ident: Ident,
    pub items: Vec<Item>,
}

impl Parse for ModelAst {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let doc = docs(&input.call(Attribute::parse_outer)?);
        let vis = input.parse()?;
        let kw: Ident = input.parse()?;
        if kw != "model" {
            return Err(syn::Error::new(
                kw.span(),
                format!("expected `model Name {{ .. }}`, found `{kw}`"),
            ));
        }
        let ident = input.parse()?;
        let content;
        braced!(content in input);
        let mut items = Vec::new();
        while !content.is_empty() {
            items.push(item(&content)?);
        }
        Ok(ModelAst {
            doc,
            vis,
            ident,
            items,
        })
    }
}

pub fn item(input: ParseStream) -> syn::Result<Item> {
    if input.peek(Token![let]) {
        input.parse::<Token![let]>()?;
        let name = input.parse()?;
        input.parse::<Token![=]>()?;
        let value = input.parse()?;
        input.parse::<Token![;]>()?;
        return Ok(Item::Let(name, Box::new(value)));
    }
    let kw: Ident = input.parse()?;
    let item = match kw.to_string().as_str() {
        "name" => {
            let s = input.parse()?;
            input.parse::<Token![;]>()?;
            Item::Name(s)
        }
        "params" => {
            let content;
            braced!(content in input);
            Item::Params(Punctuated::<ParamAst, Token![,]>::parse_terminated(&content)?.into_iter().collect())
        }
        "gas" => Item::Gas(kw.span(), fields(input)?),
        "body" => body(input, false)?,
        "flywheel" => body(input, true)?,
        "crank" | "linkage" => mechanism(input, kw)?,
        "coupling" => {
            let a = input.parse()?;
            input.parse::<Token![,]>()?;
            let b = input.parse()?;
            Item::Coupling(CouplingAst { a, b, fields: fields(input)? })
        }
        "space" => Item::Space(vessel(input)?),
        "cv" => Item::Cv(vessel(input)?),
        "wall" => Item::Wall(vessel(input)?),
        "link" => link(input, kw.span())?,
        "sensor" => Item::Sensor(sensor(input)?),
        "effect" => Item::Effect(input.parse()?),
        "free" => {
            let names = Punctuated::<Ident, Token![,]>::parse_separated_nonempty(input)?;
            input.parse::<Token![;]>()?;
            Item::Free(kw.span(), names.into_iter().collect())
        }
        other => {
            return Err(syn::Error::new(
                kw.span(),
                format!("unknown item `{other}`: expected one of name, params, let, gas, body, flywheel, crank, linkage, coupling, space, cv, wall, link, sensor, free, effect"),
            ))
        }
    };
    Ok(item)
}

fn body(input: ParseStream, rotary: bool) -> syn::Result<Item> {
    let name = input.parse()?;
    let content;
    parenthesized!(content in input);
    let pos = content.parse()?;
    content.parse::<Token![,]>()?;
    let vel = content.parse()?;
    Ok(Item::Body(BodyAst {
        name,
        pos,
        vel,
        fields: fields(input)?,
        rotary,
    }))
}

fn mechanism(input: ParseStream, kind: Ident) -> syn::Result<Item> {
    let name = input.parse()?;
    let content;
    parenthesized!(content in input);
    let pos = content.parse()?;
    let on: Ident = input.parse()?;
    if on != "on" {
        return Err(syn::Error::new(
            on.span(),
            format!("expected `on <flywheel>` after `{kind} {name}({pos})`, found `{on}`"),
        ));
    }
    let on = input.parse()?;
    Ok(Item::Mechanism(MechanismAst {
        kind,
        name,
        pos,
        on,
        fields: fields(input)?,
    }))
}

fn vessel(input: ParseStream) -> syn::Result<VesselAst> {
    let name = input.parse()?;
    let array = if input.peek(syn::token::Bracket) {
        let content;
        bracketed!(content in input);
        Some(content.parse()?)
    } else {
        None
    };
    let content;
    braced!(content in input);
    let mut v = VesselAst {
        name,
        array,
        fields: Vec::new(),
        faces: Vec::new(),
        ports: Vec::new(),
    };
    while !content.is_empty() {
        let key: Ident = content.fork().parse()?;
        if key == "faces" && content.peek2(syn::token::Brace) {
            content.parse::<Ident>()?;
            v.faces.extend(fields(&content)?);
        } else if key == "port" && !content.peek2(Token![:]) {
            content.parse::<Ident>()?;
            let name = content.parse()?;
            v.ports.push(PortAst {
                name,
                fields: fields(&content)?,
            });
        } else {
            v.fields.push(content.parse()?);
        }
        if !content.is_empty() {
            content.parse::<Token![,]>()?;
        }
    }
    Ok(v)
}

fn link(input: ParseStream, span: Span) -> syn::Result<Item> {
    let from = input.parse()?;
    input.parse::<Token![->]>()?;
    let to = input.parse()?;
    let range = if input.peek(Token![for]) {
        let kw = input.parse::<Token![for]>()?;
        let var = input.parse()?;
        input.parse::<Token![in]>()?;
        let Expr::Range(r) = Expr::parse_without_eager_brace(input)? else {
            return Err(syn::Error::new(
                kw.span,
                "expected a range after `in`, e.g. `for j in 0..n - 1`",
            ));
        };
        let span = kw.span.join(var_span(&r)).unwrap_or(kw.span);
        let (Some(start), Some(end)) = (r.start, r.end) else {
            return Err(syn::Error::new(span, "expected a range `a..b`"));
        };
        Some(RangeAst {
            var,
            start: *start,
            end: *end,
            span,
        })
    } else {
        None
    };
    Ok(Item::Link(LinkAst {
        span,
        from,
        to,
        range,
        fields: fields(input)?,
    }))
}

fn var_span(r: &syn::ExprRange) -> Span {
    use syn::spanned::Spanned;
    r.span()
}
