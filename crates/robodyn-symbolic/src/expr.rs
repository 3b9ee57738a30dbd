//! Expression trees over named symbols with exact rational constants.
//!
//! Expressions are immutable and shared (`Arc`), built through canonicalising constructors so that
//! trivial algebra disappears as soon as an expression is formed: sums and products are flattened,
//! numeric constants are folded, like terms are collected (`2*x + 3*x = 5*x`), powers of the same
//! base are merged, and `sin`/`cos` of rational multiples of pi/2 are evaluated exactly.

use num_rational::Rational64;
use num_traits::{CheckedAdd, CheckedMul, One, Signed, ToPrimitive, Zero};
use std::cmp::Ordering;
use std::fmt;
use std::sync::Arc;

/// Elementary functions an expression may contain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Sqrt,
    Abs,
    /// sign(x): -1, 0 or 1 (used for Coulomb friction).
    Sign,
}

impl Func {
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
}

/// A shared, immutable symbolic expression.
#[derive(Clone, PartialEq)]
pub struct Expr(Arc<Node>);

/// Error while evaluating an expression numerically.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EvalError {
    #[error("unknown symbol `{0}`")]
    UnknownSymbol(String),
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
        Expr(Arc::new(node))
    }

    /// The node behind this expression.
    pub fn node(&self) -> &Node {
        &self.0
    }

    pub fn zero() -> Expr {
        Expr::rational(Rational64::zero())
    }

    pub fn one() -> Expr {
        Expr::rational(Rational64::one())
    }

    pub fn int(n: i64) -> Expr {
        Expr::rational(Rational64::from_integer(n))
    }

    pub fn rational(r: Rational64) -> Expr {
        Expr::new(Node::Rational(r))
    }

    pub fn pi() -> Expr {
        Expr::new(Node::Pi)
    }

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

    pub fn as_rational(&self) -> Option<Rational64> {
        match self.node() {
            Node::Rational(r) => Some(*r),
            _ => None,
        }
    }

    pub fn as_symbol(&self) -> Option<&str> {
        match self.node() {
            Node::Symbol(s) => Some(s),
            _ => None,
        }
    }

    pub fn is_zero(&self) -> bool {
        match self.node() {
            Node::Rational(r) => r.is_zero(),
            Node::Float(x) => *x == 0.0,
            _ => false,
        }
    }

    pub fn is_one(&self) -> bool {
        match self.node() {
            Node::Rational(r) => r.is_one(),
            Node::Float(x) => *x == 1.0,
            _ => false,
        }
    }

    pub fn is_number(&self) -> bool {
        matches!(self.node(), Node::Rational(_) | Node::Float(_))
    }

    /// True when the expression contains no symbol (numbers, pi and functions of them).
    pub fn is_constant(&self) -> bool {
        match self.node() {
            Node::Rational(_) | Node::Float(_) | Node::Pi => true,
            Node::Symbol(_) => false,
            Node::Add(v) | Node::Mul(v) => v.iter().all(Expr::is_constant),
            Node::Pow(b, _) => b.is_constant(),
            Node::Func(_, a) => a.is_constant(),
        }
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
        match self.node() {
            Node::Symbol(s) => out.push(s.clone()),
            Node::Add(v) | Node::Mul(v) => v.iter().for_each(|e| e.collect_symbols(out)),
            Node::Pow(b, _) => b.collect_symbols(out),
            Node::Func(_, a) => a.collect_symbols(out),
            _ => {}
        }
    }

    /// Whether symbol `name` occurs in the expression.
    pub fn depends_on(&self, name: &str) -> bool {
        match self.node() {
            Node::Symbol(s) => s == name,
            Node::Add(v) | Node::Mul(v) => v.iter().any(|e| e.depends_on(name)),
            Node::Pow(b, _) => b.depends_on(name),
            Node::Func(_, a) => a.depends_on(name),
            _ => false,
        }
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
        })
    }

    /// Replace symbols by expressions (symbols `f` maps to `None` are kept).
    pub fn substitute(&self, f: &dyn Fn(&str) -> Option<Expr>) -> Expr {
        match self.node() {
            Node::Symbol(s) => f(s).unwrap_or_else(|| self.clone()),
            Node::Add(v) => Expr::sum(v.iter().map(|e| e.substitute(f))),
            Node::Mul(v) => Expr::product(v.iter().map(|e| e.substitute(f))),
            Node::Pow(b, n) => b.substitute(f).powi(*n),
            Node::Func(fun, a) => Expr::func(*fun, a.substitute(f)),
            _ => self.clone(),
        }
    }

    /// Sum of terms, canonicalised.
    pub fn sum(terms: impl IntoIterator<Item = Expr>) -> Expr {
        // Flatten, split each term into (coefficient, rest), collect like rests.
        let mut constant = Rational64::zero();
        let mut float_constant = 0.0f64;
        let mut has_float = false;
        let mut parts: Vec<(Expr, Coef)> = Vec::new();
        let push = |e: &Expr, parts: &mut Vec<(Expr, Coef)>| {
            let (c, rest) = e.split_coefficient();
            if let Some(slot) = parts.iter_mut().find(|(r, _)| *r == rest) {
                slot.1 = slot.1.add(c);
            } else {
                parts.push((rest, c));
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
                Node::Rational(r) => constant += *r,
                Node::Float(x) => {
                    float_constant += *x;
                    has_float = true;
                }
                _ => push(&t, &mut parts),
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
                    if let Some(slot) = bases.iter_mut().find(|(x, _)| *x == b) {
                        slot.1 += n;
                    } else {
                        bases.push((b, n));
                    }
                }
            }
            if coef.is_zero() {
                return Expr::zero();
            }
        }
        let mut out: Vec<Expr> = bases
            .into_iter()
            .filter(|(_, n)| *n != 0)
            .map(|(b, n)| b.powi(n))
            .collect();
        // powi may have produced numbers (e.g. (pi)^0 handled above, sqrt(2)^2 below): refold
        if out
            .iter()
            .any(|e| e.is_number() || matches!(e.node(), Node::Mul(_)))
        {
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
            Node::Pow(b, m) => b.powi(m * n),
            Node::Mul(v) => Expr::product(v.iter().map(|f| f.powi(n))),
            Node::Func(Func::Sqrt, a) if n % 2 == 0 => a.powi(n / 2),
            _ => Expr::new(Node::Pow(self.clone(), n)),
        }
    }

    /// Apply an elementary function, with exact values where known.
    pub fn func(f: Func, a: Expr) -> Expr {
        if let Some(x) = a.as_f64() {
            if matches!(a.node(), Node::Float(_)) {
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

    pub fn sin(&self) -> Expr {
        Expr::func(Func::Sin, self.clone())
    }

    pub fn cos(&self) -> Expr {
        Expr::func(Func::Cos, self.clone())
    }

    pub fn sqrt(&self) -> Expr {
        Expr::func(Func::Sqrt, self.clone())
    }

    /// If the expression is k*pi/2 for an integer k, return k.
    fn multiple_of_half_pi(&self) -> Option<i64> {
        if self.is_zero() {
            return Some(0);
        }
        let (c, rest) = self.split_coefficient();
        if !matches!(rest.node(), Node::Pi) {
            return None;
        }
        match c {
            Coef::Rat(r) => {
                let twice = r * Rational64::from_integer(2);
                twice.is_integer().then(|| twice.to_integer())
            }
            Coef::Float(_) => None,
        }
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
    /// of sums included).
    pub fn expand(&self) -> Expr {
        match self.node() {
            Node::Add(v) => Expr::sum(v.iter().map(Expr::expand)),
            Node::Mul(v) => {
                let mut acc = vec![Expr::one()];
                for f in v {
                    let f = f.expand();
                    let terms: Vec<Expr> = match f.node() {
                        Node::Add(t) => t.clone(),
                        _ => vec![f.clone()],
                    };
                    acc = acc
                        .iter()
                        .flat_map(|a| {
                            terms
                                .iter()
                                .map(move |t| Expr::product([a.clone(), t.clone()]))
                        })
                        .collect();
                }
                Expr::sum(acc)
            }
            Node::Pow(b, n) if *n > 1 => {
                let b = b.expand();
                if matches!(b.node(), Node::Add(_)) {
                    let mut r = Expr::one();
                    for _ in 0..*n {
                        r = Expr::product([r, b.clone()]).expand();
                    }
                    r
                } else {
                    b.powi(*n)
                }
            }
            Node::Func(f, a) => Expr::func(*f, a.expand()),
            _ => self.clone(),
        }
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
            Coef::Rat(r) => Coef::Rat(-r),
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
    (s * s == n).then_some(s)
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
        Node::Add(_) => 6,
    }
}

/// Total structural order, used for canonical ordering of sums and products.
pub fn cmp_expr(a: &Expr, b: &Expr) -> Ordering {
    match (a.node(), b.node()) {
        (Node::Rational(x), Node::Rational(y)) => x.cmp(y),
        (Node::Float(x), Node::Float(y)) => x.total_cmp(y),
        (Node::Symbol(x), Node::Symbol(y)) => natural_cmp(x, y),
        (Node::Pow(b1, n1), Node::Pow(b2, n2)) => cmp_expr(b1, b2).then(n1.cmp(n2)),
        (Node::Func(f1, a1), Node::Func(f2, a2)) => cmp_expr(a1, a2).then(f1.cmp(f2)),
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
    let split = |s: &str| {
        let i = s.trim_end_matches(|c: char| c.is_ascii_digit()).len();
        (s[..i].to_string(), s[i..].parse::<u64>().ok())
    };
    let (pa, na) = split(a);
    let (pb, nb) = split(b);
    pa.cmp(&pb).then(na.cmp(&nb)).then(a.cmp(b))
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
/// by the program builder for common-subexpression sharing.
impl std::hash::Hash for Expr {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        self.node().hash(h)
    }
}

impl Eq for Expr {}

impl std::hash::Hash for Node {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        std::mem::discriminant(self).hash(h);
        match self {
            Node::Rational(r) => r.hash(h),
            // -0.0 == 0.0: hash them alike
            Node::Float(x) => (if *x == 0.0 { 0.0f64 } else { *x }).to_bits().hash(h),
            Node::Pi => {}
            Node::Symbol(s) => s.hash(h),
            Node::Add(v) | Node::Mul(v) => v.hash(h),
            Node::Pow(b, n) => {
                b.hash(h);
                n.hash(h)
            }
            Node::Func(f, a) => {
                f.hash(h);
                a.hash(h)
            }
        }
    }
}
