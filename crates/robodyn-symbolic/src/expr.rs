//! Expression trees over named symbols with exact rational constants.
//!
//! Expressions are immutable and shared (`Arc`), built through canonicalising constructors so that
//! trivial algebra disappears as soon as an expression is formed: sums and products are flattened,
//! numeric constants are folded, like terms are collected (`2*x + 3*x = 5*x`), powers of the same
//! base are merged, and `sin`/`cos` of rational multiples of pi/2 are evaluated exactly.

use num_rational::Rational64;
use num_traits::{CheckedAdd, CheckedMul, One, Signed, ToPrimitive, Zero};
use std::cmp::Ordering;
use std::collections::HashMap;
use std::fmt;
use std::sync::Arc;

/// Elementary functions an expression may contain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Func {
    /// Sine.
    Sin,
    /// Cosine.
    Cos,
    /// Tangent.
    Tan,
    /// Square root.
    Sqrt,
    /// Absolute value.
    Abs,
    /// sign(x): -1, 0 or 1 (used for Coulomb friction).
    Sign,
}

impl Func {
    /// The name in expressions and generated code (`sin`, `sqrt`...).
    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Sqrt => "sqrt",
            Func::Abs => "abs",
            Func::Sign => "sign",
        }
    }

    /// The function of a name (`sin`, `Sin` or `SIN`...), if it is one.
    pub fn from_name(name: &str) -> Option<Func> {
        Some(match name {
            "sin" | "Sin" | "SIN" => Func::Sin,
            "cos" | "Cos" | "COS" => Func::Cos,
            "tan" | "Tan" | "TAN" => Func::Tan,
            "sqrt" | "Sqrt" | "SQRT" => Func::Sqrt,
            "abs" | "Abs" | "ABS" => Func::Abs,
            "sign" | "Sign" | "SIGN" => Func::Sign,
            _ => return None,
        })
    }

    /// The function's value at `x`.
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Sqrt => x.sqrt(),
            Func::Abs => x.abs(),
            Func::Sign => {
                if x > 0.0 {
                    1.0
                } else if x < 0.0 {
                    -1.0
                } else {
                    0.0
                }
            }
        }
    }
}

/// A node of an expression tree. Build nodes through [`Expr`]'s constructors, never directly,
/// so that the canonical form holds.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    /// An exact rational number.
    Rational(Rational64),
    /// An inexact number (only for values that are not representable as a small rational).
    Float(f64),
    /// The constant pi.
    Pi,
    /// A named symbol (`d3`, `RL4`, `XX1`, `th2`...).
    Symbol(String),
    /// A sum of at least two terms, canonically ordered, at most one numeric term (first).
    Add(Vec<Expr>),
    /// A product of at least two factors, canonically ordered, at most one numeric factor (first).
    Mul(Vec<Expr>),
    /// base ^ exponent with an integer exponent other than 0 and 1.
    Pow(Expr, i32),
    /// An elementary function.
    Func(Func, Expr),
    /// atan2(y, x): the angle of the point (x, y), in (-pi, pi].
    Atan2(Expr, Expr),
}

/// A shared, immutable symbolic expression.
///
/// Each node memoizes its structural hash and its depth when it is built, so that hashing (the
/// common-subexpression passes hash every sub-node) costs O(1) and deep trees can be handled
/// without recursion: drop is iterative and the recursive walks grow their stack on demand.
#[derive(Clone)]
pub struct Expr(Arc<Inner>);

/// A node with its memoized structural hash and depth (a leaf has depth 1).
struct Inner {
    node: Node,
    hash: u64,
    depth: u32,
}

/// Run a recursive step of a walk over an expression, on a fresh heap-allocated stack segment
/// when the current one runs low: the depth of an expression is not bounded (a long serial
/// chain's unnamed expressions nest as deep as the chain is long), a thread's stack is.
#[inline]
pub(crate) fn grow<R>(f: impl FnOnce() -> R) -> R {
    stacker::maybe_grow(128 * 1024, 4 * 1024 * 1024, f)
}

/// Error while evaluating an expression numerically.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// A symbol has no value.
    #[error("unknown symbol `{0}`")]
    UnknownSymbol(String),
    /// The value is NaN or infinite (the expression, printed, is given).
    #[error("expression `{0}` does not evaluate to a finite number")]
    NotFinite(String),
}

impl fmt::Debug for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Expr({self})")
    }
}

impl Default for Expr {
    fn default() -> Self {
        Expr::zero()
    }
}

impl Expr {
    fn new(node: Node) -> Expr {
        let (hash, depth) = node_hash_depth(&node);
        Expr(Arc::new(Inner { node, hash, depth }))
    }

    /// The node behind this expression.
    pub fn node(&self) -> &Node {
        &self.0.node
    }

    /// Depth of the expression tree (1 for a number or a symbol).
    pub fn depth(&self) -> u32 {
        self.0.depth
    }

    /// The number 0.
    pub fn zero() -> Expr {
        Expr::rational(Rational64::zero())
    }

    /// The number 1.
    pub fn one() -> Expr {
        Expr::rational(Rational64::one())
    }

    /// An integer.
    pub fn int(n: i64) -> Expr {
        Expr::rational(Rational64::from_integer(n))
    }

    /// An exact rational number.
    pub fn rational(r: Rational64) -> Expr {
        // a numerator or denominator of i64::MIN could not be negated: keep its value as a float
        if *r.numer() == i64::MIN || *r.denom() == i64::MIN {
            return Expr::new(Node::Float(r.to_f64().unwrap_or(f64::NAN)));
        }
        Expr::new(Node::Rational(r))
    }

    /// The constant pi.
    pub fn pi() -> Expr {
        Expr::new(Node::Pi)
    }

    /// A named symbol.
    pub fn symbol(name: impl Into<String>) -> Expr {
        Expr::new(Node::Symbol(name.into()))
    }

    /// A number: exact rational when `x` is an integer or a short decimal, float otherwise.
    pub fn num(x: f64) -> Expr {
        match f64_to_rational(x) {
            Some(r) => Expr::rational(r),
            None => Expr::new(Node::Float(x)),
        }
    }

    /// The numeric value if this expression is a number.
    pub fn as_f64(&self) -> Option<f64> {
        match self.node() {
            Node::Rational(r) => r.to_f64(),
            Node::Float(x) => Some(*x),
            _ => None,
        }
    }

    /// The exact value if this expression is a rational number.
    pub fn as_rational(&self) -> Option<Rational64> {
        match self.node() {
            Node::Rational(r) => Some(*r),
            _ => None,
        }
    }

    /// The name if this expression is a symbol.
    pub fn as_symbol(&self) -> Option<&str> {
        match self.node() {
            Node::Symbol(s) => Some(s),
            _ => None,
        }
    }

    /// True for the number 0.
    pub fn is_zero(&self) -> bool {
        match self.node() {
            Node::Rational(r) => r.is_zero(),
            Node::Float(x) => *x == 0.0,
            _ => false,
        }
    }

    /// True for the number 1.
    pub fn is_one(&self) -> bool {
        match self.node() {
            Node::Rational(r) => r.is_one(),
            Node::Float(x) => *x == 1.0,
            _ => false,
        }
    }

    /// True for a number (rational or float).
    pub fn is_number(&self) -> bool {
        matches!(self.node(), Node::Rational(_) | Node::Float(_))
    }

    /// True when the expression contains no symbol (numbers, pi and functions of them).
    pub fn is_constant(&self) -> bool {
        grow(|| match self.node() {
            Node::Rational(_) | Node::Float(_) | Node::Pi => true,
            Node::Symbol(_) => false,
            Node::Add(v) | Node::Mul(v) => v.iter().all(Expr::is_constant),
            Node::Pow(b, _) => b.is_constant(),
            Node::Func(_, a) => a.is_constant(),
            Node::Atan2(y, x) => y.is_constant() && x.is_constant(),
        })
    }

    /// Names of all symbols, sorted and without repetition.
    pub fn symbols(&self) -> Vec<String> {
        let mut out = Vec::new();
        self.collect_symbols(&mut out);
        out.sort();
        out.dedup();
        out
    }

    fn collect_symbols(&self, out: &mut Vec<String>) {
        self.for_each_symbol(&mut |s| out.push(s.to_string()));
    }

    /// Call `f` on every occurrence of a symbol, left to right.
    pub fn for_each_symbol(&self, f: &mut dyn FnMut(&str)) {
        grow(|| match self.node() {
            Node::Symbol(s) => f(s),
            Node::Add(v) | Node::Mul(v) => v.iter().for_each(|e| e.for_each_symbol(f)),
            Node::Pow(b, _) | Node::Func(_, b) => b.for_each_symbol(f),
            Node::Atan2(y, x) => {
                y.for_each_symbol(f);
                x.for_each_symbol(f)
            }
            _ => {}
        })
    }

    /// Whether symbol `name` occurs in the expression.
    pub fn depends_on(&self, name: &str) -> bool {
        grow(|| match self.node() {
            Node::Symbol(s) => s == name,
            Node::Add(v) | Node::Mul(v) => v.iter().any(|e| e.depends_on(name)),
            Node::Pow(b, _) | Node::Func(_, b) => b.depends_on(name),
            Node::Atan2(y, x) => y.depends_on(name) || x.depends_on(name),
            _ => false,
        })
    }

    /// Numeric value, with symbol values from `env`.
    pub fn eval(&self, env: &dyn Fn(&str) -> Option<f64>) -> Result<f64, EvalError> {
        let v = self.eval_inner(env)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(EvalError::NotFinite(self.to_string()))
        }
    }

    fn eval_inner(&self, env: &dyn Fn(&str) -> Option<f64>) -> Result<f64, EvalError> {
        grow(|| self.eval_node(env))
    }

    fn eval_node(&self, env: &dyn Fn(&str) -> Option<f64>) -> Result<f64, EvalError> {
        Ok(match self.node() {
            Node::Rational(r) => r.to_f64().unwrap_or(f64::NAN),
            Node::Float(x) => *x,
            Node::Pi => std::f64::consts::PI,
            Node::Symbol(s) => env(s).ok_or_else(|| EvalError::UnknownSymbol(s.clone()))?,
            Node::Add(v) => {
                let mut s = 0.0;
                for e in v {
                    s += e.eval_inner(env)?;
                }
                s
            }
            Node::Mul(v) => {
                let mut p = 1.0;
                for e in v {
                    p *= e.eval_inner(env)?;
                }
                p
            }
            Node::Pow(b, n) => b.eval_inner(env)?.powi(*n),
            Node::Func(f, a) => f.apply(a.eval_inner(env)?),
            Node::Atan2(y, x) => y.eval_inner(env)?.atan2(x.eval_inner(env)?),
        })
    }

    /// Replace symbols by expressions (symbols `f` maps to `None` are kept).
    pub fn substitute(&self, f: &dyn Fn(&str) -> Option<Expr>) -> Expr {
        self.map_children(&|e| e.substitute(f), &|s| f(s))
    }

    /// Rebuild the expression with `child` applied to every direct sub-expression (through the
    /// canonicalising constructors) and `leaf` to every symbol (`None` keeps it). The walk of
    /// the passes that rewrite a tree (substitution, factoring, replacement).
    pub fn map_children(
        &self,
        child: &dyn Fn(&Expr) -> Expr,
        leaf: &dyn Fn(&str) -> Option<Expr>,
    ) -> Expr {
        grow(|| match self.node() {
            Node::Symbol(s) => leaf(s).unwrap_or_else(|| self.clone()),
            Node::Add(v) => Expr::sum(v.iter().map(child)),
            Node::Mul(v) => Expr::product(v.iter().map(child)),
            Node::Pow(b, n) => child(b).powi(*n),
            Node::Func(fun, a) => Expr::func(*fun, child(a)),
            Node::Atan2(y, x) => Expr::atan2(child(y), child(x)),
            _ => self.clone(),
        })
    }

    /// Sum of terms, canonicalised.
    pub fn sum(terms: impl IntoIterator<Item = Expr>) -> Expr {
        // Flatten, split each term into (coefficient, rest), collect like rests.
        let mut constant = Rational64::zero();
        let mut float_constant = 0.0f64;
        let mut has_float = false;
        let mut parts: Vec<(Expr, Coef)> = Vec::new();
        // like terms: a linear search while the sum is short, an index beyond
        let mut index: HashMap<Expr, usize> = HashMap::new();
        let push = |e: &Expr, parts: &mut Vec<(Expr, Coef)>, index: &mut HashMap<Expr, usize>| {
            let (c, rest) = e.split_coefficient();
            // the index is empty (linear search) or complete: it is built whole when the
            // sum reaches LINEAR_SEARCH parts (a partial index missed like terms)
            let found = if index.is_empty() {
                parts.iter().position(|(r, _)| *r == rest)
            } else {
                index.get(&rest).copied()
            };
            match found {
                Some(i) => parts[i].1 = parts[i].1.add(c),
                None => {
                    if !index.is_empty() {
                        index.insert(rest.clone(), parts.len());
                    }
                    parts.push((rest, c));
                    if index.is_empty() && parts.len() >= LINEAR_SEARCH {
                        index.extend(parts.iter().enumerate().map(|(i, (r, _))| (r.clone(), i)));
                    }
                }
            }
        };
        let mut stack: Vec<Expr> = terms.into_iter().collect();
        stack.reverse();
        while let Some(t) = stack.pop() {
            match t.node() {
                Node::Add(v) => {
                    for e in v.iter().rev() {
                        stack.push(e.clone());
                    }
                }
                // -(a + b) as a term: its terms, negated (free: subtractions)
                Node::Mul(f)
                    if f.len() == 2
                        && f[0].as_rational() == Some(-Rational64::one())
                        && matches!(f[1].node(), Node::Add(_)) =>
                {
                    if let Node::Add(v) = f[1].node() {
                        for e in v.iter().rev() {
                            stack.push(-e.clone());
                        }
                    }
                }
                Node::Rational(r) => match constant.checked_add(r) {
                    Some(c) => constant = c,
                    None => {
                        float_constant += r.to_f64().unwrap_or(f64::NAN);
                        has_float = true;
                    }
                },
                Node::Float(x) => {
                    float_constant += *x;
                    has_float = true;
                }
                _ => push(&t, &mut parts, &mut index),
            }
        }
        let mut out: Vec<Expr> = parts
            .into_iter()
            .filter(|(_, c)| !c.is_zero())
            .map(|(rest, c)| c.times(rest))
            .collect();
        out.sort_by(cmp_terms);
        let num = if has_float {
            let v = float_constant + constant.to_f64().unwrap_or(0.0);
            if v == 0.0 {
                None
            } else {
                Some(Expr::num(v))
            }
        } else if constant.is_zero() {
            None
        } else {
            Some(Expr::rational(constant))
        };
        if let Some(n) = num {
            out.insert(0, n);
        }
        // a sum whose collected coefficient became 1 (`2*(a+b) - (a+b)`) is spliced in
        if out.iter().any(|t| matches!(t.node(), Node::Add(_))) {
            return Expr::sum(out);
        }
        match out.len() {
            0 => Expr::zero(),
            1 => out.pop().unwrap(),
            _ => Expr::new(Node::Add(out)),
        }
    }

    /// Product of factors, canonicalised.
    pub fn product(factors: impl IntoIterator<Item = Expr>) -> Expr {
        let mut coef = Coef::Rat(Rational64::one());
        let mut bases: Vec<(Expr, i32)> = Vec::new();
        let mut index: HashMap<Expr, usize> = HashMap::new();
        let mut stack: Vec<Expr> = factors.into_iter().collect();
        stack.reverse();
        while let Some(f) = stack.pop() {
            match f.node() {
                Node::Mul(v) => {
                    for e in v.iter().rev() {
                        stack.push(e.clone());
                    }
                }
                Node::Rational(r) => coef = coef.mul(Coef::Rat(*r)),
                Node::Float(x) => coef = coef.mul(Coef::Float(*x)),
                _ => {
                    let (b, n) = match f.node() {
                        Node::Pow(b, n) => (b.clone(), *n),
                        _ => (f.clone(), 1),
                    };
                    // empty (linear search) or complete index, as in `sum`
                    let found = if index.is_empty() {
                        bases.iter().position(|(x, _)| *x == b)
                    } else {
                        index.get(&b).copied()
                    };
                    // an exponent that would overflow or exceed MAX_POWER stays a separate factor
                    let merged = found.and_then(|i| {
                        let s = bases[i].1.checked_add(n)?;
                        (s.abs() <= MAX_POWER).then_some((i, s))
                    });
                    match merged {
                        Some((i, s)) => bases[i].1 = s,
                        None => {
                            if !index.is_empty() {
                                index.entry(b.clone()).or_insert(bases.len());
                            }
                            bases.push((b, n));
                            if index.is_empty() && bases.len() >= LINEAR_SEARCH {
                                // first occurrence of each base wins, as `position` finds it
                                for (i, (x, _)) in bases.iter().enumerate() {
                                    index.entry(x.clone()).or_insert(i);
                                }
                            }
                        }
                    }
                }
            }
            if coef.is_zero() {
                return Expr::zero();
            }
        }
        // powi may turn a factor into another base (sqrt(T)^2 = T, to merge with a T^-1 of the
        // same product), a number (sqrt(2)^2) or a product: then the factors are folded again
        let mut rebased = false;
        let mut out: Vec<Expr> = bases
            .into_iter()
            .filter(|(_, n)| *n != 0)
            .map(|(b, n)| {
                let p = b.powi(n);
                rebased |= match p.node() {
                    Node::Pow(x, _) => *x != b,
                    _ => p != b,
                };
                p
            })
            .collect();
        if rebased {
            return Expr::product(out.into_iter().chain(std::iter::once(coef.to_expr())));
        }
        out.sort_by(cmp_factors);
        if !coef.is_one() {
            out.insert(0, coef.to_expr());
        }
        match out.len() {
            0 => Expr::one(),
            1 => out.pop().unwrap(),
            _ => Expr::new(Node::Mul(out)),
        }
    }

    /// Integer power.
    pub fn powi(&self, n: i32) -> Expr {
        if n == 0 {
            return Expr::one();
        }
        if n == 1 {
            return self.clone();
        }
        match self.node() {
            Node::Rational(r) => {
                if r.is_zero() && n < 0 {
                    return Expr::new(Node::Float(f64::INFINITY));
                }
                match checked_pow(*r, n) {
                    Some(p) => Expr::rational(p),
                    None => Expr::num(r.to_f64().unwrap_or(f64::NAN).powi(n)),
                }
            }
            Node::Float(x) => Expr::num(x.powi(n)),
            // (x^m)^n = x^(mn) while |mn| <= MAX_POWER, else kept nested
            Node::Pow(b, m) => match i32::checked_mul(*m, n).filter(|k| k.abs() <= MAX_POWER) {
                Some(k) => b.powi(k),
                None => Expr::new(Node::Pow(self.clone(), n)),
            },
            Node::Mul(v) => Expr::product(v.iter().map(|f| f.powi(n))),
            Node::Func(Func::Sqrt, a) if n % 2 == 0 => a.powi(n / 2),
            // sqrt(a)^(2k+1) = a^k sqrt(a), sqrt(a)^-(2k+1) = a^-k / sqrt(a) (k >= 1): so that the
            // a^k merges with other powers of a in a product
            Node::Func(Func::Sqrt, a) if n.abs() >= 3 => {
                let k = n / 2;
                Expr::product([a.powi(k), self.powi(n - 2 * k)])
            }
            _ => Expr::new(Node::Pow(self.clone(), n)),
        }
    }

    /// Apply an elementary function, with exact values where known.
    pub fn func(f: Func, a: Expr) -> Expr {
        if let Some(x) = a.as_f64() {
            if matches!(a.node(), Node::Float(_)) {
                let k = (x / std::f64::consts::FRAC_PI_4).round();
                if k.abs() <= 8.0 && (x - k * std::f64::consts::FRAC_PI_4).abs() < 1e-15 * k.abs() {
                    if let Some(v) = odd_quarter_turn(f, k as i64) {
                        return v;
                    }
                }
                return Expr::num(f.apply(x));
            }
        }
        match f {
            Func::Sin | Func::Cos | Func::Tan => {
                // odd/even symmetry on a negative coefficient
                let (c, rest) = a.split_coefficient();
                if c.is_negative() {
                    let pos = c.neg().times(rest);
                    return match f {
                        Func::Cos => Expr::func(f, pos),
                        _ => -Expr::func(f, pos),
                    };
                }
                if let (Func::Sin | Func::Cos, Node::Add(terms)) = (f, a.node()) {
                    // sin/cos(x + k*pi/2) = +-sin/cos(x): shift the argument exactly
                    if let Some((i, k)) = terms
                        .iter()
                        .enumerate()
                        .find_map(|(i, t)| t.multiple_of_half_pi().map(|k| (i, k)))
                    {
                        let rest = Expr::sum(
                            terms
                                .iter()
                                .enumerate()
                                .filter(|(j, _)| *j != i)
                                .map(|(_, t)| t.clone()),
                        );
                        let k = k.rem_euclid(4);
                        let (g, neg) = match (f, k) {
                            (Func::Sin, 0) | (Func::Cos, 3) => (Func::Sin, false),
                            (Func::Sin, 1) | (Func::Cos, 0) => (Func::Cos, false),
                            (Func::Sin, 2) | (Func::Cos, 1) => (Func::Sin, true),
                            _ => (Func::Cos, true),
                        };
                        let v = Expr::func(g, rest);
                        return if neg { -v } else { v };
                    }
                }
                if let Some(k) = a.multiple_of_half_pi() {
                    // k * pi/2, exact values
                    let k = k.rem_euclid(4);
                    let (s, c) = [(0, 1), (1, 0), (0, -1), (-1, 0)][k as usize];
                    return match f {
                        Func::Sin => Expr::int(s),
                        Func::Cos => Expr::int(c),
                        Func::Tan => {
                            if c == 0 {
                                Expr::new(Node::Float(f64::INFINITY))
                            } else {
                                Expr::int(s / c)
                            }
                        }
                        _ => unreachable!(),
                    };
                }
                if let Some(v) = a
                    .multiple_of_quarter_pi()
                    .and_then(|k| odd_quarter_turn(f, k))
                {
                    return v;
                }
                Expr::new(Node::Func(f, a))
            }
            Func::Sqrt => match a.as_rational() {
                Some(r) if r >= Rational64::zero() => {
                    let (n, d) = (*r.numer(), *r.denom());
                    match (isqrt(n), isqrt(d)) {
                        (Some(a), Some(b)) => Expr::rational(Rational64::new(a, b)),
                        _ => Expr::new(Node::Func(f, Expr::rational(r))),
                    }
                }
                _ => Expr::new(Node::Func(f, a)),
            },
            Func::Abs | Func::Sign => match a.as_rational() {
                Some(r) => Expr::rational(if f == Func::Abs { r.abs() } else { r.signum() }),
                None => Expr::new(Node::Func(f, a)),
            },
        }
    }

    /// atan2(y, x), with exact values on the axes (y or x zero, the other a rational number) and
    /// a number when both arguments are floats.
    pub fn atan2(y: Expr, x: Expr) -> Expr {
        if let (Node::Float(_), Node::Float(_))
        | (Node::Float(_), Node::Rational(_))
        | (Node::Rational(_), Node::Float(_)) = (y.node(), x.node())
        {
            if let (Some(a), Some(b)) = (y.as_f64(), x.as_f64()) {
                return Expr::num(a.atan2(b));
            }
        }
        if let (Some(a), Some(b)) = (y.as_rational(), x.as_rational()) {
            let half_pi = || Expr::pi() / Expr::int(2);
            match (a.signum().to_integer(), b.signum().to_integer()) {
                (0, 1) => return Expr::zero(),
                (0, -1) => return Expr::pi(),
                (1, 0) => return half_pi(),
                (-1, 0) => return -half_pi(),
                _ => {}
            }
        }
        Expr::new(Node::Atan2(y, x))
    }

    /// sin of this expression.
    pub fn sin(&self) -> Expr {
        Expr::func(Func::Sin, self.clone())
    }

    /// cos of this expression.
    pub fn cos(&self) -> Expr {
        Expr::func(Func::Cos, self.clone())
    }

    /// Square root of this expression.
    pub fn sqrt(&self) -> Expr {
        Expr::func(Func::Sqrt, self.clone())
    }

    /// If the expression is k*pi/4 for an integer k, return k.
    fn multiple_of_quarter_pi(&self) -> Option<i64> {
        let (c, rest) = self.split_coefficient();
        match (c, rest.node()) {
            (Coef::Rat(r), Node::Pi) => {
                let k = r.checked_mul(&Rational64::from_integer(4))?;
                k.is_integer().then(|| k.to_integer())
            }
            _ => None,
        }
    }

    /// If the expression is k*pi/2 for an integer k, return k.
    fn multiple_of_half_pi(&self) -> Option<i64> {
        if self.is_zero() {
            return Some(0);
        }
        self.multiple_of_quarter_pi()
            .filter(|k| k % 2 == 0)
            .map(|k| k / 2)
    }

    /// Split into numeric coefficient and the rest: `3*x*y` -> (3, x*y).
    fn split_coefficient(&self) -> (Coef, Expr) {
        match self.node() {
            Node::Rational(r) => (Coef::Rat(*r), Expr::one()),
            Node::Float(x) => (Coef::Float(*x), Expr::one()),
            Node::Mul(v) if v[0].is_number() => {
                let c = match v[0].node() {
                    Node::Rational(r) => Coef::Rat(*r),
                    Node::Float(x) => Coef::Float(*x),
                    _ => unreachable!(),
                };
                let rest = if v.len() == 2 {
                    v[1].clone()
                } else {
                    Expr::new(Node::Mul(v[1..].to_vec()))
                };
                (c, rest)
            }
            _ => (Coef::Rat(Rational64::one()), self.clone()),
        }
    }

    /// Expand products of sums (distributes multiplication over addition, positive integer powers
    /// of sums included). A product or power whose expansion would exceed `EXPAND_TERMS`
    /// (100 000) terms is kept as it is (its factors expanded): the result is always equal to
    /// `self`, and a file's `(a + b + ... + h)^54` cannot take minutes and gigabytes.
    pub fn expand(&self) -> Expr {
        grow(|| self.expand_node())
    }

    fn expand_node(&self) -> Expr {
        match self.node() {
            Node::Add(v) => Expr::sum(v.iter().map(Expr::expand)),
            Node::Mul(v) => {
                let factors: Vec<Expr> = v.iter().map(Expr::expand).collect();
                let mut size = 1usize;
                for f in &factors {
                    size = size.saturating_mul(term_count(f));
                }
                if size > EXPAND_TERMS {
                    return Expr::product(factors);
                }
                let mut acc = Expr::one();
                for f in &factors {
                    acc = distribute(&acc, f);
                }
                acc
            }
            Node::Pow(b, n) if *n > 1 => {
                let b = b.expand();
                let k = term_count(&b);
                if k > 1 && k.checked_pow(*n as u32).is_none_or(|t| t > EXPAND_TERMS) {
                    return b.powi(*n);
                }
                if matches!(b.node(), Node::Add(_)) {
                    // multiplied out term by term: a product of equal sums would fold back
                    // into the power
                    let mut r = b.clone();
                    for _ in 1..*n {
                        r = distribute(&r, &b);
                    }
                    r
                } else {
                    b.powi(*n)
                }
            }
            Node::Func(f, a) => Expr::func(*f, a.expand()),
            Node::Atan2(y, x) => Expr::atan2(y.expand(), x.expand()),
            _ => self.clone(),
        }
    }
}

/// Largest number of term products an expansion multiplies out (see [`Expr::expand`]).
pub const EXPAND_TERMS: usize = 100_000;

/// Number of terms of an expanded expression (1 unless it is a sum).
fn term_count(e: &Expr) -> usize {
    match e.node() {
        Node::Add(t) => t.len(),
        _ => 1,
    }
}

/// The product of two expanded expressions, multiplied out: the sum of the products of their
/// terms.
fn distribute(a: &Expr, b: &Expr) -> Expr {
    let terms = |e: &Expr| -> Vec<Expr> {
        match e.node() {
            Node::Add(t) => t.clone(),
            _ => vec![e.clone()],
        }
    };
    let (ta, tb) = (terms(a), terms(b));
    Expr::sum(ta.iter().flat_map(|x| {
        tb.iter()
            .map(move |y| Expr::product([x.clone(), y.clone()]))
    }))
}

/// Largest exponent (in absolute value) a power merges to: `x^40*x^40` stays two factors and
/// `(x^40)^2` a power of a power, so that what prints reads back (the parser takes written
/// exponents up to this bound).
pub const MAX_POWER: i32 = 64;

/// Below this many terms (factors), a sum (product) finds like terms by a linear search.
const LINEAR_SEARCH: usize = 16;

/// sin, cos or tan of k*pi/4 for an odd k: +-1/sqrt(2) (one number for both, so that
/// `cos(pi/4)*x - sin(pi/4)*y` shares its factor) or +-1; `None` for an even k (the exact
/// values of [`Expr::func`]) or another function.
fn odd_quarter_turn(f: Func, k: i64) -> Option<Expr> {
    if k % 2 == 0 {
        return None;
    }
    let k = k.rem_euclid(8);
    let (sin_pos, cos_pos) = (k < 4, k == 1 || k == 7);
    let h = Expr::num(std::f64::consts::FRAC_1_SQRT_2);
    let signed = |pos: bool| if pos { h.clone() } else { -h.clone() };
    match f {
        Func::Sin => Some(signed(sin_pos)),
        Func::Cos => Some(signed(cos_pos)),
        Func::Tan => Some(Expr::int(if sin_pos == cos_pos { 1 } else { -1 })),
        _ => None,
    }
}

/// Numeric coefficient of a term: exact when possible.
#[derive(Clone, Copy, Debug)]
enum Coef {
    Rat(Rational64),
    Float(f64),
}

impl Coef {
    fn is_zero(self) -> bool {
        match self {
            Coef::Rat(r) => r.is_zero(),
            Coef::Float(x) => x == 0.0,
        }
    }
    fn is_one(self) -> bool {
        match self {
            Coef::Rat(r) => r.is_one(),
            Coef::Float(x) => x == 1.0,
        }
    }
    fn is_negative(self) -> bool {
        match self {
            Coef::Rat(r) => r.is_negative(),
            Coef::Float(x) => x < 0.0,
        }
    }
    fn neg(self) -> Coef {
        match self {
            Coef::Rat(r) => match r.numer().checked_neg() {
                Some(n) => Coef::Rat(Rational64::new_raw(n, *r.denom())),
                None => Coef::Float(-r.to_f64().unwrap_or(f64::NAN)),
            },
            Coef::Float(x) => Coef::Float(-x),
        }
    }
    fn f(self) -> f64 {
        match self {
            Coef::Rat(r) => r.to_f64().unwrap_or(f64::NAN),
            Coef::Float(x) => x,
        }
    }
    fn add(self, o: Coef) -> Coef {
        match (self, o) {
            (Coef::Rat(a), Coef::Rat(b)) => match a.checked_add(&b) {
                Some(s) => Coef::Rat(s),
                None => Coef::Float(self.f() + o.f()),
            },
            _ => Coef::Float(self.f() + o.f()),
        }
    }
    fn mul(self, o: Coef) -> Coef {
        match (self, o) {
            (Coef::Rat(a), Coef::Rat(b)) => match a.checked_mul(&b) {
                Some(s) => Coef::Rat(s),
                None => Coef::Float(self.f() * o.f()),
            },
            _ => Coef::Float(self.f() * o.f()),
        }
    }
    fn to_expr(self) -> Expr {
        match self {
            Coef::Rat(r) => Expr::rational(r),
            Coef::Float(x) => Expr::num(x),
        }
    }
    /// coefficient * rest as a canonical product (rest is not a number unless it is 1)
    fn times(self, rest: Expr) -> Expr {
        if rest.is_one() {
            return self.to_expr();
        }
        if self.is_one() {
            return rest;
        }
        let mut v = vec![self.to_expr()];
        match rest.node() {
            Node::Mul(f) => v.extend(f.iter().cloned()),
            _ => v.push(rest),
        }
        Expr::new(Node::Mul(v))
    }
}

fn checked_pow(r: Rational64, n: i32) -> Option<Rational64> {
    let base = if n < 0 {
        if r.is_zero() {
            return None;
        }
        r.recip()
    } else {
        r
    };
    let mut acc = Rational64::one();
    for _ in 0..n.unsigned_abs() {
        acc = acc.checked_mul(&base)?;
    }
    Some(acc)
}

fn isqrt(n: i64) -> Option<i64> {
    if n < 0 {
        return None;
    }
    let s = (n as f64).sqrt().round() as i64;
    (s.checked_mul(s) == Some(n)).then_some(s)
}

/// Exact rational for integers and decimals with few digits (as read from files).
fn f64_to_rational(x: f64) -> Option<Rational64> {
    if !x.is_finite() {
        return None;
    }
    for &den in &[
        1i64,
        10,
        100,
        1000,
        10_000,
        100_000,
        1_000_000,
        10_000_000,
        100_000_000,
        1_000_000_000,
    ] {
        let n = x * den as f64;
        if n.abs() < 1e15 && n == n.round() {
            let r = Rational64::new(n as i64, den);
            if r.to_f64() == Some(x) {
                return Some(r);
            }
        }
    }
    None
}

/// Rank used to order node kinds canonically.
fn kind_rank(e: &Expr) -> u8 {
    match e.node() {
        Node::Rational(_) | Node::Float(_) => 0,
        Node::Pi => 1,
        Node::Symbol(_) => 2,
        Node::Pow(..) => 3,
        Node::Mul(_) => 4,
        Node::Func(..) => 5,
        Node::Atan2(..) => 6,
        Node::Add(_) => 7,
    }
}

/// Total structural order, used for canonical ordering of sums and products.
pub fn cmp_expr(a: &Expr, b: &Expr) -> Ordering {
    if Arc::ptr_eq(&a.0, &b.0) {
        return Ordering::Equal;
    }
    grow(|| cmp_nodes(a, b))
}

fn cmp_nodes(a: &Expr, b: &Expr) -> Ordering {
    match (a.node(), b.node()) {
        (Node::Rational(x), Node::Rational(y)) => x.cmp(y),
        (Node::Float(x), Node::Float(y)) => x.total_cmp(y),
        // a rational and a float: by value, then the rational first (a total order with the two
        // arms above; comparing them as equal broke transitivity and made sorting panic)
        (Node::Rational(x), Node::Float(y)) => rational_f64(x).total_cmp(y).then(Ordering::Less),
        (Node::Float(x), Node::Rational(y)) => {
            x.total_cmp(&rational_f64(y)).then(Ordering::Greater)
        }
        (Node::Symbol(x), Node::Symbol(y)) => natural_cmp(x, y),
        (Node::Pow(b1, n1), Node::Pow(b2, n2)) => cmp_expr(b1, b2).then(n1.cmp(n2)),
        (Node::Func(f1, a1), Node::Func(f2, a2)) => cmp_expr(a1, a2).then(f1.cmp(f2)),
        (Node::Atan2(y1, x1), Node::Atan2(y2, x2)) => {
            cmp_expr(y1, y2).then_with(|| cmp_expr(x1, x2))
        }
        (Node::Add(x), Node::Add(y)) | (Node::Mul(x), Node::Mul(y)) => {
            for (p, q) in x.iter().zip(y) {
                let o = cmp_expr(p, q);
                if o != Ordering::Equal {
                    return o;
                }
            }
            x.len().cmp(&y.len())
        }
        _ => kind_rank(a).cmp(&kind_rank(b)),
    }
}

fn rational_f64(r: &Rational64) -> f64 {
    r.to_f64().unwrap_or(f64::NAN)
}

/// Key of a factor for ordering: its base.
fn factor_base(e: &Expr) -> &Expr {
    match e.node() {
        Node::Pow(b, _) => b,
        _ => e,
    }
}

fn cmp_factors(a: &Expr, b: &Expr) -> Ordering {
    cmp_expr(factor_base(a), factor_base(b)).then_with(|| cmp_expr(a, b))
}

/// Terms are ordered by their non-numeric part, so that `XX2 - YY2 + 3*d3` reads naturally.
fn cmp_terms(a: &Expr, b: &Expr) -> Ordering {
    let (_, ra) = a.split_coefficient();
    let (_, rb) = b.split_coefficient();
    let key = |e: &Expr| -> Expr {
        // order products by their first symbolic factor
        e.clone()
    };
    let (ka, kb) = (key(&ra), key(&rb));
    let first = |e: &Expr| -> Expr {
        match e.node() {
            Node::Mul(v) => factor_base(&v[0]).clone(),
            _ => factor_base(e).clone(),
        }
    };
    cmp_expr(&first(&ka), &first(&kb)).then_with(|| cmp_expr(&ka, &kb))
}

/// Compare names so that `M2 < M10` and `XX1 < XX2`.
fn natural_cmp(a: &str, b: &str) -> Ordering {
    fn split(s: &str) -> (&[u8], Option<u64>) {
        let i = s.trim_end_matches(|c: char| c.is_ascii_digit()).len();
        (&s.as_bytes()[..i], s[i..].parse::<u64>().ok())
    }
    let (pa, na) = split(a);
    let (pb, nb) = split(b);
    pa.cmp(pb).then(na.cmp(&nb)).then(a.cmp(b))
}

impl std::ops::Add for Expr {
    type Output = Expr;
    fn add(self, o: Expr) -> Expr {
        if self.is_zero() {
            return o;
        }
        if o.is_zero() {
            return self;
        }
        Expr::sum([self, o])
    }
}

impl std::ops::Sub for Expr {
    type Output = Expr;
    fn sub(self, o: Expr) -> Expr {
        if o.is_zero() {
            return self;
        }
        Expr::sum([self, -o])
    }
}

impl std::ops::Mul for Expr {
    type Output = Expr;
    fn mul(self, o: Expr) -> Expr {
        if self.is_zero() || o.is_zero() {
            return Expr::zero();
        }
        if self.is_one() {
            return o;
        }
        if o.is_one() {
            return self;
        }
        Expr::product([self, o])
    }
}

impl std::ops::Div for Expr {
    type Output = Expr;
    fn div(self, o: Expr) -> Expr {
        self * o.powi(-1)
    }
}

impl std::ops::Neg for Expr {
    type Output = Expr;
    fn neg(self) -> Expr {
        let (c, rest) = self.split_coefficient();
        c.neg().times(rest)
    }
}

macro_rules! ref_ops {
    ($($tr:ident $m:ident),*) => {$(
        impl std::ops::$tr<&Expr> for &Expr {
            type Output = Expr;
            fn $m(self, o: &Expr) -> Expr { std::ops::$tr::$m(self.clone(), o.clone()) }
        }
    )*};
}
ref_ops!(Add add, Sub sub, Mul mul, Div div);

impl std::ops::AddAssign for Expr {
    fn add_assign(&mut self, o: Expr) {
        *self = self.clone() + o;
    }
}
impl std::ops::SubAssign for Expr {
    fn sub_assign(&mut self, o: Expr) {
        *self = self.clone() - o;
    }
}
impl std::ops::MulAssign for Expr {
    fn mul_assign(&mut self, o: Expr) {
        *self = self.clone() * o;
    }
}
impl std::ops::DivAssign for Expr {
    fn div_assign(&mut self, o: Expr) {
        *self = self.clone() / o;
    }
}

impl From<f64> for Expr {
    fn from(x: f64) -> Expr {
        Expr::num(x)
    }
}
impl From<i64> for Expr {
    fn from(x: i64) -> Expr {
        Expr::int(x)
    }
}
impl From<&str> for Expr {
    fn from(s: &str) -> Expr {
        Expr::symbol(s)
    }
}

impl num_traits::Zero for Expr {
    fn zero() -> Expr {
        Expr::zero()
    }
    fn is_zero(&self) -> bool {
        Expr::is_zero(self)
    }
}

impl num_traits::One for Expr {
    fn one() -> Expr {
        Expr::one()
    }
}

/// Structural hash (floats by their bits), consistent with `PartialEq` for non-NaN values; used
/// by the program builder for common-subexpression sharing. Memoized: O(1).
impl std::hash::Hash for Expr {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        h.write_u64(self.0.hash)
    }
}

/// Structural equality; shared nodes and different memoized hashes answer at once.
impl PartialEq for Expr {
    fn eq(&self, o: &Expr) -> bool {
        Arc::ptr_eq(&self.0, &o.0)
            || (self.0.hash == o.0.hash
                && self.0.depth == o.0.depth
                && grow(|| self.0.node == o.0.node))
    }
}

impl Eq for Expr {}

/// The memoized hash and depth of a new node, from its children's.
fn node_hash_depth(node: &Node) -> (u64, u32) {
    use std::hash::{Hash, Hasher};
    let mut h = std::hash::DefaultHasher::new();
    std::mem::discriminant(node).hash(&mut h);
    let mut depth = 0u32;
    let mut child = |e: &Expr, h: &mut std::hash::DefaultHasher| {
        h.write_u64(e.0.hash);
        depth = depth.max(e.0.depth);
    };
    match node {
        Node::Rational(r) => r.hash(&mut h),
        // -0.0 == 0.0: hash them alike
        Node::Float(x) => (if *x == 0.0 { 0.0f64 } else { *x }).to_bits().hash(&mut h),
        Node::Pi => {}
        Node::Symbol(s) => s.hash(&mut h),
        Node::Add(v) | Node::Mul(v) => {
            v.len().hash(&mut h);
            v.iter().for_each(|e| child(e, &mut h));
        }
        Node::Pow(b, n) => {
            child(b, &mut h);
            n.hash(&mut h)
        }
        Node::Func(f, a) => {
            f.hash(&mut h);
            child(a, &mut h)
        }
        Node::Atan2(y, x) => {
            child(y, &mut h);
            child(x, &mut h)
        }
    }
    (h.finish(), depth.saturating_add(1))
}

/// Trees shallower than this are dropped by the compiler's (recursive) drop glue.
const SHALLOW: u32 = 64;

/// Deep trees are taken apart iteratively: the last owner of a node moves its children onto a
/// work list before the node goes, so dropping never recurses deeper than `SHALLOW` (64) levels.
impl Drop for Expr {
    fn drop(&mut self) {
        if self.0.depth < SHALLOW {
            return;
        }
        let mut work: Vec<Node> = Vec::new();
        let take = |e: &mut Expr, work: &mut Vec<Node>| {
            if e.0.depth >= SHALLOW {
                if let Some(inner) = Arc::get_mut(&mut e.0) {
                    work.push(std::mem::replace(&mut inner.node, Node::Pi));
                    inner.depth = 1;
                }
            }
        };
        take(self, &mut work);
        while let Some(node) = work.pop() {
            match node {
                Node::Add(v) | Node::Mul(v) => {
                    for mut e in v {
                        take(&mut e, &mut work);
                    }
                }
                Node::Pow(mut b, _) | Node::Func(_, mut b) => take(&mut b, &mut work),
                Node::Atan2(mut y, mut x) => {
                    take(&mut y, &mut work);
                    take(&mut x, &mut work);
                }
                _ => {}
            }
        }
    }
}
