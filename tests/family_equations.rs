//! The generated right-hand sides are the equations of docs/physics.md: every family member is
//! checked at a fixed non-equilibrium state against a plain-Rust reference written out by
//! hand below from docs/physics.md sections 1-6 (geometry, mechanics, Schmidt pressure, control
//! volumes, the family table, the equilibrium). Nothing here is taken from generated code;
//! the default engine of section 8 is typed in by hand and checked against the declared
//! defaults.
//!
//! Test state: equilibrium plus `x = +3 mm`, `v = 0.2 m/s`, `y = -2 mm`, `w = -0.1 m/s`,
//! `P_i = Pmean (1 + 0.01 (i+1))`, `m_i = 1.02 m_i0 (1 - 0.005 i)` (`i` from 0); with `frozen`
//! (and for `cv1`, which has no links) the masses stay at `m_i0`.

use std::f64::consts::PI;

use stirling::dsl::Closure;
use stirling::models::build;

/// docs/physics.md section 8, by hand.
#[derive(Clone, Copy, Debug)]
struct Engine {
    r: f64,
    gamma: f64,
    a: f64,
    ar: f64,
    vh0: f64,
    vc0: f64,
    vr: f64,
    th: f64,
    tk: f64,
    pmean: f64,
    pb: f64,
    md: f64,
    mp: f64,
    kd: f64,
    kp: f64,
    bd: f64,
    bp: f64,
    b: f64,
    bqd: f64,
    bqp: f64,
    awh0: f64,
    awc0: f64,
    awr: f64,
    hh: f64,
    hk: f64,
    hr: f64,
    rf: f64,
    mdot_eps: f64,
}

const ENGINE: Engine = Engine {
    r: 287.05,
    gamma: 1.4,
    a: PI / 4.0 * 0.06 * 0.06,
    ar: PI / 4.0 * 0.015 * 0.015,
    vh0: 1.5e-4,
    vc0: 1.2e-4,
    vr: 4.0e-5,
    th: 600.0,
    tk: 300.0,
    pmean: 101325.0,
    pb: 101325.0,
    md: 0.08228,
    mp: 0.33363,
    kd: 650.74,
    kp: 61.482,
    bd: 0.48643,
    bp: 7.9083,
    b: 0.1,
    bqd: 0.5,
    bqp: 5.0,
    awh0: 0.0128,
    awc0: 0.0112,
    awr: 0.0377,
    hh: 500.0,
    hk: 500.0,
    hr: 100.0,
    rf: 1.0e5,
    mdot_eps: 1.0e-5,
};

impl Engine {
    /// The cylinder diameter `D = sqrt(4A/pi)`.
    fn d(&self) -> f64 {
        (4.0 * self.a / PI).sqrt()
    }
    /// In the order and with the names of the declaration, to compare with the model's defaults.
    fn by_name(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("R", self.r),
            ("gamma", self.gamma),
            ("A", self.a),
            ("Ar", self.ar),
            ("Vh0", self.vh0),
            ("Vc0", self.vc0),
            ("Vr", self.vr),
            ("Th", self.th),
            ("Tk", self.tk),
            ("Pmean", self.pmean),
            ("Pb", self.pb),
            ("md", self.md),
            ("mp", self.mp),
            ("kd", self.kd),
            ("kp", self.kp),
            ("bd", self.bd),
            ("bp", self.bp),
            ("b", self.b),
            ("bqd", self.bqd),
            ("bqp", self.bqp),
            ("Awh0", self.awh0),
            ("Awc0", self.awc0),
            ("Awr", self.awr),
            ("hh", self.hh),
            ("hk", self.hk),
            ("hr", self.hr),
            ("Rf", self.rf),
            ("mdot_eps", self.mdot_eps),
        ]
    }
}

/// A value and the sum of the magnitudes of the terms it is made of (the round-off scale).
#[derive(Clone, Copy, Debug, Default)]
struct Val {
    v: f64,
    scale: f64,
}

impl Val {
    fn add(&mut self, t: f64) {
        self.v += t;
        self.scale += t.abs();
    }
}

/// A heat port: `Q = h Aw(x, y) (Tw - T)` with `Aw = aw0 + awx x + awy y`.
struct Port {
    h: f64,
    aw0: f64,
    awx: f64,
    awy: f64,
    tw: f64,
}

/// A gas control volume: `V = v0 + ax x + ay y`; its face coefficients are `ax`, `ay` (section 1).
struct Cv {
    v0: f64,
    ax: f64,
    ay: f64,
    ports: Vec<Port>,
}

/// A linear mass-flow link `from -> to` with resistance `r`.
struct Link {
    from: usize,
    to: usize,
    r: f64,
}

/// The four family members as CVs, ports and links (section 5).
fn hot_port(e: &Engine) -> Port {
    Port {
        h: e.hh,
        aw0: e.awh0,
        awx: -PI * e.d(),
        awy: 0.0,
        tw: e.th,
    }
}
fn cold_port(e: &Engine) -> Port {
    Port {
        h: e.hk,
        aw0: e.awc0,
        awx: PI * e.d(),
        awy: -PI * e.d(),
        tw: e.tk,
    }
}
fn wall(h: f64, aw: f64, tw: f64) -> Port {
    Port {
        h,
        aw0: aw,
        awx: 0.0,
        awy: 0.0,
        tw,
    }
}

fn cv1(e: &Engine) -> (Vec<Cv>, Vec<Link>) {
    // One pressure on every face: a_x = -A + (A - Ar) = -Ar, a_y = -(A - Ar).
    let gas = Cv {
        v0: e.vh0 + e.vc0 + e.vr,
        ax: -e.a + (e.a - e.ar),
        ay: -(e.a - e.ar),
        ports: vec![
            hot_port(e),
            cold_port(e),
            wall(e.hr, e.awr, (e.th + e.tk) / 2.0),
        ],
    };
    (vec![gas], vec![])
}

fn cv2(e: &Engine) -> (Vec<Cv>, Vec<Link>) {
    let hot = Cv {
        v0: e.vh0 + e.vr / 2.0,
        ax: -e.a,
        ay: 0.0,
        ports: vec![
            hot_port(e),
            wall(e.hr, e.awr / 2.0, (3.0 * e.th + e.tk) / 4.0),
        ],
    };
    let cold = Cv {
        v0: e.vc0 + e.vr / 2.0,
        ax: e.a - e.ar,
        ay: -(e.a - e.ar),
        ports: vec![
            cold_port(e),
            wall(e.hr, e.awr / 2.0, (e.th + 3.0 * e.tk) / 4.0),
        ],
    };
    (
        vec![hot, cold],
        vec![Link {
            from: 0,
            to: 1,
            r: e.rf,
        }],
    )
}

fn nsection(e: &Engine, n: usize) -> (Vec<Cv>, Vec<Link>) {
    let nf = n as f64;
    let mut cvs = vec![Cv {
        v0: e.vh0,
        ax: -e.a,
        ay: 0.0,
        ports: vec![hot_port(e)],
    }];
    for j in 1..=n {
        let tw = e.th - (j as f64 - 0.5) * (e.th - e.tk) / nf;
        cvs.push(Cv {
            v0: e.vr / nf,
            ax: 0.0,
            ay: 0.0,
            ports: vec![wall(e.hr, e.awr / nf, tw)],
        });
    }
    cvs.push(Cv {
        v0: e.vc0,
        ax: e.a - e.ar,
        ay: -(e.a - e.ar),
        ports: vec![cold_port(e)],
    });
    let mut links = vec![Link {
        from: 0,
        to: 1,
        r: e.rf / (2.0 * nf),
    }];
    for j in 1..n {
        links.push(Link {
            from: j,
            to: j + 1,
            r: e.rf / nf,
        });
    }
    links.push(Link {
        from: n,
        to: n + 1,
        r: e.rf / (2.0 * nf),
    });
    (cvs, links)
}

/// Section 6: `T_i0 = sum(h Aw Tw)/sum(h Aw)` at rest, `m_i0 = Pmean V_i0 / (R T_i0)`.
fn rest_mass(e: &Engine, cv: &Cv) -> f64 {
    let hw: f64 = cv.ports.iter().map(|p| p.h * p.aw0).sum();
    let hwt: f64 = cv.ports.iter().map(|p| p.h * p.aw0 * p.tw).sum();
    e.pmean * cv.v0 / (e.r * hwt / hw)
}

/// Section 2: `m a' = F - k q - b_own q' - b (q' - q'_other) - bq q'|q'|`.
fn body(
    m: f64,
    k: f64,
    b_own: f64,
    bq: f64,
    b: f64,
    q: f64,
    qd: f64,
    other: f64,
    force: Val,
) -> Val {
    let mut s = force;
    for t in [-k * q, -b_own * qd, -b * (qd - other), -bq * qd * qd.abs()] {
        s.add(t);
    }
    Val {
        v: s.v / m,
        scale: s.scale / m,
    }
}

/// Mechanics for given face forces `F_x`, `F_y` (with the bounce space): rows x', v', y', w'.
fn mechanics(e: &Engine, z: &[f64], fx: Val, fy: Val) -> Vec<Val> {
    let (x, v, y, w) = (z[0], z[1], z[2], z[3]);
    let exact = |t: f64| Val {
        v: t,
        scale: t.abs(),
    };
    vec![
        exact(v),
        body(e.md, e.kd, e.bd, e.bqd, e.b, x, v, w, fx),
        exact(w),
        body(e.mp, e.kp, e.bp, e.bqp, e.b, y, w, v, fy),
    ]
}

/// Bounce-space face forces: `a_x = Ar`, `a_y = A - Ar` at pressure `Pb`.
fn bounce_forces(e: &Engine) -> (Val, Val) {
    let (mut fx, mut fy) = (Val::default(), Val::default());
    fx.add(e.ar * e.pb);
    fy.add((e.a - e.ar) * e.pb);
    (fx, fy)
}

/// Section 3: the Schmidt model, states `[x, v, y, w]`.
fn schmidt_rhs(e: &Engine, z: &[f64]) -> Vec<Val> {
    let tr = (e.th - e.tk) / (e.th / e.tk).ln();
    let mr = e.pmean * (e.vh0 / e.th + e.vc0 / e.tk + e.vr / tr);
    let vh = e.vh0 - e.a * z[0];
    let vc = e.vc0 + (e.a - e.ar) * (z[0] - z[2]);
    let p = mr / (vh / e.th + vc / e.tk + e.vr / tr);
    let (mut fx, mut fy) = bounce_forces(e);
    fx.add(-e.a * p);
    fx.add((e.a - e.ar) * p);
    fy.add(-(e.a - e.ar) * p);
    mechanics(e, z, fx, fy)
}

/// Sections 1, 2 and 4: the RHS of a CV model, states `[x, v, y, w, P.., (m..)]`; `masses`
/// are the state masses (full) or the rest masses (frozen, or no links).
fn gas_rhs(
    e: &Engine,
    cvs: &[Cv],
    links: &[Link],
    z: &[f64],
    masses: &[f64],
    with_mass_rows: bool,
) -> Vec<Val> {
    let (x, v, y, w) = (z[0], z[1], z[2], z[3]);
    let ncv = cvs.len();
    let pr = &z[4..4 + ncv];
    let cp = e.gamma * e.r / (e.gamma - 1.0);
    let vol: Vec<f64> = cvs.iter().map(|c| c.v0 + c.ax * x + c.ay * y).collect();
    let vdot: Vec<f64> = cvs.iter().map(|c| c.ax * v + c.ay * w).collect();
    let temp: Vec<f64> = (0..ncv)
        .map(|i| pr[i] * vol[i] / (masses[i] * e.r))
        .collect();
    // Energy into each CV (heat and enthalpy) and mass into each CV.
    let mut energy = vec![Val::default(); ncv];
    let mut mass = vec![Val::default(); ncv];
    for (i, c) in cvs.iter().enumerate() {
        for p in &c.ports {
            energy[i].add(p.h * (p.aw0 + p.awx * x + p.awy * y) * (p.tw - temp[i]));
        }
    }
    for l in links {
        let mdot = (pr[l.from] - pr[l.to]) / l.r;
        let s = (1.0 + (mdot / e.mdot_eps).tanh()) / 2.0;
        let h = cp * mdot * (s * temp[l.from] + (1.0 - s) * temp[l.to]);
        energy[l.from].add(-h);
        energy[l.to].add(h);
        mass[l.from].add(-mdot);
        mass[l.to].add(mdot);
    }
    let (mut fx, mut fy) = bounce_forces(e);
    for (c, p) in cvs.iter().zip(pr) {
        fx.add(c.ax * p);
        fy.add(c.ay * p);
    }
    let mut out = mechanics(e, z, fx, fy);
    for i in 0..ncv {
        // P' = ((gamma-1)(Q + Hin - Hout) - gamma P V') / V
        let work = e.gamma * pr[i] * vdot[i];
        let num = (e.gamma - 1.0) * energy[i].v - work;
        let scale = (e.gamma - 1.0) * energy[i].scale + work.abs();
        out.push(Val {
            v: num / vol[i],
            scale: scale / vol[i],
        });
    }
    if with_mass_rows {
        out.extend(mass);
    }
    out
}

/// The reference RHS of a family member and closure at the test state; returns the state too.
fn reference(name: &str, n: usize, closure: Closure) -> (Vec<f64>, Vec<Val>) {
    let e = ENGINE;
    let mut z = vec![0.003, 0.2, -0.002, -0.1];
    if name == "schmidt" {
        return (z.clone(), schmidt_rhs(&e, &z));
    }
    let (cvs, links) = match name {
        "cv1" => cv1(&e),
        "cv2" => cv2(&e),
        _ => nsection(&e, n),
    };
    let rest: Vec<f64> = cvs.iter().map(|c| rest_mass(&e, c)).collect();
    let full = closure == Closure::Full && !links.is_empty();
    z.extend((0..cvs.len()).map(|i| e.pmean * (1.0 + 0.01 * (i + 1) as f64)));
    let masses: Vec<f64> = if full {
        rest.iter()
            .enumerate()
            .map(|(i, m)| 1.02 * m * (1.0 - 0.005 * i as f64))
            .collect()
    } else {
        rest
    };
    if full {
        z.extend(&masses);
    }
    let f = gas_rhs(&e, &cvs, &links, &z, &masses, full);
    (z, f)
}

/// Compare the model's RHS with the reference: `|f - ref| <= 1e-9 max(|ref|, 1e-3 terms)`.
fn check(name: &str, n: Option<usize>, closure: Closure) {
    let m = build(name, n, closure).unwrap();
    let (z, want) = reference(name, n.unwrap_or(1), closure);
    assert_eq!(m.n_states(), z.len(), "{name} {closure}: state count");
    let mut eq = vec![0.0; z.len()];
    m.equilibrium_guess(&m.default_params(), &mut eq);
    let rest = if name == "schmidt" {
        vec![]
    } else {
        reference_equilibrium(name, n.unwrap_or(1), closure)
    };
    assert_eq!(
        eq[4..].len(),
        rest.len(),
        "{name} {closure}: equilibrium length"
    );
    for (i, (a, b)) in eq[4..].iter().zip(&rest).enumerate() {
        assert!(
            (a - b).abs() <= 1e-12 * b.abs(),
            "{name} {closure}: equilibrium state {} = {a}, reference {b}",
            i + 4
        );
    }
    let mut got = vec![0.0; z.len()];
    m.rhs(&m.default_params(), &z, 0.0, &mut got);
    let names = m.state_names();
    for (r, (g, w)) in got.iter().zip(&want).enumerate() {
        let tol = 1e-9 * w.v.abs().max(1e-3 * w.scale);
        assert!(
            (g - w.v).abs() <= tol,
            "{name} n={n:?} {closure}: {}' = {g:.12e}, reference {:.12e} (terms {:.3e})",
            names[r],
            w.v,
            w.scale
        );
    }
}

/// Section 6 by hand: pressures at `Pmean`, masses `m_i0` (full only).
fn reference_equilibrium(name: &str, n: usize, closure: Closure) -> Vec<f64> {
    let e = ENGINE;
    let (cvs, links) = match name {
        "cv1" => cv1(&e),
        "cv2" => cv2(&e),
        _ => nsection(&e, n),
    };
    let mut out = vec![e.pmean; cvs.len()];
    if closure == Closure::Full && !links.is_empty() {
        out.extend(cvs.iter().map(|c| rest_mass(&e, c)));
    }
    out
}

#[test]
fn defaults_are_the_engine_of_physics_md_section_8() {
    for name in ["schmidt", "cv1", "cv2", "nsection"] {
        let m = build(name, None, Closure::Full).unwrap();
        let declared: Vec<(&str, f64)> = m.params().iter().map(|p| (p.name, p.default)).collect();
        let by_hand = ENGINE.by_name();
        assert_eq!(declared.len(), by_hand.len(), "{name}: parameter count");
        for ((dn, dv), (hn, hv)) in declared.iter().zip(&by_hand) {
            assert_eq!(dn, hn, "{name}: parameter order");
            assert!(
                (dv - hv).abs() <= 1e-15 * hv.abs(),
                "{name}: {dn} = {dv}, docs/physics.md says {hv}"
            );
        }
    }
}

#[test]
fn schmidt_matches_the_hand_written_equations() {
    check("schmidt", None, Closure::Full);
    check("schmidt", None, Closure::Frozen);
}

#[test]
fn cv1_matches_the_hand_written_equations() {
    check("cv1", None, Closure::Full);
    check("cv1", None, Closure::Frozen);
}

#[test]
fn cv2_matches_the_hand_written_equations() {
    check("cv2", None, Closure::Full);
    check("cv2", None, Closure::Frozen);
}

#[test]
fn nsection_matches_the_hand_written_equations() {
    for n in [1, 2, 3, 10] {
        check("nsection", Some(n), Closure::Full);
        check("nsection", Some(n), Closure::Frozen);
    }
}

/// The seed's 4th-order pressure (S13-S15): `P - Pmean` is linear in `x`, `y` near rest with
/// `C1 = MR/(S0^2 Th)`, `C2 = MR/(S0^2 Tk)`; the model's `v'` and `w'` rows carry it through
/// `-Ar (P - Pb)` and `-(A - Ar)(P - Pb)`.
#[test]
fn schmidt_linearization_is_the_seed_s13_to_s15() {
    let e = ENGINE;
    let tr = (e.th - e.tk) / (e.th / e.tk).ln();
    let s0 = e.vh0 / e.th + e.vc0 / e.tk + e.vr / tr;
    let mr = e.pmean * s0;
    let (c1, c2) = (mr / (s0 * s0 * e.th), mr / (s0 * s0 * e.tk));
    let dp_dx = c1 * e.a - c2 * (e.a - e.ar);
    let dp_dy = c2 * (e.a - e.ar);
    let m = build("schmidt", None, Closure::Full).unwrap();
    let j = m.jacobian_dense(&m.default_params(), &[0.0; 4], 0.0);
    let want = [
        (1, 0, -e.ar * dp_dx / e.md - e.kd / e.md),
        (1, 2, -e.ar * dp_dy / e.md),
        (3, 0, -(e.a - e.ar) * dp_dx / e.mp),
        (3, 2, -(e.a - e.ar) * dp_dy / e.mp - e.kp / e.mp),
    ];
    for (r, c, v) in want {
        let got = j[r + 4 * c];
        assert!(
            (got - v).abs() <= 1e-10 * v.abs(),
            "J[{r},{c}] = {got}, S13-S15 give {v}"
        );
    }
}
