//! The custom engine of `examples/custom_topology.rs` (closed bounce space with its own heat
//! port, linear alternator load), declared in user code, runs through every analysis:
//! its generated Jacobians match finite differences, its energy budget closes along a
//! trajectory with the bounce-space terms, it is linearly unstable, and it settles on a
//! limit cycle that delivers electric power.

mod common;
#[path = "../examples/custom_topology.rs"]
#[allow(dead_code)]
mod ex;

use ex::AlternatorEngine;
use stirling::dsl::{Closure, Model, StateKind};
use stirling::models::sim::{self, EnergySystem, Hooks, ModelSystem, SimOptions};

fn model(n: usize) -> AlternatorEngine {
    AlternatorEngine::new(n, Closure::Full).unwrap()
}

fn value(m: &dyn Model, p: &[f64], name: &str) -> f64 {
    p[m.param_index(name)
        .unwrap_or_else(|| panic!("no parameter {name}"))]
}

#[test]
fn the_closed_bounce_space_is_a_control_volume() {
    let m = model(2);
    // [x, v, y, w] + P of hot, regen[0], regen[1], cold, bounce + m of the four linked CVs
    assert_eq!(m.n_states(), 4 + 5 + 4, "{:?}", m.state_names());
    let vessels = m.vessel_names();
    assert_eq!(
        vessels.len(),
        5,
        "no given-pressure space is left: {vessels:?}"
    );
    assert!(vessels.iter().any(|v| v.contains("bounce")), "{vessels:?}");
    let masses = m
        .states()
        .iter()
        .filter(|s| matches!(s.kind, StateKind::Mass(_)))
        .count();
    assert_eq!(
        masses, 4,
        "the bounce gas has no link, so its mass is a constant"
    );
}

/// The shared checker (`tests/common`) at random states, with one adjustment: its pressure
/// step is 5 % of the smallest gap between any two pressures (so that a central difference
/// does not straddle a link's `dP = 0`), which for the balanced states is ~1e-5 Pa. The
/// bounce gas has no link, and its own row is slow (`dP_b'/dP_b` ~ 1e-2 1/s against
/// `P_b'` ~ 1e5 Pa/s), so at such a step round-off dominates; its column is checked
/// separately with a step of 1 Pa (Ridders shrinks it), where nothing switches.
#[test]
fn jacobians_match_finite_differences() {
    for n in [1, 3] {
        let m = model(n);
        let p = m.default_params();
        let names = m.state_names();
        let ib = names
            .iter()
            .position(|s| s == "P_bounce")
            .expect("P_bounce state");
        let scales = common::state_scales(&m, &p);
        let mut rng = common::rng(90 + n as u64);
        let mut report = Vec::new();
        for spread in [common::Spread::Wide, common::Spread::Balanced] {
            for k in 0..3 {
                let x = common::random_state(&m, &p, spread, &mut rng);
                let mut bad: Vec<common::Mismatch> = common::check_jacobians(&m, &p, &x)
                    .into_iter()
                    .filter(|b| b.col != names[ib])
                    .collect();
                let mut steps = common::fd_steps(&m, &p, &x);
                steps[ib] = 1.0;
                let f = |xx: &[f64], out: &mut [f64]| m.rhs(&p, xx, 0.0, out);
                let fd = common::fd_jacobian(&f, &x, x.len(), &steps);
                let jac = m.jacobian_dense(&p, &x, 0.0);
                bad.extend(
                    common::compare(
                        &jac,
                        &fd,
                        &names,
                        &names,
                        &scales,
                        &scales,
                        common::REL,
                        common::TINY,
                    )
                    .into_iter()
                    .filter(|b| b.col == names[ib]),
                );
                for b in bad {
                    report.push(format!(
                        "  n = {n}, {spread:?} state {k}: d {}/d {}: analytic {:.12e}, fd {:.12e}",
                        b.row, b.col, b.analytic, b.fd
                    ));
                }
            }
        }
        assert!(
            report.is_empty(),
            "{} Jacobian entries disagree:\n{}",
            report.len(),
            report.join("\n")
        );
    }
}

/// Power terms by hand at random states: all heat ports including the bounce wall, no
/// boundary term (nothing is held at a given pressure), and the mechanical power of every
/// damper plus the alternator force.
#[test]
fn power_terms_hold_the_bounce_and_alternator_terms() {
    let m = model(2);
    let p = m.default_params();
    let v = |name: &str| value(&m, &p, name);
    let mut rng = common::rng(7);
    for _ in 0..5 {
        let x = common::random_state(&m, &p, common::Spread::Wide, &mut rng);
        let (xd, vd, y, w) = (x[0], x[1], x[2], x[3]);
        let mut t = vec![0.0; 5];
        m.temperatures(&p, &x, &mut t);
        let d = (4.0 * v("A") / std::f64::consts::PI).sqrt();
        let pi = std::f64::consts::PI;
        let heat = v("hh") * (v("Awh0") - pi * d * xd) * (v("Th") - t[0])
            + (0..2)
                .map(|j| {
                    v("hr") * v("Awr") / 2.0
                        * (v("Th") - (j as f64 + 0.5) * (v("Th") - v("Tk")) / 2.0 - t[1 + j])
                })
                .sum::<f64>()
            + v("hk") * (v("Awc0") + pi * d * (xd - y)) * (v("Tk") - t[3])
            + v("hb") * v("Awb") * (v("Tb") - t[4]);
        let mech = -v("bd") * vd * vd
            - (v("bp") + v("c_alt")) * w * w
            - v("b") * (vd - w).powi(2)
            - v("bqd") * vd.abs().powi(3)
            - v("bqp") * w.abs().powi(3);
        let pw = m.power(&p, &x);
        assert!(
            (pw.heat - heat).abs() <= 1e-9 * heat.abs().max(1.0),
            "heat {} vs {heat}",
            pw.heat
        );
        assert_eq!(
            pw.boundary, 0.0,
            "a closed engine has no given-pressure boundary"
        );
        assert!(
            (pw.mechanical - mech).abs() <= 1e-9 * mech.abs().max(1e-6),
            "mechanical {} vs {mech}",
            pw.mechanical
        );
        // the stored energy holds the bounce gas: sum P V / (gamma - 1) over all five CVs
        let (mut pr, mut vol) = (vec![0.0; 5], vec![0.0; 5]);
        m.pv(&p, &x, &mut pr, &mut vol);
        let gas: f64 = pr.iter().zip(&vol).map(|(a, b)| a * b).sum::<f64>() / (v("gamma") - 1.0);
        let e = gas
            + 0.5 * v("md") * vd * vd
            + 0.5 * v("mp") * w * w
            + 0.5 * v("kd") * xd * xd
            + 0.5 * v("kp") * y * y;
        assert!(
            (m.energy(&p, &x) - e).abs() <= 1e-12 * e,
            "energy {} vs {e}",
            m.energy(&p, &x)
        );
    }
}

/// docs/physics.md section 10 with the closed bounce space: `E(t) - E(0)` equals the integral of
/// `heat + mechanical` (the boundary term is zero), carried as a quadrature state of the same
/// run and, independently, by the trapezoid rule on dense samples.
#[test]
fn energy_budget_closes_along_a_trajectory() {
    let m = model(2);
    let p = m.default_params();
    let x0 = ex::perturbed(&m, &p);
    let n = m.n_states();
    let e0 = m.energy(&p, &x0);
    let t_end = 0.2;
    let samples = sim::uniform_samples(t_end, 4000);
    let mut z0 = x0.clone();
    z0.push(0.0);
    let sys = EnergySystem {
        inner: ModelSystem { model: &m, p: &p },
    };
    for rtol in [1e-6, 1e-9] {
        let opts = SimOptions {
            rtol,
            atol: rtol,
            ..Default::default()
        };
        let tr = sim::integrate(&sys, &z0, t_end, &samples, &opts, Hooks::default()).unwrap();
        let (mut worst, mut swing, mut trap, mut trap_worst) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let total = |x: &[f64]| {
            let pw = m.power(&p, x);
            pw.heat + pw.boundary + pw.mechanical
        };
        for k in 0..tr.x.len() {
            let z = &tr.x[k];
            let de = m.energy(&p, &z[..n]) - e0;
            worst = worst.max((de - z[n]).abs());
            swing = swing.max(de.abs());
            if k > 0 {
                trap += 0.5 * (tr.t[k] - tr.t[k - 1]) * (total(&tr.x[k - 1][..n]) + total(&z[..n]));
                trap_worst = trap_worst.max((de - trap).abs());
            }
        }
        eprintln!("rtol {rtol:e}: |dE - quadrature| <= {worst:.3e} J, |dE - trapezoid| <= {trap_worst:.3e} J (E0 = {e0:.4} J, max |dE| = {swing:.3e} J)");
        assert!(swing > 1e-3, "the trajectory exchanges energy: {swing:e} J");
        assert!(
            worst < 100.0 * rtol * e0,
            "budget gap {worst:e} J at rtol {rtol:e}"
        );
        assert!(
            trap_worst < 1e-3 * swing,
            "trapezoid budget gap {trap_worst:e} J"
        );
    }
}

/// The whole example at n = 1: unstable pair, margins, limit cycle, PV diagram written.
#[test]
fn the_example_runs_every_analysis() {
    let dir = std::env::temp_dir().join(format!("custom_topology_test_{}", std::process::id()));
    let args = ex::parse_args(
        ["--n", "1", "--out", dir.to_str().unwrap(), "--t-max", "20"].map(String::from),
    )
    .unwrap();
    let t0 = std::time::Instant::now();
    let s = ex::run(&args).unwrap();
    ex::print(&s);
    let json = ex::json(&s);
    let lin = &s.linear;
    let f = &s.cycle.figures;
    eprintln!("wall {:?}", t0.elapsed());
    let unstable: Vec<_> = lin.dynamics.poles.iter().filter(|p| p.rhp).collect();
    assert_eq!(
        unstable.len(),
        2,
        "one unstable pair: {:?}",
        lin.dynamics.poles
    );
    assert!(
        unstable[0].im.abs() > 30.0 && unstable[0].im.abs() < 300.0,
        "{:?}",
        unstable[0]
    );
    assert!(
        lin.margins.gain_db.is_some() || lin.margins.phase_deg.is_some(),
        "{:?}",
        lin.margins
    );
    assert!(
        f.frequency_hz > 5.0 && f.frequency_hz < 50.0,
        "f = {}",
        f.frequency_hz
    );
    assert!(
        f.x_amp > 1e-3 && f.x_amp < 5e-2 && f.y_amp > 1e-4 && f.y_amp < 5e-2,
        "{f:?}"
    );
    assert!(
        s.cycle.work.total > 0.0 && s.electric_power_w > 0.0,
        "work {}, electric {}",
        s.cycle.work.total,
        s.electric_power_w
    );
    assert!(
        s.electric_power_w < s.indicated_power_w,
        "the alternator gets part of the indicated power"
    );
    // the bounce gas is a gas spring with hysteresis: it absorbs work over a cycle
    let ib = s
        .cycle
        .work
        .vessels
        .iter()
        .position(|v| v.contains("bounce"))
        .unwrap();
    assert!(
        s.cycle.work.per_vessel[ib] < 0.0,
        "bounce-space work {:?}",
        s.cycle.work.per_vessel
    );
    let ones = s
        .cycle
        .cycle
        .floquet
        .iter()
        .filter(|&&(re, im)| (re - 1.0).hypot(im) < 1e-5)
        .count();
    assert!(
        ones >= 2,
        "trivial and inventory multipliers: {:?}",
        s.cycle.cycle.floquet
    );
    for file in &s.files {
        let text = std::fs::read_to_string(file).unwrap();
        assert!(
            text.starts_with("<svg") || text.contains("<svg"),
            "{} is an SVG",
            file.display()
        );
    }
    assert!(s.files.iter().any(|f| f.ends_with("pv.svg")));
    assert!(
        json["limit_cycle"]["frequency_hz"].as_f64().is_some() && json["linear"]["rhp_count"] == 2,
        "{json}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_command_line_is_checked() {
    assert_eq!(
        ex::parse_args(Vec::<String>::new()).unwrap(),
        ex::Args::default()
    );
    let a = ex::parse_args(["--n", "5", "--json", "--no-plots"].map(String::from)).unwrap();
    assert_eq!((a.n, a.json, a.out), (5, true, None));
    assert!(ex::parse_args(["--n", "0"].map(String::from))
        .unwrap_err()
        .contains("at least 1"));
    assert!(ex::parse_args(["--n"].map(String::from))
        .unwrap_err()
        .contains("needs a value"));
    assert!(ex::parse_args(["--bogus"].map(String::from))
        .unwrap_err()
        .contains("unknown argument"));
}

/// The rig's record of the engine with its own sensors: `p` (cold CV), `x`, `y` and the
/// bounce-space transducer `p_bounce`, a start-up from a small kick, with offsets.
fn bounce_record(
    channels: &[&str],
) -> (AlternatorEngine, Vec<f64>, stirling::models::data::Measured) {
    bounce_record_with(channels, Vec::new())
}

/// [`bounce_record`] with the noise levels of named channels (`RigConfig::noise`).
fn bounce_record_with(
    channels: &[&str],
    noise: Vec<(String, f64)>,
) -> (AlternatorEngine, Vec<f64>, stirling::models::data::Measured) {
    use stirling::models::rig::{measure, RigConfig};
    let m = model(2);
    let truth = m.default_params();
    let cfg = RigConfig {
        t_end: 3.0,
        x0: 5e-4,
        offset_p: 50.0,
        seed: 2,
        channels: channels.iter().map(|c| c.to_string()).collect(),
        noise,
        ..Default::default()
    };
    let rec = measure(&m, &truth, &cfg).expect("measured");
    (m, truth, rec)
}

/// The engine fitted from its own sensors: the closed bounce space is not part of the
/// working gas, so stage 1 takes its pressure from `p_bounce` and stage 2 simulates it and
/// fits that sensor (with its offset); the intervals cover the truth and the calibrated
/// model's free run matches the record, bounce pressure included.
#[test]
fn the_engine_is_fitted_from_its_own_sensors() {
    use stirling::models::fit::{self, FitOptions};
    let (m, truth, rec) = bounce_record(&["p", "x", "y", "p_bounce"]);
    let mut p0 = truth.clone();
    for (k, v) in [
        ("kd", 683.0),
        ("hh", 650.0),
        ("hk", 650.0),
        ("bp", 2.4),
        ("Rf", 1.5e5),
    ] {
        p0[m.param_index(k).unwrap()] = v;
    }
    let free = ["kd", "kp", "bd", "bp", "hh", "hk", "Rf"];
    let opts = FitOptions {
        free: Some(free.map(String::from).to_vec()),
        ..Default::default()
    };
    let id = fit::identify(&m, &p0, &rec, &opts).expect("fitted");
    common::fit::assert_recovered(&id, free.map(|k| (k, value(&m, &truth, k))), 0.5);
    let off = id.offsets.get("p_bounce");
    assert!((off - 50.0).abs() < 30.0, "p_bounce offset {off}");
    common::fit::assert_free_run_amplitudes(&id, &["x", "y", "p", "p_bounce"], 0.05);
}

/// The engine's expression sensors are fitted outputs like its states: the differential
/// transducer across the piston (`sensor dp: P_cold - P_bounce "Pa";`) and the alternator's
/// voltage (`sensor emf: Kv * w "V";`, with its constant `Kv` free). Multiple shooting over
/// a record with both recovers the parameters, `Kv` among them, with intervals that cover
/// the truth, reproduces the channels down to their noise, and so does the free run.
#[test]
fn expression_sensors_are_fitted_outputs() {
    use stirling::models::fit::multiple_shooting::{multiple_shooting, MsOptions};
    use stirling::models::fit::{self, FitOptions};
    let (m, truth, rec) = bounce_record_with(
        &["p", "x", "y", "p_bounce", "dp", "emf"],
        vec![("emf".into(), 0.02)],
    );
    let sd = stirling::models::rig::RigConfig::default().noise_p;
    // the rig reads the expression: the difference of the two absolute transducers (their
    // offsets cancel) up to the noise
    let (pc, pb, dp) = (
        rec.channel("p").unwrap(),
        rec.channel("p_bounce").unwrap(),
        rec.channel("dp").unwrap(),
    );
    let worst = (0..dp.len())
        .map(|k| (dp[k] - (pc[k] - pb[k])).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 6.0 * 3f64.sqrt() * sd,
        "dp against p - p_bounce: {worst} Pa"
    );
    let free = ["kd", "kp", "bd", "bp", "hh", "hk", "Rf", "Kv"];
    let id = fit::identify(
        &m,
        &truth,
        &rec,
        &FitOptions {
            free: Some(free[..7].iter().map(|k| k.to_string()).collect()),
            ..Default::default()
        },
    )
    .expect("fitted");
    let mut p0 = truth.clone();
    for (k, f) in [
        ("kd", 1.02),
        ("bp", 1.1),
        ("hh", 0.9),
        ("Rf", 1.2),
        ("Kv", 0.9),
    ] {
        p0[m.param_index(k).unwrap()] *= f;
    }
    let idx: Vec<usize> = free.iter().map(|k| m.param_index(k).unwrap()).collect();
    let ms = multiple_shooting(
        &m,
        &p0,
        &idx,
        &rec,
        &id.offsets,
        id.train,
        &MsOptions::default(),
    )
    .expect("refined");
    for k in free {
        let e = ms.estimate(k).unwrap();
        eprintln!("{k}: {:.5e} [{:.5e}, {:.5e}]", e.value, e.ci_low, e.ci_high);
        assert!(e.covers(value(&m, &truth, k)), "{k}: {e:?}");
    }
    let kv = ms.estimate("Kv").unwrap();
    assert!(kv.ci_high - kv.ci_low < 0.02 * 25.0, "Kv interval {kv:?}");
    for (ch, sd) in [("dp", sd), ("emf", 0.02)] {
        let f = ms.fits.iter().find(|f| f.channel == ch).expect("fitted");
        eprintln!("{ch}: {:.2} %, rms {:.3e}", f.fit_percent, f.rms);
        assert!(f.rms < 1.2 * sd, "{ch}: rms {} against noise {sd}", f.rms);
    }
    let fr = id.free_run.as_ref().expect("free run");
    for ch in ["dp", "emf"] {
        let short = fr
            .fit_percent(ch, "free_run_short")
            .expect("in the free run");
        assert!(short > 85.0, "free run of {ch}: {short:.2} %");
    }
}

/// Without its bounce-space sensor the record cannot carry the fit: refused by name.
#[test]
fn identification_refuses_the_engine_without_its_bounce_sensor() {
    use stirling::models::fit::{self, FitError};
    let (m, truth, rec) = bounce_record(&["p", "x", "y"]);
    let err = fit::identify(&m, &truth, &rec, &Default::default()).expect_err("no p_bounce");
    assert!(
        matches!(&err, FitError::OutsideUnmeasured { vessel, sensor, .. }
            if vessel == "bounce" && sensor == "p_bounce"),
        "{err}"
    );
    assert!(err.to_string().contains("no such column"), "{err}");
}

/// The rig measures the engine with its own sensors: the seed's `p` (cold CV, where the
/// engine's inherited sensor puts it, not its last CV) and `x`, `y`, and the bounce-space
/// transducer `p_bounce` it declares; the record carries it by name through a CSV.
#[test]
fn the_rig_measures_the_declared_bounce_sensor() {
    use stirling::models::data::{read_csv, write_csv};
    use stirling::models::rig::{measure, RigConfig, RigError};
    let m = model(2);
    let p = m.default_params();
    let cfg = RigConfig {
        t_end: 0.3,
        rate: 2000.0,
        noise_p: 20.0,
        channels: ["p", "x", "y", "p_bounce"].map(String::from).to_vec(),
        ..Default::default()
    };
    let rec = measure(&m, &p, &cfg).expect("measured");
    assert_eq!(rec.channels(), ["p", "x", "y", "p_bounce"]);
    // the same run, sampled clean: each channel within 6 sigma of its state
    let samples: Vec<f64> = rec.t.clone();
    let mut x0 = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x0);
    x0[0] += cfg.x0;
    let opts = stirling::models::sim::SimOptions {
        rtol: 1e-8,
        atol: 1e-8,
        ..Default::default()
    };
    let traj = stirling::models::sim::simulate(&m, &p, &x0, cfg.t_end, &samples, &opts).unwrap();
    let names = m.state_names();
    for (channel, state, sd) in [
        ("p", "P_cold", cfg.noise_p),
        ("p_bounce", "P_bounce", cfg.noise_p),
        ("x", "x", cfg.noise_x),
    ] {
        let k = names.iter().position(|s| s == state).unwrap();
        let v = rec.channel(channel).unwrap();
        let worst = v
            .iter()
            .zip(&traj.x)
            .map(|(a, row)| (a - row[k]).abs())
            .fold(0.0, f64::max);
        assert!(worst < 6.0 * sd, "{channel}: {worst} against sd {sd}");
    }
    // the bounce and cold pressures differ: the channel is not the cold one relabelled
    let (pb, pc) = (rec.channel("p_bounce").unwrap(), rec.channel("p").unwrap());
    let swing = |v: &[f64]| {
        v.iter().fold(f64::MIN, |a, &b| a.max(b)) - v.iter().fold(f64::MAX, |a, &b| a.min(b))
    };
    assert!(
        (swing(pc) - swing(pb)).abs() > 0.1 * swing(pc),
        "{} {}",
        swing(pc),
        swing(pb)
    );
    let dir = std::env::temp_dir().join(format!("stirling_bounce_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("bounce.csv");
    write_csv(&f, &rec, &[]).unwrap();
    let back = read_csv(&f).unwrap();
    assert_eq!(back.channels(), ["p", "x", "y", "p_bounce"]);
    assert!((back.channel("p_bounce").unwrap()[7] - pb[7]).abs() < 1e-6 * pb[7]);
    // a channel the engine does not declare is refused with the ones it does
    let bad = RigConfig {
        channels: vec!["p_crank".into()],
        ..cfg.clone()
    };
    let err = measure(&m, &p, &bad).unwrap_err();
    assert!(matches!(err, RigError::UnknownChannel { .. }), "{err}");
    assert!(err.to_string().contains("p_bounce"), "{err}");
}

/// A record of the augmented engine (`AlternatorFx`) with the piston's Coulomb friction at
/// `fcp` (N; 0: the clean engine), measured with the engine's own sensors, and a start
/// perturbed from the nominal parameters as a user's first guess would be.
fn fx_record(fcp: f64) -> (ex::AlternatorFx, Vec<f64>, stirling::models::data::Measured) {
    let m = ex::AlternatorFx::new(2, Closure::Full).unwrap();
    common::startup::start_up_record(m, &[("Fc_piston", fcp)], &[])
}

fn diagnose_options() -> stirling::models::diagnose::DiagnoseOptions {
    stirling::models::diagnose::DiagnoseOptions {
        effects: Some(["coulomb", "sensor_lag"].map(String::from).to_vec()),
        bootstrap: 200,
        fit_all: true,
        ..Default::default()
    }
}

/// The diagnosis on the engine's own sensors names a withheld Coulomb friction on its
/// piston (the effect the engine's augmented member declares with `effect` items on both
/// bodies), and finds no significant gap on a clean record. A 2 s start-up record: the
/// amplitude grows, which is what tells Coulomb friction (its equivalent damping falls with
/// amplitude) from the viscous `bp` that absorbs it on a record at steady amplitude (1 s
/// after 0.1 s of settling: not significant, `bp` moved x5.8); seeds 5 and 6 both give
/// `coulomb` (p = 1e-8 and 2e-14, closure 0.92 and 0.86) and a clean `no_significant_gap`.
#[test]
fn the_diagnosis_names_withheld_piston_friction_and_passes_a_clean_record() {
    use stirling::models::diagnose::diagnose;
    let (m, p0, rec) = fx_record(0.5);
    let d = diagnose(&m, &p0, &rec, &diagnose_options()).expect("diagnosed");
    eprintln!(
        "friction: {} {:?} ({})",
        d.verdict.verdict, d.verdict.effect, d.verdict.reason
    );
    assert_eq!(d.verdict.verdict, "effect", "{}", d.verdict.reason);
    assert_eq!(d.verdict.effect.as_deref(), Some("coulomb"));
    // the candidate is the engine's own: its parameters are those its `effect` items declare,
    // and the fit puts the friction on the piston
    let entry = d.ranking.iter().find(|e| e.effect == "coulomb").unwrap();
    let at = |name: &str| {
        entry
            .params
            .iter()
            .find(|q| q.name == name)
            .map(|q| q.value)
    };
    let (on_piston, on_displacer) = (at("Fc_piston").unwrap(), at("Fc_displacer").unwrap());
    eprintln!("Fc_piston {on_piston}, Fc_displacer {on_displacer}");
    assert!(
        (0.25..1.0).contains(&on_piston),
        "Fc_piston {on_piston} (truth 0.5)"
    );
    assert!(
        on_displacer.abs() < 0.5 * on_piston,
        "Fc_displacer {on_displacer}"
    );
    let (m, p0, rec) = fx_record(0.0);
    let d = diagnose(&m, &p0, &rec, &diagnose_options()).expect("diagnosed");
    common::verdict::assert_verdict(&d, "clean", "no_significant_gap", None);
}

/// The command line serves the engine once a binary registers it (as a user's crate would:
/// `user_models::register`, then `stirling_cli::main()`): `stirling models` lists it,
/// `stirling rig` measures it with its declared sensors and an effect its augmented member
/// declares, `stirling fit` fits it from that CSV and `stirling diagnose` reports the
/// withheld piston friction in report.md.
#[test]
fn the_command_line_fits_and_diagnoses_the_registered_engine() {
    use stirling::models::user_models::{register, UserModel};
    register(UserModel {
        name: "alternator_engine",
        summary: "closed bounce space, linear alternator (examples/custom_topology.rs)",
        has_array: true,
        build: |n, c| Ok(Box::new(AlternatorEngine::new(n, c)?)),
        augmented: Some(|n, c| Ok(Box::new(ex::AlternatorFx::new(n, c)?))),
    })
    .expect("registered");
    let dir = std::env::temp_dir().join(format!("stirling_cli_user_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("alternator.csv");
    let run = |args: &[&str]| {
        stirling_cli::run_args(std::iter::once("stirling").chain(args.iter().copied()))
    };
    run(&["models"]).expect("models");
    // the rig measures it with its declared sensors and the friction the member declares
    let rig = [
        "rig",
        "alternator_engine",
        "--n",
        "2",
        "--effect",
        "Fc_piston=0.5",
        "--t-end",
        "2",
    ];
    let chans = [
        "--rate",
        "1000",
        "--seed",
        "5",
        "--channels",
        "p,x,y,p_bounce",
        "--force",
    ];
    let out = ["--out", csv.to_str().unwrap()];
    run(&[&rig[..], &chans[..], &out[..]].concat()).expect("rig");
    let rec = stirling::models::data::read_csv(&csv).unwrap();
    assert_eq!(rec.channels(), ["p", "x", "y", "p_bounce"]);
    // the record the library's rig gives with the same settings and seed
    let lib = fx_record(0.5).2;
    let (a, b) = (
        rec.channel("p_bounce").unwrap(),
        lib.channel("p_bounce").unwrap(),
    );
    assert!(
        (a[500] - b[500]).abs() < 1e-6 * b[500],
        "{} {}",
        a[500],
        b[500]
    );
    let plot = dir.join("fit.svg");
    let (c, p) = (csv.to_str().unwrap(), plot.to_str().unwrap());
    run(&[
        "fit",
        "alternator_engine",
        "--n",
        "2",
        "--data",
        c,
        "--plot",
        p,
        "--force",
    ])
    .expect("fit");
    assert!(
        std::fs::metadata(&plot).unwrap().len() > 1000,
        "fit figure written"
    );
    let report = dir.join("report");
    let r = report.to_str().unwrap();
    let args = ["diagnose", "alternator_engine", "--n", "2", "--data", c];
    let opts = [
        "--effects",
        "coulomb,sensor_lag",
        "--fit-all",
        "--report",
        r,
        "--force",
    ];
    run(&[&args[..], &opts[..]].concat()).expect("diagnose");
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains("**Verdict: effect (`coulomb`)**"), "{md}");
    // a name nobody registered lists the registered ones
    let err = run(&["fit", "alternator", "--data", c])
        .unwrap_err()
        .to_string();
    assert!(err.contains("registered model: alternator_engine"), "{err}");
}
