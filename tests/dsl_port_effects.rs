//! Effects on a CV's heat port (docs/custom-topologies.md, "Effects named where they act"):
//! `effect heater_input on port hot.hot;` turns the port's fixed wall temperature into a
//! heater head of finite capacity fed through a finite conductance, `effect matrix_capacity
//! on port regen.wall;` an array's profile into a regenerator matrix of finite capacity with
//! axial conduction. At their null (inverse capacities 0) the walls are frozen at the fixed
//! temperatures they replace, so the model is the nominal one; switched on they are the
//! family's hand-written `nsection_ext_fx` walls; their Jacobians match finite differences.

mod common;

use stirling::dsl::{Closure, EffectSite, Model};
use stirling::models::effects::NSectionExtFx;
use stirling::models::family::NSection;
use stirling::stirling_model;

stirling_model! {
    /// `nsection` with the hot space's heater head and the regenerator's matrix named as
    /// port effects.
    pub model Walled extends stirling::models::nsection_engine {
        name "walled";
        effect heater_input on port hot.hot;
        effect matrix_capacity on port regen.wall;
    }
}

stirling_model! {
    /// The same with the walls' capacities finite (declared, so the effects add no default).
    pub model WalledOn extends stirling::models::nsection_engine {
        name "walled_on";
        params {
            /// inverse heat capacity of the heater head
            kh_hot_hot: 2.0e-3 "K/J",
            /// inverse heat capacity of the whole matrix
            km_regen_wall: 5.0e-3 "K/J",
        }
        effect heater_input on port hot.hot;
        effect matrix_capacity on port regen.wall;
    }
}

/// The effects add the walls' states and their parameters at the null, and list their sites.
#[test]
fn a_port_effect_adds_a_wall_at_its_null() {
    let m = Walled::new(3, Closure::Full).unwrap();
    let plain = NSection::new(3, Closure::Full).unwrap();
    let added: Vec<(&str, f64, &str)> = m
        .params()
        .iter()
        .skip(plain.params().len())
        .map(|p| (p.name, p.default, p.unit))
        .collect();
    assert_eq!(
        added,
        [
            ("kh_hot_hot", 0.0, "K/J"),
            ("Gh_hot_hot", 0.5, "W/K"),
            ("km_regen_wall", 0.0, "K/J"),
            ("Gm_regen_wall", 0.03, "W/K"),
        ]
    );
    let names = m.state_names();
    let walls: Vec<&str> = names
        .iter()
        .filter(|s| s.starts_with("Tw_"))
        .map(String::as_str)
        .collect();
    assert_eq!(
        walls,
        [
            "Tw_hot_hot",
            "Tw_regen_wall[0]",
            "Tw_regen_wall[1]",
            "Tw_regen_wall[2]"
        ]
    );
    assert_eq!(m.n_states(), plain.n_states() + 4);
    assert_eq!(
        m.effect_sites(),
        [
            EffectSite {
                effect: "heater_input",
                at: "port hot.hot",
                params: &["kh_hot_hot", "Gh_hot_hot"]
            },
            EffectSite {
                effect: "matrix_capacity",
                at: "port regen.wall",
                params: &["km_regen_wall", "Gm_regen_wall"]
            },
        ]
    );
    // the walls rest at the fixed temperatures they replace
    let p = m.default_params();
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x);
    let at = |s: &str| x[names.iter().position(|n| n == s).unwrap()];
    let (th, tk) = (
        p[m.param_index("Th").unwrap()],
        p[m.param_index("Tk").unwrap()],
    );
    assert_eq!(at("Tw_hot_hot"), th);
    assert!((at("Tw_regen_wall[1]") - (th + tk) / 2.0).abs() < 1e-9);
}

/// At the null the walls are frozen at their rest and every other state moves as in the
/// nominal model, bit for bit.
#[test]
fn at_the_null_the_port_effects_are_absent() {
    for n in [1, 4] {
        let (m, plain) = (
            Walled::new(n, Closure::Full).unwrap(),
            NSection::new(n, Closure::Full).unwrap(),
        );
        let (p, pp) = (m.default_params(), plain.default_params());
        let xp = common::random_state(&plain, &pp, common::Spread::Wide, &mut common::rng(9));
        let (names, pnames) = (m.state_names(), plain.state_names());
        let mut x = vec![0.0; m.n_states()];
        m.equilibrium_guess(&p, &mut x);
        for (k, s) in pnames.iter().enumerate() {
            x[names.iter().position(|q| q == s).unwrap()] = xp[k];
        }
        let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; xp.len()]);
        m.rhs(&p, &x, 0.0, &mut a);
        plain.rhs(&pp, &xp, 0.0, &mut b);
        for (k, s) in names.iter().enumerate() {
            match pnames.iter().position(|q| q == s) {
                Some(j) => assert_eq!(a[k].to_bits(), b[j].to_bits(), "n = {n}: d{s}/dt"),
                None => assert_eq!(a[k], 0.0, "n = {n}: the wall {s} is frozen"),
            }
        }
    }
}

/// Switched on, the port effects are the family's hand-written walls of `nsection_ext_fx`
/// (heater head fed through `Gloss`, matrix with axial conduction `Gm`): the same right-hand
/// side, states matched by name (to rounding: the head's law is written `Gloss (Th - T)`
/// here and `Gloss (Th - Tk) - Gloss (T - Tk)` there).
#[test]
fn switched_on_they_are_the_familys_hand_written_walls() {
    for n in [1, 3] {
        let (m, ext) = (
            Walled::new(n, Closure::Full).unwrap(),
            NSectionExtFx::new(n, Closure::Full).unwrap(),
        );
        let mut p = m.default_params();
        let mut pe = ext.default_params();
        for (ours, theirs, v) in [
            ("kh_hot_hot", "kh", 2e-3),
            ("km_regen_wall", "km", 5e-3),
            ("Gh_hot_hot", "Gloss", 0.7),
            ("Gm_regen_wall", "Gm", 0.05),
        ] {
            p[m.param_index(ours).unwrap()] = v;
            pe[ext.param_index(theirs).unwrap()] = v;
        }
        let rename = |s: &str| {
            s.replace("Tw_hot_hot", "Tw_head")
                .replace("Tw_regen_wall", "Tw_matrix")
        };
        let names: Vec<String> = m.state_names().iter().map(|s| rename(s)).collect();
        let enames = ext.state_names();
        assert_eq!(names.len(), enames.len(), "{names:?} / {enames:?}");
        let to_ext: Vec<usize> = names
            .iter()
            .map(|s| enames.iter().position(|q| q == s).expect(s))
            .collect();
        for seed in 0..4 {
            let x = common::random_state(&m, &p, common::Spread::Balanced, &mut common::rng(seed));
            let mut xe = vec![0.0; x.len()];
            for (k, &j) in to_ext.iter().enumerate() {
                xe[j] = x[k];
            }
            // the walls away from their rest, so that every conduction carries heat
            for (k, s) in names.iter().enumerate() {
                if s.starts_with("Tw_") {
                    xe[to_ext[k]] += 3.0 + k as f64;
                }
            }
            let xw: Vec<f64> = to_ext.iter().map(|&j| xe[j]).collect();
            let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
            m.rhs(&p, &xw, 0.0, &mut a);
            ext.rhs(&pe, &xe, 0.0, &mut b);
            for (k, &j) in to_ext.iter().enumerate() {
                let tol = 1e-9 * a[k].abs().max(b[j].abs()).max(1e-9);
                assert!(
                    (a[k] - b[j]).abs() <= tol,
                    "n = {n}: d{}/dt {} vs {}",
                    names[k],
                    a[k],
                    b[j]
                );
            }
        }
    }
}

/// The generated Jacobians of the walls switched on match finite differences.
#[test]
fn the_port_effects_jacobians_hold() {
    for n in [1, 3] {
        let m = WalledOn::new(n, Closure::Full).unwrap();
        common::assert_jacobians(&m, &format!("port effects n = {n}"), 61, 3);
    }
}
