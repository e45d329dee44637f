use stirling::stirling_model;

stirling_model! {
    pub model Demo {
        params { J: 1e-4 "kg m^2", r: 0.01 "m", L: 0.05 "m", A: 1e-3 "m^2", V0: 1e-4 "m^3",
                 Tw: 300.0 "K", h: 100.0 "W/(m^2 K)", Aw: 0.01 "m^2", R: 287.0 "J/(kg K)",
                 gamma: 1.4 "-", P0: 1e5 "Pa", eps: 1e-5 "kg/s" }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body slider(z, u) { mass: 1.0 }
        flywheel wheel(theta, omega) { inertia: J }
        crank piston(y) on slider { radius: r, rod: L }
        cv gas { volume: V0, faces { piston: -A }, port wall { h: h, area: Aw, wall: Tw } }
    }
}

fn main() {}
