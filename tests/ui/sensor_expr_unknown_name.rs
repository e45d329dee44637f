use stirling::stirling_model;

stirling_model! {
    pub model Demo {
        params { m: 1.0 "kg", ks: 100.0 "N/m", A: 1e-3 "m^2", V0: 1e-4 "m^3", Tw: 300.0 "K",
                 h: 100.0 "W/(m^2 K)", Aw: 0.01 "m^2", R: 287.0 "J/(kg K)", gamma: 1.4 "-",
                 P0: 1e5 "Pa", eps: 1e-5 "kg/s", Rf: 1e5 "Pa s/kg" }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: ks }
        cv gas { volume: V0, faces { piston: -A }, port wall { h: h, area: Aw, wall: Tw } }
        sensor dp: P_gas - Pamb "Pa";
    }
}

fn main() {}
