//! State layout in generated code: block offsets as functions of `n`, and how
//! symbols read the state vector, the parameters and the section index.

use std::collections::HashSet;

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

use crate::expr::{At, Sym};
use crate::topology::{System, Topology};

/// Turns symbols into Rust for one system.
pub struct Layout<'a> {
    pub sys: &'a System,
    pub topo: &'a Topology,
}

impl Layout<'_> {
    /// The identifier holding a block's offset, e.g. `o_P_regen`.
    pub fn offset_ident(&self, sym: u32) -> Ident {
        let i = self.block(sym);
        format_ident!("o_{}", self.sys.blocks[i].name)
    }

    fn block(&self, sym: u32) -> usize {
        self.sys
            .block_index(sym)
            .unwrap_or_else(|| panic!("internal: state block {sym} has no state in this closure"))
    }

    /// `let o_x: usize = 0; ...` for every block named in `used`, as `scalars + arrays * n`.
    pub fn offsets(&self, used: &HashSet<String>) -> TokenStream {
        let (mut s, mut a) = (0usize, 0usize);
        let mut out = TokenStream::new();
        for b in &self.sys.blocks {
            let id = format_ident!("o_{}", b.name);
            let (sl, al) = (Literal::usize_unsuffixed(s), Literal::usize_unsuffixed(a));
            if used.contains(&id.to_string()) || used.contains(&slice_of(&b.name).to_string()) {
                out.extend(match (s, a) {
                    (_, 0) => quote! { let #id: usize = #sl; },
                    (0, 1) => quote! { let #id: usize = n; },
                    (_, 1) => quote! { let #id: usize = #sl + n; },
                    (0, _) => quote! { let #id: usize = #al * n; },
                    _ => quote! { let #id: usize = #sl + #al * n; },
                });
            }
            if b.array {
                a += 1;
            } else {
                s += 1;
            }
        }
        out
    }

    /// One bounds check of the parameter slice, then `let R = p[0]; ...` for every
    /// parameter named in `used`.
    pub fn params(&self, used: &HashSet<String>) -> TokenStream {
        let count = Literal::usize_unsuffixed(self.topo.params.len());
        let mut out = TokenStream::new();
        for (i, p) in self.topo.params.iter().enumerate() {
            if !used.contains(&p.name) {
                continue;
            }
            let (id, k) = (
                Ident::new(&p.name, Span::call_site()),
                Literal::usize_unsuffixed(i),
            );
            out.extend(quote! { let #id: f64 = p[#k]; });
        }
        if out.is_empty() {
            return out;
        }
        quote! {
            let p: &[f64; #count] = p.first_chunk().expect("one value per declared parameter");
            #out
        }
    }

    /// The identifier of an array block's slice of the state, e.g. `__x_P_regen`.
    fn slice_ident(&self, sym: u32) -> Ident {
        slice_of(&self.sys.blocks[self.block(sym)].name)
    }

    /// Index of a state element inside its array block.
    fn in_block(at: At) -> TokenStream {
        match at {
            At::Scalar | At::First => quote!(0),
            At::Rel(0) => quote!(j),
            At::Rel(k) if k > 0 => {
                let k = Literal::usize_unsuffixed(k as usize);
                quote!(j + #k)
            }
            At::Rel(k) => {
                let k = Literal::usize_unsuffixed((-k) as usize);
                quote!(j - #k)
            }
            At::Last => quote!(n - 1),
        }
    }

    /// `let __x_P_regen: &[f64] = &x[o_P_regen..o_P_regen + n];` for every array block whose
    /// slice is named in `used` (after `offsets`).
    pub fn slices(&self, used: &HashSet<String>) -> TokenStream {
        let mut out = TokenStream::new();
        for b in self.sys.blocks.iter().filter(|b| b.array) {
            let (x, o) = (slice_of(&b.name), format_ident!("o_{}", b.name));
            if used.contains(&x.to_string()) {
                out.extend(quote! { let #x: &[f64] = &x[#o..#o + n]; });
            }
        }
        out
    }

    /// Index expression of a state element.
    pub fn index(&self, block: u32, at: At) -> TokenStream {
        let o = self.offset_ident(block);
        match at {
            At::Scalar | At::First => quote!(#o),
            _ => {
                let i = Self::in_block(at);
                quote!(#o + #i)
            }
        }
    }

    /// The Rust for a symbol inside a generated function.
    pub fn leaf(&self, s: Sym) -> TokenStream {
        match s {
            Sym::Param(i) => {
                let id = Ident::new(&self.topo.params[i as usize].name, Span::call_site());
                quote!(#id)
            }
            Sym::State(b, at) if self.sys.blocks[self.block(b)].array => {
                // through the block's own slice (`slices`): an index below `n` in a loop over
                // the sections needs no bounds check
                let (x, idx) = (self.slice_ident(b), Self::in_block(at));
                quote!(#x[#idx])
            }
            Sym::State(b, at) => {
                let idx = self.index(b, at);
                quote!(x[#idx])
            }
            Sym::Index => quote!(jf),
            Sym::Count => quote!(nf),
            Sym::Input(i) => {
                let i = Literal::u32_unsuffixed(i);
                quote!(u[#i])
            }
            Sym::Sum(k) => {
                let id = format_ident!("__sum{}", k);
                quote!(#id)
            }
        }
    }

    /// Display name of a symbol for the printers.
    pub fn name(&self, s: Sym) -> String {
        match s {
            Sym::Param(i) => self.topo.params[i as usize].name.clone(),
            Sym::State(b, at) => {
                let name = self
                    .sys
                    .block_index(b)
                    .map(|i| self.sys.blocks[i].name.clone())
                    .unwrap_or_else(|| format!("s{b}"));
                match at {
                    At::Scalar => name,
                    At::Rel(r) => format!("{name}[{}]", crate::topology::frame::index_text(r)),
                    At::First => format!("{name}[0]"),
                    At::Last => format!("{name}[n-1]"),
                }
            }
            Sym::Index => "j".into(),
            Sym::Count => "n".into(),
            Sym::Input(i) => format!("u{i}"),
            Sym::Sum(k) => format!("S{k}"),
        }
    }
}

/// The identifier of the slice of the state that holds array block `name`.
fn slice_of(name: &str) -> Ident {
    format_ident!("__x_{}", name)
}
