//! The block shooting route against the dense one: block products equal single products on any
//! number of factoring threads; at nsection n = 10 the same limit cycle as the dense route and
//! the same leading Floquet multipliers (to 1e-6), at n = 100 the dense monodromy's multipliers
//! on the block route's cycle.

use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::sim::{
    self, floquet_multipliers_scaled, flow_with_monodromy, shoot, shoot_block_counted,
    tangent::flow_with_tangent, BlockOptions, LimitCycle, ShootingOptions, SimOptions,
};

/// The settled cycle of the default engine at `n` (start: displacer at 5 mm).
fn settled(model: &dyn Model, p: &[f64]) -> sim::Settled {
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x0);
    x0[0] = 5e-3;
    let opts = SimOptions::default();
    sim::settle(model, p, &x0, 20.0, &[], 3, 1e-3, &opts, None).unwrap()
}

fn max_abs(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |a, b| a.max(b.abs()))
}

/// A block of three columns by one thread, by two, and column by column: the same products.
#[test]
fn block_products_equal_single_products_on_any_thread_count() {
    let model = NSection::new(3, Closure::Full).unwrap();
    let p = model.default_params();
    let st = settled(&model, &p);
    let n = model.n_states();
    let opts = ShootingOptions::default().sim;
    let (_, mut tf, _) = flow_with_tangent(&model, &p, &st.x0, st.period, &opts, 1, 0).unwrap();
    let k = 3;
    let v: Vec<f64> = (0..n * k)
        .map(|i| ((i * 7 + 3) % 11) as f64 / 11.0 - 0.5)
        .collect();
    let (mut one, mut two) = (v.clone(), v.clone());
    tf.apply_block_threads(&mut one, k, 1).unwrap();
    tf.apply_block_threads(&mut two, k, 2).unwrap();
    let scale = max_abs(one.iter().copied());
    let e_threads = max_abs(one.iter().zip(&two).map(|(a, b)| a - b)) / scale;
    let mut e_single = 0.0f64;
    for (c, col) in v.chunks_exact(n).enumerate() {
        let mut w = col.to_vec();
        tf.apply(&mut w).unwrap();
        let got = &one[c * n..(c + 1) * n];
        e_single = e_single.max(max_abs(w.iter().zip(got).map(|(a, b)| a - b)) / scale);
    }
    eprintln!("threads {e_threads:.2e}, single {e_single:.2e}");
    assert!(e_threads < 1e-12, "one vs two threads: {e_threads:e}");
    assert_eq!(e_single, 0.0, "block vs single products on one thread");
    assert!(tf.apply_block_threads(&mut [0.0; 4], k, 1).is_err());
}

/// Every multiplier of `b` above 1e-6 within `tol` of one of `dense`.
fn multipliers_agree(b: &LimitCycle, dense: &[(f64, f64)], tol: f64) {
    eprintln!("dense {:?}", &dense[..b.floquet.len()]);
    eprintln!("block {:?}", b.floquet);
    assert!(b.floquet.len() >= 8);
    assert!(b.trivial_multiplier_error() < 1e-6);
    let mut worst = 0.0f64;
    for &(re, im) in &b.floquet {
        if re.hypot(im) < 1e-6 {
            continue; // the cloud near 0
        }
        let near = dense
            .iter()
            .map(|&(a, b)| (a - re).hypot(b - im))
            .fold(f64::MAX, f64::min);
        worst = worst.max(near);
    }
    eprintln!("worst multiplier difference {worst:.2e}");
    assert!(worst < tol, "multipliers differ by {worst:e}");
}

fn block(model: &NSection, p: &[f64], st: &sim::Settled) -> LimitCycle {
    let opts = ShootingOptions::default();
    let bopts = BlockOptions::default();
    let (b, c) = shoot_block_counted(model, p, &st.x0, st.period, &opts, &bopts).unwrap();
    eprintln!("{c:?}");
    // nothing kept: the multipliers from a few sweeps
    assert!(c.sweeps <= 4, "{c:?}");
    b
}

/// n = 10: both routes from the same settled cycle reach the same cycle, and the multipliers
/// agree to 1e-6.
#[test]
fn block_route_equals_dense_route_at_n10() {
    let model = NSection::new(10, Closure::Full).unwrap();
    let p = model.default_params();
    let st = settled(&model, &p);
    let d = shoot(&model, &p, &st.x0, st.period, &ShootingOptions::default()).unwrap();
    let b = block(&model, &p, &st);
    let s = sim::state_scale(&model, &p);
    let dx = max_abs(
        d.x0.iter()
            .zip(&b.x0)
            .zip(&s)
            .map(|((a, b), w)| (a - b) / w),
    );
    let dt = (d.period - b.period).abs() / d.period;
    eprintln!("period difference {dt:.2e}, scaled x0 difference {dx:.2e}");
    assert!(dt < 1e-9, "period: {dt:e}");
    assert!(dx < 1e-7, "x0: {dx:e}");
    multipliers_agree(&b, &d.floquet, 1e-6);
}

/// n = 100 (208 states): the block route's multipliers are the dense monodromy's on the same
/// orbit (one dense monodromy instead of a dense shot keeps the test cheap in a debug build).
#[test]
fn block_route_equals_dense_monodromy_at_n100() {
    let model = NSection::new(100, Closure::Full).unwrap();
    let p = model.default_params();
    let st = settled(&model, &p);
    let b = block(&model, &p, &st);
    let n = model.n_states();
    let opts = ShootingOptions::default().sim;
    let (_, mono, _) = flow_with_monodromy(&model, &p, &b.x0, b.period, &opts).unwrap();
    let dense = floquet_multipliers_scaled(&mono, n, &sim::state_scale(&model, &p));
    multipliers_agree(&b, &dense, 1e-6);
}
