//! Two-stage identification on rig data from `nsection` n = 2 with perturbed parameters and noise.

use stirling::dsl::Closure;
use stirling::models::fit::{self, FitOptions};
use stirling::models::rig::{self, RigConfig};

#[test]
fn nsection2_two_stage_recovers_perturbed_parameters() {
    let truth = [
        "kd=680", "kp=58", "bd=0.55", "bp=8.4", "hh=560", "hk=450", "Rf=1.3e5",
    ];
    let cfg = RigConfig {
        model: "nsection".into(),
        channels: ["p", "p_hot", "x", "y"].map(String::from).to_vec(),
        n: Some(2),
        set: truth.iter().map(|s| s.to_string()).collect(),
        t_end: 0.8,
        settle: 0.4,
        rate: 2000.0,
        noise_p: 50.0,
        noise_x: 20e-6,
        offset_p: 300.0,
        offset_x: 1.5e-3,
        offset_y: -2e-3,
        seed: 11,
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    let model = stirling::models::build("nsection", Some(2), Closure::Full).unwrap();
    let p0 = model.default_params();
    let opts = FitOptions {
        free: Some(
            ["kd", "kp", "bd", "bp", "hh", "hk", "Rf"]
                .iter()
                .map(|s| s.to_string())
                .collect(),
        ),
        ..Default::default()
    };
    let res = fit::identify(model.as_ref(), &p0, &out.data, &opts).unwrap();
    eprintln!("total {:.2} s", res.seconds);
    for st in [res.stage1.as_ref().unwrap(), res.stage2.as_ref().unwrap()] {
        eprintln!(
            "{}: {} it, converged {}, s2 = {:.3}",
            st.stage, st.iterations, st.converged, st.stats.sigma2
        );
        for e in &st.stats.estimates {
            eprintln!(
                "  {:<12} {:>13.6e} +- {:.2e}  [{:.6e}, {:.6e}]",
                e.name, e.value, e.std_error, e.ci_low, e.ci_high
            );
        }
        for f in &st.fits {
            eprintln!("  fit {} {} {:.2} %", f.channel, f.block, f.fit_percent);
        }
        for w in &st.stats.warnings {
            eprintln!("  warning: {w}");
        }
    }
    for s in truth {
        let (k, v) = s.split_once('=').unwrap();
        let v: f64 = v.parse().unwrap();
        let e = res
            .stage1
            .as_ref()
            .and_then(|s| s.estimate(k))
            .or_else(|| res.stage2.as_ref().and_then(|s| s.estimate(k)))
            .unwrap();
        assert!(
            e.covers(v),
            "{k}: truth {v} outside [{}, {}]",
            e.ci_low,
            e.ci_high
        );
    }
    let p_off = res.stage2.as_ref().unwrap().estimate("p_offset").unwrap();
    // the pressure offset is coupled to the position offsets through the static shift
    // (1 Pa moves the piston ~0.2 mm) and stage 2 does not yet carry the stage-1 offset
    // uncertainty, so its interval is too narrow: only a loose check here
    assert!((p_off.value - 300.0).abs() < 30.0, "p offset {p_off:?}");
    for st in [res.stage1.as_ref().unwrap(), res.stage2.as_ref().unwrap()] {
        for f in st.fits.iter().filter(|f| f.block == "holdout") {
            assert!(
                f.fit_percent > 90.0,
                "{} holdout fit {:.2} %",
                f.channel,
                f.fit_percent
            );
        }
    }
}
