//! `sensor name: STATE "unit";`: the observed state must be one the model declares (a body's
//! position or velocity, a CV's pressure or mass, a wall's temperature; an array's element
//! needs an index, a scalar's none). Whether an index is below `n`, and whether a mass state
//! exists in the chosen closure, is known at run time only (`Model::sensor_state`).

use stirling_dsl::topology::{SensorDecl, Vessel};

use super::Lower;
use crate::ast::SensorAst;

impl Lower {
    /// `free a, b;`: each a declared parameter, once.
    pub(super) fn free(&mut self, names: &[syn::Ident]) {
        for id in names {
            let name = id.to_string();
            if !self.is_param(&name) {
                self.cx.error(id.span(), format!("`free {name}`: no parameter `{name}`; `free` lists the parameters a fit frees by default"));
            } else if self.topo.free.contains(&name) {
                self.cx.error(id.span(), format!("`free`: `{name}` twice"));
            } else {
                self.topo.free.push(name);
            }
        }
    }

    pub(super) fn sensor(&mut self, s: &SensorAst) {
        let name = s.name.to_string();
        if name == "t" {
            self.cx.error(
                s.name.span(),
                "`t` is the time column; name the sensor otherwise",
            );
            return;
        }
        if self.topo.sensors.iter().any(|d| d.name == name) {
            self.cx
                .error(s.name.span(), format!("duplicate sensor `{name}`"));
            return;
        }
        let state = s.state.to_string();
        let Some((array, unit)) = self.sensed_state(&state) else {
            self.cx.error(
                s.state.span(),
                format!("sensor `{name}`: no state `{state}`; a sensor observes a body's position or velocity (its declared name), `P_<cv>`, `m_<cv>` or `Tw_<wall>`"),
            );
            return;
        };
        let full = match (&s.index, array) {
            (None, false) => state,
            (Some(k), true) => match k.base10_parse::<usize>() {
                Ok(k) => format!("{state}[{k}]"),
                Err(e) => {
                    self.cx.errors.push(e);
                    return;
                }
            },
            (None, true) => {
                self.cx.error(
                    s.state.span(),
                    format!("sensor `{name}`: `{state}` is an array state: write `{state}[k]`"),
                );
                return;
            }
            (Some(_), false) => {
                self.cx.error(
                    s.state.span(),
                    format!("sensor `{name}`: `{state}` is not an array state: drop the index"),
                );
                return;
            }
        };
        self.topo.sensors.push(SensorDecl {
            name,
            state: full,
            unit: s.unit.as_ref().map_or(unit.to_string(), |u| u.value()),
        });
    }

    /// Whether `state` names a declared state: `(is an array, its unit)`.
    fn sensed_state(&self, state: &str) -> Option<(bool, &'static str)> {
        if self.topo.bodies.iter().any(|b| b.pos == state) {
            return Some((false, "m"));
        }
        if self.topo.bodies.iter().any(|b| b.vel == state) {
            return Some((false, "m/s"));
        }
        let cv = |name: &str| match self.vessels.get(name) {
            Some(Vessel::Cv(i)) => Some(self.topo.cvs[*i].array),
            _ => None,
        };
        if let Some(v) = state.strip_prefix("P_") {
            return cv(v).map(|a| (a, "Pa"));
        }
        if let Some(v) = state.strip_prefix("m_") {
            return cv(v).map(|a| (a, "kg"));
        }
        let w = state.strip_prefix("Tw_")?;
        self.walls.get(w).map(|&(_, a)| (a, "K"))
    }
}
