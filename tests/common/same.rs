//! Two declarations of one model compared: the same states, parameters (by name) and
//! defaults, and the same right-hand side, Jacobian and parameter Jacobian at random states
//! and parameters (`tests/compose.rs`, `tests/dsl_effects.rs`).
#![allow(dead_code)]

use rand::Rng;
use stirling::dsl::Model;

/// Scaled largest difference of two vectors: `max |a - b| / max(|a|, |b|, floor)` per entry.
fn worst(a: &[f64], b: &[f64], floor: f64) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / x.abs().max(y.abs()).max(floor))
        .fold(0.0, f64::max)
}

/// `ext` and `hand` are one model: states, defaults, right-hand side, Jacobian and parameter
/// Jacobian (columns by parameter name) at random states and parameters. Returns the
/// largest scaled difference seen.
pub fn same_model(ext: &dyn Model, hand: &dyn Model, seed: u64) -> f64 {
    assert_eq!(ext.state_names(), hand.state_names());
    let names = |m: &dyn Model| {
        let mut v: Vec<&str> = m.params().iter().map(|p| p.name).collect();
        v.sort_unstable();
        v
    };
    assert_eq!(names(ext), names(hand), "the same parameters");
    // column of each of `ext`'s parameters in `hand`
    let map: Vec<usize> = ext
        .params()
        .iter()
        .map(|p| hand.param_index(p.name).unwrap())
        .collect();
    let to_hand = |pe: &[f64]| {
        let mut ph = vec![0.0; pe.len()];
        for (k, &i) in map.iter().enumerate() {
            ph[i] = pe[k];
        }
        ph
    };
    assert_eq!(
        to_hand(&ext.default_params()),
        hand.default_params(),
        "the same defaults"
    );
    let (n, np) = (ext.n_states(), ext.params().len());
    let mut rng = super::rng(seed);
    let mut w = 0.0f64;
    for k in 0..6 {
        let mut pe = ext.default_params();
        if k > 0 {
            pe.iter_mut()
                .for_each(|v| *v *= 1.0 + 0.05 * rng.gen_range(-1.0..1.0));
        }
        let ph = to_hand(&pe);
        let spread = if k % 2 == 0 {
            super::Spread::Wide
        } else {
            super::Spread::Balanced
        };
        let x = super::random_state(ext, &pe, spread, &mut rng);
        let (mut fe, mut fh) = (vec![0.0; n], vec![0.0; n]);
        ext.rhs(&pe, &x, 0.0, &mut fe);
        hand.rhs(&ph, &x, 0.0, &mut fh);
        let fmax = fe.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        w = w.max(worst(&fe, &fh, 1e-12 * fmax));
        let (je, jh) = (
            ext.jacobian_dense(&pe, &x, 0.0),
            hand.jacobian_dense(&ph, &x, 0.0),
        );
        let jmax = je.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        w = w.max(worst(&je, &jh, 1e-12 * jmax));
        let (pje, pjh) = (
            ext.param_jacobian_dense(&pe, &x, 0.0),
            hand.param_jacobian_dense(&ph, &x, 0.0),
        );
        // column-major n x np: ext's column c is hand's column map[c]
        let mut pjh_e = vec![0.0; n * np];
        for c in 0..np {
            pjh_e[n * c..n * (c + 1)].copy_from_slice(&pjh[n * map[c]..n * (map[c] + 1)]);
        }
        let pmax = pje.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        w = w.max(worst(&pje, &pjh_e, 1e-12 * pmax));
    }
    w
}
