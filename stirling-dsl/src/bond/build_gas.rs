//! The gas part of the bond graph: each CV element a multiport `C` field (volume, heat and
//! mass ports), each given-pressure space an effort source, each face a `TF`, each heat port
//! a 1-junction with its conductance `R`, each mass-flow link a 1-junction with its `R`.

use super::build::{Builder, Ports};
use super::ends::{self, End};
use super::error::BondError;
use super::graph::{Domain, Kind, NodeId, Store};
use crate::Closure;

impl Builder<'_> {
    /// The field node of every CV element and the face transformers of every vessel.
    pub(super) fn vessels(&mut self) {
        let topo = self.topo;
        for v in topo.vessels {
            let count = if v.is_cv { self.count(v.array) } else { 1 };
            let mut fields = Vec::new();
            let mut ports = Vec::new();
            for j in 0..count {
                if v.is_cv {
                    let label = if v.array {
                        format!("{}[{j}]", v.name)
                    } else {
                        v.name.to_string()
                    };
                    fields.push(self.g.node(Kind::C, label));
                }
                let mut p = Ports::default();
                for f in v.faces {
                    let Some(k) = topo.bodies.iter().position(|b| *b == f.body) else {
                        continue;
                    };
                    let tf = if f.modulus.is_empty() {
                        self.g.node(Kind::Tf, f.coeff)
                    } else {
                        // a face on a mechanism: modulated by the flywheel's angle
                        self.g
                            .node(Kind::Mtf, format!("{} * {}", f.coeff, f.modulus))
                    };
                    self.g.bond(tf, self.bodies[k], Domain::Mechanical);
                    p.volume.push((tf, true));
                }
                ports.push(p);
            }
            self.fields.push(fields);
            self.vessels.push(ports);
        }
    }

    /// Each heat port: the wall temperature (a source, or a declared wall's 0-junction) and
    /// the gas temperature across a 1-junction (common heat flow) with the conductance `R`.
    pub(super) fn ports(&mut self) -> Result<(), BondError> {
        let topo = self.topo;
        for (vi, v) in topo.vessels.iter().enumerate() {
            for j in 0..self.vessels[vi].len() {
                for pt in v.ports {
                    let wall = match pt.wall_ref {
                        Some(w) => self.wall_node(w, if v.array { Some(j) } else { None })?,
                        None if v.array => self.effort_source(&at_section(pt.wall, j)),
                        None => self.effort_source(pt.wall),
                    };
                    let one = self.g.node(Kind::One, format!("Q {}.{}", v.name, pt.name));
                    self.g.bond(wall, one, Domain::Heat);
                    let r = self.g.node(Kind::R, format!("hA {}", pt.name));
                    self.g.bond(one, r, Domain::Heat);
                    self.vessels[vi][j].heat.push((one, false));
                }
            }
        }
        Ok(())
    }

    /// The 0-junction of element `j` of wall `name` (element 0 of a scalar wall).
    pub(super) fn wall_node(&self, name: &str, j: Option<usize>) -> Result<NodeId, BondError> {
        let w = self.topo.walls.iter().position(|w| w.name == name);
        let nodes = w.map(|w| &self.walls[w]);
        nodes
            .and_then(|ns| ns.get(if ns.len() > 1 { j.unwrap_or(0) } else { 0 }))
            .copied()
            .ok_or_else(|| BondError::Unknown(name.to_string()))
    }

    /// Each mass-flow link: a 1-junction (common mass flow) with its resistance `R`, between
    /// the mass ports of the two vessel elements.
    pub(super) fn links(&mut self) -> Result<(), BondError> {
        for l in self.topo.links {
            let (a, b) = (ends::parse(l.from)?, ends::parse(l.to)?);
            for j in ends::sections(&a, &b, self.n) {
                let (va, ea) = self.vessel_element(&a, j)?;
                let (vb, eb) = self.vessel_element(&b, j)?;
                let one = self.g.node(Kind::One, format!("mdot {}->{}", l.from, l.to));
                let r = self.g.node(Kind::R, l.resistance);
                self.g.bond(one, r, Domain::MassFlow);
                self.vessels[va][ea].mass.push((one, true));
                self.vessels[vb][eb].mass.push((one, false));
            }
        }
        Ok(())
    }

    /// The vessel and element an end names at section `j`.
    fn vessel_element(&self, e: &End, j: usize) -> Result<(usize, usize), BondError> {
        let unknown = || BondError::Unknown(e.name.to_string());
        let v = self
            .topo
            .vessels
            .iter()
            .position(|v| v.name == e.name)
            .ok_or_else(unknown)?;
        let el = ends::element(e.index, j, self.vessels[v].len()).ok_or_else(unknown)?;
        Ok((v, el))
    }

    /// Joins every field and space source to its ports and sets the fields' states.
    pub(super) fn finish(&mut self) {
        let topo = self.topo;
        let (mut cv, mut space) = (0, 0);
        for (vi, v) in topo.vessels.iter().enumerate() {
            let ports = std::mem::take(&mut self.vessels[vi]);
            for (j, p) in ports.iter().enumerate() {
                if v.is_cv {
                    let field = self.fields[vi][j];
                    self.g.nodes[field].states = self.field_states(cv, p);
                    let name = self.g.nodes[field].label.clone();
                    self.attach(field, &p.volume, Domain::Volume, format!("P {name}"));
                    self.attach(field, &p.heat, Domain::Heat, format!("T {name}"));
                    self.attach(field, &p.mass, Domain::MassFlow, format!("P {name} (mass)"));
                    cv += 1;
                } else {
                    let pressure = topo.space_pressures.get(space).copied().unwrap_or(v.name);
                    for (conns, domain) in
                        [(&p.volume, Domain::Volume), (&p.mass, Domain::MassFlow)]
                    {
                        if !conns.is_empty() {
                            let src = self.effort_source(pressure);
                            self.attach(src, conns, domain, format!("P {}", v.name));
                        }
                    }
                }
            }
            if !v.is_cv {
                space += 1;
            }
        }
    }

    /// The states of CV element `k`: its volume (when faces move it), its energy, and its
    /// mass when a link changes it and the closure keeps it.
    fn field_states(&self, k: usize, p: &Ports) -> Vec<Store> {
        let mut s = Vec::new();
        if !p.volume.is_empty() {
            s.push(Store::Volume(k));
        }
        s.push(Store::Energy(k));
        if !p.mass.is_empty() && self.closure == Closure::Full {
            s.push(Store::Mass(k));
        }
        s
    }
}

/// `expr` with the section index `j` written as the number `j` (`Th - (j + 0.5) * dT / n` at
/// section 1: `Th - (1 + 0.5) * dT / n`).
fn at_section(expr: &str, j: usize) -> String {
    let mut out = String::new();
    let mut word = String::new();
    for c in expr.chars().chain(std::iter::once(' ')) {
        if c.is_alphanumeric() || c == '_' {
            word.push(c);
            continue;
        }
        if word == "j" {
            out.push_str(&j.to_string());
        } else {
            out.push_str(&word);
        }
        word.clear();
        out.push(c);
    }
    out.pop();
    out
}
