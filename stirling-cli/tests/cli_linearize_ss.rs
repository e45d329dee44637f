//! `linearize --ss FILE` / `--json`: the state-space export of the broken and the closed loop,
//! consistent with itself (closed = broken - B C, the pole tables as `damp`) and with the
//! seed's margins of `schmidt` (the gain of `C (jwI - A)^-1 B` at the phase crossover).

mod support;

use serde_json::Value;
use support::{fails_with, s, scratch, stirling, succeeds};

fn matrix(v: &Value) -> Vec<Vec<f64>> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        })
        .collect()
}

type C = (f64, f64);

fn mul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}

fn div(a: C, b: C) -> C {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

/// `C (jw I - A)^-1 B` by Gaussian elimination with partial pivoting.
fn gain(a: &[Vec<f64>], b: &[Vec<f64>], c: &[Vec<f64>], w: f64) -> C {
    let n = a.len();
    let mut m: Vec<Vec<C>> = (0..n)
        .map(|i| {
            let mut r: Vec<C> = (0..n)
                .map(|j| (-a[i][j], if i == j { w } else { 0.0 }))
                .collect();
            r.push((b[i][0], 0.0));
            r
        })
        .collect();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&x, &y| {
                m[x][k]
                    .0
                    .hypot(m[x][k].1)
                    .total_cmp(&m[y][k].0.hypot(m[y][k].1))
            })
            .unwrap();
        m.swap(k, p);
        for i in k + 1..n {
            let f = div(m[i][k], m[k][k]);
            for j in k..=n {
                let t = mul(f, m[k][j]);
                m[i][j] = (m[i][j].0 - t.0, m[i][j].1 - t.1);
            }
        }
    }
    let mut z = vec![(0.0, 0.0); n];
    for i in (0..n).rev() {
        let mut acc = m[i][n];
        for j in i + 1..n {
            let t = mul(m[i][j], z[j]);
            acc = (acc.0 - t.0, acc.1 - t.1);
        }
        z[i] = div(acc, m[i][i]);
    }
    z.iter()
        .zip(&c[0])
        .fold((0.0, 0.0), |s, (z, c)| (s.0 + c * z.0, s.1 + c * z.1))
}

#[test]
fn schmidt_export_carries_the_seed_margins() {
    let dir = scratch("ss_schmidt");
    let f = dir.join("schmidt.json");
    let err = succeeds(&["linearize", "schmidt", "--ss", s(&f)]);
    assert!(err.contains(&format!("wrote {}", f.display())), "{err}");
    let e: Value = serde_json::from_str(&std::fs::read_to_string(&f).unwrap()).unwrap();
    assert_eq!(e["inventory_reduced"], false);
    assert_eq!(e["states"].as_array().unwrap().len(), 4);
    let bl = &e["broken_loop"];
    let (a, b, c) = (matrix(&bl["a"]), matrix(&bl["b"]), matrix(&bl["c"]));
    assert_eq!((a.len(), b.len(), c[0].len()), (4, 4, 4));
    assert_eq!(matrix(&bl["d"]), vec![vec![0.0]]);
    assert!(bl["input"].as_str().unwrap().contains("pressure (Pa)"));
    // Gm -6.63 dB at 81.6 rad/s: |L| = +6.63 dB where the phase crosses -180 deg
    let l = gain(&a, &b, &c, 81.60);
    let db = 20.0 * l.0.hypot(l.1).log10();
    assert!((db - 6.63).abs() < 0.02, "{db} dB");
    assert!(
        l.1.abs() < 0.02 * l.0.abs() && l.0 < 0.0,
        "{l:?} on the negative real axis"
    );
    // Pm -79.5 deg at 91.3 rad/s: |L| = 1 there
    let l = gain(&a, &b, &c, 91.30);
    assert!((l.0.hypot(l.1) - 1.0).abs() < 2e-3, "{l:?}");
    let pm = 180.0 + l.1.atan2(l.0).to_degrees();
    assert!((pm.rem_euclid(360.0) - (360.0 - 79.5)).abs() < 0.1, "{pm}");
    // closed = broken - B C
    let ca = matrix(&e["closed_loop"]["a"]);
    for i in 0..4 {
        for j in 0..4 {
            let want = a[i][j] - b[i][0] * c[0][j];
            assert!(
                (ca[i][j] - want).abs() <= 1e-9 * (1.0 + want.abs()),
                "{i},{j}"
            );
        }
    }
    // damp: natural frequency and damping ratio
    let p0 = &e["closed_loop"]["poles"][0];
    let (re, im) = (p0["re"].as_f64().unwrap(), p0["im"].as_f64().unwrap());
    assert!((re - 9.6225).abs() < 1e-3 && (im - 89.5373).abs() < 1e-3);
    let wn = p0["natural_rad_s"].as_f64().unwrap();
    assert!((wn - re.hypot(im)).abs() < 1e-9);
    assert!((p0["damping_ratio"].as_f64().unwrap() + re / wn).abs() < 1e-12);
    let bode = &e["bode"];
    let nw = bode["w_rad_s"].as_array().unwrap().len();
    assert!(nw > 100 && bode["phase_deg"].as_array().unwrap().len() == nw);
    // the file is not overwritten without --force
    fails_with(
        &["linearize", "schmidt", "--ss", s(&f)],
        &["--ss", "exists", "--force"],
    );
}

#[test]
fn full_closure_is_reduced_and_json_carries_the_export() {
    let out = stirling(&["linearize", "cv2", "--json"]);
    assert!(out.status.success());
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["model"], "cv2");
    let e = &r["state_space"];
    assert_eq!(e["inventory_reduced"], true);
    let n = r["n_states"].as_u64().unwrap() as usize;
    let states = e["states"].as_array().unwrap();
    assert_eq!(states.len(), n - 1);
    let full = e["full_states"].as_array().unwrap();
    let gone: Vec<&Value> = full.iter().filter(|f| !states.contains(f)).collect();
    assert_eq!(gone.len(), 1, "one mass state eliminated");
    assert!(e["reduction"]
        .as_str()
        .unwrap()
        .contains(gone[0].as_str().unwrap()));
    let t = matrix(&e["basis"]);
    assert_eq!((t.len(), t[0].len()), (n, n - 1));
    assert_eq!(matrix(&e["closed_loop"]["a"]).len(), n - 1);
    assert_eq!(e["closed_loop"]["poles"].as_array().unwrap().len(), n - 1);
    // the closed-loop A has the report's poles: its trace is their sum
    let ca = matrix(&e["closed_loop"]["a"]);
    let trace: f64 = (0..n - 1).map(|i| ca[i][i]).sum();
    let sum: f64 = r["poles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["re"].as_f64().unwrap())
        .sum();
    assert!(
        (trace - sum).abs() < 1e-6 * sum.abs().max(1.0),
        "{trace} vs {sum}"
    );
}

#[test]
fn large_models_add_a_sparse_form() {
    let out = stirling(&["linearize", "nsection", "--n", "100", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    let bl = &r["state_space"]["broken_loop"];
    let sp = &bl["a_sparse"];
    let n = sp["rows"].as_u64().unwrap() as usize;
    assert!(n >= 200);
    let nnz = sp["v"].as_array().unwrap().len();
    assert!(nnz > n && nnz < n * n / 10, "{nnz} nonzeros of {n}^2");
    assert_eq!(matrix(&bl["a"]).len(), n);
}

/// The keys of an object.
fn keys(v: &Value) -> Vec<&str> {
    v.as_object().unwrap().keys().map(|k| k.as_str()).collect()
}

#[test]
fn below_200_states_no_sparse_field_is_written() {
    let out = stirling(&["linearize", "nsection", "--n", "95", "--json"]);
    assert!(out.status.success());
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    let e = &r["state_space"];
    assert_eq!(r["n_states"], 198);
    assert!(!keys(e).contains(&"basis_sparse"));
    let bl = &e["broken_loop"];
    assert!(bl["a_sparse"].is_null());
    for k in ["b_sparse", "c_sparse", "d_sparse"] {
        assert!(!keys(bl).contains(&k), "{k}");
    }
    assert_eq!(matrix(&bl["b"]).len(), 197);
}

/// Triplets as a dense matrix.
fn from_triplets(t: &Value) -> Vec<Vec<f64>> {
    let n = |k: &str| t[k].as_u64().unwrap() as usize;
    let mut m = vec![vec![0.0; n("cols")]; n("rows")];
    let (i, j, v) = (
        t["i"].as_array().unwrap(),
        t["j"].as_array().unwrap(),
        t["v"].as_array().unwrap(),
    );
    assert!(i.len() == j.len() && j.len() == v.len());
    for k in 0..v.len() {
        let (r, c) = (
            i[k].as_u64().unwrap() as usize,
            j[k].as_u64().unwrap() as usize,
        );
        assert_eq!(m[r][c], 0.0, "({r}, {c}) repeated");
        m[r][c] = v[k].as_f64().unwrap();
    }
    m
}

#[test]
fn above_500_states_only_triplets_and_closed_is_broken_minus_bc() {
    let out = stirling(&["linearize", "nsection", "--n", "250", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    let e = &r["state_space"];
    assert_eq!(r["n_states"], 508);
    assert!(e["basis"].is_null());
    let t = from_triplets(&e["basis_sparse"]);
    assert_eq!((t.len(), t[0].len()), (508, 507));
    let (bl, cl) = (&e["broken_loop"], &e["closed_loop"]);
    for k in ["a", "b", "c", "d"] {
        assert!(
            bl[k].is_null() && cl[k].is_null(),
            "{k} dense above 500 states"
        );
        let f = bl[format!("{k}_sparse")]["format"].as_str().unwrap();
        assert!(
            f.starts_with("triplets, 0-based: entry k is row i[k], column j[k]"),
            "{f}"
        );
    }
    let (a0, b, c) = (
        from_triplets(&bl["a_sparse"]),
        from_triplets(&bl["b_sparse"]),
        from_triplets(&bl["c_sparse"]),
    );
    assert_eq!((b.len(), b[0].len(), c.len(), c[0].len()), (507, 1, 1, 507));
    assert_eq!(from_triplets(&bl["d_sparse"]), vec![vec![0.0]]);
    assert_eq!(from_triplets(&cl["b_sparse"]), b);
    let a = from_triplets(&cl["a_sparse"]);
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..507 {
        for j in 0..507 {
            let want = a0[i][j] - b[i][0] * c[0][j];
            assert!((a[i][j] - want).abs() <= 1e-12 * scale, "{i},{j}");
        }
    }
}
