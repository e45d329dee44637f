//! `effect <kind> on <body> [as <names>];`, `effect <kind> <end> -> <end> [as <names>];`,
//! `effect <kind> on link <end> -> <end> ..;`, `effect <kind> on port <cv>.<port> ..;` and
//! `effect <kind> on sensor <name>;`.

use proc_macro2::Span;
use syn::parse::{Parse, ParseStream};
use syn::punctuated::Punctuated;
use syn::{Ident, Token};

use super::{ends, EndAst};

/// Where an effect acts.
pub enum Site {
    /// `on <body>`.
    Body(Ident),
    /// `<from> -> <to>`: between two volumes (a leak).
    Between(EndAst, EndAst),
    /// `on link <from> -> <to>`: on a declared link (its ends as written).
    Link(EndAst, EndAst),
    /// `on port <cv>.<port>`: on a CV's heat port.
    Port(Ident, Ident),
    /// `on sensor <name>`: on a declared sensor's reading.
    Sensor(Ident),
}

/// One `effect` item.
pub struct EffectAst {
    pub kind: Ident,
    pub site: Site,
    /// The parameter names given after `as` (in the effect's parameter order; the rest keep
    /// their default names).
    pub names: Vec<Ident>,
    pub span: Span,
}

impl Parse for EffectAst {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let kind: Ident = input.parse()?;
        let span = kind.span();
        let site = if input.peek(Ident) && input.fork().parse::<Ident>()? == "on" {
            input.parse::<Ident>()?;
            let next = || input.fork().parse::<Ident>().map(|i| i.to_string());
            if input.peek(Ident) && input.peek2(Ident) && next()? == "link" {
                input.parse::<Ident>()?;
                let from: EndAst = input.parse()?;
                input.parse::<Token![->]>()?;
                Site::Link(from, input.parse()?)
            } else if input.peek(Ident) && input.peek2(Ident) && next()? == "sensor" {
                input.parse::<Ident>()?;
                Site::Sensor(input.parse()?)
            } else if input.peek(Ident) && input.peek2(Ident) && next()? == "port" {
                input.parse::<Ident>()?;
                let cv: Ident = input.parse()?;
                input.parse::<Token![.]>()?;
                Site::Port(cv, input.parse()?)
            } else {
                Site::Body(input.parse()?)
            }
        } else {
            let from: EndAst = input.parse()?;
            input.parse::<Token![->]>()?;
            Site::Between(from, input.parse()?)
        };
        let names = if input.peek(Token![as]) {
            input.parse::<Token![as]>()?;
            Punctuated::<Ident, Token![,]>::parse_separated_nonempty(input)?
                .into_iter()
                .collect()
        } else {
            Vec::new()
        };
        input.parse::<Token![;]>()?;
        Ok(EffectAst {
            kind,
            site,
            names,
            span,
        })
    }
}

impl Site {
    /// As written: `piston`, `cold -> bounce`, `link hot -> regen[0]`.
    pub fn describe(&self) -> String {
        match self {
            Site::Body(b) => b.to_string(),
            Site::Link(a, b) => format!("link {}", ends(a, b)),
            Site::Between(a, b) => ends(a, b),
            Site::Port(cv, port) => format!("port {cv}.{port}"),
            Site::Sensor(name) => format!("sensor {name}"),
        }
    }
}
