//! Walls with a temperature state (thermal masses), docs/physics.md section 4:
//!
//! ```text
//! C Tw' = input - sum_ports h A (Tw - T_gas) + sum_links G (T_other - Tw)
//! ```
//!
//! A port of a CV that names the wall gives the gas `Q = h A (Tw - T)` and takes the same
//! heat from the wall; a conduction link `a -> b` carries `Q = G (T_a - T_b)` from `a` to
//! `b`, between two walls or between a wall and a fixed temperature. An array of walls
//! `matrix[n]` is assembled once in its own frame (section `j`, neighbours at `j +- 1`),
//! like an array of CVs. The energy budget holds `C Tw` per wall element; the heat from
//! outside is the walls' `input` and what the links bring from fixed temperatures.

use std::collections::HashMap;

use super::assemble::{Assembler, RowAt};
use super::decl::{ConductionDecl, HeatEnd, Topology, Vessel};
use super::frame::Place;
use super::links::{end_name, end_place, rel_min, touches};
use super::system::{BlockInfo, BlockKind, WallTerms};
use crate::expr::{At, Id, Node, Sym};

/// The heat of one CV port into the gas from a declared wall, in the CV's frame.
#[derive(Clone, Copy, Debug)]
pub(super) struct PortHeat {
    pub(super) wall: usize,
    pub(super) q: Id,
    /// A port of an array of CVs to a single wall: the wall takes the sum over the sections.
    pub(super) summed: bool,
}

impl Assembler<'_> {
    fn wall_sym_block(&self, w: usize) -> u32 {
        Topology::wall_block(self.t.bodies.len(), self.t.cvs.len(), w)
    }

    /// The wall's temperature in its own frame.
    fn wall_sym(&mut self, w: usize) -> Id {
        let at = if self.t.walls[w].array {
            At::Rel(0)
        } else {
            At::Scalar
        };
        let b = self.wall_sym_block(w);
        self.t.arena.sym(Sym::State(b, at))
    }

    /// One temperature block per wall, after the gas states.
    pub(super) fn wall_blocks(&self) -> Vec<BlockInfo> {
        let walls = self.t.walls.iter().enumerate();
        walls
            .map(|(w, wall)| BlockInfo {
                sym: self.wall_sym_block(w),
                name: format!("Tw_{}", wall.name),
                array: wall.array,
                kind: BlockKind::WallTemperature(w),
            })
            .collect()
    }

    /// Block number -> the wall's rest temperature.
    pub(super) fn wall_rests(&self) -> HashMap<u32, Id> {
        let walls = self.t.walls.iter().enumerate();
        walls
            .map(|(w, x)| (self.wall_sym_block(w), x.rest))
            .collect()
    }

    /// `Tw'` of wall `w` at `row`.
    pub(super) fn wall_row(&mut self, w: usize, row: RowAt) -> Id {
        let mut total = self.t.walls[w].input;
        let ports: Vec<PortHeat> = self
            .port_heat
            .iter()
            .flatten()
            .filter(|h| h.wall == w)
            .copied()
            .collect();
        for h in ports {
            // every section's port into one wall: the wall row takes their sum (O(n) loop)
            let q = if h.summed { self.reduce(h.q) } else { h.q };
            total = self.t.arena.sub(total, q);
        }
        for l in self.t.conductions.clone() {
            for (end, into) in [(l.from, false), (l.to, true)] {
                let HeatEnd::Wall(e) = end else { continue };
                if e.vessel != Vessel::Wall(w) {
                    continue;
                }
                let (fa, ta) = (heat_at(l.from), heat_at(l.to));
                let per_section = l.is_per_section();
                let base = match (per_section, e.at, row) {
                    // the array end of a per-section link: every section
                    (true, At::Rel(_), RowAt::Array(..)) => Some(0),
                    (true, At::Rel(_), RowAt::Scalar) => None,
                    _ => touches(e.at, row, rel_min(fa, ta)),
                };
                if let Some(base) = base {
                    let q = self.conduction(&l, row, base);
                    // the scalar end of a per-section link: the sum over the sections
                    let q = if per_section && row == RowAt::Scalar {
                        self.reduce(q)
                    } else {
                        q
                    };
                    let a = &mut self.t.arena;
                    total = if into {
                        a.add(total, q)
                    } else {
                        a.sub(total, q)
                    };
                }
            }
        }
        let c = self.t.walls[w].capacity;
        per_capacity(&mut self.t.arena, total, c)
    }

    /// `Q = G (T_from - T_to)` of link `l` seen from `row`, whose own section is `base`
    /// in the link's frame.
    fn conduction(&mut self, l: &ConductionDecl, row: RowAt, base: i32) -> Id {
        let (t_from, from_name) = self.heat_end(l.from, row, base);
        let (t_to, to_name) = self.heat_end(l.to, row, base);
        let shift = if l.is_chain() {
            Place::Shift(-base)
        } else {
            Place::Own
        };
        let g = self.placed(l.conductance, shift);
        let a = &mut self.t.arena;
        let dt = a.sub(t_from, t_to);
        let q = a.mul(g, dt);
        a.named(&format!("Q_{from_name}_{to_name}"), q)
    }

    /// Temperature and display name of a conduction end seen from `row`.
    fn heat_end(&mut self, end: HeatEnd, row: RowAt, base: i32) -> (Id, String) {
        match end {
            HeatEnd::Fixed(t) => (t, self.fixed_name(t)),
            HeatEnd::Wall(e) => {
                let Vessel::Wall(w) = e.vessel else {
                    unreachable!("a conduction end is a wall")
                };
                let pl = end_place(e.vessel, e.at, row, base);
                let own = self.wall_sym(w);
                let t = self.placed(own, pl);
                let shown = match pl {
                    Place::Own => At::Rel(0),
                    Place::Shift(k) => At::Rel(k),
                    Place::First => At::First,
                    Place::Last => At::Last,
                };
                let wall = &self.t.walls[w];
                (t, end_name(&wall.name, wall.array, shown))
            }
        }
    }

    /// The display name of a fixed temperature: its parameter or `let` name.
    fn fixed_name(&self, t: Id) -> String {
        match *self.t.arena.node(t) {
            Node::Sym(Sym::Param(k)) => self.t.params[k as usize].name.clone(),
            Node::Named(i, _) => self.t.arena.name(i).to_string(),
            _ => "fixed".to_string(),
        }
    }

    /// Per wall `C Tw` and its `input`; and the heat the conduction links bring from fixed
    /// temperatures into the walls.
    pub(super) fn wall_terms(&mut self) -> (Vec<WallTerms>, Id) {
        let mut terms = Vec::new();
        for w in 0..self.t.walls.len() {
            let tw = self.wall_sym(w);
            let wall = self.t.walls[w].clone();
            let energy = self.t.arena.mul(wall.capacity, tw);
            terms.push(WallTerms {
                array: wall.array,
                energy,
                heat: wall.input,
            });
        }
        let mut boundary = self.t.arena.num(0.0);
        for l in self.t.conductions.clone() {
            let sign = match (l.from, l.to) {
                (HeatEnd::Fixed(_), _) => 1.0,
                (_, HeatEnd::Fixed(_)) => -1.0,
                _ => continue,
            };
            let q = self.conduction(&l, RowAt::Scalar, 0);
            let q = if l.is_per_section() {
                self.reduce(q)
            } else {
                q
            };
            let a = &mut self.t.arena;
            let s = a.num(sign);
            let term = a.mul(s, q);
            boundary = a.add(boundary, term);
        }
        (terms, boundary)
    }
}

fn heat_at(e: HeatEnd) -> At {
    match e {
        HeatEnd::Wall(e) => e.at,
        HeatEnd::Fixed(_) => At::Scalar,
    }
}

/// `total / C`; a capacity written `1 / k` gives `k total`, so that `k = 0` (infinite
/// capacity, the fixed wall) is exact.
fn per_capacity(a: &mut crate::expr::Arena, total: Id, c: Id) -> Id {
    let inner = a.unname(c);
    if let Node::Div(num, k) = *a.node(inner) {
        if a.as_const(num) == Some(1.0) {
            return a.mul(k, total);
        }
    }
    a.div(total, c)
}
