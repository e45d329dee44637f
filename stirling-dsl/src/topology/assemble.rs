//! The energetic assembly rules (docs/physics.md sections 1, 2, 4 and 6).
//!
//! Per control volume `i` (ideal gas, `cv = R/(gamma-1)`):
//!
//! ```text
//! V_i  = V_i0 + sum_k a_ik q_k            T_i = P_i V_i / (m_i R)
//! Q_i  = sum_ports h Aw (Tw - T_i)        mdot = (P_from - P_to) / R_link
//! H    = cp mdot (s T_from + (1-s) T_to),  s = (1 + tanh(mdot / mdot_eps)) / 2
//! P_i' = ((gamma-1)(Q_i + H_in - H_out) - gamma P_i V_i') / V_i
//! m_i' = mdot_in - mdot_out
//! ```
//! and per body `m q'' = sum_i a_ik P_i + F - k q - c q' - cq q'|q'| - couplings`.

use super::decl::{Topology, Vessel};
use super::frame::{place, Place};
use super::system::{BlockInfo, BlockKind, Row, System, Variant, VesselTerms, VARIANTS};
use super::walls::PortHeat;
use crate::expr::{At, Id};
use crate::Closure;

/// Where a row is assembled: a scalar block, or a section variant of an array CV or wall.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum RowAt {
    Scalar,
    Array(Vessel, Variant),
}

/// Quantities of a CV in its own frame.
#[derive(Clone, Copy, Debug)]
pub(super) struct CvTemplate {
    pub(super) p: Id,
    pub(super) m: Id,
    pub(super) v: Id,
    pub(super) vdot: Id,
    pub(super) t: Id,
    pub(super) q: Id,
    pub(super) m0: Id,
}

/// Assemble the equations of `topo` under `closure`.
pub fn assemble(topo: &mut Topology, closure: Closure) -> System {
    Assembler::new(topo, closure).run()
}

pub(super) struct Assembler<'t> {
    pub(super) t: &'t mut Topology,
    closure: Closure,
    array_blocks: Vec<bool>,
    pub(super) cv: Vec<CvTemplate>,
    /// Per CV, the heat of each port that names a declared wall, in the CV's frame.
    pub(super) port_heat: Vec<Vec<PortHeat>>,
    /// Templates summed over the sections (`Sym::Sum(k)`), from per-section links.
    pub(super) sums: Vec<Id>,
}

impl<'t> Assembler<'t> {
    pub(super) fn new(t: &'t mut Topology, closure: Closure) -> Self {
        let (nb, ncv) = (t.bodies.len(), t.cvs.len());
        let mut array_blocks = vec![false; 2 * nb + 2 * ncv + t.walls.len()];
        for (i, c) in t.cvs.iter().enumerate() {
            array_blocks[2 * nb + i] = c.array;
            array_blocks[2 * nb + ncv + i] = c.array;
        }
        for (w, wall) in t.walls.iter().enumerate() {
            array_blocks[Topology::wall_block(nb, ncv, w) as usize] = wall.array;
        }
        Self {
            t,
            closure,
            array_blocks,
            cv: Vec::new(),
            port_heat: Vec::new(),
            sums: Vec::new(),
        }
    }

    pub(super) fn p_block(&self, i: usize) -> u32 {
        (2 * self.t.bodies.len() + i) as u32
    }

    pub(super) fn m_block(&self, i: usize) -> u32 {
        (2 * self.t.bodies.len() + self.t.cvs.len() + i) as u32
    }

    pub(super) fn has_mass_state(&self, i: usize) -> bool {
        self.closure == Closure::Full && self.t.cv_is_linked(i)
    }

    pub(super) fn own(&self, i: usize) -> At {
        if self.t.cvs[i].array {
            At::Rel(0)
        } else {
            At::Scalar
        }
    }

    pub(super) fn label(&self, i: usize, what: &str) -> String {
        let c = &self.t.cvs[i];
        if c.array {
            format!("{what}_{}[j]", c.name)
        } else {
            format!("{what}_{}", c.name)
        }
    }

    pub(super) fn run(mut self) -> System {
        for i in 0..self.t.cvs.len() {
            let tpl = self.cv_template(i);
            self.cv.push(tpl);
        }
        let blocks = self.blocks();
        let rows = blocks.iter().map(|b| self.row(b)).collect();
        let init = blocks.iter().map(|b| self.init_row(b)).collect();
        let forces = (0..self.t.bodies.len()).map(|k| self.force(k)).collect();
        let mut vessels: Vec<VesselTerms> =
            (0..self.t.cvs.len()).map(|i| self.cv_terms(i)).collect();
        vessels.extend((0..self.t.spaces.len()).map(|s| self.space_terms(s)));
        let (mech_energy, mech_power) = (self.mech_energy(), self.mech_power());
        let (walls, wall_boundary_heat) = self.wall_terms();
        let array_blocks = self.array_blocks.clone();
        let sums = std::mem::take(&mut self.sums);
        System {
            closure: self.closure,
            blocks,
            rows,
            init,
            forces,
            vessels,
            mech_energy,
            mech_power,
            walls,
            wall_boundary_heat,
            sums,
            array_blocks,
        }
    }

    pub(super) fn blocks(&self) -> Vec<BlockInfo> {
        let mut out = Vec::new();
        for (k, b) in self.t.bodies.iter().enumerate() {
            out.push(BlockInfo {
                sym: Topology::pos_block(k),
                name: b.pos.clone(),
                array: false,
                kind: BlockKind::Position(k),
            });
            out.push(BlockInfo {
                sym: Topology::vel_block(k),
                name: b.vel.clone(),
                array: false,
                kind: BlockKind::Velocity(k),
            });
        }
        for (i, c) in self.t.cvs.iter().enumerate() {
            let name = format!("P_{}", c.name);
            out.push(BlockInfo {
                sym: self.p_block(i),
                name,
                array: c.array,
                kind: BlockKind::Pressure(i),
            });
        }
        for (i, c) in self.t.cvs.iter().enumerate() {
            if self.has_mass_state(i) {
                let name = format!("m_{}", c.name);
                out.push(BlockInfo {
                    sym: self.m_block(i),
                    name,
                    array: c.array,
                    kind: BlockKind::Mass(i),
                });
            }
        }
        out.extend(self.wall_blocks());
        out
    }

    pub(super) fn placed(&mut self, id: Id, at: Place) -> Id {
        place(&mut self.t.arena, id, at, &self.array_blocks)
    }

    pub(super) fn row(&mut self, b: &BlockInfo) -> Row {
        match b.kind {
            BlockKind::Position(k) => Row::Scalar(self.body_syms(k).1),
            BlockKind::Velocity(k) => Row::Scalar(self.acceleration(k)),
            BlockKind::Pressure(i) | BlockKind::Mass(i) => {
                let want_p = matches!(b.kind, BlockKind::Pressure(_));
                if b.array {
                    Row::Array(
                        VARIANTS.map(|v| self.balance(i, RowAt::Array(Vessel::Cv(i), v), want_p)),
                    )
                } else {
                    Row::Scalar(self.balance(i, RowAt::Scalar, want_p))
                }
            }
            BlockKind::WallTemperature(w) => {
                if b.array {
                    Row::Array(VARIANTS.map(|v| self.wall_row(w, RowAt::Array(Vessel::Wall(w), v))))
                } else {
                    Row::Scalar(self.wall_row(w, RowAt::Scalar))
                }
            }
        }
    }

    pub(super) fn init_row(&mut self, b: &BlockInfo) -> Row {
        let id = match b.kind {
            BlockKind::Position(_) | BlockKind::Velocity(_) => self.t.arena.num(0.0),
            BlockKind::Pressure(_) => self.t.gas.as_ref().expect("checked").charge,
            BlockKind::Mass(i) => self.cv[i].m0,
            BlockKind::WallTemperature(w) => self.t.walls[w].rest,
        };
        if b.array {
            Row::Array([id; 4])
        } else {
            Row::Scalar(id)
        }
    }
}
