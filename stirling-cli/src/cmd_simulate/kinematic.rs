//! A kinematic engine's run, read as `stirling simulate` reports it: the speed and indicated
//! power of its last whole revolutions ([`sim::running`]) and Schmidt's isothermal analysis
//! at the gas's cycle-mean temperatures and mass ([`sim::schmidt`]).

use std::io::Write;

use stirling_dsl::Model;
use stirling_models::layout::StateLayout;
use stirling_models::sim::{self, SimSummary, Trajectory};

/// Add the running figures and Schmidt's analysis to `summary` when `model` is a kinematic
/// engine (one flywheel); a run that does not turn gets a note saying how to push it.
pub fn add_running(model: &dyn Model, p: &[f64], tr: &Trajectory, summary: &mut SimSummary) {
    let wheels = StateLayout::flywheels(model);
    let [(_, omega)] = wheels.as_slice() else {
        return;
    };
    let running = match sim::running::running(model, p, &tr.t, &tr.x) {
        Ok(r) => r,
        Err(e) => {
            let name = model.state_names()[*omega].clone();
            summary.running_note = Some(format!(
                "not running: {e}; the figures need two whole revolutions in the run's second half: push the flywheel (--start {name}=6.3) and run longer (--t-end)"
            ));
            return;
        }
    };
    let temps: Vec<f64> = running.temperatures.iter().map(|t| t.1).collect();
    match sim::schmidt::schmidt(model, p, &temps, running.mass) {
        Ok(s) => summary.schmidt = Some(s),
        Err(e) => summary.running_note = Some(format!("no Schmidt analysis: {e}")),
    }
    summary.running = Some(running);
}

/// The running lines of the text summary.
pub fn print(o: &mut impl Write, s: &SimSummary) -> std::io::Result<()> {
    if let Some(r) = &s.running {
        writeln!(
            o,
            "running: {:.4} Hz ({:.1} rpm) over the last {} revolutions, speed ripple {:.2} %",
            r.hz,
            60.0 * r.hz,
            r.revolutions,
            100.0 * r.ripple
        )?;
        writeln!(
            o,
            "indicated work {:.4e} J per revolution (sum of closed-integral P dV over the spaces), indicated power {:.4e} W",
            r.work, r.power
        )?;
        for (name, w) in &r.work_per_space {
            writeln!(o, "  {name:>12}: {w:+.4e} J")?;
        }
    }
    if let (Some(r), Some(sch)) = (&s.running, &s.schmidt) {
        let temps: Vec<String> = sch
            .spaces
            .iter()
            .map(|sp| format!("{} {:.2} K", sp.name, sp.temperature))
            .collect();
        writeln!(
            o,
            "Schmidt (isothermal spaces at their cycle-mean gas temperatures: {}; {:.4e} kg of gas): {:.4e} J per revolution, {:.4e} W at this speed, p {:.1} to {:.1} Pa",
            temps.join(", "),
            sch.mass,
            sch.work,
            sch.work * r.hz,
            sch.p_min,
            sch.p_max
        )?;
        if sch.work > 0.0 {
            writeln!(
                o,
                "the engine indicates {:.3} of Schmidt's work (heat transfer, flow losses, leak)",
                r.work / sch.work
            )?;
        }
    }
    if let Some(n) = &s.running_note {
        writeln!(o, "{n}")?;
    }
    Ok(())
}
