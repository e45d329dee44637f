//! Why a fit failed: one typed error for every stage of the identification.

use crate::sim::SimError;

use super::excitation;

/// Why a fit failed.
#[derive(Clone, Debug, thiserror::Error)]
pub enum FitError {
    #[error("{stage}: simulation failed: {source}")]
    Sim {
        stage: String,
        #[source]
        source: SimError,
    },
    #[error("{stage}: the block {from}:{to} s holds {samples} samples, fewer than {need}")]
    ShortBlock {
        stage: String,
        from: f64,
        to: f64,
        samples: usize,
        need: usize,
    },
    #[error("{stage}: the block {from}:{to} s holds fewer than two cycles of the motion")]
    BlockCycles { stage: String, from: f64, to: f64 },
    #[error("the static stiffness of the bodies is singular: no static shift of the offsets")]
    SingularStatics,
    #[error("`{model}`: body `{position}` has no velocity state")]
    NoVelocity { model: String, position: String },
    #[error("{0}: the optimizer could not evaluate the starting point")]
    Start(String),
    #[error("unknown parameter `{name}` of model `{model}`: see `stirling info {model}`")]
    UnknownParameter { name: String, model: String },
    #[error("parameter `{name}` is named twice in the free parameters: name each once")]
    DuplicateFree { name: String },
    #[error(
        "parameter `{name}` does not enter the equations of `{model}`: it cannot be identified"
    )]
    NotInEquations { name: String, model: String },
    #[error("{file}: {samples} samples are too few to fit")]
    TooFewSamples { file: String, samples: usize },
    #[error(transparent)]
    Sampling(crate::data::DataError),
    #[error("{file}: channel `{channel}` does not move enough to fit: its standard deviation on the training block is {sd:.3e}, its noise level {noise:.3e} (needs more than {} times the noise); is the engine running in this record?", excitation::MIN_SIGNAL_TO_NOISE)]
    NoExcitation {
        file: String,
        channel: String,
        sd: f64,
        noise: f64,
    },
    #[error("{file}: the training block ({seconds:.3} s) holds fewer than two cycles of the motion: the record is too short (or does not oscillate) to identify the dynamics")]
    TooFewCycles { file: String, seconds: f64 },
    #[error("{file}: {count} outlier sample(s), first {first}: a corrupt sample would pull the fit (pass --drop-outliers to replace each by its neighbours' interpolation, or repair the file)")]
    Outliers {
        file: String,
        count: usize,
        first: String,
    },
    #[error("{file}: the record cycles at {record:.4} Hz, the model at {model:.4} Hz (its dominant pole at rest, from the parameters given), more than {}x apart: {hint}", excitation::MAX_FREQUENCY_RATIO)]
    FrequencyMismatch {
        file: String,
        record: f64,
        model: f64,
        hint: String,
    },
    #[error("{file}: the record samples at {rate:.4} Hz, {per_cycle:.1} samples per cycle of its {freq:.4} Hz motion: too coarse to follow the cycle (at least {} samples per cycle are needed; a record sampled below twice the engine's frequency shows an alias of the motion, not the motion): record at a higher rate, or check the time column's unit", excitation::MIN_SAMPLES_PER_CYCLE)]
    Undersampled {
        file: String,
        rate: f64,
        freq: f64,
        per_cycle: f64,
    },
    #[error("the training block {from}:{to} holds {samples} samples, fewer than 11")]
    ShortTraining { from: f64, to: f64, samples: usize },
    #[error("{file}: {stage} needs the columns p, x and y")]
    MissingColumns { file: String, stage: &'static str },
    #[error("parameter `{name}` = {value:.4e} is outside its bounds [{lo:.4e}, {hi:.4e}]")]
    OutsideBounds {
        name: String,
        value: f64,
        lo: f64,
        hi: f64,
    },
    #[error("bounds of `{name}`: {why}")]
    BadBounds { name: String, why: String },
    #[error("parameter `{name}` = {value:.4e} fell below {floor:.4e} (2 % of its start): the data push it out of the physical range")]
    ParamRange {
        name: String,
        value: f64,
        floor: f64,
    },
    #[error(
        "`{model}`: control volume `{vessel}` has no mass-flow link to the working gas (a closed \
         bounce space?) and no sensor on its pressure; its pressure is its own, so the fit needs \
         it measured: declare `sensor p_{vessel}: P_{vessel} \"Pa\";` with the model and record \
         that column"
    )]
    OutsideChain { model: String, vessel: String },
    #[error("{file}: control volume `{vessel}` is outside the working gas, so the fit needs its sensor `{sensor}`, but {why}")]
    OutsideUnmeasured {
        file: String,
        vessel: String,
        sensor: String,
        why: String,
    },
    #[error(
        "`{model}` declares sensor `{channel}` on {state}; the two stages read `{channel}` from \
         {expected} (x, y: the two bodies' positions; p: the last CV's pressure; p_hot: the \
         first's) - fitting a channel placed elsewhere is not supported yet"
    )]
    SensorPlace {
        model: String,
        channel: &'static str,
        state: String,
        expected: String,
    },
    #[error("{file}: column `{column}` cannot be compared with the model: {source}")]
    Observe {
        file: String,
        column: String,
        source: Box<stirling_dsl::ObserveError>,
    },
    #[error("{file}: fit: a kinematic engine needs {what}: `{model}` is one, and {why}")]
    KinematicColumn {
        file: String,
        model: String,
        what: String,
        why: String,
    },
    #[error("fit: a kinematic engine needs one flywheel and no free bodies (its angle drives the gas); `{model}` has {wheels} flywheel(s) and {bodies} free body(ies)")]
    KinematicBodies {
        model: String,
        wheels: usize,
        bodies: usize,
    },
    #[error("fit: the flywheel's parameters `{names}` of `{model}` cannot be told apart by its torque balance (the measured angle's acceleration against the fitted gas's torque), or one acts on nothing it sees: free fewer of them (a Coulomb torque and a load are one torque at a steady speed; free one)")]
    KinematicFlywheel { model: String, names: String },
    #[error("{file}: fit: the flywheel's angle `{angle}` turns {revolutions:.3} revolutions in the {seconds:.3} s of the training block: the engine stands (or stopped), and a kinematic engine's fit drives the gas with the measured motion; record it running, over at least a few revolutions (or the angle column is not the flywheel's)")]
    KinematicStands {
        file: String,
        angle: String,
        revolutions: f64,
        seconds: f64,
    },
    #[error("{file}: fit: the angle `{angle}` turns at {turns:.4} rev/s on the training block but the pressure `p` cycles at {cycles:.4} Hz: the angle must be in rad (or carry its unit, `{angle} [deg]`) and be of the same record")]
    KinematicSpeed {
        file: String,
        angle: String,
        turns: f64,
        cycles: f64,
    },
    #[error("{file}: the record samples at {rate:.4} Hz, {per_rev:.1} samples per revolution of the flywheel (its angle `{angle}` turns at {turns:.4} rev/s): too coarse for a kinematic engine's fit, which needs at least {} samples a revolution, {need:.1} Hz or more here: below that the pressure's cycle is not followed from sample to sample, its third differences (the noise estimate) are the signal's own, and the pressure looks like noise; record at {need:.1} Hz or more", super::excitation::MIN_SAMPLES_PER_CYCLE)]
    KinematicRate {
        file: String,
        angle: String,
        rate: f64,
        turns: f64,
        per_rev: f64,
        need: f64,
    },
    #[error("{stage} expects two bodies (displacer x, piston y); `{model}` has {found}")]
    Bodies {
        stage: &'static str,
        model: String,
        found: usize,
    },
}
