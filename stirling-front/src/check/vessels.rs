//! Spaces, control volumes and their heat ports.

use stirling_dsl::topology::{CvDecl, PortDecl, SpaceDecl};

use super::Lower;
use crate::ast::VesselAst;

impl Lower {
    pub(super) fn space(&mut self, v: &VesselAst) {
        let what = format!("space `{}`", v.name);
        if let Some(n) = &v.array {
            self.cx.error(
                n.span(),
                format!("{what}: a given-pressure space cannot be an array"),
            );
        }
        if !v.ports.is_empty() {
            self.cx.error(
                v.ports[0].name.span(),
                format!("{what}: a given-pressure space has no heat ports (make it a `cv`)"),
            );
        }
        let f = self.fields(&v.fields, &["pressure", "volume", "temperature"], &what);
        let pressure = self.required(&f, "pressure", v.name.span(), &what, None);
        let volume = self
            .optional(&f, "volume", None)
            .unwrap_or_else(|| self.topo.arena.num(0.0));
        let temperature = self.optional(&f, "temperature", None);
        let faces = self.faces(&v.faces, &v.name.to_string());
        self.topo.spaces.push(SpaceDecl {
            name: v.name.to_string(),
            pressure,
            volume,
            temperature,
            faces,
        });
    }

    pub(super) fn cv(&mut self, v: &VesselAst) {
        let what = format!("control volume `{}`", v.name);
        let index = v.array.as_ref().map(|_| "j");
        if let Some(n) = &v.array {
            self.check_array_length(n, &what);
            if let Some(f) = v.faces.first() {
                self.cx.error(f.name.span(), format!("{what}: faces on an array of CVs are not supported; give the faces to a single CV"));
            }
        }
        let f = self.fields(&v.fields, &["volume"], &what);
        let volume = match f.get("volume") {
            Some(field) => {
                self.static_expr(&field.value, index, &format!("the volume of `{}`", v.name))
            }
            None => {
                self.cx.error(v.name.span(), format!("{what} has no volume: expected `volume: <expression>` (its volume at rest)"));
                self.topo.arena.num(1.0)
            }
        };
        if v.ports.is_empty() {
            self.cx.error(v.name.span(), format!("{what} has no heat port: expected `port name {{ h: .., area: .., wall: .. }}` (its rest temperature is the ports' mean wall temperature)"));
        }
        let ports = v.ports.iter().map(|p| self.port(p, index)).collect();
        let faces = if v.array.is_some() {
            Vec::new()
        } else {
            self.faces(&v.faces, &v.name.to_string())
        };
        self.topo.cvs.push(CvDecl {
            name: v.name.to_string(),
            array: v.array.is_some(),
            volume,
            faces,
            ports,
        });
    }

    pub(super) fn port(&mut self, p: &crate::ast::PortAst, index: Option<&str>) -> PortDecl {
        let what = format!("heat port `{}`", p.name);
        let f = self.fields(&p.fields, &["h", "area", "wall"], &what);
        let h = self.required(&f, "h", p.name.span(), &what, index);
        let area = self.required(&f, "area", p.name.span(), &what, index);
        let (wall, wall_ref) = match f.get("wall") {
            Some(field) => self.port_wall(&field.value, index),
            None => {
                self.cx.error(
                    p.name.span(),
                    format!("{what} has no wall temperature: expected `wall: <expression>` or `wall: <declared wall>`"),
                );
                (self.topo.arena.num(1.0), None)
            }
        };
        PortDecl {
            name: p.name.to_string(),
            h,
            area,
            wall,
            wall_ref,
        }
    }
}
