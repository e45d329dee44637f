//! Long work (a run, a limit cycle, a fit, a diagnosis, a sweep, the rig) on a worker thread
//! with the GIL released, while the calling thread waits in slices of [`POLL`]: between them
//! it takes the GIL to check for signals (Ctrl-C) and to pass progress to the Python callback.
//! On a signal, or an exception from the callback, it asks the library to stop
//! ([`stirling_models::sim::interrupt`]: every step loop ends at its next step), waits for the
//! worker to wind down, withdraws the request and raises what it caught (`KeyboardInterrupt`).
//! Python is only ever called from the calling thread; the worker sends it events.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError, Sender};
use std::sync::Mutex;
use std::time::Duration;

use pyo3::prelude::*;
use stirling_models::sim::interrupt;

use crate::errors::{Failure, Kind};

/// How often the waiting thread checks for signals and progress.
const POLL: Duration = Duration::from_millis(40);

/// Progress steps reported over a piece of work (events finer than this are not sent).
const STEPS: f64 = 1000.0;

/// What the worker tells the waiting thread.
enum Event {
    /// Done so far, in the work's unit (simulated seconds, points, ...).
    At(f64),
    /// A line of text (the diagnosis's progress lines).
    Line(String),
}

/// The worker's side: where it reports progress.
pub struct Reporter {
    tx: Mutex<Sender<Event>>,
    total: f64,
    last: AtomicU64,
    /// Whether anyone listens: without a callback no event is sent, so the waiting thread
    /// wakes only to check for signals (an event per progress step cost a simulated second
    /// of `nsection` n = 2 about 6 ms of thread wake-ups on 2 cores).
    listening: bool,
}

impl Reporter {
    /// Report `done` (out of the total the work was started with); only steps of a
    /// thousandth are sent.
    pub fn at(&self, done: f64) {
        if !self.listening {
            return;
        }
        let step = if self.total > 0.0 {
            (STEPS * done / self.total).clamp(0.0, STEPS) as u64
        } else {
            0
        };
        if self.last.fetch_max(step, Ordering::Relaxed) < step {
            self.send(Event::At(done));
        }
    }

    /// Report one more unit done (sweep points).
    pub fn tick(&self, done: &AtomicU64) {
        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
        self.at(d as f64);
    }

    /// Report a line of text.
    pub fn line(&self, line: &str) {
        if !self.listening {
            return;
        }
        self.send(Event::Line(line.to_string()));
    }

    fn send(&self, e: Event) {
        if let Ok(tx) = self.tx.lock() {
            // a waiting thread that stopped listening is not an error of the work
            let _ = tx.send(e);
        }
    }
}

/// Run `work` off the GIL, with `progress(done, total, line)` called from this thread and
/// Ctrl-C stopping it. `total` is the work's size in the unit `Reporter::at` counts.
pub fn run<T, E, F>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    total: f64,
    work: F,
) -> PyResult<T>
where
    T: Send,
    E: Into<Failure> + Send,
    F: FnOnce(&Reporter) -> Result<T, E> + Send,
{
    let (tx, rx) = channel();
    let reporter = Reporter {
        tx: Mutex::new(tx),
        total,
        last: AtomicU64::new(0),
        listening: progress.is_some(),
    };
    let (outcome, caught) = std::thread::scope(|s| {
        let worker = s.spawn(move || {
            let r = work(&reporter);
            drop(reporter); // closes the channel: the waiting thread stops waiting
            r
        });
        let caught = wait(py, rx, progress, total);
        (worker.join(), caught)
    });
    if let Some(e) = caught {
        interrupt::clear();
        return Err(e);
    }
    match outcome {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(e.into().into()),
        Err(panic) => Err(Failure::new(Kind::Internal, panic_message(&panic)).into()),
    }
}

/// Wait for the worker to close the channel, passing its events to `progress` and checking
/// for signals; the first exception caught (a signal's, the callback's) asks the work to stop.
fn wait(
    py: Python<'_>,
    mut rx: Receiver<Event>,
    progress: Option<&Bound<'_, PyAny>>,
    total: f64,
) -> Option<PyErr> {
    let mut caught: Option<PyErr> = None;
    loop {
        let (back, first) = py.detach(move || {
            let e = rx.recv_timeout(POLL);
            (rx, e)
        });
        rx = back;
        let mut events = Vec::new();
        let open = match first {
            Ok(e) => {
                events.push(e);
                events.extend(rx.try_iter());
                true
            }
            Err(RecvTimeoutError::Timeout) => true,
            Err(RecvTimeoutError::Disconnected) => false,
        };
        let mut step = py.check_signals();
        if step.is_ok() {
            if let Some(cb) = progress {
                step = deliver(cb, &events, total);
            }
        }
        if let (Err(e), None) = (step, &caught) {
            interrupt::request();
            caught = Some(e);
        }
        if !open {
            return caught;
        }
    }
}

/// Pass the events to the callback: the last position, and every line.
fn deliver(cb: &Bound<'_, PyAny>, events: &[Event], total: f64) -> PyResult<()> {
    let mut at = None;
    for e in events {
        match e {
            Event::At(d) => at = Some(*d),
            Event::Line(l) => {
                cb.call1((at.unwrap_or(f64::NAN), total, l.as_str()))?;
            }
        }
    }
    if let Some(d) = at {
        cb.call1((d, total, py_none(cb.py())))?;
    }
    Ok(())
}

fn py_none(py: Python<'_>) -> Bound<'_, PyAny> {
    py.None().into_bound(py)
}

/// The text of a worker's panic.
fn panic_message(p: &Box<dyn std::any::Any + Send>) -> String {
    let what = p
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    format!("internal error (please report it): {what}")
}

/// Where the diagnosis's progress lines go: the library takes a plain `fn(&str)`, so the
/// reporter of the diagnosis in progress is held here. Two diagnoses at once (two Python
/// threads) share it: the lines go to the later one's callback.
static LINES: Mutex<Option<Sender<String>>> = Mutex::new(None);

/// The `fn(&str)` the diagnosis calls with each progress line.
pub fn forward_line(line: &str) {
    if let Ok(g) = LINES.lock() {
        if let Some(tx) = g.as_ref() {
            let _ = tx.send(line.to_string());
        }
    }
}

/// Route [`forward_line`] to `reporter` while `f` runs.
pub fn with_lines<T>(reporter: &Reporter, f: impl FnOnce() -> T) -> T {
    let (tx, rx) = channel::<String>();
    if let Ok(mut g) = LINES.lock() {
        *g = Some(tx);
    }
    let out = std::thread::scope(|s| {
        let relay = s.spawn(move || {
            for l in rx {
                reporter.line(&l);
            }
        });
        let out = f();
        if let Ok(mut g) = LINES.lock() {
            *g = None; // closes the channel: the relay ends
        }
        let _ = relay.join();
        out
    });
    out
}
