//! The node type of the expression arena.
//!
//! Nodes refer to their children by [`Id`](crate::expr::node::Id); a child is always pushed before
//! its parent, so the arena's order is a valid evaluation (topological) order.

/// Index of a node in an [`crate::Arena`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Id(pub u32);

impl Id {
    /// Position in the arena.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Where an element of a state block is taken, relative to the section being assembled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum At {
    /// A scalar block (bodies, single CVs).
    Scalar,
    /// Element `j + offset` of an array block, `j` being the current section.
    Rel(i32),
    /// Element `0` of an array block.
    First,
    /// Element `n - 1` of an array block.
    Last,
}

/// A leaf symbol.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sym {
    /// Model parameter by index.
    Param(u32),
    /// State block `block`, element `at`.
    State(u32, At),
    /// The current section index `j` (0-based) as a number.
    Index,
    /// The run-time number of sections `n` as a number.
    Count,
    /// An external input channel (e.g. a force injected where the loop is broken).
    Input(u32),
    /// Reduction `k`: the sum over the sections `j = 0..n-1` of a template in an array's
    /// frame (a per-section link seen from its scalar end).
    Sum(u32),
}

/// Scalar functions of one argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func {
    Sqrt,
    Ln,
    Exp,
    Tanh,
    Abs,
    Sign,
    Sin,
    Cos,
}

impl Func {
    /// The Rust method name and the DSL function name.
    pub fn name(self) -> &'static str {
        match self {
            Func::Sqrt => "sqrt",
            Func::Ln => "ln",
            Func::Exp => "exp",
            Func::Tanh => "tanh",
            Func::Abs => "abs",
            Func::Sign => "signum",
            Func::Sin => "sin",
            Func::Cos => "cos",
        }
    }

    /// Look a function up by its DSL name.
    pub fn from_name(name: &str) -> Option<Func> {
        Some(match name {
            "sqrt" => Func::Sqrt,
            "ln" => Func::Ln,
            "exp" => Func::Exp,
            "tanh" => Func::Tanh,
            "abs" => Func::Abs,
            "sign" | "signum" => Func::Sign,
            "sin" => Func::Sin,
            "cos" => Func::Cos,
            _ => return None,
        })
    }

    /// Numeric value.
    pub fn apply(self, a: f64) -> f64 {
        match self {
            Func::Sqrt => a.sqrt(),
            Func::Ln => a.ln(),
            Func::Exp => a.exp(),
            Func::Tanh => super::tanh(a),
            Func::Abs => a.abs(),
            Func::Sign => sign(a),
            Func::Sin => a.sin(),
            Func::Cos => a.cos(),
        }
    }
}

/// Sign with `sign(0) = 0`, the convention of the generated code.
pub fn sign(a: f64) -> f64 {
    if a > 0.0 {
        1.0
    } else if a < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// One expression node.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// A constant, stored by its bits so that nodes hash.
    Const(u64),
    Sym(Sym),
    Add(Id, Id),
    Sub(Id, Id),
    Mul(Id, Id),
    Div(Id, Id),
    Neg(Id),
    Powi(Id, i32),
    Powf(Id, Id),
    Func(Func, Id),
    /// A named intermediate quantity: transparent for evaluation and differentiation,
    /// printed by name (its definition is listed separately).
    Named(u32, Id),
}

impl Node {
    /// The node's children, in order.
    pub fn children(&self) -> Vec<Id> {
        match *self {
            Node::Const(_) | Node::Sym(_) => vec![],
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) => vec![a, b],
            Node::Powf(a, b) => vec![a, b],
            Node::Neg(a) | Node::Powi(a, _) | Node::Func(_, a) | Node::Named(_, a) => vec![a],
        }
    }

    /// The same node over other children (`kids` in [`Node::children`] order).
    pub fn with_children(&self, kids: &[Id]) -> Node {
        match *self {
            Node::Const(_) | Node::Sym(_) => self.clone(),
            Node::Add(..) => Node::Add(kids[0], kids[1]),
            Node::Sub(..) => Node::Sub(kids[0], kids[1]),
            Node::Mul(..) => Node::Mul(kids[0], kids[1]),
            Node::Div(..) => Node::Div(kids[0], kids[1]),
            Node::Powf(..) => Node::Powf(kids[0], kids[1]),
            Node::Neg(_) => Node::Neg(kids[0]),
            Node::Powi(_, k) => Node::Powi(kids[0], k),
            Node::Func(f, _) => Node::Func(f, kids[0]),
            Node::Named(n, _) => Node::Named(n, kids[0]),
        }
    }
}
