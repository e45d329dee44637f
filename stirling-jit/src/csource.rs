//! The C source of a tape, for the system's C compiler (`cc.rs`): one statement per
//! instruction, each the IEEE operation the interpreter performs (`Tape::run`), so that
//! compiled without contraction (`-ffp-contract=off`) it gives the interpreter's bits.

use std::fmt::Write;

use stirling_dsl::compiled::{Op, Tape};
use stirling_dsl::expr::Func;

/// The name of the compiled function.
pub(crate) const ENTRY: &str = "stirling_tape";

/// The index of a function's pointer in the table the code takes as its last argument
/// (`cc::SHIMS`); `powf` is the last.
pub(crate) fn slot(f: Func) -> usize {
    match f {
        Func::Sqrt => 0,
        Func::Ln => 1,
        Func::Exp => 2,
        Func::Tanh => 3,
        Func::Abs => 4,
        Func::Sign => 5,
        Func::Sin => 6,
        Func::Cos => 7,
    }
}

/// The slot of `powf` in the table.
pub(crate) const POWF_SLOT: usize = 8;

const PRELUDE: &str = "typedef double (*f1)(double);\n\
typedef double (*f2)(double, double);\n\
static inline double st_tanh(double a, f1 slow) {\n\
  if (__builtin_expect(__builtin_fabs(a) >= 22.0, 1)) return __builtin_copysign(1.0, a);\n\
  return slow(a);\n\
}\n\
static inline double st_sign(double a) { return a > 0.0 ? 1.0 : (a < 0.0 ? -1.0 : 0.0); }\n";

/// The C source of `tape` as `void stirling_tape(x, p, v, head, tail, fns)`: output `k` to
/// `head[k]` below the tape's split, to `tail[k - split]` from it.
pub(crate) fn source(tape: &Tape) -> String {
    let mut s = String::with_capacity(64 * tape.ops.len() + 1024);
    s.push_str(PRELUDE);
    let _ = writeln!(
        s,
        "void {ENTRY}(const double *restrict x, const double *restrict p, \
         const double *restrict v, double *restrict head, double *restrict tail, \
         const void *const *fns) {{"
    );
    for (i, op) in tape.ops.iter().enumerate() {
        let _ = writeln!(s, "  const double r{i} = {};", expr(op, i));
    }
    let head = tape.head();
    for (k, &r) in tape.outputs.iter().enumerate() {
        let _ = match k.checked_sub(head) {
            None => writeln!(s, "  head[{k}] = r{r};"),
            Some(t) => writeln!(s, "  tail[{t}] = r{r};"),
        };
    }
    s.push_str("}\n");
    s
}

/// A number as a C expression with the same bits.
fn number(c: f64) -> String {
    if c.is_nan() {
        "__builtin_nan(\"\")".into()
    } else if c.is_infinite() {
        if c > 0.0 {
            "__builtin_inf()"
        } else {
            "(-__builtin_inf())"
        }
        .into()
    } else {
        // Rust's `{:e}` is the shortest decimal that reads back to the same bits, and C's
        // reading of a decimal literal is correctly rounded
        format!("({c:e})")
    }
}

/// The right-hand side of instruction `i`.
fn expr(op: &Op, i: usize) -> String {
    let r = |k: u32| format!("r{k}");
    match *op {
        Op::X(k) => format!("x[{k}]"),
        Op::P(k) => format!("p[{k}]"),
        Op::V(k) => format!("v[{k}]"),
        Op::K(c) => number(c),
        Op::Add(a, b) => format!("r{a} + r{b}"),
        Op::Sub(a, b) => format!("r{a} - r{b}"),
        Op::Mul(a, b) => format!("r{a} * r{b}"),
        Op::Div(a, b) => format!("r{a} / r{b}"),
        Op::Neg(a) => format!("-r{a}"),
        Op::Powi(a, k) => powi(&r(a), k, i),
        Op::Powf(a, b) => format!("((f2)fns[{POWF_SLOT}])(r{a}, r{b})"),
        Op::Func(f, a) => func(f, &r(a)),
        Op::MulAdd(a, b, c) => format!("__builtin_fma(r{a}, r{b}, r{c})"),
        Op::MulSub(a, b, c) => format!("__builtin_fma(r{a}, r{b}, -r{c})"),
        Op::NegMulAdd(a, b, c) => format!("__builtin_fma(-r{a}, r{b}, r{c})"),
    }
}

/// A function of the library: `abs`, `sqrt`, `sign` and the saturated `tanh` inline (as the
/// Cranelift code has them), the others through the interpreter's own functions.
fn func(f: Func, a: &str) -> String {
    match f {
        Func::Abs => format!("__builtin_fabs({a})"),
        Func::Sqrt => format!("__builtin_sqrt({a})"),
        Func::Sign => format!("st_sign({a})"),
        Func::Tanh => format!("st_tanh({a}, (f1)fns[{}])", slot(f)),
        _ => format!("((f1)fns[{}])({a})", slot(f)),
    }
}

/// `a^k` by the multiplications `f64::powi` performs (compiler-rt's `__powidf2`: square and
/// multiply from the lowest bit, the reciprocal for a negative `k`), as `build::powi`: a
/// statement expression of the products, unrolled here (the exponent is known).
fn powi(a: &str, k: i32, i: usize) -> String {
    let mut e = k.unsigned_abs();
    let mut s = format!("({{ const double b{i}_0 = {a}; ");
    let (mut base, mut r, mut n) = (format!("b{i}_0"), None::<String>, 0);
    loop {
        if e & 1 == 1 {
            r = Some(match r {
                Some(q) => {
                    n += 1;
                    let _ = write!(s, "const double q{i}_{n} = {q} * {base}; ");
                    format!("q{i}_{n}")
                }
                None => base.clone(),
            });
        }
        e /= 2;
        if e == 0 {
            break;
        }
        n += 1;
        let _ = write!(s, "const double b{i}_{n} = {base} * {base}; ");
        base = format!("b{i}_{n}");
    }
    let r = r.unwrap_or_else(|| "1.0".into());
    if k < 0 {
        let _ = write!(s, "1.0 / {r}; }})");
    } else {
        let _ = write!(s, "{r}; }})");
    }
    s
}
