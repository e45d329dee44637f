//! `stirling rig`: the virtual test rig (truth model + effects + sensor noise and offsets).

use std::path::PathBuf;

use std::io::Write;

use clap::Args;
use stirling_models::rig::{self, RigConfig};

use crate::common::{self, ranges};

/// Arguments of `stirling rig`.
#[derive(Args, Debug)]
pub struct RigArgs {
    /// Base model: cv1, nsection or nsection_ext (nsection with wall states and the orifice leak; aliases order5, order7, order8), or an engine file `engine.stirling` (also --model FILE)
    pub model: String,
    /// Effect or effect parameter, e.g. --effect leak=2e-8 --effect xmax=0.004 (repeatable);
    /// effects: leak, coulomb, regen_quadratic, end_stops, sensor_lag, sensor_gain; on nsection_ext also matrix_capacity, heater_input, orifice_leak
    #[arg(long = "effect", value_name = "NAME=VALUE")]
    pub effect: Vec<String>,
    /// Truth model outside the effect library instead of the augmented member (nsection
    /// only; the diagnosis does not know it): h_speed (strength --set chv=..., s/m) or
    /// spring_cubic (--set k3=..., N/m^3)
    #[arg(long)]
    pub truth: Option<String>,
    /// The truth's parameters: sections, file, overrides
    #[command(flatten)]
    pub with: crate::common::ParamArgs,
    /// Record length (s)
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub t_end: f64,
    /// Simulated time discarded before the record starts (s)
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub settle: f64,
    /// Sample rate (Hz)
    #[arg(long, default_value_t = 2000.0, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub rate: f64,
    /// Pressure noise standard deviation (Pa)
    #[arg(long, default_value_t = 50.0, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub noise_p: f64,
    /// Position noise standard deviation (m)
    #[arg(long, default_value_t = 20e-6, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub noise_x: f64,
    /// Noise standard deviation of one channel, in its unit: overrides --noise-p/--noise-x, and
    /// gives the level of a declared sensor in another unit, e.g. --noise emf=0.05 (repeatable)
    #[arg(long, value_name = "CHANNEL=SD", value_parser = ranges::channel_noise)]
    pub noise: Vec<(String, f64)>,
    /// Pressure sensor offset (Pa), on p and p_hot
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub offset_p: f64,
    /// Displacer position sensor offset (m)
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub offset_x: f64,
    /// Piston position sensor offset (m)
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub offset_y: f64,
    /// Initial displacer displacement from rest (m)
    #[arg(long, default_value_t = 2e-3, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub x0: f64,
    /// Starting value of a state by name, set after the rest state and the --x0 kick, e.g.
    /// --start omega=18: a push start of a kinematic engine's flywheel (rad/s; repeatable)
    #[arg(long, value_name = "STATE=VALUE", allow_hyphen_values = true, value_parser = ranges::state_value)]
    pub start: Vec<(String, f64)>,
    /// Noise seed
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = ranges::seed)]
    pub seed: u64,
    /// Channels to write besides t: the seed's sensors p (cold side), x, y by default (on a
    /// kinematic engine, its state channels: p and the flywheel's angle, e.g. p,theta); add
    /// p_hot (hot-side pressure, multi-CV models) for a richer rig than the seed's engine had
    #[arg(long, value_delimiter = ',')]
    pub channels: Option<Vec<String>>,
    /// Output CSV (the truth goes to FILE.truth.json)
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite existing files
    #[arg(long)]
    pub force: bool,
    /// Machine-readable summary
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &RigArgs) -> anyhow::Result<()> {
    let name = |s: &String| s.split('=').next().unwrap_or("").trim().to_string();
    let mut noise = a.noise.clone();
    let channels = match &a.channels {
        Some(c) => c.clone(),
        None => {
            let (channels, angle) = default_channels(&a.model, a.with.n);
            // the angle's noise in rad, when not given: an encoder's 0.1 degree
            if let Some(angle) = angle.filter(|n| !noise.iter().any(|(c, _)| c == n)) {
                noise.push((angle, ANGLE_NOISE));
            }
            channels
        }
    };
    common::unique("--channels", &channels, |c| c.trim().to_string())?;
    common::unique("--effect", &a.effect, name)?;
    common::unique("--noise", &a.noise, |(c, _)| c.clone())?;
    common::unique("--start", &a.start, |(c, _)| c.clone())?;
    let cfg = RigConfig {
        model: a.model.clone(),
        n: a.with.n,
        params: a.with.params.clone(),
        set: a.with.set.clone(),
        effects: a.effect.clone(),
        t_end: a.t_end,
        settle: a.settle,
        rate: a.rate,
        noise_p: a.noise_p,
        noise_x: a.noise_x,
        noise,
        offset_p: a.offset_p,
        offset_x: a.offset_x,
        offset_y: a.offset_y,
        x0: a.x0,
        start: a.start.clone(),
        seed: a.seed,
        channels,
        truth: a.truth.clone(),
    };
    // refuse before the (long) simulation
    // both files of the pair: a folder in the sidecar's place would leave the record alone
    for f in [a.out.clone(), rig::sidecar_path(&a.out)] {
        if f.is_dir() {
            anyhow::bail!(
                "`{}` is a folder: the record and its truth sidecar ({}) must both be files; \
                 choose another --out or move the folder",
                f.display(),
                rig::sidecar_path(&a.out).display()
            );
        }
        if f.exists() && !a.force {
            anyhow::bail!("`{}` exists: pass --force to overwrite", f.display());
        }
    }
    let out = rig::run(&cfg)?;
    if let Some(dir) = a.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("cannot create `{}`: {e}", dir.display()))?;
    }
    let side = rig::write(&out, &a.out, a.force)?;
    let mut o = crate::common::stdout();
    if a.json {
        writeln!(
            o,
            "{}",
            serde_json::json!({ "csv": a.out, "truth": side, "samples": out.data.len(), "channels": out.data.channels(), "model": out.truth.model, "active_effects": out.truth.active_effects })
        )?;
    } else {
        writeln!(
            o,
            "wrote {} ({} samples, channels t,{}) and {}; truth model {} with effects: {}",
            a.out.display(),
            out.data.len(),
            out.data.channels().join(","),
            side.display(),
            out.truth.model,
            if out.truth.active_effects.is_empty() {
                "none".to_string()
            } else {
                out.truth.active_effects.join(", ")
            }
        )?;
    }
    Ok(())
}

/// The noise of a kinematic engine's angle channel when `--channels` and `--noise` leave it
/// to the rig (rad): an encoder's resolution, 0.1 degree.
const ANGLE_NOISE: f64 = 0.002;

/// The channels a rig record of `model` carries when `--channels` is not given: the seed's
/// `p, x, y`, or on a kinematic engine (a flywheel drives its cranks, so it has no free body
/// `x`, `y`) the pressure and the flywheel's angle, what its fit and diagnosis read (the
/// angle's name returned too).
fn default_channels(model: &str, n: Option<usize>) -> (Vec<String>, Option<String>) {
    let seed = || (["p", "x", "y"].map(String::from).to_vec(), None);
    // a model that does not build is refused by the rig itself, with its own message
    let Ok(m) = stirling_models::effects::augmented(model, n, stirling_dsl::Closure::Full) else {
        return seed();
    };
    let wheels = stirling_models::layout::StateLayout::flywheels(m.as_ref());
    match wheels.first() {
        Some(&(angle, _)) => {
            let name = m.state_names()[angle].clone();
            (vec!["p".into(), name.clone()], Some(name))
        }
        None => seed(),
    }
}
