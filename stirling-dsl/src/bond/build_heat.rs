//! The walls of the bond graph: each wall element a 0-junction (common wall temperature)
//! with its heat capacity `C` and its heat input `Sf`; each conduction link a 1-junction
//! (common heat flow) with its thermal resistance `R: 1/G`.

use super::build::Builder;
use super::ends::{self, End};
use super::error::BondError;
use super::graph::{Domain, Kind, NodeId, Store};

impl Builder<'_> {
    /// The wall elements.
    pub(super) fn walls(&mut self) {
        let topo = self.topo;
        let mut k = 0;
        for w in topo.walls {
            let mut nodes = Vec::new();
            for j in 0..self.count(w.array) {
                let name = if w.array {
                    format!("{}[{j}]", w.name)
                } else {
                    w.name.to_string()
                };
                let zero = self.g.node(Kind::Zero, format!("T {name}"));
                let c = self
                    .g
                    .storage(Kind::C, w.capacity, vec![Store::WallHeat(k)]);
                self.g.bond(zero, c, Domain::Heat);
                if w.input != "0" {
                    let sf = self.g.node(Kind::Sf, w.input);
                    self.g.bond(sf, zero, Domain::Heat);
                }
                nodes.push(zero);
                k += 1;
            }
            self.walls.push(nodes);
        }
    }

    /// The conduction links.
    pub(super) fn conductions(&mut self) -> Result<(), BondError> {
        for c in self.topo.conductions {
            let (a, b) = (ends::parse(c.from)?, ends::parse(c.to)?);
            let sections = if c.fixed[0] || c.fixed[1] {
                let wall = if c.fixed[0] { &b } else { &a };
                ends::sections(wall, wall, self.n)
            } else {
                ends::sections(&a, &b, self.n)
            };
            for j in sections {
                let from = self.heat_end(&a, c.from, c.fixed[0], j)?;
                let to = self.heat_end(&b, c.to, c.fixed[1], j)?;
                let one = self.g.node(Kind::One, format!("Q {}->{}", c.from, c.to));
                self.g.bond(from, one, Domain::Heat);
                self.g.bond(one, to, Domain::Heat);
                let r = self.g.node(Kind::R, format!("1/({})", c.conductance));
                self.g.bond(one, r, Domain::Heat);
            }
        }
        Ok(())
    }

    /// A conduction end: a fixed temperature (a new source) or a wall element.
    fn heat_end(
        &mut self,
        e: &End,
        text: &str,
        fixed: bool,
        j: usize,
    ) -> Result<NodeId, BondError> {
        if fixed {
            return Ok(self.effort_source(text));
        }
        let w = self.topo.walls.iter().position(|w| w.name == e.name);
        let len = w.map_or(0, |w| self.walls[w].len());
        let el = ends::element(e.index, j, len);
        match (w, el) {
            (Some(w), Some(el)) => Ok(self.walls[w][el]),
            _ => Err(BondError::Unknown(text.to_string())),
        }
    }
}
