//! The balances of a CV (docs/physics.md sections 2 and 4): `P'` and `m'` from the heat, the
//! link flows seen from the row, and the sums over the sections of per-section links.

use super::assemble::{Assembler, RowAt};
use super::decl::{LinkDecl, Vessel};
use super::frame::Place;
use super::links::{end_name, end_place, enthalpy, orifice_flow, quadratic_flow, rel_min, touches};
use crate::expr::{At, Id, Sym};

impl Assembler<'_> {
    /// `P'` (`want_p`) or `m'` of CV `i` at `row`.
    pub(super) fn balance(&mut self, i: usize, row: RowAt, want_p: bool) -> Id {
        let (summed, flows): (Vec<Flow>, Vec<Flow>) =
            self.flows_of(i, row).into_iter().partition(|f| f.summed);
        let tpl = self.cv[i];
        let gas = self.t.gas.clone().expect("checked");
        let pick = |f: &Flow| if want_p { f.h } else { f.mdot };
        let start = if want_p { tpl.q } else { self.t.arena.num(0.0) };
        let mut total = signed(&mut self.t.arena, start, &flows, &pick);
        if !summed.is_empty() {
            let zero = self.t.arena.num(0.0);
            let template = signed(&mut self.t.arena, zero, &summed, &pick);
            let sum = self.reduce(template);
            total = self.t.arena.add(total, sum);
        }
        let a = &mut self.t.arena;
        if !want_p {
            return total;
        }
        let one = a.num(1.0);
        let gm1 = a.sub(gas.gamma, one);
        let qh = total;
        let e = a.mul(gm1, qh);
        let gp = a.mul(gas.gamma, tpl.p);
        let w = a.mul(gp, tpl.vdot);
        let num = a.sub(e, w);
        a.div(num, tpl.v)
    }

    /// The links touching CV `i` at `row`, with their flows in the row's frame.
    pub(super) fn flows_of(&mut self, i: usize, row: RowAt) -> Vec<Flow> {
        let links = self.t.links.clone();
        let mut out = Vec::new();
        for l in &links {
            for (end, into) in [(&l.from, false), (&l.to, true)] {
                if end.vessel != Vessel::Cv(i) {
                    continue;
                }
                let base = if l.is_per_section() && matches!(end.at, At::Rel(_)) {
                    // the array end of a per-section link: every section
                    matches!(row, RowAt::Array(..)).then_some(0)
                } else {
                    touches(end.at, row, rel_min(l.from.at, l.to.at))
                };
                if let Some(base) = base {
                    out.push(self.flow(l, row, base, into));
                }
            }
        }
        out
    }

    /// The flow of link `l` seen from `row`, whose own section is `base` in the link's frame.
    pub(super) fn flow(&mut self, l: &LinkDecl, row: RowAt, base: i32, into: bool) -> Flow {
        let (p_from, t_from, from_name) = self.end_state(l.from.vessel, l.from.at, row, base);
        let (p_to, t_to, to_name) = self.end_state(l.to.vessel, l.to.at, row, base);
        let shift = if l.is_chain() {
            Place::Shift(-base)
        } else {
            Place::Own
        };
        let r = self.placed(l.resistance, shift);
        let rq = l.quadratic.map(|q| self.placed(q, shift));
        let g = l.conductance.map(|g| self.placed(g, shift));
        let orifice = l
            .orifice
            .map(|(c, dp0)| (self.placed(c, shift), self.placed(dp0, shift)));
        let name = format!("{from_name}_{to_name}");
        let gas = self.t.gas.clone().expect("checked");
        let a = &mut self.t.arena;
        let dp = a.sub(p_from, p_to);
        let mdot_raw = match (g, rq) {
            _ if orifice.is_some() => {
                let (c, dp0) = orifice.expect("checked");
                orifice_flow(a, dp, c, dp0)
            }
            (Some(g), _) => a.mul(g, dp),
            (None, None) => a.div(dp, r),
            (None, Some(rq)) => quadratic_flow(a, dp, r, rq),
        };
        let mdot = a.named(&format!("mdot_{name}"), mdot_raw);
        let h_raw = enthalpy(a, mdot, t_from, t_to, &gas);
        let h = a.named(&format!("H_{name}"), h_raw);
        let summed = l.is_per_section() && row == RowAt::Scalar;
        Flow {
            mdot,
            h,
            into,
            summed,
        }
    }

    /// `Sym::Sum(k)`: the sum of `template` (in an array's frame) over the sections.
    pub(super) fn reduce(&mut self, template: Id) -> Id {
        let k = match self.sums.iter().position(|&s| s == template) {
            Some(k) => k,
            None => {
                self.sums.push(template);
                self.sums.len() - 1
            }
        };
        self.t.arena.sym(Sym::Sum(k as u32))
    }

    /// Pressure, temperature and display name of a link end seen from `row`.
    pub(super) fn end_state(
        &mut self,
        vessel: Vessel,
        at: At,
        row: RowAt,
        base: i32,
    ) -> (Id, Id, String) {
        match vessel {
            Vessel::Space(s) => {
                let sp = &self.t.spaces[s];
                (
                    sp.pressure,
                    sp.temperature
                        .expect("checked: a linked space has a temperature"),
                    sp.name.clone(),
                )
            }
            Vessel::Wall(_) => unreachable!("checked: a mass-flow link never ends at a wall"),
            Vessel::Cv(c) => {
                let pl = end_place(vessel, at, row, base);
                let tpl = self.cv[c];
                let (p, t) = (self.placed(tpl.p, pl), self.placed(tpl.t, pl));
                let shown = match pl {
                    Place::Own => At::Rel(0),
                    Place::Shift(k) => At::Rel(k),
                    Place::First => At::First,
                    Place::Last => At::Last,
                };
                (
                    p,
                    t,
                    end_name(&self.t.cvs[c].name, self.t.cvs[c].array, shown),
                )
            }
        }
    }
}

/// One link's flow as seen by a CV balance.
pub(super) struct Flow {
    pub(super) mdot: Id,
    pub(super) h: Id,
    pub(super) into: bool,
    /// A per-section link seen from its scalar end: the flow is a template to sum over `j`.
    pub(super) summed: bool,
}

/// `start + sum(into) - sum(out)` of the picked quantity of `flows`.
pub(super) fn signed(
    a: &mut crate::expr::Arena,
    start: Id,
    flows: &[Flow],
    pick: &dyn Fn(&Flow) -> Id,
) -> Id {
    flows.iter().fold(start, |acc, f| {
        if f.into {
            a.add(acc, pick(f))
        } else {
            a.sub(acc, pick(f))
        }
    })
}
