//! The Cranelift IR of a tape: one SSA value per register, in one block per function, the
//! inputs loaded from `x`, `p` and `v` and each output stored to its buffer as soon as it is
//! computed. A long tape is cut into several functions ([`Layout`]) that pass the registers
//! a later one reads through a scratch array.

use std::collections::HashMap;
use std::ops::Range;

use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{
    types, AbiParam, BlockArg, FuncRef, InstBuilder, MemFlagsData, Signature, StackSlotData,
    StackSlotKind, Value,
};
use cranelift_codegen::isa::CallConv;
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::JITModule;
use cranelift_module::{Linkage, Module};
use stirling_dsl::compiled::{Op, Tape};
use stirling_dsl::expr::Func;

use crate::{shims, JitError};

/// The shims a function calls, declared in it once each.
pub(crate) struct Imports {
    pub funcs: Vec<(Func, FuncRef)>,
    pub powf: Option<FuncRef>,
    /// Whether `tanh`'s unsaturated case calls the trampoline [`TANH_KEEP`] (the looped
    /// code) rather than the shim itself (the unrolled code, where it measured faster at
    /// n = 2: with every register kept the allocator's other spills there cost more).
    pub tanh_keep: bool,
}

/// How a tape is cut into functions (Cranelift's compile time grows faster than linearly
/// with one block, so a long tape is compiled as several): the ranges of instructions, and
/// the slot in the scratch array of every register that a later function reads.
pub(crate) struct Layout {
    pub chunks: Vec<Range<usize>>,
    /// `slot[r]`: where register `r` is kept for later functions (`u32::MAX`: nowhere).
    slot: Vec<u32>,
    /// The number of scratch slots.
    pub slots: usize,
    /// `(register, output)` pairs, sorted by register: each output stored as its register
    /// is computed (no value kept alive to the end of the function for it).
    stores: Vec<(u32, u32)>,
    /// The tape's numbers (`slot[r]` of an `Op::K` is its index here), their address the
    /// code's last argument.
    pub consts: Box<[f64]>,
}

impl Layout {
    /// Cut `tape` into functions of at most `chunk` instructions.
    pub(crate) fn new(tape: &Tape, chunk: usize) -> Layout {
        let len = tape.ops.len();
        let chunk = chunk.max(1);
        let chunks: Vec<Range<usize>> = (0..len.div_ceil(chunk).max(1))
            .map(|c| c * chunk..((c + 1) * chunk).min(len))
            .collect();
        let mut slot = vec![u32::MAX; len];
        let mut slots = 0u32;
        for (k, op) in tape.ops.iter().enumerate() {
            let (args, count) = operands(op);
            for &a in &args[..count] {
                let (a, first) = (a as usize, k - k % chunk);
                if a < first && !leaf(&tape.ops[a]) && slot[a] == u32::MAX {
                    slot[a] = slots;
                    slots += 1;
                }
            }
        }
        let mut consts = Vec::new();
        for (k, op) in tape.ops.iter().enumerate() {
            if let Op::K(c) = *op {
                slot[k] = consts.len() as u32;
                consts.push(c);
            }
        }
        let consts: Box<[f64]> = consts.into_boxed_slice();
        let mut stores: Vec<(u32, u32)> = (0..tape.outputs.len() as u32)
            .map(|k| (tape.outputs[k as usize], k))
            .collect();
        stores.sort_unstable();
        Layout {
            chunks,
            slot,
            slots: slots as usize,
            stores,
            consts,
        }
    }
}

pub(crate) use stirling_dsl::compiled::operands;

/// Whether `op` reads an input or is a number (emitted again where a later function needs
/// it, never kept in the scratch array).
pub(crate) fn leaf(op: &Op) -> bool {
    matches!(op, Op::X(_) | Op::P(_) | Op::V(_) | Op::K(_))
}

/// The function's arguments: `x`, `p`, `v`, the two output buffers and the scratch array.
struct Args {
    x: Value,
    p: Value,
    v: Value,
    head: Value,
    tail: Value,
    scratch: Value,
}

/// Fill `func` (its signature set) with the code of chunk `c` of `tape` (`layout`).
pub(crate) fn function(
    module: &mut JITModule,
    func: &mut cranelift_codegen::ir::Function,
    tape: &Tape,
    layout: &Layout,
    c: usize,
) -> Result<(), JitError> {
    let range = layout.chunks[c].clone();
    let mut fctx = FunctionBuilderContext::new();
    let mut imports = Imports {
        funcs: Vec::new(),
        powf: None,
        tanh_keep: false,
    };
    declare_imports(module, func, &tape.ops[range.clone()], &mut imports)?;
    let config = module.target_config();
    let mut b = FunctionBuilder::new(func, &mut fctx);
    let block = b.create_block();
    b.append_block_params_for_function_params(block);
    b.switch_to_block(block);
    b.seal_block(block);
    let a = b.block_params(block).to_vec();
    let args = Args {
        x: a[0],
        p: a[1],
        v: a[2],
        head: a[3],
        tail: a[4],
        scratch: a[5],
    };
    let head = tape.head();
    let flags = MemFlagsData::trusted();
    // the registers this function has: its own (none for a leaf), and those of earlier
    // functions it read
    let mut regs: HashMap<u32, Value> = HashMap::new();
    let mut own: Vec<Option<Value>> = vec![None; range.len()];
    let mut minus_zero: Option<Value> = None;
    // the numbers' address: an argument, so one register (as an `iconst`, Cranelift
    // materialised the 64-bit address again before every load, 51 `movabs` at n = 2)
    let consts = a[crate::tape::ARGS - 1];
    // in the order that keeps fewer values live (`schedule`) where the tape reads no
    // parameter (folded: `nsection` at n = 10, 134 to 123 ns), in the tape's order where it
    // does (scheduled, its RHS + Jacobian at n = 10 measured 167 to 177-182 ns); each output
    // stored as its register is computed
    let order: Vec<usize> = if tape.ops.iter().any(|op| matches!(op, Op::P(_))) {
        range.clone().collect()
    } else {
        crate::schedule::order(&tape.ops, range.clone())
    };
    let last = last_reads(&tape.ops, &order, range.start);
    for (at, k) in order.into_iter().enumerate() {
        let mut stores = layout.stores.partition_point(|&(r, _)| (r as usize) < k);
        // a leaf is loaded again at every use (a memory operand of its user): never kept in a
        // register across the function, never spilled (the parameters are used everywhere)
        let mut r = |q: u32| -> Value {
            let q_us = q as usize;
            if let Some(v) = leaf_value(&mut b, &args, consts, layout, q_us, &tape.ops[q_us]) {
                return v;
            }
            if q_us >= range.start {
                if let Some(v) = own[q_us - range.start] {
                    return v;
                }
            }
            *regs.entry(q).or_insert_with(|| {
                let at = offset(layout.slot[q_us]);
                b.ins().load(types::F64, flags, args.scratch, at)
            })
        };
        let op = tape.ops[k];
        let val = match op {
            Op::X(_) | Op::P(_) | Op::V(_) | Op::K(_) => {
                let has_output = layout
                    .stores
                    .get(stores)
                    .is_some_and(|&(g, _)| g as usize == k);
                if !has_output {
                    continue;
                }
                r(k as u32)
            }
            Op::MulAdd(..) | Op::MulSub(..) | Op::NegMulAdd(..) => {
                let (args, _) = operands(&op);
                // x86's `vfmadd213`/`132` (what Cranelift emits) write the first factor's
                // register: a factor read later would be copied first, so the factor read for
                // the last time goes first (the product commutes: the same bits)
                let (p, q) = (args[0] as usize, args[1] as usize);
                let ends = |q: usize| {
                    leaf(&tape.ops[q]) || (q >= range.start && last[q - range.start] == at)
                };
                let (p, q) = if !ends(p) && ends(q) { (q, p) } else { (p, q) };
                let (x, y, z) = (r(p as u32), r(q as u32), r(args[2]));
                fused(&mut b, op, x, y, z)
            }
            _ => {
                let (args, count) = operands(&op);
                let a = r(args[0]);
                let (a, c) = if count == 2 {
                    let c = r(args[1]);
                    let mem = |q: u32| leaf(&tape.ops[q as usize]);
                    crate::looped::commuted(op, a, c, [mem(args[0]), mem(args[1])])
                } else {
                    (a, a)
                };
                arith(&mut b, &imports, &mut minus_zero, op, a, c)?
            }
        };
        own[k - range.start] = Some(val);
        if !leaf(&op) && layout.slot[k] != u32::MAX {
            b.ins()
                .store(flags, val, args.scratch, offset(layout.slot[k]));
        }
        while let Some(&(reg, out)) = layout.stores.get(stores) {
            if reg as usize != k {
                break;
            }
            let out = out as usize;
            let (base, at) = if out < head {
                (args.head, out)
            } else {
                (args.tail, out - head)
            };
            b.ins().store(flags, val, base, offset(at as u32));
            stores += 1;
        }
    }
    b.ins().return_(&[]);
    b.finalize(config);
    Ok(())
}

/// For instructions `start..` emitted in `order`: where in it each is read for the last time
/// (`usize::MAX`: never read there).
fn last_reads(ops: &[Op], order: &[usize], start: usize) -> Vec<usize> {
    let mut last = vec![usize::MAX; order.len()];
    for (at, &k) in order.iter().enumerate() {
        let (args, count) = operands(&ops[k]);
        for &q in &args[..count] {
            if q as usize >= start {
                last[q as usize - start] = at;
            }
        }
    }
    last
}

/// The value of the operation `op` (not a leaf) on `a` and `c` (its second operand, if it
/// has one); `minus_zero`: the function's shared `-0.0`, made on first use.
pub(crate) fn arith(
    b: &mut FunctionBuilder,
    imports: &Imports,
    minus_zero: &mut Option<Value>,
    op: Op,
    a: Value,
    c: Value,
) -> Result<Value, JitError> {
    Ok(match op {
        Op::Add(..) => b.ins().fadd(a, c),
        Op::Sub(..) => b.ins().fsub(a, c),
        Op::Mul(..) => b.ins().fmul(a, c),
        Op::Div(..) => b.ins().fdiv(a, c),
        Op::Neg(_) => {
            // the sign bit flipped, as `fneg` (and Rust's `-a`) does; `fneg` would
            // build its mask again at every use, 3 instructions instead of 1
            let sign = *minus_zero.get_or_insert_with(|| b.ins().f64const(-0.0));
            b.ins().bxor(a, sign)
        }
        Op::Powi(_, e) => powi(b, a, e),
        Op::Powf(..) => match imports.powf {
            Some(f) => call(b, f, &[a, c]),
            None => return Err(missing()),
        },
        Op::Func(f, _) => func_value(b, imports, f, a)?,
        Op::X(_) | Op::P(_) | Op::V(_) | Op::K(_) => {
            return Err(JitError::Codegen("a leaf is not an operation".into()))
        }
        // its callers emit it with its three operands ([`fused`])
        Op::MulAdd(..) | Op::MulSub(..) | Op::NegMulAdd(..) => {
            return Err(JitError::Codegen(
                "a multiply-add has three operands".into(),
            ))
        }
    })
}

/// A fused multiply-add (`op` one of [`Op::MulAdd`], [`Op::MulSub`], [`Op::NegMulAdd`]) on
/// `a`, `b`, `c`: one `fma`, a negated operand by `fneg` (x86 folds it into the instruction:
/// `vfmsub`, `vfnmadd`).
pub(crate) fn fused(b: &mut FunctionBuilder, op: Op, a: Value, x: Value, c: Value) -> Value {
    match op {
        Op::MulSub(..) => {
            let c = b.ins().fneg(c);
            b.ins().fma(a, x, c)
        }
        Op::NegMulAdd(..) => {
            let a = b.ins().fneg(a);
            b.ins().fma(a, x, c)
        }
        _ => b.ins().fma(a, x, c),
    }
}

/// The value of leaf instruction `k`, loaded (`None` for any other instruction). A number is
/// loaded from the tape's table of numbers (`f64const` would be one value shared by every
/// use, kept in a register or spilled for the whole function).
fn leaf_value(
    b: &mut FunctionBuilder,
    args: &Args,
    consts: Value,
    layout: &Layout,
    k: usize,
    op: &Op,
) -> Option<Value> {
    let flags = MemFlagsData::trusted();
    Some(match *op {
        Op::X(i) => b.ins().load(types::F64, flags, args.x, offset(i)),
        Op::P(k) => b.ins().load(types::F64, flags, args.p, offset(k)),
        Op::V(i) => b.ins().load(types::F64, flags, args.v, offset(i)),
        Op::K(_) => b
            .ins()
            .load(types::F64, flags, consts, offset(layout.slot[k])),
        _ => return None,
    })
}

/// The byte offset of element `i` of an `f64` array.
pub(crate) fn offset(i: u32) -> i32 {
    (i as i64 * 8).min(i32::MAX as i64) as i32
}

/// An import the tape needs was not declared (a flaw of this crate, reported as an error).
fn missing() -> JitError {
    JitError::Codegen("a shim of stirling-jit was not declared".into())
}

/// Declare the shims the tape calls (only those).
pub(crate) fn declare_imports(
    module: &mut JITModule,
    func: &mut cranelift_codegen::ir::Function,
    ops: &[Op],
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
    for op in ops {
        match *op {
            Op::Func(f, _) if inline(f) => {}
            Op::Func(Func::Tanh, _)
                if imports.tanh_keep && !imports.funcs.iter().any(|&(g, _)| g == Func::Tanh) =>
            {
                let id =
                    module.declare_function(TANH_KEEP, Linkage::Local, &keep_signature(module))?;
                let r = module.declare_func_in_func(id, func);
                imports.funcs.push((Func::Tanh, r));
            }
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

/// The symbol of the trampoline to `tanh`'s shim that keeps every register
/// ([`define_tanh_keep`]).
pub(crate) const TANH_KEEP: &str = "stirling_tanh_keep";

/// The signature of [`TANH_KEEP`]: `(a, out)`, `tanh(a)` stored to `*out`, every register
/// kept (Cranelift's `preserve_all` convention, which has no return values).
fn keep_signature(module: &JITModule) -> Signature {
    let ptr = module.target_config().pointer_type();
    let mut s = Signature::new(CallConv::PreserveAll);
    s.params.push(AbiParam::new(types::F64));
    s.params.push(AbiParam::new(ptr));
    s
}

/// Define [`TANH_KEEP`] in `module`: it calls `tanh`'s shim (the C convention) and, being
/// `preserve_all`, saves and restores every register that call may clobber, so that the
/// code calling it (in a cold block) keeps its values in registers across the call.
pub(crate) fn define_tanh_keep(module: &mut JITModule) -> Result<(), JitError> {
    let sig = keep_signature(module);
    let id = module.declare_function(TANH_KEEP, Linkage::Local, &sig)?;
    let mut ctx = module.make_context();
    ctx.func.signature = sig;
    let mut unary = module.make_signature();
    unary.params.push(AbiParam::new(types::F64));
    unary.returns.push(AbiParam::new(types::F64));
    let shim = module.declare_function(shims::name(Func::Tanh), Linkage::Import, &unary)?;
    let shim = module.declare_func_in_func(shim, &mut ctx.func);
    let mut fctx = FunctionBuilderContext::new();
    let mut b = FunctionBuilder::new(&mut ctx.func, &mut fctx);
    let block = b.create_block();
    b.append_block_params_for_function_params(block);
    b.switch_to_block(block);
    b.seal_block(block);
    let (a, out) = (b.block_params(block)[0], b.block_params(block)[1]);
    let v = call(&mut b, shim, &[a]);
    b.ins().store(MemFlagsData::trusted(), v, out, 0);
    b.ins().return_(&[]);
    b.finalize(module.target_config());
    module.define_function(id, &mut ctx)?;
    module.clear_context(&mut ctx);
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
        Func::Tanh => match imports.funcs.iter().find(|&&(g, _)| g == f) {
            Some(&(_, r)) => tanh(b, r, a, imports.tanh_keep),
            None => return Err(missing()),
        },
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

/// `tanh(a)` as `stirling_dsl::expr::tanh` computes it (and as the macro's code inlines it):
/// saturated, `|a| >= 22`, it is `+-1` (the usual case, away from a flow reversal), inline;
/// else the shim is called in a cold block. A call makes the code spill every live `xmm`
/// register around it (all caller-saved), so calling on every `tanh` cost the JIT a spill
/// of everything at every link of every section.
fn tanh(b: &mut FunctionBuilder, shim: FuncRef, a: Value, keep: bool) -> Value {
    let abs = b.ins().fabs(a);
    let limit = b.ins().f64const(22.0);
    let saturated = b.ins().fcmp(FloatCC::GreaterThanOrEqual, abs, limit);
    let (sat, slow, join) = (b.create_block(), b.create_block(), b.create_block());
    b.append_block_param(join, types::F64);
    b.ins().brif(saturated, sat, &[], slow, &[]);
    b.seal_block(sat);
    b.seal_block(slow);
    b.switch_to_block(sat);
    let one = b.ins().f64const(1.0);
    let v = b.ins().fcopysign(one, a);
    b.ins().jump(join, &[BlockArg::Value(v)]);
    b.switch_to_block(slow);
    b.set_cold_block(slow);
    if !keep {
        let v = call(b, shim, &[a]);
        b.ins().jump(join, &[BlockArg::Value(v)]);
        b.seal_block(join);
        b.switch_to_block(join);
        return b.block_params(join)[0];
    }
    // through the trampoline that keeps every register (`define_tanh_keep`), its result in
    // a stack slot: a call of the shim itself clobbers every `xmm` register, so every value
    // live across a `tanh` was spilled (on the hot path too) and reloaded after it
    let slot = b.create_sized_stack_slot(StackSlotData::new(StackSlotKind::ExplicitSlot, 8, 3));
    // the functions' first parameter is a pointer (`x`)
    let ptr = b.func.signature.params[0].value_type;
    let at = b.ins().stack_addr(ptr, slot, 0);
    b.ins().call(shim, &[a, at]);
    let v = b.ins().stack_load(ptr, types::F64, slot, 0);
    b.ins().jump(join, &[BlockArg::Value(v)]);
    b.seal_block(join);
    b.switch_to_block(join);
    b.block_params(join)[0]
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
