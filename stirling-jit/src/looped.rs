//! The Cranelift IR of a tape whose interior sections repeat ([`Repeat`]): one function, the
//! instructions before the run straight, then one loop over the run's sections (the body
//! once, its state, parameter, output and table addresses advanced per iteration, the values
//! the next section reads carried in the scratch array), then the instructions after the run
//! straight, reading the last iteration's values from the loop's exit. The arithmetic is the
//! unrolled code's instruction for instruction (`build::arith`), so the results are the same
//! bits.

use std::collections::HashMap;

use cranelift_codegen::ir::condcodes::IntCC;
use cranelift_codegen::ir::{types, BlockArg, InstBuilder, MemFlagsData, Value};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::JITModule;
use cranelift_module::Module;
use stirling_dsl::compiled::{Arg, LoopLeaf, Op, Repeat, Step, Tape};

use crate::build::{arith, declare_imports, leaf, offset, operands, Imports};
use crate::JitError;

/// The numbers the code reads: the tape's and the body's (each once), then the table of the
/// iterations' own numbers (`Repeat::table`) from `table`.
pub(crate) struct Numbers {
    pub values: Box<[f64]>,
    index: HashMap<u64, u32>,
    table: usize,
}

impl Numbers {
    pub(crate) fn new(tape: &Tape, rep: &Repeat) -> Numbers {
        let mut values = Vec::new();
        let mut index = HashMap::new();
        let mut add = |c: f64| {
            index.entry(c.to_bits()).or_insert_with(|| {
                values.push(c);
                values.len() as u32 - 1
            });
        };
        for op in &tape.ops {
            if let Op::K(c) = *op {
                add(c);
            }
        }
        for s in &rep.body {
            let leaves = match *s {
                Step::Leaf(l) => [Some(l), None, None],
                Step::Op { args, .. } => args.map(|a| match a {
                    Arg::Leaf(l) => Some(l),
                    _ => None,
                }),
            };
            for l in leaves.into_iter().flatten() {
                if let LoopLeaf::K(c) = l {
                    add(c);
                }
            }
        }
        let table = values.len();
        values.extend(&rep.table);
        Numbers {
            values: values.into_boxed_slice(),
            index,
            table,
        }
    }

    fn slot(&self, c: f64) -> u32 {
        self.index.get(&c.to_bits()).copied().unwrap_or(0)
    }
}

/// The function's arguments: `x`, `p`, `v`, the two output buffers, the scratch array
/// (the values computed before the loop that it reads, [`Arg::Before`]).
struct Args {
    ptrs: [Value; 5],
    scratch: Value,
}

const X: usize = 0;
const P: usize = 1;
const V: usize = 2;
const HEAD: usize = 3;
const TAIL: usize = 4;

/// The code being built: the builder and what every part shares.
struct Emit<'a, 'b> {
    b: FunctionBuilder<'b>,
    tape: &'a Tape,
    rep: &'a Repeat,
    imports: Imports,
    args: Args,
    numbers: &'a Numbers,
    consts: Value,
    minus_zero: Option<Value>,
    /// `(register, output)`, sorted by register.
    stores: Vec<(u32, u32)>,
}

fn flags() -> MemFlagsData {
    MemFlagsData::trusted()
}

impl Emit<'_, '_> {
    fn load(&mut self, base: Value, i: u32) -> Value {
        self.b.ins().load(types::F64, flags(), base, offset(i))
    }

    /// Leaf instruction `op` of the straight parts, loaded.
    fn leaf(&mut self, op: Op) -> Value {
        match op {
            Op::X(i) => self.load(self.args.ptrs[X], i),
            Op::P(k) => self.load(self.args.ptrs[P], k),
            Op::V(i) => self.load(self.args.ptrs[V], i),
            Op::K(c) => self.load(self.consts, self.numbers.slot(c)),
            _ => self.consts,
        }
    }

    /// Store `val` as output `out` (to the first or the second buffer), `moved`: the
    /// buffers' addresses in this iteration (the straight parts: the arguments).
    fn store(&mut self, val: Value, out: u32, moved: Option<(Value, Value)>) {
        let head = self.tape.head() as u32;
        let (h, t) = moved.unwrap_or((self.args.ptrs[HEAD], self.args.ptrs[TAIL]));
        let (base, at) = if out < head {
            (h, out)
        } else {
            (t, out - head)
        };
        self.b.ins().store(flags(), val, base, offset(at));
    }

    /// Instructions `range` of the tape, straight; `value(q)`: a register computed elsewhere.
    fn straight(
        &mut self,
        range: std::ops::Range<usize>,
        vals: &mut [Option<Value>],
        exit: &HashMap<usize, Exit>,
    ) -> Result<(), JitError> {
        let mut s = self
            .stores
            .partition_point(|&(r, _)| (r as usize) < range.start);
        for k in range {
            let op = self.tape.ops[k];
            let stored = self.stores.get(s).is_some_and(|&(r, _)| r as usize == k);
            let val = if leaf(&op) {
                if !stored {
                    continue;
                }
                self.leaf(op)
            } else {
                let (a, count) = operands(&op);
                let x = self.reg(a[0] as usize, vals, exit)?;
                if count == 3 {
                    let y = self.reg(a[1] as usize, vals, exit)?;
                    let z = self.reg(a[2] as usize, vals, exit)?;
                    crate::build::fused(&mut self.b, op, x, y, z)
                } else {
                    let (x, y) = if count == 2 {
                        let y = self.reg(a[1] as usize, vals, exit)?;
                        let mem =
                            |q: u32| leaf(&self.tape.ops[q as usize]) || vals[q as usize].is_none();
                        commuted(op, x, y, [mem(a[0]), mem(a[1])])
                    } else {
                        (x, x)
                    };
                    arith(&mut self.b, &self.imports, &mut self.minus_zero, op, x, y)?
                }
            };
            vals[k] = Some(val);
            while let Some(&(r, out)) = self.stores.get(s) {
                if r as usize != k {
                    break;
                }
                self.store(val, out, None);
                s += 1;
            }
        }
        Ok(())
    }

    /// Register `q` read by a straight part.
    fn reg(
        &mut self,
        q: usize,
        vals: &[Option<Value>],
        exit: &HashMap<usize, Exit>,
    ) -> Result<Value, JitError> {
        let op = self.tape.ops[q];
        if leaf(&op) {
            return Ok(self.leaf(op));
        }
        if let Some(v) = vals[q] {
            return Ok(v);
        }
        // the last iteration's values: loaded at each use, as the leaves are
        match exit.get(&q) {
            Some(&Exit::Slot(k)) => Ok(self.load(self.args.scratch, k)),
            Some(&Exit::Carried(buf, c)) => Ok(self.load(buf, c)),
            None => Err(JitError::Codegen(format!(
                "register {q} read before it is computed"
            ))),
        }
    }
}

/// The addresses one iteration reads and writes at, each computed once per iteration.
struct Moved {
    i: Value,
    cache: HashMap<(usize, i64), Value>,
}

impl Moved {
    /// `base + i * step` elements of 8 bytes.
    fn at(&mut self, e: &mut Emit, base: Value, key: usize, step: i64) -> Value {
        if step == 0 {
            return base;
        }
        let i = self.i;
        *self.cache.entry((key, step)).or_insert_with(|| {
            let by = e.b.ins().imul_imm_s(i, step * 8);
            e.b.ins().iadd(base, by)
        })
    }
}

/// The value of loop leaf `l` in the iteration `m`.
fn loop_leaf(e: &mut Emit, m: &mut Moved, l: LoopLeaf) -> Value {
    let (key, base, at, step) = match l {
        LoopLeaf::X { base, step } => (X, e.args.ptrs[X], base, step),
        LoopLeaf::P { base, step } => (P, e.args.ptrs[P], base, step),
        LoopLeaf::V { base, step } => (V, e.args.ptrs[V], base, step),
        LoopLeaf::K(c) => (0, e.consts, e.numbers.slot(c), 0),
        LoopLeaf::Table(col) => {
            let at = (e.numbers.table + col as usize) as u32;
            (5, e.consts, at, e.rep.cols as i64)
        }
    };
    let ptr = m.at(e, base, key, step);
    e.load(ptr, at)
}

/// Fill `func` (its signature set: `x`, `p`, `v`, the two output buffers, the scratch
/// array, the numbers' table) with the looped code of `tape`.
pub(crate) fn function(
    module: &mut JITModule,
    func: &mut cranelift_codegen::ir::Function,
    tape: &Tape,
    rep: &Repeat,
    numbers: &Numbers,
) -> Result<(), JitError> {
    let mut fctx = FunctionBuilderContext::new();
    let mut imports = Imports {
        funcs: Vec::new(),
        powf: None,
        tanh_keep: true,
    };
    declare_imports(module, func, &tape.ops, &mut imports)?;
    let config = module.target_config();
    let mut b = FunctionBuilder::new(func, &mut fctx);
    let entry = b.create_block();
    b.append_block_params_for_function_params(entry);
    b.switch_to_block(entry);
    b.seal_block(entry);
    let a = b.block_params(entry).to_vec();
    // the numbers' address: the last argument (`build::function`)
    let consts = a[crate::tape::ARGS - 1];
    let mut stores: Vec<(u32, u32)> = (0..tape.outputs.len() as u32)
        .map(|k| (tape.outputs[k as usize], k))
        .collect();
    let spread = spread(tape, rep);
    if !spread.is_empty() {
        let mut moved = std::collections::HashSet::new();
        for &(_, o, step) in &spread {
            for i in 0..rep.count as u32 {
                moved.insert(o + i * step);
            }
        }
        stores.retain(|&(_, k)| !moved.contains(&k));
    }
    stores.sort_unstable();
    let mut e = Emit {
        b,
        tape,
        rep,
        imports,
        args: Args {
            ptrs: [a[0], a[1], a[2], a[3], a[4]],
            scratch: a[5],
        },
        numbers,
        consts,
        minus_zero: None,
        stores,
    };
    let mut vals: Vec<Option<Value>> = vec![None; tape.ops.len()];
    let none = HashMap::new();
    e.straight(0..rep.start, &mut vals, &none)?;
    let exit = body(&mut e, &vals)?;
    e.straight(rep.end()..tape.ops.len(), &mut vals, &exit)?;
    e.b.ins().return_(&[]);
    e.b.finalize(config);
    Ok(())
}

/// The body instructions the next iteration reads (`Arg::Prev`), with the register each
/// reads in the first, in order.
pub(crate) fn carried(rep: &Repeat) -> Vec<(u32, u32)> {
    let mut c: Vec<(u32, u32)> = Vec::new();
    for s in &rep.body {
        if let Step::Op { args, .. } = s {
            for a in args {
                if let Arg::Prev { t, init } = *a {
                    if !c.iter().any(|&(u, _)| u == t) {
                        c.push((t, init));
                    }
                }
            }
        }
    }
    c.sort_unstable();
    c
}

/// The registers computed before the loop that the body reads ([`Arg::Before`]), each
/// given a slot of the scratch array in this order.
pub(crate) fn before(rep: &Repeat) -> Vec<u32> {
    let mut v: Vec<u32> = Vec::new();
    for s in &rep.body {
        if let Step::Op { args, .. } = s {
            for a in args {
                if let Arg::Before(r) = *a {
                    v.push(r);
                }
            }
        }
    }
    v.sort_unstable();
    v.dedup();
    v
}

/// The body instructions of the last iteration the code after the loop reads.
pub(crate) fn live_out(tape: &Tape, rep: &Repeat) -> Vec<u32> {
    let last = rep.end() - rep.len;
    let mut v: Vec<u32> = Vec::new();
    for op in &tape.ops[rep.end()..] {
        let (a, count) = operands(op);
        for &q in &a[..count] {
            let q = q as usize;
            if (last..rep.end()).contains(&q) && !leaf(&tape.ops[q]) {
                v.push((q - last) as u32);
            }
        }
    }
    v.sort_unstable();
    v.dedup();
    v
}

/// The length of the scratch array of the looped code: the values from before the loop,
/// two buffers of the carried values (this iteration's and the next one's, swapped per
/// iteration), and the last iteration's values the code after the loop reads.
pub(crate) fn scratch_len(tape: &Tape, rep: &Repeat) -> usize {
    before(rep).len() + 2 * carried(rep).len() + live_out(tape, rep).len() + spread(tape, rep).len()
}

/// The outputs of a register computed before the loop that one per iteration stores:
/// `(register, output, step)`, the register's value is output `output + i * step` for every
/// iteration `i` (each run of `rep.count` outputs of one register evenly spaced, in the same
/// buffer). Stored by the straight part before the loop (e.g. a Jacobian entry every section
/// has, the same number in each), they were a pass over the output buffer of its own, and at
/// n = 1000 the buffer (72 KB) no longer fits the level-1 cache between that pass and the
/// loop's; stored in the loop, each goes to the cache line the iteration writes anyway.
pub(crate) fn spread(tape: &Tape, rep: &Repeat) -> Vec<(u32, u32, u32)> {
    let head = tape.head() as u32;
    let mut by_reg: HashMap<u32, Vec<u32>> = HashMap::new();
    for (k, &r) in tape.outputs.iter().enumerate() {
        if (r as usize) < rep.start {
            by_reg.entry(r).or_default().push(k as u32);
        }
    }
    let n = rep.count;
    let mut v = Vec::new();
    for (r, mut outs) in by_reg {
        if n < 2 || outs.len() < n {
            continue;
        }
        outs.sort_unstable();
        let mut i = 0;
        while i + n <= outs.len() {
            let w = &outs[i..i + n];
            let step = w[1] - w[0];
            let even = step > 0 && w.windows(2).all(|p| p[1] - p[0] == step);
            if even && (w[n - 1] < head || w[0] >= head) {
                v.push((r, w[0], step));
                i += n;
            } else {
                i += 1;
            }
        }
    }
    v.sort_unstable();
    v
}

/// Where the code after the loop finds a value of the last iteration.
#[derive(Clone, Copy)]
pub(crate) enum Exit {
    /// Slot `k` of the scratch array.
    Slot(u32),
    /// Slot `k` of the carried buffer the last iteration wrote (its address `Value`).
    Carried(Value, u32),
}

/// The loop; where the code after it finds the registers of its last iteration that it
/// reads, by register.
fn body(e: &mut Emit, vals: &[Option<Value>]) -> Result<HashMap<usize, Exit>, JitError> {
    let rep = e.rep;
    let carried = carried(rep);
    let outs = live_out(e.tape, rep);
    let ptr = e.b.func.dfg.value_type(e.args.scratch);
    let lp = e.b.create_block();
    let i = e.b.append_block_param(lp, types::I64);
    // the carried values: read from `cur`, written to `nxt` as soon as they are computed
    // (kept in a register to the end of the body for a later read of the previous one,
    // they were spilled, stored and reloaded), the two swapped per iteration
    let cur = e.b.append_block_param(lp, ptr);
    let nxt = e.b.append_block_param(lp, ptr);
    let exit = e.b.create_block();
    let last_buf = e.b.append_block_param(exit, ptr);
    // the values computed before the loop go to the scratch array, read where they are used
    // (a memory operand of their user): kept in registers across the loop they were
    // spilled, and reloaded before each use, an instruction more per use
    let before = before(rep);
    for (k, &r) in before.iter().enumerate() {
        let v = vals[r as usize]
            .ok_or_else(|| JitError::Codegen(format!("loop reads register {r} unset")))?;
        e.b.ins()
            .store(flags(), v, e.args.scratch, offset(k as u32));
    }
    let zero = e.b.ins().iconst(types::I64, 0);
    let nc = carried.len() as u32;
    let buf_a =
        e.b.ins()
            .iadd_imm_s(e.args.scratch, before.len() as i64 * 8);
    let buf_b = e.b.ins().iadd_imm_s(buf_a, nc as i64 * 8);
    // the last iteration's values the code after the loop reads (other than carried ones):
    // stored as computed, read where used (as exit block parameters they were live, and
    // spilled, to the end of the body)
    let out_base = before.len() as u32 + 2 * nc;
    let mut out_slot: HashMap<u32, Exit> = HashMap::new();
    let mut k = 0;
    for &t in &outs {
        if let Some(c) = carried.iter().position(|&(w, _)| w == t) {
            out_slot.insert(t, Exit::Carried(last_buf, c as u32));
        } else {
            out_slot.insert(t, Exit::Slot(out_base + k));
            k += 1;
        }
    }
    for (c, &(_, r)) in carried.iter().enumerate() {
        let v = vals[r as usize]
            .ok_or_else(|| JitError::Codegen(format!("loop reads register {r} unset")))?;
        e.b.ins().store(flags(), v, buf_a, offset(c as u32));
    }
    // the values before the loop that each iteration stores (`spread`): to the scratch
    // array after the last iteration's values (a number: loaded from the table in the loop)
    let spread = spread(e.tape, rep);
    let spread_base = out_base + k;
    for (j, &(r, ..)) in spread.iter().enumerate() {
        if !leaf(&e.tape.ops[r as usize]) {
            let v = vals[r as usize]
                .ok_or_else(|| JitError::Codegen(format!("loop stores register {r} unset")))?;
            e.b.ins()
                .store(flags(), v, e.args.scratch, offset(spread_base + j as u32));
        }
    }
    e.b.ins().jump(
        lp,
        &[
            BlockArg::Value(zero),
            BlockArg::Value(buf_a),
            BlockArg::Value(buf_b),
        ],
    );
    e.b.switch_to_block(lp);
    let mut m = Moved {
        i,
        cache: HashMap::new(),
    };
    let mut own: Vec<Option<Value>> = vec![None; rep.len];
    let mut s = 0;
    for (t, step) in rep.body.iter().enumerate() {
        let stored = rep.stores.get(s).is_some_and(|&(u, ..)| u as usize == t);
        let live = out_slot.contains_key(&(t as u32));
        let val = match *step {
            Step::Leaf(l) => {
                if !stored && !live {
                    continue;
                }
                loop_leaf(e, &mut m, l)
            }
            Step::Op { op, args } => {
                let (_, count) = operands(&op);
                let mut v = [e.consts; 3];
                let mut mem = [false; 3];
                for k in 0..count {
                    v[k] = match args[k] {
                        Arg::Leaf(l) => {
                            mem[k] = true;
                            loop_leaf(e, &mut m, l)
                        }
                        Arg::Before(r) => {
                            mem[k] = true;
                            let slot = before.binary_search(&r).unwrap_or(0);
                            e.load(e.args.scratch, slot as u32)
                        }
                        Arg::Body(u) => own[u as usize].ok_or_else(|| {
                            JitError::Codegen(format!("body reads instruction {u} unset"))
                        })?,
                        Arg::Prev { t: u, .. } => {
                            mem[k] = true;
                            let c = carried.iter().position(|&(w, _)| w == u).unwrap_or(0);
                            e.load(cur, c as u32)
                        }
                    };
                }
                if count == 3 {
                    crate::build::fused(&mut e.b, op, v[0], v[1], v[2])
                } else {
                    let (x, y) = if count == 2 {
                        commuted(op, v[0], v[1], [mem[0], mem[1]])
                    } else {
                        (v[0], v[0])
                    };
                    arith(&mut e.b, &e.imports, &mut e.minus_zero, op, x, y)?
                }
            }
        };
        own[t] = Some(val);
        if let Some(c) = carried.iter().position(|&(w, _)| w as usize == t) {
            e.b.ins().store(flags(), val, nxt, offset(c as u32));
        }
        if let Some(&Exit::Slot(k)) = out_slot.get(&(t as u32)) {
            e.b.ins().store(flags(), val, e.args.scratch, offset(k));
        }
        while let Some(&(u, out, step)) = rep.stores.get(s) {
            if u as usize != t {
                break;
            }
            let (h, tl) = (e.args.ptrs[HEAD], e.args.ptrs[TAIL]);
            let h = m.at(e, h, HEAD, step as i64);
            let tl = m.at(e, tl, TAIL, step as i64);
            e.store(val, out, Some((h, tl)));
            s += 1;
        }
    }
    for (j, &(r, out, step)) in spread.iter().enumerate() {
        let op = e.tape.ops[r as usize];
        let v = if leaf(&op) {
            e.leaf(op)
        } else {
            e.load(e.args.scratch, spread_base + j as u32)
        };
        let (h, tl) = (e.args.ptrs[HEAD], e.args.ptrs[TAIL]);
        let h = m.at(e, h, HEAD, step as i64);
        let tl = m.at(e, tl, TAIL, step as i64);
        e.store(v, out, Some((h, tl)));
    }
    let next = e.b.ins().iadd_imm_s(i, 1);
    let more =
        e.b.ins()
            .icmp_imm_s(IntCC::UnsignedLessThan, next, rep.count as i64);
    let again = [
        BlockArg::Value(next),
        BlockArg::Value(nxt),
        BlockArg::Value(cur),
    ];
    e.b.ins()
        .brif(more, lp, &again, exit, &[BlockArg::Value(nxt)]);
    e.b.seal_block(lp);
    e.b.seal_block(exit);
    e.b.switch_to_block(exit);
    let last = rep.end() - rep.len;
    Ok(out_slot
        .into_iter()
        .map(|(t, x)| (last + t as usize, x))
        .collect())
}

/// The operands of the binary `op` in the order to emit them: a commutative operation
/// (`+`, `*`: the same bits either way) with its first operand read from memory and its
/// second not takes them swapped, so that the load becomes the instruction's memory operand
/// (x86 folds a load into the second operand only) rather than a load into a register.
pub(crate) fn commuted(op: Op, a: Value, b: Value, mem: [bool; 2]) -> (Value, Value) {
    match op {
        Op::Add(..) | Op::Mul(..) if mem[0] && !mem[1] => (b, a),
        _ => (a, b),
    }
}
