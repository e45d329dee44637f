//! `effect <kind> on <body> [as <names>];` and `effect <kind> <end> -> <end> [as <names>];`.

use proc_macro2::Span;
use syn::parse::{Parse, ParseStream};
use syn::punctuated::Punctuated;
use syn::{Ident, Token};

use crate::ast::EndAst;

/// Where an effect acts.
pub enum Site {
    /// `on <body>`.
    Body(Ident),
    /// `<from> -> <to>`: between two volumes (a leak).
    Between(EndAst, EndAst),
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
            Site::Body(input.parse()?)
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
    /// As written: `piston`, `cold -> bounce`.
    pub fn describe(&self) -> String {
        match self {
            Site::Body(b) => b.to_string(),
            Site::Between(a, b) => format!(
                "{} -> {}",
                crate::compose::end_str(a),
                crate::compose::end_str(b)
            ),
        }
    }
}
