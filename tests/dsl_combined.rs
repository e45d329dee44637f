//! `Model::rhs_and_jacobian` (the right-hand side and the Jacobian in one pass) gives
//! exactly what `rhs` and `jacobian` give separately, bit for bit and in the same triplet
//! order, and its Jacobian matches finite differences of its right-hand side; for the
//! family members, the test chains and every section count that peels differently
//! (n = 1, 2, 3 and longer), per-section links into a scalar CV (the sums' arrow) and a
//! wall array. The values-only writers give the same values in the pattern's order.

mod common;
#[path = "dsl_sections/models.rs"]
mod sections;
#[path = "dsl_walls/models.rs"]
mod walls;

use common::models::{Chain, ChainQuad, OneCv, TwoCv};
use common::{compare, fd_jacobian, fd_steps, random_state, rng, state_scales, Spread};
use common::{REL, TINY};
use stirling::dsl::{Closure, JacSink, Model};
use stirling::models::family::{Cv1, Cv2, NSection};

type Triplets = Vec<(usize, usize, f64)>;

fn separate(m: &dyn Model, p: &[f64], x: &[f64]) -> (Vec<f64>, Triplets) {
    let mut f = vec![0.0; m.n_states()];
    m.rhs(p, x, 0.0, &mut f);
    let mut t = Vec::new();
    m.jacobian(p, x, 0.0, &mut JacSink::Triplets(&mut t));
    (f, t)
}

fn combined(m: &dyn Model, p: &[f64], x: &[f64]) -> (Vec<f64>, Triplets) {
    let mut f = vec![f64::NAN; m.n_states()];
    let mut t = Vec::new();
    m.rhs_and_jacobian(p, x, 0.0, &mut f, &mut JacSink::Triplets(&mut t));
    (f, t)
}

/// The values-only writers (`jacobian_values`, `rhs_and_jacobian_values`) give the triplets'
/// values bit for bit, in the order of `jacobian_pattern`, which is the triplets' positions.
fn values_only(m: &dyn Model, p: &[f64], x: &[f64], f: &[f64], t: &Triplets, label: &str) {
    let pattern = m.jacobian_pattern(p);
    let at: Vec<(usize, usize)> = t.iter().map(|e| (e.0, e.1)).collect();
    assert_eq!(
        pattern, at,
        "{label}: pattern differs from the triplets' positions"
    );
    let want: Vec<f64> = t.iter().map(|e| e.2).collect();
    let mut v = vec![f64::NAN; pattern.len()];
    m.jacobian_values(p, x, 0.0, &mut v);
    assert_eq!(bits(&v), bits(&want), "{label}: jacobian_values differ");
    let (mut g, mut w) = (vec![f64::NAN; f.len()], vec![f64::NAN; pattern.len()]);
    m.rhs_and_jacobian_values(p, x, 0.0, &mut g, &mut w);
    assert_eq!(
        bits(&g),
        bits(f),
        "{label}: rhs_and_jacobian_values' rhs differs"
    );
    assert_eq!(
        bits(&w),
        bits(&want),
        "{label}: rhs_and_jacobian_values' values differ"
    );
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// `fd`: also check the combined Jacobian against finite differences of the combined RHS
/// (off for the arrow models: their closed CV's columns are below finite-difference
/// resolution of a single step; their separate Jacobians are checked in `dsl_sections` and
/// `dsl_walls` with the multi-step estimate, and the combined one equals them bit for bit).
fn check(m: &dyn Model, label: &str, seed: u64, fd: bool) {
    let p = m.default_params();
    let mut r = rng(seed);
    let n = m.n_states();
    for spread in [Spread::Wide, Spread::Balanced] {
        for k in 0..2 {
            let x = random_state(m, &p, spread, &mut r);
            let (f, t) = separate(m, &p, &x);
            let (g, u) = combined(m, &p, &x);
            assert_eq!(bits(&f), bits(&g), "{label} {spread:?} {k}: rhs differs");
            let key = |t: &Triplets| {
                t.iter()
                    .map(|e| (e.0, e.1, e.2.to_bits()))
                    .collect::<Vec<_>>()
            };
            assert_eq!(key(&t), key(&u), "{label} {spread:?} {k}: Jacobian differs");
            values_only(m, &p, &x, &f, &t, &format!("{label} {spread:?} {k}"));
            if !fd {
                continue;
            }
            // the combined Jacobian against finite differences of the combined rhs
            let mut dense = vec![0.0; n * n];
            let mut scratch = vec![0.0; n];
            let sink = &mut JacSink::Dense {
                data: &mut dense,
                nrows: n,
            };
            m.rhs_and_jacobian(&p, &x, 0.0, &mut scratch, sink);
            let rhs = |xx: &[f64], out: &mut [f64]| {
                let mut junk = Vec::new();
                m.rhs_and_jacobian(&p, xx, 0.0, out, &mut JacSink::Triplets(&mut junk));
            };
            let fd = fd_jacobian(&rhs, &x, n, &fd_steps(m, &p, &x));
            let (names, scales) = (m.state_names(), state_scales(m, &p));
            let bad = compare(&dense, &fd, &names, &names, &scales, &scales, REL, TINY);
            assert!(
                bad.is_empty(),
                "{label} {spread:?} {k}: {} entries off finite differences, first {:?}",
                bad.len(),
                bad.first()
            );
        }
    }
}

fn both(make: impl Fn(Closure) -> Box<dyn Model>, label: &str, seed: u64) {
    both_fd(make, label, seed, true)
}

fn both_fd(make: impl Fn(Closure) -> Box<dyn Model>, label: &str, seed: u64, fd: bool) {
    for c in [Closure::Full, Closure::Frozen] {
        check(make(c).as_ref(), &format!("{label} ({c})"), seed, fd);
    }
}

#[test]
fn family_combined_equals_separate() {
    for n in [1, 2, 3, 4, 10] {
        let label = format!("nsection n={n}");
        both(
            |c| Box::new(NSection::new(n, c).unwrap()),
            &label,
            10 + n as u64,
        );
    }
    both(|c| Box::new(Cv1::new(1, c).unwrap()), "cv1", 1);
    both(|c| Box::new(Cv2::new(1, c).unwrap()), "cv2", 2);
}

#[test]
fn chains_combined_equals_separate() {
    both(|c| Box::new(OneCv::new(1, c).unwrap()), "one_cv", 3);
    both(|c| Box::new(TwoCv::new(1, c).unwrap()), "two_cv", 4);
    for n in [1, 2, 3, 7] {
        both(
            |c| Box::new(Chain::new(n, c).unwrap()),
            &format!("chain n={n}"),
            20 + n as u64,
        );
        let label = format!("chain_quad n={n}");
        both(
            |c| Box::new(ChainQuad::new(n, c).unwrap()),
            &label,
            30 + n as u64,
        );
    }
}

#[test]
fn per_section_links_combined_equals_separate() {
    for n in [1, 2, 3, 6] {
        let label = format!("leak_to_cv n={n}");
        both_fd(
            |c| Box::new(sections::LeakToCv::new(n, c).unwrap()),
            &label,
            40 + n as u64,
            false,
        );
        let label = format!("leak_to_space n={n}");
        both_fd(
            |c| Box::new(sections::LeakToSpace::new(n, c).unwrap()),
            &label,
            50 + n as u64,
            false,
        );
        let label = format!("matrix_wall n={n}");
        both_fd(
            |c| Box::new(walls::MatrixWall::new(n, c).unwrap()),
            &label,
            60 + n as u64,
            false,
        );
    }
}
