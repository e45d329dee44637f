//! The CSV reader over random input: 60 000 random byte strings and 60 000 random mutations
//! of a valid record (seeded, deterministic) give a record or a short error naming a row,
//! never a panic. A record returned satisfies the reader's promises.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use stirling::models::data::{check_uniform, parse_csv_bytes, DataError, Measured};

const ALPHABET: &[u8] = b"0123456789.,,,-+eE \t\n\n\r#tpxy_hotnaifNI\"";
const TOKENS: [&str; 16] = [
    "nan",
    "inf",
    "-inf",
    "1e400",
    "-1e300",
    "1e-320",
    ",",
    "\n",
    "\u{feff}",
    "#",
    "t",
    "p_hot",
    "0.0",
    "00000000000000000000000000000001",
    "\"",
    "\r\n",
];

fn valid_record() -> Vec<u8> {
    let mut s = String::from("# rig\nt,p,p_hot,x,y\n");
    for k in 0..30 {
        let t = k as f64 * 5e-4;
        let w = (k as f64 * 0.4).sin();
        s.push_str(&format!(
            "{t},{},{},{},{}\n",
            1e6 + 1e4 * w,
            1.01e6 + 1e4 * w,
            4e-3 * w,
            3e-3 * (k as f64 * 0.4 - 1.0).sin()
        ));
    }
    s.into_bytes()
}

fn random_bytes(rng: &mut StdRng) -> Vec<u8> {
    let n = rng.gen_range(0..120);
    let mut v = Vec::with_capacity(n);
    if rng.gen_bool(0.3) {
        v.extend_from_slice(b"t,p,x\n");
    }
    for _ in 0..n {
        match rng.gen_range(0..20) {
            0..=15 => v.push(ALPHABET[rng.gen_range(0..ALPHABET.len())]),
            16..=18 => v.push(rng.gen()),
            _ => v.extend_from_slice(TOKENS[rng.gen_range(0..TOKENS.len())].as_bytes()),
        }
    }
    v
}

fn mutate(rng: &mut StdRng, base: &[u8]) -> Vec<u8> {
    let mut v = base.to_vec();
    for _ in 0..rng.gen_range(1..=4) {
        let at = rng.gen_range(0..=v.len());
        match rng.gen_range(0..7) {
            0 if at < v.len() => v[at] = ALPHABET[rng.gen_range(0..ALPHABET.len())],
            1 if at < v.len() => v[at] = rng.gen(),
            2 => {
                let tok = TOKENS[rng.gen_range(0..TOKENS.len())].as_bytes();
                v.splice(at..at, tok.iter().copied());
            }
            3 => {
                let end = (at + rng.gen_range(1..40)).min(v.len());
                v.drain(at..end);
            }
            4 => v.truncate(at),
            5 => {
                // duplicate a stretch (repeated or reordered rows)
                let end = (at + rng.gen_range(1..60)).min(v.len());
                let piece: Vec<u8> = v[at..end].to_vec();
                let to = rng.gen_range(0..=v.len());
                v.splice(to..to, piece);
            }
            _ => {
                let end = (at + rng.gen_range(1..20)).min(v.len());
                for b in &mut v[at..end] {
                    *b = b.to_ascii_uppercase();
                }
            }
        }
    }
    v
}

fn check(bytes: &[u8], counts: &mut [usize; 2]) {
    match parse_csv_bytes("fuzz.csv", bytes) {
        Ok(m) => {
            counts[0] += 1;
            check_record(&m);
            // the sampling check must not panic either
            let _ = check_uniform(&m, None);
        }
        Err(e) => {
            counts[1] += 1;
            check_error(bytes, &e);
        }
    }
}

fn check_record(m: &Measured) {
    assert!(m.len() >= 2);
    assert!(
        m.t.windows(2).all(|w| w[1] > w[0]),
        "time increases strictly"
    );
    for c in m.channels() {
        let v = m.channel(c).unwrap();
        assert_eq!(v.len(), m.len());
        assert!(v.iter().all(|x| x.is_finite()));
    }
    assert!(m.t.iter().all(|x| x.is_finite()));
}

fn check_error(bytes: &[u8], e: &DataError) {
    let lines = 1 + bytes.iter().filter(|&&b| b == b'\n').count();
    assert!(e.row <= lines + 1, "row {} of {lines} lines: {e}", e.row);
    let s = e.to_string();
    assert!(s.starts_with("fuzz.csv: row "), "{s}");
    assert!(
        s.len() < 1000,
        "a message stays short: {} bytes\n{s}",
        s.len()
    );
}

#[test]
fn random_bytes_and_mutations_never_panic() {
    let mut rng = StdRng::seed_from_u64(16);
    let base = valid_record();
    let mut counts = [0usize; 2];
    check(&base, &mut counts);
    assert_eq!(counts, [1, 0], "the base record is valid");
    for _ in 0..60_000 {
        let b = random_bytes(&mut rng);
        check(&b, &mut counts);
    }
    for _ in 0..60_000 {
        let b = mutate(&mut rng, &base);
        check(&b, &mut counts);
    }
    eprintln!("{} records, {} errors", counts[0], counts[1]);
    assert_eq!(counts[0] + counts[1], 120_001);
    // the mutations reach both outcomes
    assert!(counts[0] > 1_000 && counts[1] > 10_000, "{counts:?}");
}
