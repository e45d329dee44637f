//! `stirling`: the command line of the framework (the library `stirling_cli`; a user's crate
//! that registers its own engines runs the same command line from its own binary).

mod cmd_diagnose;
mod cmd_fit;
mod cmd_info;
mod cmd_linearize;
mod cmd_locus;
mod cmd_models;
mod cmd_rig;
mod cmd_serve;
mod cmd_simulate;
mod cmd_sweep;
mod common;
mod serve;

use clap::{Parser, Subcommand};

/// Energetic, symbolic modeling of free-piston Stirling engines.
#[derive(Parser, Debug)]
#[command(name = "stirling", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// List the model family and its aliases
    Models {
        /// Machine-readable output
        #[arg(long)]
        json: bool,
    },
    /// Sim-to-real gap diagnosis: where the gap lies, which omitted effect, how far it closes
    Diagnose(Box<cmd_diagnose::DiagnoseArgs>),
    /// Virtual test rig: truth model plus effects, noise and offsets -> measured CSV + truth sidecar
    Rig(cmd_rig::RigArgs),
    /// Two-stage identification from measured data (mechanics, then gas), with intervals and fit %
    Fit(cmd_fit::FitArgs),
    /// Equilibrium, poles, the loop broken at a pressure force, gain and phase margins
    Linearize(cmd_linearize::LinearizeArgs),
    /// Root locus: the poles over a parameter range
    Locus(cmd_locus::LocusArgs),
    /// The interactive teaching page on localhost: bond graph, poles, Bode, limit cycle
    Serve(cmd_serve::ServeArgs),
    /// Simulate a model (stiff BDF); --limit-cycle refines the periodic orbit by shooting
    Simulate(cmd_simulate::SimulateArgs),
    /// States, parameters and generated equations of a model, or its bond graph (--graph)
    Info(cmd_info::InfoArgs),
    /// Design sweep over a parameter grid: poles, whether the engine runs, its cycle and power
    Sweep(cmd_sweep::SweepArgs),
    /// Join the sweep.json files of `stirling sweep --shard` slices into one sweep
    SweepMerge(cmd_sweep::MergeArgs),
}

/// Run the command line on the process's arguments and exit with its status (0: done, 2: an
/// error, printed). A user's binary registers its engines first
/// (`stirling_models::user_models::register`), then calls this: `stirling fit`, `diagnose`,
/// `info`, `linearize`, `simulate` ... then take their names.
pub fn main() {
    let cli = Cli::parse_from(model_option(std::env::args_os()));
    if let Err(e) = dispatch(cli.command) {
        // a reader that stopped early (`| head`) is the end of the output, not an error
        if common::is_stdout_closed(&e) {
            std::process::exit(0);
        }
        common::note(format_args!("error: {e:#}"));
        std::process::exit(2);
    }
}

/// Run one command from `args` (the first is the program name) without exiting: for a user's
/// binary or a test that drives the command line in-process. A malformed command line is an
/// error here too (clap's message, `--help` included).
pub fn run_args<I, T>(args: I) -> anyhow::Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    dispatch(Cli::try_parse_from(model_option(args))?.command)
}

/// `stirling CMD .. --model FILE ..` as `stirling CMD FILE ..`: every command that takes a
/// model as its first argument takes it as `--model` too (`--model FILE`, `--model=FILE`).
fn model_option<I, T>(args: I) -> Vec<std::ffi::OsString>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let mut v: Vec<std::ffi::OsString> = args.into_iter().map(Into::into).collect();
    let Some(k) = v
        .iter()
        .skip(2)
        .position(|a| a == "--model" || a.to_str().is_some_and(|s| s.starts_with("--model=")))
    else {
        return v;
    };
    let k = k + 2;
    let inline = v[k]
        .to_str()
        .and_then(|s| s.strip_prefix("--model="))
        .map(std::ffi::OsString::from);
    let value = match inline {
        Some(value) => {
            v.remove(k);
            value
        }
        // a missing value is left for clap to report
        None if k + 1 == v.len() => return v,
        None => {
            v.remove(k);
            v.remove(k)
        }
    };
    v.insert(2, value);
    v
}

fn dispatch(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Models { json } => cmd_models::run(json),
        Command::Diagnose(a) => cmd_diagnose::run(&a),
        Command::Rig(a) => cmd_rig::run(&a),
        Command::Fit(a) => cmd_fit::run(&a),
        Command::Linearize(a) => cmd_linearize::run(&a),
        Command::Locus(a) => cmd_locus::run(&a),
        Command::Serve(a) => cmd_serve::run(&a),
        Command::Simulate(a) => cmd_simulate::run(&a),
        Command::Info(a) => cmd_info::run(&a),
        Command::Sweep(a) => cmd_sweep::run(&a),
        Command::SweepMerge(a) => cmd_sweep::merge(&a),
    }
}

#[cfg(test)]
mod tests {
    use super::model_option;

    fn run(args: &str) -> String {
        let v = model_option(args.split(' '));
        let s: Vec<_> = v.iter().map(|a| a.to_string_lossy().into_owned()).collect();
        s.join(" ")
    }

    #[test]
    fn model_option_becomes_the_first_argument() {
        assert_eq!(
            run("stirling info --n 2 --model e.stirling --json"),
            "stirling info e.stirling --n 2 --json"
        );
        assert_eq!(
            run("stirling fit --model=e.stirling --data d.csv"),
            "stirling fit e.stirling --data d.csv"
        );
        assert_eq!(run("stirling info cv1"), "stirling info cv1");
        assert_eq!(run("stirling info --model"), "stirling info --model");
    }
}
