//! A fuzz of the command line's arguments (issue 38): random commands built from every
//! command's options with good, bad and strange values. Each run must end in time, never
//! panic, and either succeed or fail with a message on stderr (exit 2 for usage, 1 for an
//! error); a success writes only inside the scratch folder. Deterministic: one seed, 240 runs,
//! each held to short work (short records, small grids) so that the whole takes seconds.

mod support;

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use support::{s, scratch, write_record};

/// A small deterministic generator (no dependency needed for a test's choices).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn pick<'a>(&mut self, from: &[&'a str]) -> &'a str {
        from[(self.next() as usize) % from.len()]
    }
}

const MODELS: &[&str] = &[
    "cv1",
    "schmidt",
    "nsection",
    "order8",
    "nope",
    "",
    "cv1.stirling",
    "-1",
];
const NUMBERS: &[&str] = &[
    "0", "-1", "1e-3", "0.01", "nan", "inf", "-inf", "1e308", "abc", "", "1,5", "0x10", "2",
    "1e-30",
];
const SETS: &[&str] = &[
    "kd=700",
    "kd=",
    "=1",
    "kd=nan",
    "Th=-5",
    "nope=1",
    "kd=1=2",
    "Pmean=1e5",
];
const GRIDS: &[&str] = &[
    "Th=500:700:3",
    "Th=700:500:3",
    "Th=500:700:0",
    "Th=a:b:c",
    "Th",
    "kd=1:2:2",
];

/// The options each command takes, with the kind of value they get.
fn options(cmd: &str) -> &'static [(&'static str, &'static str)] {
    match cmd {
        "linearize" => &[
            ("--n", "num"),
            ("--set", "set"),
            ("--json", ""),
            ("--closure", "closure"),
        ],
        "simulate" => &[
            ("--n", "num"),
            ("--t-end", "small"),
            ("--samples", "num"),
            ("--set", "set"),
            ("--json", ""),
        ],
        "locus" => &[
            ("--param", "name"),
            ("--from", "num"),
            ("--to", "num"),
            ("--steps", "num"),
        ],
        "info" => &[
            ("--n", "num"),
            ("--graph", ""),
            ("--closure", "closure"),
            ("--latex", ""),
        ],
        "rig" => &[
            ("--t-end", "small"),
            ("--rate", "num"),
            ("--effect", "set"),
            ("--noise-p", "num"),
            ("--seed", "num"),
            ("--channels", "name"),
        ],
        "fit" => &[
            ("--data", "data"),
            ("--free", "name"),
            ("--train", "range"),
            ("--holdout", "range"),
        ],
        "diagnose" => &[
            ("--data", "data"),
            ("--effects", "name"),
            ("--alpha", "num"),
            ("--train", "range"),
        ],
        "sweep" => &[
            ("--grid", "grid"),
            ("--poles-only", ""),
            ("--n", "num"),
            ("--shard", "shard"),
        ],
        _ => &[],
    }
}

fn value(rng: &mut Lcg, kind: &str, data: &str) -> String {
    match kind {
        "num" => rng.pick(NUMBERS).into(),
        "small" => rng.pick(&["0.01", "0", "-1", "nan", "1e9", "x"]).into(),
        "set" => rng.pick(SETS).into(),
        "closure" => rng.pick(&["full", "frozen", "none", ""]).into(),
        "name" => rng
            .pick(&["kd", "kd,kd", "leak", "p,x,y", "", "nope", "Th"])
            .into(),
        "range" => rng
            .pick(&["0:0.5", "0.5:0", "a:b", "0:1e9", "-1:0.2", ":"])
            .into(),
        "grid" => rng.pick(GRIDS).into(),
        "shard" => rng.pick(&["1/2", "0/2", "3/2", "a/b", "1/0"]).into(),
        "data" => rng.pick(&[data, "/nonexistent.csv", "", "/"]).into(),
        _ => String::new(),
    }
}

/// One random command line; the options' values are heavy only where the option is bounded.
fn args(rng: &mut Lcg, out: &str, data: &str) -> Vec<String> {
    let cmd = rng.pick(&[
        "linearize",
        "simulate",
        "locus",
        "info",
        "rig",
        "fit",
        "diagnose",
        "sweep",
        "models",
        "bogus",
    ]);
    let mut a = vec![cmd.to_string(), rng.pick(MODELS).to_string()];
    let opts = options(cmd);
    for _ in 0..(rng.next() % 4) {
        if opts.is_empty() {
            break;
        }
        let (name, kind) = opts[(rng.next() as usize) % opts.len()];
        a.push(name.into());
        if !kind.is_empty() {
            a.push(value(rng, kind, data));
        }
    }
    match cmd {
        "rig" | "sweep" => a.extend(["--out".into(), out.into(), "--force".into()]),
        "simulate" if rng.next().is_multiple_of(2) => a.extend(["--t-end".into(), "0.05".into()]),
        _ => {}
    }
    a
}

/// Run with a deadline; `(exit code, stderr, seconds)`, `None` for the code when killed.
fn run(a: &[String], limit: Duration) -> (Option<i32>, String, f64) {
    let clock = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_stirling"))
        .args(a)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = String::new();
    let mut stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let _ = stderr.read_to_string(&mut err);
        err
    });
    let code = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st.code();
        }
        if clock.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    (code, reader.join().unwrap(), clock.elapsed().as_secs_f64())
}

#[test]
fn random_arguments_never_panic_hang_or_fail_silently() {
    let dir = scratch("fuzz_args");
    let data = dir.join("rec.csv");
    write_record(&data);
    let out = dir.join("out");
    let mut rng = Lcg(38);
    let (mut ok, mut refused) = (0, 0);
    for case in 0..240 {
        let a = args(&mut rng, s(&out), s(&data));
        let (code, err, secs) = run(&a, Duration::from_secs(60));
        let line = a.join(" ");
        assert!(code.is_some(), "case {case}: `{line}` ran past 60 s");
        assert!(
            !err.contains("panicked"),
            "case {case}: `{line}` panicked:\n{err}"
        );
        match code {
            Some(0) => ok += 1,
            Some(1 | 2) => {
                assert!(
                    !err.trim().is_empty(),
                    "case {case}: `{line}` failed without a message"
                );
                refused += 1;
            }
            Some(c) => panic!("case {case}: `{line}` exited {c} after {secs:.1} s:\n{err}"),
            None => unreachable!(),
        }
    }
    eprintln!("{ok} succeeded, {refused} refused");
    // the fuzz reaches both sides
    assert!(
        ok >= 5 && refused >= 100,
        "{ok} succeeded, {refused} refused"
    );
}
