//! The gamma LTD's p-V loop from a lab record (docs/custom-topologies.md section 13, "Worked
//! example"): the rig records the engine of `examples/engines/gamma_ltd.stirling` with a
//! truth off the defaults (`Rf` 2e4, `Gleak` 1.2e-9) as a data logger would (`t [ms]`,
//! `p [kPa gauge]`, `theta [deg]` wrapping at a revolution, 100 Hz, 10 Pa pressure noise,
//! 2 mrad angle noise); the record is written, read back through the CSV reader and fitted
//! (`hp`, `hs`, `Rf`, `Gleak` free, from the defaults). Drawn over the held-out block:
//! `pv_loop.svg`, the measured p-V loop (points; the volume is the model's working-gas volume
//! at the measured angle) and the fitted model's (line), and `pv_difference.svg`, the pressure
//! difference (model - record) against the crank angle, with the noise level.
//!
//! Run: `cargo run --release --example kinematic_pv -- --out target/kinematic_pv`
//! (`--force` overwrites the figures; `--seconds S` sets the record's length, 10 s).

use std::error::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use stirling::dsl::{Closure, Model};
use stirling::models::data::{parse_csv, units::AMBIENT, Measured};
use stirling::models::files;
use stirling::models::fit::{self, FitOptions, Identification};
use stirling::models::plot::pv_record::{difference_by_angle_svg, pv_loops_svg, Loop};
use stirling::models::rig::{measure, RigConfig};
use stirling::models::signal::noise_sigma;
use stirling::models::sim::indicated::{
    volume_at_angles, volume_slope_at_angles, whole_revolutions, work_per_revolution,
};

/// The figures written into `--out`.
pub const FIGURES: [&str; 2] = ["pv_loop.svg", "pv_difference.svg"];
/// The record written into `--out` as a lab would, and read back.
pub const RECORD: &str = "gamma_record.csv";
/// The free parameters.
pub const FREE: [&str; 4] = ["hp", "hs", "Rf", "Gleak"];
/// The truth: parameters changed from the defaults.
pub const TRUTH: [(&str, f64); 2] = [("Rf", 2e4), ("Gleak", 1.2e-9)];
/// The rig's pressure noise (Pa, 1 sd).
pub const NOISE_P: f64 = 10.0;

#[derive(Clone, Debug)]
pub struct Args {
    pub out: PathBuf,
    pub force: bool,
    /// Record length after settling (s).
    pub seconds: f64,
}

const USAGE: &str = "usage: kinematic_pv --out DIR [--force] [--seconds S]";

/// Parse `--out DIR`, `--force`, `--seconds S`.
pub fn parse_args<I: IntoIterator<Item = String>>(args: I) -> Result<Args, String> {
    let (mut out, mut force, mut seconds) = (None, false, 10.0);
    let mut it = args.into_iter();
    while let Some(flag) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .ok_or_else(|| format!("{name} needs a value\n{USAGE}"))
        };
        match flag.as_str() {
            "--out" => out = Some(PathBuf::from(value("--out")?)),
            "--force" => force = true,
            "--seconds" => {
                let v = value("--seconds")?;
                seconds = v
                    .parse::<f64>()
                    .ok()
                    .filter(|s| s.is_finite() && (2.0..=120.0).contains(s))
                    .ok_or_else(|| {
                        format!("--seconds: `{v}` is not a length from 2 to 120 s\n{USAGE}")
                    })?;
            }
            "-h" | "--help" => return Err(USAGE.to_string()),
            other => return Err(format!("unknown argument `{other}`\n{USAGE}")),
        }
    }
    let out = out.ok_or_else(|| format!("--out DIR is required\n{USAGE}"))?;
    Ok(Args {
        out,
        force,
        seconds,
    })
}

/// The loop of the record and of the model over the held-out block's whole revolutions.
pub struct Summary {
    pub id: Identification,
    /// Truth of the free parameters, by name.
    pub truth: Vec<(String, f64)>,
    /// Indicated work per revolution (J) of the record and of the model, and the revolutions.
    pub work_record: f64,
    pub work_model: f64,
    /// The truth's, from the rig's run without noise over the same samples (J).
    pub work_truth: f64,
    pub revolutions: usize,
    /// The noise level of the recorded pressure (Pa, from its third differences).
    pub noise: f64,
    /// RMS of model - record over the held-out block (Pa).
    pub rms_difference: f64,
    pub files: Vec<PathBuf>,
}

/// The gamma LTD from its file.
pub fn gamma() -> Result<Box<dyn Model>, Box<dyn Error>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/engines/gamma_ltd.stirling");
    Ok(files::build(&path, 1, Closure::Full)?)
}

/// The record as a lab writes it: time in ms, gauge pressure in kPa, the angle in degrees
/// from a counter that wraps at a revolution.
pub fn lab_csv(rec: &Measured, angle: &str) -> Result<String, Box<dyn Error>> {
    let (p, th) = match (rec.p.as_ref(), rec.channel(angle)) {
        (Some(p), Some(th)) => (p, th),
        _ => return Err(format!("the rig's record lacks `p` or `{angle}`").into()),
    };
    let mut s = format!("# gamma LTD on the rig\nt [ms],p [kPa gauge],{angle} [deg]\n");
    for ((t, p), a) in rec.t.iter().zip(p).zip(th) {
        let deg = a.to_degrees().rem_euclid(360.0);
        writeln!(s, "{:.1},{:.4},{deg:.2}", 1e3 * t, 1e-3 * (p - AMBIENT))?;
    }
    Ok(s)
}

/// Rig, write, read back, fit, measure the loops, draw the figures into `args.out`.
pub fn run(args: &Args) -> Result<Summary, Box<dyn Error>> {
    let paths: Vec<PathBuf> = FIGURES.iter().map(|f| args.out.join(f)).collect();
    let csv_path = args.out.join(RECORD);
    if !args.force {
        if let Some(p) = paths.iter().chain([&csv_path]).find(|p| p.exists()) {
            return Err(format!("{} exists: pass --force to overwrite it", p.display()).into());
        }
    }
    let model = gamma()?;
    let m = model.as_ref();
    let mut truth = m.default_params();
    for (name, v) in TRUTH {
        let j = m
            .param_index(name)
            .ok_or(format!("no parameter `{name}`"))?;
        truth[j] = v;
    }
    let cfg = RigConfig {
        t_end: args.seconds,
        settle: 5.0,
        rate: 100.0,
        noise_p: NOISE_P,
        start: vec![("omega".into(), 17.7)],
        noise: vec![("theta".into(), 0.002)],
        channels: vec!["p".into(), "theta".into()],
        seed: 7,
        ..Default::default()
    };
    let raw = measure(m, &truth, &cfg)?;
    let angle = stirling::models::sim::indicated::angle_state(m)?;
    let angle_name = m.state_names()[angle].clone();
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("cannot create {}: {e}", args.out.display()))?;
    let text = lab_csv(&raw, &angle_name)?;
    std::fs::write(&csv_path, &text)
        .map_err(|e| format!("cannot write {}: {e}", csv_path.display()))?;
    // read back as any lab record: units to SI, the wrapping angle unwrapped
    let mut rec = parse_csv(&csv_path.display().to_string(), &text)?;
    fit::kinematic::unwrap_angle(m, &mut rec);
    let opts = FitOptions {
        free: Some(FREE.map(String::from).to_vec()),
        ..Default::default()
    };
    let id = fit::identify(m, &m.default_params(), &rec, &opts)?;
    let fitted: Vec<f64> = id.params.iter().map(|(_, v)| *v).collect();
    let s2 = id.stage2.as_ref().ok_or("the fit ran no stage 2")?;
    let series = s2
        .series
        .iter()
        .find(|s| s.channel == "p")
        .ok_or("the fit has no series of `p`")?;
    let (h0, h1) = id.holdout.ok_or("the fit has no held-out block")?;
    // the held-out samples of the series, and the record's angle at them
    let theta = rec
        .channel(&angle_name)
        .ok_or("the record lost its angle")?;
    let dt = rec.dt();
    let (mut th, mut idx) = (Vec::new(), Vec::new());
    let (mut pm, mut pf) = (Vec::new(), Vec::new());
    for (k, &t) in series.t.iter().enumerate() {
        if t < h0 - 0.5 * dt || t > h1 + 0.5 * dt {
            continue;
        }
        let i = ((t - rec.t[0]) / dt).round() as usize;
        let a = theta
            .get(i)
            .copied()
            .ok_or("the series outruns the record")?;
        th.push(a);
        idx.push(i);
        pm.push(series.measured[k]);
        pf.push(series.model[k]);
    }
    // the volume at the measured angle, in the fitted model (the volume depends on no
    // fitted parameter; the model's own expressions)
    let v = volume_at_angles(m, &fitted, &th)?;
    let dv = volume_slope_at_angles(m, &fitted, &th)?;
    let (work_record, revolutions) = work_per_revolution(&th, &dv, &pm)?;
    let (work_model, _) = work_per_revolution(&th, &dv, &pf)?;
    // the truth's loop over the same samples: the rig's run without its noise
    let clean_cfg = RigConfig {
        noise_p: 0.0,
        noise: vec![("theta".into(), 0.0)],
        ..cfg.clone()
    };
    let clean = measure(m, &truth, &clean_cfg)?;
    let (Some(cp), Some(ct)) = (clean.p.as_ref(), clean.channel(&angle_name)) else {
        return Err("the noise-free record lacks `p` or the angle".into());
    };
    let at = |v: &[f64]| -> Result<Vec<f64>, String> {
        idx.iter()
            .map(|&i| {
                v.get(i)
                    .copied()
                    .ok_or("the records differ in length".to_string())
            })
            .collect()
    };
    let (tc, pc) = (at(ct)?, at(cp)?);
    let (work_truth, _) = work_per_revolution(&tc, &volume_slope_at_angles(m, &truth, &tc)?, &pc)?;
    // the figures show those whole revolutions
    let (_, end) = whole_revolutions(&th)?;
    let (th, v, pm, pf) = (&th[..end], &v[..end], &pm[..end], &pf[..end]);
    let diff: Vec<f64> = pf.iter().zip(pm.iter()).map(|(a, b)| a - b).collect();
    let noise = noise_sigma(pm);
    let rms_difference = (diff.iter().map(|d| d * d).sum::<f64>() / diff.len() as f64).sqrt();
    let to_plot = |p: &[f64]| -> Vec<(f64, f64)> {
        v.iter()
            .zip(p)
            .map(|(v, p)| (1e6 * v, 1e-3 * (p - AMBIENT)))
            .collect()
    };
    let (lm, lf) = (to_plot(pm), to_plot(pf));
    let label_m = format!("record: W = {:.3} mJ per revolution", 1e3 * work_record);
    let label_f = format!(
        "fitted model: W = {:.3} mJ per revolution",
        1e3 * work_model
    );
    pv_loops_svg(
        &paths[0],
        &format!("gamma LTD: p-V loop, held-out block ({revolutions} revolutions)"),
        &Loop {
            label: &label_m,
            points: &lm,
        },
        &Loop {
            label: &label_f,
            points: &lf,
        },
        end / revolutions,
    )?;
    let deg: Vec<f64> = th.iter().map(|a| a.to_degrees()).collect();
    difference_by_angle_svg(
        &paths[1],
        &format!("gamma LTD: fitted model - record, held-out block ({revolutions} revolutions)"),
        &deg,
        &diff,
        noise,
        36,
    )?;
    let truth = FREE
        .iter()
        .filter_map(|n| m.param_index(n).map(|j| (n.to_string(), truth[j])))
        .collect();
    Ok(Summary {
        id,
        truth,
        work_record,
        work_model,
        work_truth,
        revolutions,
        noise,
        rms_difference,
        files: paths,
    })
}

fn main() {
    let args = match parse_args(std::env::args().skip(1)) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    match run(&args) {
        Ok(s) => print(&s),
        Err(e) => {
            eprintln!("kinematic_pv: {e}");
            std::process::exit(1);
        }
    }
}

fn print(s: &Summary) {
    println!("fitted in {:.2} s", s.id.seconds);
    println!("parameter    truth       estimate    95 % interval");
    for (name, t) in &s.truth {
        if let Some(e) = s.id.estimate(name) {
            println!(
                "{name:<8} {t:>11.4e} {:>11.4e}  [{:.4e}, {:.4e}]",
                e.value, e.ci_low, e.ci_high
            );
        }
    }
    if let Some(s2) = &s.id.stage2 {
        if !s2.converged {
            println!(
                "warning: {} did not converge in {} iterations: the estimates are not an optimum",
                s2.stage, s2.iterations
            );
        }
        for block in ["train", "holdout"] {
            if let Some(f) = s2.fit_percent("p", block) {
                println!("fit of p on the {block} block: {f:.2} %");
            }
        }
    }
    println!(
        "indicated work per revolution over {} held-out revolutions: record {:.4} mJ, model \
         {:.4} mJ, model / record {:.4}",
        s.revolutions,
        1e3 * s.work_record,
        1e3 * s.work_model,
        s.work_model / s.work_record
    );
    println!(
        "the truth's (the rig's run without noise, same samples): {:.4} mJ, record / truth {:.4}",
        1e3 * s.work_truth,
        s.work_record / s.work_truth
    );
    println!(
        "model - record: rms {:.2} Pa; the record's noise {:.2} Pa",
        s.rms_difference, s.noise
    );
    for f in &s.files {
        println!("wrote {}", f.display());
    }
}
