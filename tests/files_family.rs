//! Every family member declared in a file (`examples/engines/*.stirling`), loaded and
//! compiled at run time, is the macro's model: the same states, parameters and sensors, and
//! the same right-hand side, Jacobian, parameter Jacobian, sensor outputs, forces, energy and
//! power to 1e-12 relative at random states and parameters, for n = 1, 2, 10, 100 and both
//! closures; the compiled Jacobians agree with finite differences.

mod common;

use std::path::Path;

use common::{fd_jacobian, fd_steps, random_state, rng, Spread};
use rand::Rng;
use stirling::dsl::{Closure, Model};
use stirling::models::effects::{NSectionExtFx, NSectionFx};
use stirling::models::family::{Cv1, Cv2, NSection, Schmidt};
use stirling::models::files;

type Build = fn(usize, Closure) -> Box<dyn Model>;

/// The family members and their files, with the section counts to test.
fn members() -> Vec<(&'static str, Build, &'static [usize])> {
    const SCALAR: &[usize] = &[1];
    const ARRAY: &[usize] = &[1, 2, 10, 100];
    vec![
        (
            "schmidt",
            |n, c| Box::new(Schmidt::new(n, c).unwrap()),
            SCALAR,
        ),
        ("cv1", |n, c| Box::new(Cv1::new(n, c).unwrap()), SCALAR),
        ("cv2", |n, c| Box::new(Cv2::new(n, c).unwrap()), SCALAR),
        (
            "nsection",
            |n, c| Box::new(NSection::new(n, c).unwrap()),
            ARRAY,
        ),
        (
            "nsection_fx",
            |n, c| Box::new(NSectionFx::new(n, c).unwrap()),
            ARRAY,
        ),
        (
            "nsection_ext",
            |n, c| Box::new(NSectionExtFx::new(n, c).unwrap()),
            ARRAY,
        ),
    ]
}

fn file(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/engines")
        .join(format!("{name}.stirling"))
}

/// `max |a - b| / max(|a|, |b|)` over the entries (0 where both are 0).
fn rel(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let m = x.abs().max(y.abs());
            if m == 0.0 {
                0.0
            } else {
                (x - y).abs() / m
            }
        })
        .fold(0.0, f64::max)
}

/// The same description: name, states, parameters, sensors, effect sites, free parameters.
fn same_description(a: &dyn Model, b: &dyn Model) {
    assert_eq!(a.name(), b.name());
    assert_eq!(a.n_states(), b.n_states());
    assert_eq!(a.states(), b.states());
    assert_eq!(a.params(), b.params());
    assert_eq!(a.bodies(), b.bodies());
    assert_eq!(a.sensors(), b.sensors());
    assert_eq!(a.effect_sites(), b.effect_sites());
    assert_eq!(a.declared_free(), b.declared_free());
    assert_eq!(a.vessel_names(), b.vessel_names());
    assert_eq!(a.has_array(), b.has_array());
    assert_eq!(format!("{:?}", a.topology()), format!("{:?}", b.topology()));
    for style in [stirling::dsl::Style::Text, stirling::dsl::Style::Latex] {
        assert_eq!(a.equations(style), b.equations(style));
    }
}

/// The floor of [`Worst::see_matrix`] for two codes of the same operations in another order.
const CANCELLED: f64 = 1e-9;
/// The floor for the folded model, whose multiply-adds are fused ([`CompiledModel::folded`]).
const FUSED_CANCELLED: f64 = 1e-4;

/// The largest relative difference so far, what it was in, and the floor of
/// [`Worst::see_matrix`] (a fraction of a row's largest entry).
#[derive(Clone, Copy, Debug)]
struct Worst(f64, &'static str, f64);

impl Worst {
    fn see(&mut self, what: &'static str, a: &[f64], b: &[f64]) {
        let r = rel(a, b);
        if r > self.0 {
            *self = Worst(r, what, self.2);
        }
    }

    /// Matrices of `rows` rows (column-major), each entry relative to itself or, for an
    /// entry that is a cancellation of much larger terms, to 1e-9 of the largest entry of
    /// its row: `d P_regen[k]' / d Rf` is the difference of two flows through the sections
    /// (-0.048 in a row whose entries reach 1.6e10 at n = 100), where the two codes' sums in
    /// another order differ by 1e-12 of the entry and 3e-24 of the row.
    fn see_matrix(&mut self, what: &'static str, rows: usize, a: &[f64], b: &[f64]) {
        self.see_matrix_floor(what, rows, (a, b), self.2);
    }

    fn see_matrix_floor(
        &mut self,
        what: &'static str,
        rows: usize,
        (a, b): (&[f64], &[f64]),
        floor: f64,
    ) {
        let cols = a.len() / rows.max(1);
        for r in 0..rows {
            let row_max = (0..cols)
                .map(|c| a[r + rows * c].abs().max(b[r + rows * c].abs()))
                .fold(0.0, f64::max);
            for c in 0..cols {
                let (x, y) = (a[r + rows * c], b[r + rows * c]);
                let m = x.abs().max(y.abs()).max(floor * row_max);
                if m > 0.0 && (x - y).abs() / m > self.0 {
                    *self = Worst((x - y).abs() / m, what, self.2);
                }
            }
        }
    }
}

/// Every numeric output of the two models at `(p, x)`: the largest relative difference.
fn compare_at(a: &dyn Model, b: &dyn Model, p: &[f64], x: &[f64], w: &mut Worst) {
    let n = a.n_states();
    let (mut fa, mut fb) = (vec![0.0; n], vec![0.0; n]);
    a.rhs(p, x, 0.0, &mut fa);
    b.rhs(p, x, 0.0, &mut fb);
    w.see("rhs", &fa, &fb);
    let (ja, jb) = (a.jacobian_dense(p, x, 0.0), b.jacobian_dense(p, x, 0.0));
    w.see_matrix("jacobian", n, &ja, &jb);
    let (pa, pb) = (
        a.param_jacobian_dense(p, x, 0.0),
        b.param_jacobian_dense(p, x, 0.0),
    );
    w.see_matrix("parameter jacobian", n, &pa, &pb);
    let nb = a.bodies().len();
    let (mut ga, mut gb) = (vec![0.0; nb], vec![0.0; nb]);
    a.pressure_forces(p, x, &mut ga);
    b.pressure_forces(p, x, &mut gb);
    w.see("pressure forces", &ga, &gb);
    for k in 0..nb {
        let (mut da, mut db) = (vec![0.0; n], vec![0.0; n]);
        a.pressure_force_gradient(k, p, x, &mut da);
        b.pressure_force_gradient(k, p, x, &mut db);
        w.see("pressure force gradient", &da, &db);
    }
    w.see("energy", &[a.energy(p, x)], &[b.energy(p, x)]);
    w.see("gas mass", &[a.gas_mass(p, x)], &[b.gas_mass(p, x)]);
    let (pa, pb) = (a.power(p, x), b.power(p, x));
    w.see(
        "power",
        &[pa.heat, pa.boundary, pa.mechanical],
        &[pb.heat, pb.boundary, pb.mechanical],
    );
    let nv = a.vessel_names().len();
    let (mut ta, mut tb) = (vec![0.0; nv], vec![0.0; nv]);
    a.temperatures(p, x, &mut ta);
    b.temperatures(p, x, &mut tb);
    w.see("temperatures", &ta, &tb);
    let (mut pra, mut vola, mut prb, mut volb) =
        (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
    a.pv(p, x, &mut pra, &mut vola);
    b.pv(p, x, &mut prb, &mut volb);
    w.see("pressures", &pra, &prb);
    w.see("volumes", &vola, &volb);
    sensors(a, b, p, x, w);
}

/// Every declared sensor's output and gradient, read at `x`.
fn sensors(a: &dyn Model, b: &dyn Model, p: &[f64], x: &[f64], w: &mut Worst) {
    for (k, s) in a.sensors().iter().enumerate() {
        let names = a.state_names();
        let Some(v) = s
            .reads
            .iter()
            .map(|r| names.iter().position(|m| m == r).map(|i| x[i]))
            .collect::<Option<Vec<f64>>>()
        else {
            continue;
        };
        let (mut dva, mut dvb) = (vec![0.0; v.len()], vec![0.0; v.len()]);
        let (mut dpa, mut dpb) = (vec![0.0; p.len()], vec![0.0; p.len()]);
        let ya = a.sensor_output(k, p, &v, &mut dva, &mut dpa);
        let yb = b.sensor_output(k, p, &v, &mut dvb, &mut dpb);
        w.see("sensor output", &[ya], &[yb]);
        w.see("sensor state gradient", &dva, &dvb);
        w.see("sensor parameter gradient", &dpa, &dpb);
    }
}

#[test]
fn family_files_are_the_macro_models() {
    let mut worst = Worst(0.0, "", CANCELLED);
    for (name, build, ns) in members() {
        for &closure in &[Closure::Full, Closure::Frozen] {
            for &n in ns {
                let a = files::build(&file(name), n, closure).unwrap_or_else(|e| panic!("{e}"));
                let b = build(n, closure);
                same_description(a.as_ref(), b.as_ref());
                let mut r = rng(n as u64 * 7 + 3);
                let mut w = Worst(0.0, "", CANCELLED);
                for k in 0..4 {
                    let mut p = b.default_params();
                    if k > 0 {
                        p.iter_mut()
                            .for_each(|v| *v *= 1.0 + 0.1 * r.gen_range(-1.0..1.0));
                    }
                    let spread = if k % 2 == 0 {
                        Spread::Wide
                    } else {
                        Spread::Balanced
                    };
                    let x = random_state(b.as_ref(), &p, spread, &mut r);
                    let (mut ia, mut ib) = (vec![0.0; x.len()], vec![0.0; x.len()]);
                    a.equilibrium_guess(&p, &mut ia);
                    b.equilibrium_guess(&p, &mut ib);
                    w.see("equilibrium guess", &ia, &ib);
                    compare_at(a.as_ref(), b.as_ref(), &p, &x, &mut w);
                }
                assert!(
                    w.0 <= 1e-12,
                    "{name} n = {n} {closure}: relative difference {:e} in the {}",
                    w.0,
                    w.1
                );
                if w.0 > worst.0 {
                    worst = w;
                }
            }
        }
    }
    println!(
        "largest relative difference, file vs macro: {:e} (in the {})",
        worst.0, worst.1
    );
}

/// The compiled Jacobian against Ridders' finite differences of the compiled right-hand side.
#[test]
fn compiled_jacobians_match_finite_differences() {
    for (name, _, ns) in members() {
        for &n in ns.iter().filter(|&&n| n <= 10) {
            let m = files::build(&file(name), n, Closure::Full).unwrap();
            let p = m.default_params();
            let mut r = rng(11 + n as u64);
            let x = random_state(m.as_ref(), &p, Spread::Wide, &mut r);
            let k = m.n_states();
            let f = |x: &[f64], out: &mut [f64]| m.rhs(&p, x, 0.0, out);
            let fd = fd_jacobian(&f, &x, k, &fd_steps(m.as_ref(), &p, &x));
            let jac = m.jacobian_dense(&p, &x, 0.0);
            let scales = common::state_scales(m.as_ref(), &p);
            for c in 0..k {
                for row in 0..k {
                    // entries scaled by the states' typical sizes: `J_ij s_j / s_i`
                    let s = scales[c] / scales[row];
                    let (a, b) = (jac[row + k * c] * s, fd[row + k * c] * s);
                    let tol = 1e-6 * (1.0 + a.abs().max(b.abs()));
                    assert!(
                        (a - b).abs() <= tol,
                        "{name} n = {n}: J[{row},{c}] = {a:e}, finite differences {b:e}"
                    );
                }
            }
        }
    }
}

/// A model compiled with its parameters folded in (`CompiledModel::folded`) is the model:
/// every output equal at that parameter vector, on tapes with fewer instructions; at another
/// vector it computes with the parameters as inputs (a changed parameter is never ignored).
#[test]
fn folded_parameters_give_the_same_model() {
    for (name, _, ns) in members() {
        let def = files::definition(&file(name)).unwrap();
        for &n in ns.iter().filter(|&&n| n != 1 || ns.len() == 1) {
            let m = def.model(n, Closure::Full).unwrap();
            let mut r = rng(n as u64 + 101);
            let mut p = m.default_params();
            p.iter_mut()
                .for_each(|v| *v *= 1.0 + 0.1 * r.gen_range(-1.0..1.0));
            let folded = m.folded(&p);
            let (rhs, jac) = m.tape_sizes();
            let (frhs, fjac) = folded.tape_sizes_at(&p);
            assert!(
                frhs < rhs && fjac < jac,
                "{name} n = {n}: folded tapes {frhs}, {fjac} against {rhs}, {jac}"
            );
            // fused multiply-adds round a cancelled entry once where the macro rounds twice:
            // `d P'/d m` at n = 10 (3.19e4 in a row reaching 7.6e12) moved by 2e-9 of itself,
            // 9e-18 of its row
            let mut w = Worst(0.0, "", FUSED_CANCELLED);
            for spread in [Spread::Wide, Spread::Balanced] {
                let x = random_state(&m, &p, spread, &mut r);
                compare_at(&folded, &m, &p, &x, &mut w);
                let (mut ia, mut ib) = (vec![0.0; x.len()], vec![0.0; x.len()]);
                folded.equilibrium_guess(&p, &mut ia);
                m.equilibrium_guess(&p, &mut ib);
                w.see("equilibrium guess", &ia, &ib);
            }
            assert!(
                w.0 <= 1e-12,
                "{name} n = {n}: folded differs by {:e} in the {}",
                w.0,
                w.1
            );
            // another vector: the parameters are inputs again
            let mut q = p.clone();
            q[m.param_index("Th").unwrap()] *= 1.2;
            let x = random_state(&m, &q, Spread::Wide, &mut r);
            let (mut fa, mut fb) = (vec![0.0; x.len()], vec![0.0; x.len()]);
            folded.rhs(&q, &x, 0.0, &mut fa);
            m.rhs(&q, &x, 0.0, &mut fb);
            assert_eq!(fa, fb, "{name} n = {n}: at another vector");
            println!("{name} n = {n}: rhs tape {rhs} -> {frhs}, jacobian {jac} -> {fjac}");
        }
    }
}

#[test]
fn family_files_draw_the_macro_models_bond_graphs() {
    // the bond graph reads the topology description a compiled model leaks (its body
    // elements, coupling dampers and given pressures included): the same graph as the macro's
    for (name, build, ns) in members() {
        for &n in ns.iter().take(3) {
            let a = files::build(&file(name), n, Closure::Full).unwrap_or_else(|e| panic!("{e}"));
            let b = build(n, Closure::Full);
            let ga = stirling::dsl::bond::bond_graph(a.as_ref()).unwrap();
            let gb = stirling::dsl::bond::bond_graph(b.as_ref()).unwrap();
            assert_eq!(ga.to_dot(), gb.to_dot(), "{name} at n = {n}");
        }
    }
}
