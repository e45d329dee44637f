//! The Rust functions the compiled code calls, by the symbol names it imports them under:
//! the interpreter's own functions, so that both paths give the same bits.

use stirling_dsl::expr::Func;

extern "C" fn sqrt(a: f64) -> f64 {
    Func::Sqrt.apply(a)
}
extern "C" fn ln(a: f64) -> f64 {
    Func::Ln.apply(a)
}
extern "C" fn exp(a: f64) -> f64 {
    Func::Exp.apply(a)
}
extern "C" fn tanh(a: f64) -> f64 {
    Func::Tanh.apply(a)
}
extern "C" fn abs(a: f64) -> f64 {
    Func::Abs.apply(a)
}
extern "C" fn sign(a: f64) -> f64 {
    Func::Sign.apply(a)
}
extern "C" fn sin(a: f64) -> f64 {
    Func::Sin.apply(a)
}
extern "C" fn cos(a: f64) -> f64 {
    Func::Cos.apply(a)
}
extern "C" fn powf(a: f64, b: f64) -> f64 {
    a.powf(b)
}

/// Every unary function with its shim.
const UNARY: [(Func, extern "C" fn(f64) -> f64); 8] = [
    (Func::Sqrt, sqrt),
    (Func::Ln, ln),
    (Func::Exp, exp),
    (Func::Tanh, tanh),
    (Func::Abs, abs),
    (Func::Sign, sign),
    (Func::Sin, sin),
    (Func::Cos, cos),
];

/// The symbol name a function is imported under.
pub(crate) fn name(f: Func) -> &'static str {
    match f {
        Func::Sqrt => "stirling_sqrt",
        Func::Ln => "stirling_ln",
        Func::Exp => "stirling_exp",
        Func::Tanh => "stirling_tanh",
        Func::Abs => "stirling_abs",
        Func::Sign => "stirling_sign",
        Func::Sin => "stirling_sin",
        Func::Cos => "stirling_cos",
    }
}

/// The symbol name of `powf`.
pub(crate) const POWF: &str = "stirling_powf";

/// Every symbol with its address, for `JITBuilder::symbol`.
pub(crate) fn symbols() -> Vec<(&'static str, *const u8)> {
    let mut v: Vec<(&'static str, *const u8)> = UNARY
        .iter()
        .map(|&(f, g)| (name(f), g as *const u8))
        .collect();
    v.push((POWF, powf as extern "C" fn(f64, f64) -> f64 as *const u8));
    v
}

/// The functions' addresses in the order of `csource::slot`, `powf` last: the table the C
/// compiler's code calls through (`cc.rs`).
pub(crate) fn table() -> [*const u8; 9] {
    let mut t = [std::ptr::null::<u8>(); 9];
    for (f, g) in UNARY {
        t[crate::csource::slot(f)] = g as *const u8;
    }
    t[crate::csource::POWF_SLOT] = powf as extern "C" fn(f64, f64) -> f64 as *const u8;
    t
}
