//! The augmented family members: every DSL-expressible effect of docs/physics.md section 9 as an
//! extra parameter whose null value (0) makes the effect absent.
//!
//! - seal leak cold space -> bounce space: `mdot = Gleak (Pc - Pb)` (a `conductance:` link, so
//!   `Gleak = 0` is exactly no flow; the bounce space gets `temperature: Tk` for the enthalpy);
//! - Coulomb friction: `-Fcd tanh(v / v_eps)` on the displacer, `-Fcp tanh(w / v_eps)` on the piston;
//! - end stops: `-kc relu(|q| - q_max) sign(q)` with `relu(u) = (u + |u|)/2`;
//! - quadratic regenerator friction (`nsection` only): `quadratic: Rq` on the regenerator links,
//!   split like `Rf` (`Rq/(2n)` at the ends, `Rq/n` between sections).

// The effects that act on a body or between two volumes are `effect` items, named where they act
// (docs/custom-topologies.md, "Effects"); the rest change the frame's items with `modify`
// (docs/custom-topologies.md, "Composition"). The parameters are declared here, with the
// library's names and docs, so the `effect` items add none of their own.

// `nsection_fx_engine` is crate-local: extending it calls back through the `stirling_model` in scope.
use stirling_macros::stirling_model;

stirling_macros::stirling_model! {
    /// `cv1` with the DSL-expressible effects (leak, Coulomb friction, end stops) at null values.
    pub model Cv1Fx extends default_engine {
        effect coulomb on displacer as Fcd, v_eps;
        effect end_stops on displacer as kc, xmax;
        effect coulomb on piston as Fcp, v_eps;
        effect end_stops on piston as kc, ymax;
        modify space bounce { temperature: Tk }
        name "cv1_fx";
        params {
            /// seal-leak conductance, cold space to bounce space (0: no leak)
            Gleak: 0.0 "kg/(s Pa)",
            /// displacer Coulomb friction force (0: none)
            Fcd: 0.0 "N",
            /// power-piston Coulomb friction force (0: none)
            Fcp: 0.0 "N",
            /// velocity scale of the smoothed Coulomb friction
            v_eps: 1.0e-3 "m/s",
            /// end-stop contact stiffness (0: no stops)
            kc: 0.0 "N/m",
            /// displacer travel to its end stops
            xmax: 0.01 "m",
            /// power-piston travel to its end stops
            ymax: 0.01 "m",
        }
        cv gas {
            volume: Vh0 + Vc0 + Vr,
            faces { displacer: -A + (A - Ar), piston: -(A - Ar) },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
            port regen { h: hr, area: Awr, wall: (Th + Tk) / 2.0 },
        }
        effect leak gas -> bounce as Gleak;
    }
}

stirling_macros::stirling_model! {
    /// `nsection` with the effects that add no state (leak, Coulomb friction, end stops,
    /// quadratic regenerator friction) at null values: the frame of [`NSectionFx`] and
    /// [`NSectionExtFx`].
    base nsection_fx_engine extends nsection_engine {
        effect coulomb on displacer as Fcd, v_eps;
        effect end_stops on displacer as kc, xmax;
        effect coulomb on piston as Fcp, v_eps;
        effect end_stops on piston as kc, ymax;
        modify space bounce { temperature: Tk }
        params {
            /// seal-leak conductance, cold space to bounce space (0: no leak)
            Gleak: 0.0 "kg/(s Pa)",
            /// displacer Coulomb friction force (0: none)
            Fcd: 0.0 "N",
            /// power-piston Coulomb friction force (0: none)
            Fcp: 0.0 "N",
            /// velocity scale of the smoothed Coulomb friction
            v_eps: 1.0e-3 "m/s",
            /// end-stop contact stiffness (0: no stops)
            kc: 0.0 "N/m",
            /// displacer travel to its end stops
            xmax: 0.01 "m",
            /// power-piston travel to its end stops
            ymax: 0.01 "m",
            /// quadratic (turbulent) regenerator friction, whole regenerator (0: linear only)
            Rq: 0.0 "Pa s^2/kg^2",
        }
        modify link hot -> regen[0] { quadratic: Rq / (2.0 * n) }
        modify link regen[j] -> regen[j + 1] { quadratic: Rq / n }
        modify link regen[n - 1] -> cold { quadratic: Rq / (2.0 * n) }
        effect leak cold -> bounce as Gleak;
    }
}
// the base by path, for the outside causes' truth models (`model/outside.rs`)
pub(crate) use nsection_fx_engine;

stirling_macros::stirling_model! {
    /// `nsection` with all DSL-expressible effects (leak, Coulomb friction, end stops,
    /// quadratic regenerator friction) at null values.
    pub model NSectionFx extends nsection_fx_engine {
        name "nsection_fx";
    }
}

stirling_macros::stirling_model! {
    /// `nsection_fx` plus the effects that need walls with a temperature state or the orifice
    /// law, at null values: a regenerator matrix of heat capacity `1/km` (wall `matrix[n]`
    /// behind `regen[j]`, axial conduction `Gm` to the fixed heater and cooler ends), a heater
    /// head of heat capacity `1/kh` fed by a fixed input `Gloss (Th - Tk)` and losing heat to
    /// the cooler by conduction `Gloss` (so its rest state is `Th`), and a square-root seal leak
    /// cold space -> bounce space. At `km = kh = 0` the walls are frozen at their rest, the
    /// fixed walls of `nsection`; at `Co = 0` the orifice carries nothing.
    pub model NSectionExtFx extends nsection_fx_engine {
        name "nsection_ext_fx";
        params {
            /// inverse heat capacity of the whole regenerator matrix (0: infinite, the fixed wall)
            km: 0.0 "K/J",
            /// axial conductance of the whole matrix (its path to the heater and cooler ends)
            Gm: 0.03 "W/K",
            /// inverse heat capacity of the heater head (0: infinite, the head fixed at Th)
            kh: 0.0 "K/J",
            /// conductance from the heater head to the cooler (the heater's loss path)
            Gloss: 0.5 "W/K",
            /// orifice seal-leak coefficient, cold space to bounce space (0: no leak)
            Co: 0.0 "kg/(s Pa^0.5)",
            /// width of the orifice law's linear core
            dP0: 50.0 "Pa",
        }
        modify cv hot { port hot { h: hh, area: Awh0 - pi * D * x, wall: head } }
        wall head { capacity: 1.0 / kh, rest: Th, input: Gloss * (Th - Tk) }
        link head -> Tk { conductance: Gloss }
        modify cv regen { port wall { h: hr, area: Awr / n, wall: matrix[j] } }
        wall matrix[n] { capacity: 1.0 / (km * n), rest: Th - (j + 0.5) * (Th - Tk) / n }
        link matrix[j] -> matrix[j + 1] for j in 0..n - 1 { conductance: Gm * n }
        link Th -> matrix[0] { conductance: 2.0 * Gm * n }
        link matrix[n - 1] -> Tk { conductance: 2.0 * Gm * n }
        effect orifice_leak cold -> bounce as Co, dP0;
    }
}
