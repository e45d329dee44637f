//! Mass-flow links: flow laws (resistance, quadratic, conductance, orifice) and ends.

use std::collections::HashMap;

use stirling_dsl::expr::{At, Id};
use stirling_dsl::topology::{End, LinkDecl, Vessel};
use syn::spanned::Spanned;

use super::Lower;
use crate::ast::{EndAst, Field, LinkAst};

impl Lower {
    pub(super) fn link(&mut self, l: &LinkAst) {
        if self.is_wall(&l.from.name) || self.is_wall(&l.to.name) {
            return self.conduction(l);
        }
        let var = l.range.as_ref().map(|r| r.var.to_string());
        let from = self.end(&l.from, var.as_deref());
        let to = self.end(&l.to, var.as_deref());
        let f = self.fields(
            &l.fields,
            &["resistance", "conductance", "quadratic", "orifice", "dp0"],
            "`link`",
        );
        let orifice = self.orifice(l, &f, var.as_deref());
        let conductance = self.optional(&f, "conductance", var.as_deref());
        let resistance = match (orifice, conductance) {
            (Some((_, _, r)), _) => r,
            (None, conductance) => match conductance {
                Some(g) => {
                    if f.contains_key("resistance") || f.contains_key("quadratic") {
                        self.cx.error(l.span, "a `link` takes either `conductance: G` (mdot = G dP) or `resistance: R` with optional `quadratic: Rq`, not both");
                    }
                    let one = self.topo.arena.num(1.0);
                    self.topo.arena.div(one, g)
                }
                None => self.required(
                    &f,
                    "resistance",
                    l.span,
                    "`link` (or `conductance: G`, or `orifice: C` with `dp0: dP0`)",
                    var.as_deref(),
                ),
            },
        };
        let quadratic = if conductance.is_some() || orifice.is_some() {
            None
        } else {
            self.optional(&f, "quadratic", var.as_deref())
        };
        let (Some(from), Some(to)) = (from, to) else {
            return;
        };
        let link = LinkDecl {
            from,
            to,
            resistance,
            quadratic,
            conductance,
            orifice: orifice.map(|(c, dp0, _)| (c, dp0)),
        };
        if self.link_shape_ok(
            l,
            (link.from.vessel, link.from.at),
            (link.to.vessel, link.to.at),
        ) {
            self.topo.links.push(link);
        }
    }

    /// `orifice: C, dp0: dP0`: `(C, dP0, sqrt(dP0)/C)`, the last the small-`dP` resistance
    /// shown for the link; `None` without `orifice`.
    pub(super) fn orifice(
        &mut self,
        l: &LinkAst,
        f: &HashMap<String, &Field>,
        var: Option<&str>,
    ) -> Option<(Id, Id, Id)> {
        let Some(c) = self.optional(f, "orifice", var) else {
            if let Some(field) = f.get("dp0") {
                self.cx.error(
                    field.name.span(),
                    "`dp0` is the regularization width of an orifice: it goes with `orifice: C`",
                );
            }
            return None;
        };
        for other in ["resistance", "conductance", "quadratic"] {
            if let Some(field) = f.get(other) {
                self.cx.error(field.name.span(), format!("an orifice link (`orifice: C, dp0: dP0`, mdot = C dP / (dP^2 + dP0^2)^(1/4)) takes no `{other}`"));
            }
        }
        let at = f.get("orifice").map_or(l.span, |field| field.name.span());
        let dp0 = self.required(
            f,
            "dp0",
            at,
            "an orifice `link` (`orifice: C, dp0: dP0`: the pressure difference below which the flow is linear)",
            var,
        );
        let a = &mut self.topo.arena;
        let root = a.func(stirling_dsl::expr::Func::Sqrt, dp0);
        let r = a.div(root, c);
        Some((c, dp0, r))
    }

    pub(super) fn end(&mut self, e: &EndAst, var: Option<&str>) -> Option<End> {
        let Some(&vessel) = self.vessels.get(&e.name.to_string()) else {
            let mut names: Vec<&String> = self.vessels.keys().collect();
            names.sort();
            let list = names
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", ");
            self.cx.error(
                e.name.span(),
                format!(
                    "unknown control volume or space `{}`: expected one of {list}",
                    e.name
                ),
            );
            return None;
        };
        let array = matches!(vessel, Vessel::Cv(i) if self.is_array_cv(i));
        match (&e.index, array) {
            (None, false) => Some(End {
                vessel,
                at: At::Scalar,
            }),
            (Some(ix), false) => {
                self.cx.error(
                    ix.span(),
                    format!("`{}` is not an array: remove the index", e.name),
                );
                None
            }
            (None, true) => {
                self.cx.error(
                    e.name.span(),
                    format!(
                        "`{}` is an array: name a section, e.g. `{0}[0]`, `{0}[n - 1]` or `{0}[j]`",
                        e.name
                    ),
                );
                None
            }
            (Some(ix), true) => self.index(ix, var).map(|at| End { vessel, at }),
        }
    }
}
