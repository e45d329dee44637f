//! The Cranelift IR of one tape: one SSA value per register, in one block, the inputs loaded
//! from `x`, `p` and `v` and each output stored to `out`.

use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{types, AbiParam, FuncRef, InstBuilder, MemFlagsData, Value};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::JITModule;
use cranelift_module::{Linkage, Module};
use stirling_dsl::compiled::{Op, Tape};
use stirling_dsl::expr::Func;

use crate::{shims, JitError};

/// The shims a function calls, declared in it once each.
struct Imports {
    funcs: Vec<(Func, FuncRef)>,
    powf: Option<FuncRef>,
}

/// Fill `ctx.func` (its signature set) with the code of `tape`.
pub(crate) fn function(
    module: &mut JITModule,
    func: &mut cranelift_codegen::ir::Function,
    tape: &Tape,
) -> Result<(), JitError> {
    let mut fctx = FunctionBuilderContext::new();
    let mut imports = Imports {
        funcs: Vec::new(),
        powf: None,
    };
    declare_imports(module, func, tape, &mut imports)?;
    let config = module.target_config();
    let mut b = FunctionBuilder::new(func, &mut fctx);
    let block = b.create_block();
    b.append_block_params_for_function_params(block);
    b.switch_to_block(block);
    b.seal_block(block);
    let args = b.block_params(block).to_vec();
    let (x, p, v, out) = (args[0], args[1], args[2], args[3]);
    let flags = MemFlagsData::trusted();
    let mut regs: Vec<Value> = Vec::with_capacity(tape.ops.len());
    for op in &tape.ops {
        let r = |k: u32| regs[k as usize];
        let val = match *op {
            Op::X(i) => b.ins().load(types::F64, flags, x, offset(i)),
            Op::P(k) => b.ins().load(types::F64, flags, p, offset(k)),
            Op::V(i) => b.ins().load(types::F64, flags, v, offset(i)),
            Op::K(c) => b.ins().f64const(c),
            Op::Add(a, c) => b.ins().fadd(r(a), r(c)),
            Op::Sub(a, c) => b.ins().fsub(r(a), r(c)),
            Op::Mul(a, c) => b.ins().fmul(r(a), r(c)),
            Op::Div(a, c) => b.ins().fdiv(r(a), r(c)),
            Op::Neg(a) => b.ins().fneg(r(a)),
            Op::Powi(a, k) => powi(&mut b, r(a), k),
            Op::Powf(a, c) => match imports.powf {
                Some(f) => call(&mut b, f, &[r(a), r(c)]),
                None => return Err(missing()),
            },
            Op::Func(f, a) => func_value(&mut b, &imports, f, r(a))?,
        };
        regs.push(val);
    }
    for (k, &o) in tape.outputs.iter().enumerate() {
        b.ins()
            .store(flags, regs[o as usize], out, offset(k as u32));
    }
    b.ins().return_(&[]);
    b.finalize(config);
    Ok(())
}

/// The byte offset of element `i` of an `f64` array.
fn offset(i: u32) -> i32 {
    (i as i64 * 8).min(i32::MAX as i64) as i32
}

/// An import the tape needs was not declared (a flaw of this crate, reported as an error).
fn missing() -> JitError {
    JitError::Codegen("a shim of stirling-jit was not declared".into())
}

/// Declare the shims the tape calls (only those).
fn declare_imports(
    module: &mut JITModule,
    func: &mut cranelift_codegen::ir::Function,
    tape: &Tape,
    imports: &mut Imports,
) -> Result<(), JitError> {
    let sig = |arity: usize| {
        let mut s = module.make_signature();
        for _ in 0..arity {
            s.params.push(AbiParam::new(types::F64));
        }
        s.returns.push(AbiParam::new(types::F64));
        s
    };
    let (unary, binary) = (sig(1), sig(2));
    for op in &tape.ops {
        match *op {
            Op::Func(f, _) if inline(f) => {}
            Op::Func(f, _) if !imports.funcs.iter().any(|&(g, _)| g == f) => {
                let id = module.declare_function(shims::name(f), Linkage::Import, &unary)?;
                let r = module.declare_func_in_func(id, func);
                imports.funcs.push((f, r));
            }
            Op::Powf(..) if imports.powf.is_none() => {
                let id = module.declare_function(shims::POWF, Linkage::Import, &binary)?;
                imports.powf = Some(module.declare_func_in_func(id, func));
            }
            _ => {}
        }
    }
    Ok(())
}

/// Whether `f` is an instruction rather than a call (IEEE-exact either way).
fn inline(f: Func) -> bool {
    matches!(f, Func::Abs | Func::Sqrt | Func::Sign)
}

fn call(b: &mut FunctionBuilder, f: FuncRef, args: &[Value]) -> Value {
    let c = b.ins().call(f, args);
    b.inst_results(c)[0]
}

/// `f(a)`: an instruction where one computes it exactly, else a call of its shim.
fn func_value(
    b: &mut FunctionBuilder,
    imports: &Imports,
    f: Func,
    a: Value,
) -> Result<Value, JitError> {
    Ok(match f {
        Func::Abs => b.ins().fabs(a),
        Func::Sqrt => b.ins().sqrt(a),
        Func::Sign => {
            // sign(0) = sign(NaN) = 0, as `stirling_dsl::expr::sign`
            let zero = b.ins().f64const(0.0);
            let one = b.ins().f64const(1.0);
            let minus = b.ins().f64const(-1.0);
            let gt = b.ins().fcmp(FloatCC::GreaterThan, a, zero);
            let lt = b.ins().fcmp(FloatCC::LessThan, a, zero);
            let neg = b.ins().select(lt, minus, zero);
            b.ins().select(gt, one, neg)
        }
        _ => match imports.funcs.iter().find(|&&(g, _)| g == f) {
            Some(&(_, r)) => call(b, r, &[a]),
            None => return Err(missing()),
        },
    })
}

/// `a^k` by the multiplications `f64::powi` performs (compiler-rt's `__powidf2`: square and
/// multiply from the lowest bit, the reciprocal for a negative `k`), so the bits agree.
fn powi(b: &mut FunctionBuilder, a: Value, k: i32) -> Value {
    let mut e = k.unsigned_abs();
    let mut base = a;
    let mut r: Option<Value> = None;
    loop {
        if e & 1 == 1 {
            r = Some(match r {
                Some(r) => b.ins().fmul(r, base),
                None => base,
            });
        }
        e /= 2;
        if e == 0 {
            break;
        }
        base = b.ins().fmul(base, base);
    }
    let r = match r {
        Some(r) => r,
        None => b.ins().f64const(1.0),
    };
    if k < 0 {
        let one = b.ins().f64const(1.0);
        b.ins().fdiv(one, r)
    } else {
        r
    }
}
