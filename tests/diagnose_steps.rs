//! The stepwise diagnosis on records that carry two library effects at once (`nsection`
//! n = 2, the seed's sensors `p`, `x`, `y`): the verdict a user reads names both effects
//! and nothing else, with the steps that named them; a clean record still gives
//! `no_significant_gap` and names nothing. The wider self-check (every pair) is in
//! docs/diagnosis.md, "Several effects at once".

use stirling::models::diagnose::selfcheck::plan::plan;
use stirling::models::diagnose::selfcheck::record::{record, seeded_start, through_csv};
use stirling::models::diagnose::selfcheck::{settings, verdict_settings};
use stirling::models::diagnose::selfcheck::{Split, VerdictOptions};
use stirling::models::diagnose::{diagnose, nominal_model, DiagnoseOptions, Diagnosis};
use stirling::models::rig::{self, RigConfig};

/// A 2 s record at 1 kHz with `effects` (each at `m` times its self-check unit) diagnosed
/// over `candidates` from a perturbed start.
fn diagnosed(effects: &[&str], m: f64, seed: u64, candidates: &[&str]) -> Diagnosis {
    diagnosed_at(1000.0, effects, m, seed, candidates)
}

/// [`diagnosed`] on a record sampled at `rate`.
fn diagnosed_at(rate: f64, effects: &[&str], m: f64, seed: u64, candidates: &[&str]) -> Diagnosis {
    let settings = effects
        .iter()
        .flat_map(|e| verdict_settings(e, m))
        .collect();
    diagnosed_with(rate, settings, seed, candidates)
}

/// A 2 s record sampled at `rate` with the rig settings `effects`, diagnosed over
/// `candidates` from a perturbed start.
fn diagnosed_with(rate: f64, effects: Vec<String>, seed: u64, candidates: &[&str]) -> Diagnosis {
    let cfg = RigConfig {
        model: "nsection".into(),
        n: Some(2),
        t_end: 2.0,
        settle: 0.1,
        rate,
        seed,
        channels: ["p", "x", "y"].map(String::from).to_vec(),
        effects,
        ..Default::default()
    };
    let dir = tempdir(seed);
    let data = through_csv(rig::run(&cfg).unwrap(), &dir, 0, false).unwrap();
    let (model, p_nom) = nominal_model("nsection", Some(2)).unwrap();
    let p0 = seeded_start(model.as_ref(), &p_nom, 0.08, seed ^ 0x5EED);
    let opts = DiagnoseOptions {
        effects: Some(candidates.iter().map(|s| s.to_string()).collect()),
        bootstrap: 200,
        progress: Some(|line: &str| eprintln!("  .. {line}")),
        ..Default::default()
    };
    let d = diagnose(model.as_ref(), &p0, &data, &opts).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!(
        "{:?}: {} {:?} remainder {} ({}) in {:.1} s",
        cfg.effects,
        d.verdict.verdict,
        d.verdict.effects,
        d.verdict.unexplained_remainder,
        d.verdict.reason,
        d.seconds
    );
    d
}

/// The self-check's evaluation case `label` of the plan of `opts`, recorded and diagnosed as
/// the self-check does it (its seeded start, its options); `tag` keeps its folder apart.
fn diagnosed_case(opts: &VerdictOptions, label: &str, tag: u64) -> Diagnosis {
    let case = plan(opts)
        .unwrap()
        .into_iter()
        .find(|c| c.split == Split::Eval && c.truth.label() == label)
        .unwrap();
    let dir = tempdir(case.seed ^ tag);
    let data = record(opts, &case, &dir).unwrap();
    let (model, p_nom) = nominal_model("nsection", Some(2)).unwrap();
    let p0 = seeded_start(model.as_ref(), &p_nom, opts.perturb, case.perturb_seed);
    let d = diagnose(model.as_ref(), &p0, &data, &opts.diagnose).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!("{}: {}", d.verdict.verdict, d.verdict.reason);
    d
}

fn tempdir(seed: u64) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("stirling-steps-{}-{seed}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The named effects as a sorted set.
fn named(d: &Diagnosis) -> Vec<String> {
    let mut v = d.verdict.effects.clone();
    v.sort();
    v
}

/// The step's estimate of `name` has an interval covering `truth`.
fn assert_covers(step: &stirling::models::diagnose::types::Step, name: &str, truth: f64) {
    let q = step.params.iter().find(|q| q.name == name).unwrap();
    assert!(
        q.ci_low < truth && truth < q.ci_high,
        "{name} {:.4e} [{:.4e}, {:.4e}] misses {truth:e}",
        q.value,
        q.ci_low,
        q.ci_high
    );
}

/// The steps' record is whole: numbered from 1, each with its closure inside its interval,
/// the cumulative closure growing, every named effect's parameters estimated.
fn check_steps(d: &Diagnosis) {
    assert!(!d.steps.is_empty());
    let mut last = f64::NEG_INFINITY;
    for (k, s) in d.steps.iter().enumerate() {
        assert_eq!(s.step, k + 1);
        assert!(s.closure.ci_low <= s.closure.value && s.closure.value <= s.closure.ci_high);
        // a partner named from the one-run pass adds nothing to the restarted pass's
        // cumulative closure (`diagnose::partner`)
        assert!(
            s.cumulative.value > last || s.one_run && s.cumulative.value == last,
            "cumulative closure must grow"
        );
        last = s.cumulative.value;
        assert!(s.params.iter().all(|q| q.value.is_finite()));
        assert_eq!(s.channels.len(), 3);
    }
    let json = serde_json::to_value(d).unwrap();
    assert_eq!(
        json["verdict"]["effects"].as_array().unwrap().len(),
        d.verdict.effects.len()
    );
    assert_eq!(json["steps"].as_array().unwrap().len(), d.steps.len());
}

#[test]
fn coulomb_friction_and_a_leak_are_both_named() {
    let d = diagnosed(
        &["coulomb", "leak"],
        1.0,
        41,
        &["coulomb", "leak", "sensor_gain"],
    );
    assert_eq!(d.verdict.verdict, "effect", "{}", d.verdict.reason);
    assert_eq!(named(&d), ["coulomb", "leak"], "{}", d.verdict.reason);
    check_steps(&d);
    // the leak's conductance is recovered within its interval's reach (truth 1e-8)
    let g = d
        .steps
        .last()
        .unwrap()
        .params
        .iter()
        .find(|q| q.name == "Gleak")
        .unwrap();
    assert!((g.value / 1e-8 - 1.0).abs() < 0.3, "Gleak {:e}", g.value);
}

#[test]
fn a_leak_beside_a_position_gain_is_named_with_it() {
    // the gain, estimated in the gas stage, alone takes the leak's loss of pressure
    // amplitude (`gain_x` near 20 % for 5 %) and leaves the leak's score near its null; the
    // pair tried with the leading gain closes most of what the gain leaves
    // (`pairs::absorbing_pair`, docs/diagnosis.md "A position gain estimated where it is seen")
    let d = diagnosed_at(
        2000.0,
        &["leak", "sensor_gain"],
        1.0,
        1005,
        &["leak", "sensor_gain", "regen_quadratic"],
    );
    assert_eq!(d.verdict.verdict, "effect", "{}", d.verdict.reason);
    assert_eq!(named(&d), ["leak", "sensor_gain"], "{}", d.verdict.reason);
    check_steps(&d);
    let c = d.steps.last().unwrap().cumulative;
    assert!(c.ci_low > 0.5, "cumulative closure {c:?}");
}

#[test]
fn quadratic_regenerator_friction_and_a_pressure_lag_are_both_named() {
    let d = diagnosed(
        &["regen_quadratic", "sensor_lag"],
        1.0,
        42,
        &["regen_quadratic", "sensor_lag", "sensor_gain"],
    );
    assert_eq!(d.verdict.verdict, "effect", "{}", d.verdict.reason);
    assert_eq!(
        named(&d),
        ["regen_quadratic", "sensor_lag"],
        "{}",
        d.verdict.reason
    );
    check_steps(&d);
    let c = d.steps.last().unwrap().cumulative;
    assert!(c.ci_low > 0.5, "cumulative closure {c:?}");
}

#[test]
fn a_leak_the_calibration_absorbed_is_named_after_a_pressure_lag() {
    // the self-check's evaluation record of the pair (`--clean 4:20 --seeds 1:1`, run-h):
    // the calibration takes the leak into the regenerator friction (`Rf` far below its
    // estimate), so after the lag the leak's score is not significant (p 0.026); fitted from
    // the nominal parameters' estimates it lowers the held-out BIC by more than ten times
    // the usual bar (steps::RESET_P, docs/diagnosis.md). On five other records of the pair
    // (seeds 47 to 51 of `diagnosed_at`) the leak stays unnamed: docs/diagnosis.md.
    // The record is that narrow: at the diagnosis's default tolerance (5e-7, the runs twice
    // as fast) the leak's score after the lag moves past the reset start's bar and the verdict
    // is the lag alone (docs/diagnosis.md, "Timing of the steps"); the mechanism is tested at
    // the fit's own tolerance, where it was found (and at 3e-7 it holds too).
    let opts = VerdictOptions {
        clean: (4, 20),
        seeds: (1, 1),
        diagnose: DiagnoseOptions {
            rtol: 1e-7,
            ..Default::default()
        },
        ..Default::default()
    };
    let d = diagnosed_case(&opts, "leak+sensor_lag", 0);
    assert_eq!(d.verdict.verdict, "effect", "{}", d.verdict.reason);
    assert_eq!(named(&d), ["leak", "sensor_lag"], "{}", d.verdict.reason);
    check_steps(&d);
    let last = d.steps.last().unwrap();
    assert_eq!(last.effects, ["leak"]);
    assert!(last.from_reset, "{}", d.verdict.reason);
    assert!(
        d.verdict.reason.contains("had absorbed it"),
        "{}",
        d.verdict.reason
    );
    // the leak's conductance, refitted with the lag, within a factor of 3 of the truth
    // (the self-check's unit: `Gleak` 1e-8)
    let g = last.params.iter().find(|q| q.name == "Gleak").unwrap();
    assert!(
        g.value > 1e-8 / 3.0 && g.value < 3e-8,
        "Gleak {:e}",
        g.value
    );
}

#[test]
fn a_clean_record_names_nothing() {
    let d = diagnosed(
        &[],
        1.0,
        43,
        &["coulomb", "leak", "sensor_gain", "sensor_lag"],
    );
    assert_eq!(
        d.verdict.verdict, "no_significant_gap",
        "{}",
        d.verdict.reason
    );
    assert!(d.verdict.effects.is_empty() && d.steps.is_empty());
    assert!(!d.verdict.unexplained_remainder);
}

#[test]
fn a_withheld_end_stop_is_named_at_one_and_two_units() {
    // hard stops (the rank check's: 2 mm and 1.1 mm, 87 % of the stroke) take most of the
    // stroke; the calibration absorbs them into a piston spring at 0.02x and the first pass
    // explains nothing: the second pass, stage 1 restarted every quarter cycle, names them
    // (2 kHz, the self-check's rate)
    for (m, seed) in [(1.0, 44), (2.0, 45)] {
        let d = diagnosed_with(
            2000.0,
            settings("end_stops", m),
            seed,
            &["coulomb", "end_stops", "sensor_lag", "sensor_gain"],
        );
        assert_eq!(d.verdict.verdict, "effect", "{m}x: {}", d.verdict.reason);
        assert_eq!(named(&d), ["end_stops"], "{m}x: {}", d.verdict.reason);
        assert!(
            d.verdict.reason.contains("second pass"),
            "{}",
            d.verdict.reason
        );
        check_steps(&d);
    }
}

#[test]
fn end_stops_and_a_pressure_lag_are_both_named() {
    // stops inside the stroke (the verdict check's, 10 mm and 5.5 mm) with a 2 ms lag: the
    // second pass names the stops, then the lag on the restarted basis (truth 2 ms)
    let d = diagnosed_at(
        2000.0,
        &["end_stops", "sensor_lag"],
        1.0,
        46,
        &["coulomb", "end_stops", "sensor_lag", "sensor_gain"],
    );
    assert_eq!(d.verdict.verdict, "effect", "{}", d.verdict.reason);
    assert_eq!(
        named(&d),
        ["end_stops", "sensor_lag"],
        "{}",
        d.verdict.reason
    );
    check_steps(&d);
    let tau = d
        .steps
        .last()
        .unwrap()
        .params
        .iter()
        .find(|q| q.name == "tau_p")
        .unwrap();
    assert!(
        (tau.value / 2e-3 - 1.0).abs() < 0.3,
        "tau_p {:e}",
        tau.value
    );
}

#[test]
fn a_position_gain_is_estimated_where_the_positions_are_read() {
    // position gains of +5 % on both sensors: estimated in the gas stage, which reads the
    // positions, and given to the mechanics stage (a cut estimator, docs/diagnosis.md, "A
    // position gain estimated where it is seen"); fitted with both stages' rows the
    // mechanics stage pulled `gain_x` to -7.3 % and a quadratic regenerator loss was named
    // after it. Now the gain alone, each interval covering the truth
    let d = diagnosed_at(
        2000.0,
        &["sensor_gain"],
        1.0,
        1005,
        &["sensor_gain", "regen_quadratic"],
    );
    assert_eq!(d.verdict.effects, ["sensor_gain"], "{}", d.verdict.reason);
    let step = &d.steps[0];
    for name in ["gain_x", "gain_y"] {
        let q = step.params.iter().find(|q| q.name == name).unwrap();
        assert!(
            q.ci_low < 0.05 && 0.05 < q.ci_high,
            "{name} {:.4} [{:.4}, {:.4}] misses 0.05",
            q.value,
            q.ci_low,
            q.ci_high
        );
    }
    assert!(step.closure.ci_low > 0.9, "{:?}", step.closure);
}

#[test]
fn a_lag_beside_an_outside_cause_is_named_with_the_remainder() {
    // the self-check's mixed record (`--mixed-strength 1`, evaluation seed): a 2 ms lag
    // beside heat transfer that grows with the gas speed (outside the library); the lag
    // closes 0.98 of a gap of some 450 noise variances, no candidate is significant after
    // it, but `p` is still missed by about 4.9 times its noise: the verdict names the lag
    // and says a gap remains (it claimed a full explanation: docs/diagnosis.md)
    let opts = VerdictOptions {
        seeds: (0, 1),
        clean: (0, 0),
        mixed_strength: Some(1.0),
        ..Default::default()
    };
    let d = diagnosed_case(&opts, "sensor_lag+outside:h_speed", 0xA11);
    assert_eq!(d.verdict.effects, ["sensor_lag"], "{}", d.verdict.reason);
    assert!(d.verdict.unexplained_remainder, "{}", d.verdict.reason);
    assert!(
        d.verdict.reason.contains("times the noise"),
        "{}",
        d.verdict.reason
    );
    let last = d.steps.last().unwrap();
    let p = last.channels.iter().find(|c| c.channel == "p").unwrap();
    assert!(p.ratio > 2.0, "{p:?}");
}

#[test]
fn end_stops_beside_a_partner_name_the_quadratic_loss_and_leave_coulomb_as_a_remainder() {
    // the self-check's evaluation records of the stops alone, beside Coulomb friction and
    // beside a quadratic regenerator loss: one run explains nothing; the stops, seen in the
    // measured acceleration, call the restarted pass at their travel, which names them. The
    // quadratic loss is named from the one-run pass (`diagnose::partner`: its score there far
    // beyond what the stops alone give, its fit strongly better on the held-out block; the
    // restarts hide it); Coulomb friction's one-run fit is not better there (it lacks the
    // stops), but its score is beyond anything an absent effect gave: it is named on its
    // score alone, with the remainder said; the stops alone name no partner
    let opts = VerdictOptions::default();
    let partners = [
        ("end_stops", None),
        ("coulomb+end_stops", Some("coulomb")),
        ("end_stops+regen_quadratic", Some("regen_quadratic")),
    ];
    for (label, partner) in partners {
        let d = diagnosed_case(&opts, label, 0x5709);
        assert_eq!(d.verdict.verdict, "effect", "{label}: {}", d.verdict.reason);
        let mut want = vec!["end_stops".to_string()];
        want.extend(partner.map(String::from));
        assert_eq!(d.verdict.effects, want, "{label}: {}", d.verdict.reason);
        check_steps(&d);
        let Some(partner) = partner else {
            assert!(d.steps.iter().all(|s| !s.one_run), "{label}");
            continue;
        };
        let step = d.steps.last().unwrap();
        assert!(step.one_run && step.effects == [partner], "{label}");
        if partner == "coulomb" {
            assert!(d.verdict.unexplained_remainder, "{}", d.verdict.reason);
            assert!(
                d.verdict.reason.contains("on its score alone"),
                "{}",
                d.verdict.reason
            );
            continue;
        }
        // the self-check's unit: `Rq` 1e8 (0.1 of its typical value)
        assert_covers(step, "Rq", 1e8);
        assert!(
            d.verdict.reason.contains("one-run pass"),
            "{}",
            d.verdict.reason
        );
    }
}

#[test]
fn end_stops_beside_a_leak_are_named_from_the_acceleration_and_the_leak_on_the_gas_channel() {
    // the self-check's first evaluation record of the stops beside a leak (seed 1005, the plan
    // of docs/selfcheck-runs' runs): the calibration takes the leak into the regenerator
    // friction, so the leak's score is at its null (p 1.0) and the restarted pass's model
    // with the stops does not close the gap; the stops, seen in the measured acceleration,
    // are named from it, and the leak on the channel they do not touch (`p`, the gas stage
    // driven by the measured positions), with the remainder said (`diagnose::untouched`)
    let opts = VerdictOptions {
        seeds: (1, 2),
        clean: (4, 20),
        ..VerdictOptions::default()
    };
    let d = diagnosed_case(&opts, "end_stops+leak", 0x5711);
    assert_eq!(d.verdict.verdict, "effect", "{}", d.verdict.reason);
    assert_eq!(
        d.verdict.effects,
        ["end_stops", "leak"],
        "{}",
        d.verdict.reason
    );
    assert!(d.verdict.unexplained_remainder, "{}", d.verdict.reason);
    assert!(
        d.verdict.reason.contains("measured acceleration alone"),
        "{}",
        d.verdict.reason
    );
    let (stops, leak) = (&d.steps[0], &d.steps[1]);
    // no simulated closure is claimed for the stops; their travel is the seen one, inside
    // the truth's 4.50 mm by the smoothing's blunting
    assert!(stops.cumulative.value.is_nan() && stops.closure.value.is_nan());
    let travel = stops.params.iter().find(|q| q.name == "travel_y").unwrap();
    assert!((4.2e-3..4.5e-3).contains(&travel.value.abs()), "{travel:?}");
    // the leak on the gas channel: a gap there of some 23 noise variances, closed to the floor
    assert!(
        leak.one_run && leak.closure.ci_low > 0.9,
        "{:?}",
        leak.closure
    );
    let g = leak.params.iter().find(|q| q.name == "Gleak").unwrap();
    assert!((0.7e-8..1.3e-8).contains(&g.value), "{g:?}");
}

#[test]
fn end_stops_beside_a_position_gain_name_the_gain_and_do_not_keep_what_it_superseded() {
    // the self-check's evaluation record of the stops beside a +5 % gain on both positions:
    // the stops are held at the travel seen in the measured acceleration, which the gain
    // scales (`joint::rebase` divides it by `1 + gain`); a quadratic regenerator loss stands
    // in for part of the gain before it is named, and is not kept once the gain is fitted
    // with it (`diagnose::superseded`). The plan of docs/selfcheck-runs' runs (`--seeds 1:2
    // --clean 4:20`): its first evaluation record of the pair (seed 1005)
    let opts = VerdictOptions {
        seeds: (1, 2),
        clean: (4, 20),
        ..VerdictOptions::default()
    };
    let d = diagnosed_case(&opts, "end_stops+sensor_gain", 0x5710);
    assert_eq!(d.verdict.verdict, "effect", "{}", d.verdict.reason);
    assert_eq!(
        named(&d),
        ["end_stops", "sensor_gain"],
        "{}",
        d.verdict.reason
    );
    check_steps(&d);
    let last = d.steps.last().unwrap();
    assert!(last.superseded.is_none() && last.effects == ["sensor_gain"]);
    assert_covers(last, "gain_y", 0.05);
    for s in d.steps.iter().filter(|s| s.superseded.is_some()) {
        assert!(
            d.verdict.reason.contains("not kept"),
            "{}",
            d.verdict.reason
        );
        assert!(!d.verdict.effects.contains(&s.effects[0]));
    }
}
