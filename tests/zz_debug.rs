mod common;
use stirling::dsl::{Closure, Model};
#[test]
fn dbg() {
    let model = stirling::models::family::NSection::new(1, Closure::Full).unwrap();
    let p = model.default_params();
    let mut rng = common::rng(301);
    for _ in 0..4 { common::random_state(&model, &p, common::Spread::Wide, &mut rng); }
    let mut x = vec![];
    for _ in 0..3 { x = common::random_state(&model, &p, common::Spread::Balanced, &mut rng); }
    let names = model.state_names();
    println!("{names:?}\n{x:?}");
    let ie = model.param_index("mdot_eps").unwrap();
    let n = model.n_states();
    let pj = model.param_jacobian_dense(&p, &x, 0.0);
    let iv = names.iter().position(|s| s == "P_hot").unwrap();
    println!("analytic {:.15e}", pj[iv + n * ie]);
    for k in 2..12 {
        let h = p[ie] * 10f64.powi(-k);
        let mut pp = p.clone(); let mut fp = vec![0.0; n]; let mut fm = vec![0.0; n];
        pp[ie] = p[ie] + h; model.rhs(&pp, &x, 0.0, &mut fp);
        pp[ie] = p[ie] - h; model.rhs(&pp, &x, 0.0, &mut fm);
        println!("h {h:e}: {:.15e}", (fp[iv] - fm[iv]) / (2.0 * h));
    }
}
