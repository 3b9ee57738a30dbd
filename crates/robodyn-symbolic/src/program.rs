//! Straight-line programs: named assignments `NAME = expr` and outputs, as SYMORO writes a
//! customized model.
//!
//! A [`Program`] is recorded by running a numeric recursion on [`Expr`] while a thread-local
//! recorder is active ([`record`]): every value the recursion names through [`name_value`]
//! becomes an assignment unless it is trivial (a number, a symbol or a negated symbol), identical
//! values share one name. [`Program::optimize`] then removes dead assignments, shares common
//! subexpressions and inlines single-use intermediates when that lowers the operation count;
//! [`Program::count`] counts operations as documented in `docs/models/generated-code.md`.

use crate::expr::{Expr, Func, Node};
use num_traits::{One, Signed};
use std::cell::RefCell;
use std::collections::{HashMap, HashSet};

/// One assignment `name = expr`.
#[derive(Clone, Debug, PartialEq)]
pub struct Assignment {
    /// The name assigned.
    pub name: String,
    /// Its value.
    pub expr: Expr,
}

/// A group of input symbols passed to generated code as one argument: an array (`q`, `qd`),
/// or, for a group `by_name` (the parameters `p`), a record whose fields are the symbols (a
/// struct in C and Rust, a mapping in Python, any value with those fields in Julia and MATLAB).
#[derive(Clone, Debug, PartialEq)]
pub struct InputGroup {
    /// Argument name in generated code.
    pub name: String,
    /// What the group holds (for the header comment).
    pub doc: String,
    /// Symbol at each index; `None` for an entry the program does not read.
    pub symbols: Vec<Option<String>>,
    /// Passed by name (a record of named fields) rather than by position (an array).
    pub by_name: bool,
}

/// A straight-line program: inputs, assignments in evaluation order, named outputs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Program {
    /// Function name for generated code.
    pub name: String,
    /// Header lines (what the model is, its options).
    pub description: Vec<String>,
    /// Input arrays, in argument order.
    pub inputs: Vec<InputGroup>,
    /// Intermediate values, in evaluation order.
    pub assignments: Vec<Assignment>,
    /// Outputs, written to the output array in this order.
    pub outputs: Vec<Assignment>,
}

/// Operation counts: multiplications (divisions included), additions (subtractions included),
/// elementary function calls (sin, cos, sign, sqrt; not counted as multiplications).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCount {
    /// Multiplications and divisions.
    pub mul: usize,
    /// Additions and subtractions.
    pub add: usize,
    /// Elementary function calls.
    pub func: usize,
}

impl std::ops::Add for OpCount {
    type Output = OpCount;
    fn add(self, o: OpCount) -> OpCount {
        OpCount {
            mul: self.mul + o.mul,
            add: self.add + o.add,
            func: self.func + o.func,
        }
    }
}

impl std::fmt::Display for OpCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} multiplications, {} additions, {} functions",
            self.mul, self.add, self.func
        )
    }
}

/// Operations of one expression, counted as it is printed:
/// - a sum of n terms: n - 1 additions (a term with coefficient -1 is a subtraction);
/// - a product of k non-numeric factors: k - 1 multiplications (x^-n a division), plus one for a
///   numeric coefficient other than +-1 (a factor -1 is a sign change, free);
/// - x^n: n - 1 multiplications; x^-n alone: n - 1 multiplications and one division;
/// - sin, cos, sign, sqrt...: one function call each.
pub fn count_ops(e: &Expr) -> OpCount {
    let mut c = OpCount::default();
    count_into(e, &mut c);
    c
}

fn count_into(e: &Expr, c: &mut OpCount) {
    crate::expr::grow(|| count_node(e, c))
}

fn count_node(e: &Expr, c: &mut OpCount) {
    match e.node() {
        Node::Rational(_) | Node::Float(_) | Node::Pi | Node::Symbol(_) => {}
        Node::Add(v) => {
            c.add += v.len() - 1;
            v.iter().for_each(|t| count_into(t, c));
        }
        Node::Mul(v) => {
            let mut k: usize = 0;
            let mut positive = 0;
            for f in v {
                match f.node() {
                    Node::Rational(r) => {
                        if !r.abs().is_one() {
                            c.mul += 1;
                        }
                    }
                    Node::Float(x) => {
                        if x.abs() != 1.0 {
                            c.mul += 1;
                        }
                    }
                    Node::Pow(b, n) if *n < 0 => {
                        k += 1;
                        c.mul += (n.unsigned_abs() - 1) as usize;
                        count_into(b, c);
                    }
                    _ => {
                        k += 1;
                        positive += 1;
                        count_into(f, c);
                    }
                }
            }
            let has_coef = v[0].is_number() && {
                let x = v[0].as_f64().unwrap_or(0.0).abs();
                x != 1.0
            };
            c.mul += k.saturating_sub(1);
            if positive == 0 && !has_coef && k > 0 {
                // 1/(x*y): one more division
                c.mul += 1;
            }
        }
        Node::Pow(b, n) => {
            c.mul += (n.unsigned_abs() - 1) as usize + usize::from(*n < 0);
            count_into(b, c);
        }
        Node::Func(_, a) => {
            c.func += 1;
            count_into(a, c);
        }
        Node::Atan2(y, x) => {
            c.func += 1;
            count_into(y, c);
            count_into(x, c);
        }
    }
}

/// True for values that stay inline rather than become an assignment: numbers, constants,
/// symbols and negated symbols.
pub fn is_trivial(e: &Expr) -> bool {
    match e.node() {
        Node::Rational(_) | Node::Float(_) | Node::Pi | Node::Symbol(_) => true,
        Node::Mul(v) => {
            v.len() == 2 && v[0].as_f64() == Some(-1.0) && matches!(v[1].node(), Node::Symbol(_))
        }
        _ => e.is_constant() && count_ops(e) == OpCount::default(),
    }
}

struct Recorder {
    assignments: Vec<Assignment>,
    by_value: HashMap<Expr, Expr>,
    names: HashSet<String>,
    suffix: String,
}

impl Recorder {
    fn unique(&mut self, base: String) -> String {
        let base = format!("{base}{}", self.suffix);
        if self.names.insert(base.clone()) {
            return base;
        }
        for k in 2.. {
            let n = format!("{base}_{k}");
            if self.names.insert(n.clone()) {
                return n;
            }
        }
        unreachable!()
    }

    fn assign(&mut self, e: Expr, name: String) -> Expr {
        if let Some(s) = self.by_value.get(&e) {
            return s.clone();
        }
        let neg = match e.node() {
            Node::Add(v) => Expr::sum(v.iter().map(|t| -t.clone())),
            _ => -e.clone(),
        };
        if let Some(s) = self.by_value.get(&neg) {
            return -s.clone();
        }
        let name = self.unique(name);
        let sym = Expr::symbol(name.clone());
        self.assignments.push(Assignment {
            name,
            expr: e.clone(),
        });
        self.by_value.insert(e, sym.clone());
        sym
    }
}

thread_local! {
    static RECORDER: RefCell<Option<Recorder>> = const { RefCell::new(None) };
}

/// Run `f` with a fresh recorder on this thread and return its result with the recorded
/// assignments. `reserved` names (the input symbols) are never used for intermediates.
/// A recording already active on this thread is suspended and restored afterwards.
pub fn record<R>(reserved: &[String], f: impl FnOnce() -> R) -> (R, Vec<Assignment>) {
    let fresh = Recorder {
        assignments: Vec::new(),
        by_value: HashMap::new(),
        names: reserved.iter().cloned().collect(),
        suffix: String::new(),
    };
    let previous = RECORDER.with(|r| r.borrow_mut().replace(fresh));
    let out = f();
    let rec = RECORDER.with(|r| std::mem::replace(&mut *r.borrow_mut(), previous));
    (out, rec.map(|r| r.assignments).unwrap_or_default())
}

/// Whether a recording is active on this thread.
pub fn is_recording() -> bool {
    RECORDER.with(|r| r.borrow().is_some())
}

/// Suffix appended to the names given from now on in the active recording (e.g. `_c2` for the
/// second column of the inertia matrix); empty to stop.
pub fn set_name_suffix(suffix: &str) {
    RECORDER.with(|r| {
        if let Some(rec) = r.borrow_mut().as_mut() {
            rec.suffix = suffix.to_string();
        }
    })
}

/// Name a value in the active recording: a non-trivial value becomes `NAME = e` and its symbol
/// is returned (identical or opposite values already named are shared); without a recording,
/// or for a trivial value, `e` is returned unchanged.
pub fn name_value(e: Expr, name: impl FnOnce() -> String) -> Expr {
    if is_trivial(&e) {
        return e;
    }
    RECORDER.with(|r| match r.borrow_mut().as_mut() {
        Some(rec) => rec.assign(e, name()),
        None => e,
    })
}

/// Name the result of sin/cos (or its negation) of a non-constant argument: `sin(q2)` becomes
/// `S2`, `cos(q2)` `C2`; other arguments get `S`/`C` with a counter.
pub fn name_trig(e: Expr) -> Expr {
    if !is_recording() {
        return e;
    }
    let (negated, inner) = match e.node() {
        Node::Mul(v) if v.len() == 2 && v[0].as_f64() == Some(-1.0) => (true, v[1].clone()),
        _ => (false, e.clone()),
    };
    let Node::Func(f @ (Func::Sin | Func::Cos), arg) = inner.node() else {
        return e;
    };
    if arg.is_constant() {
        return e;
    }
    let letter = if *f == Func::Sin { "S" } else { "C" };
    let suffix = match arg.as_symbol() {
        Some(s) if s.starts_with('q') && s[1..].chars().all(|c| c.is_ascii_digit()) => {
            s[1..].to_string()
        }
        _ => "T".to_string(),
    };
    let named = RECORDER.with(|r| {
        let mut r = r.borrow_mut();
        let rec = r.as_mut().expect("recording");
        let saved = std::mem::take(&mut rec.suffix);
        let s = rec.assign(inner.clone(), format!("{letter}{suffix}"));
        rec.suffix = saved;
        s
    });
    if negated {
        -named
    } else {
        named
    }
}

impl Program {
    /// Total operations of the assignments and outputs.
    pub fn count(&self) -> OpCount {
        self.assignments
            .iter()
            .chain(&self.outputs)
            .map(|a| count_ops(&a.expr))
            .fold(OpCount::default(), |a, b| a + b)
    }

    /// Names of all input symbols.
    pub fn input_symbols(&self) -> Vec<String> {
        self.inputs
            .iter()
            .flat_map(|g| g.symbols.iter().flatten().cloned())
            .collect()
    }

    /// Evaluate with input values from `env`; returns the outputs in order.
    pub fn evaluate(
        &self,
        env: &dyn Fn(&str) -> Option<f64>,
    ) -> Result<Vec<f64>, crate::EvalError> {
        let mut vals: HashMap<String, f64> = HashMap::new();
        for a in &self.assignments {
            let v = a.expr.eval(&|s| vals.get(s).copied().or_else(|| env(s)))?;
            vals.insert(a.name.clone(), v);
        }
        self.outputs
            .iter()
            .map(|o| o.expr.eval(&|s| vals.get(s).copied().or_else(|| env(s))))
            .collect()
    }

    /// True when output `o` is just the intermediate of the same name (see [`Self::name_outputs`]).
    pub fn output_is_named(&self, o: &Assignment) -> bool {
        o.expr.as_symbol() == Some(o.name.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Expr {
        Expr::parse(s).unwrap()
    }

    /// Values of the test programs' symbols.
    fn env(s: &str) -> Option<f64> {
        match s {
            "x" => Some(0.3),
            "y" => Some(-1.7),
            "z" => Some(2.1),
            "w" => Some(0.9),
            "u" => Some(-0.4),
            _ => None,
        }
    }

    #[test]
    fn counts_follow_the_documented_rules() {
        let c = |s: &str| {
            let k = count_ops(&p(s));
            (k.mul, k.add)
        };
        assert_eq!(c("a*b + c"), (1, 1));
        assert_eq!(c("a - b"), (0, 1));
        assert_eq!(c("-a*b"), (1, 0));
        assert_eq!(c("2*a*b - c*d"), (3, 1));
        assert_eq!(c("a/b"), (1, 0));
        assert_eq!(c("1/(a*b)"), (2, 0));
        assert_eq!(c("a^2"), (1, 0));
        assert_eq!(c("1/a"), (1, 0));
        assert_eq!(c("a*b*c - a"), (2, 1));
        assert_eq!(count_ops(&p("sin(q1)*a")).func, 1);
    }

    #[test]
    fn recording_names_and_shares() {
        let reserved = vec!["a".to_string(), "b".to_string()];
        let (out, asg) = record(&reserved, || {
            let x = name_value(p("a*b + 1"), || "X".into());
            let y = name_value(p("a*b + 1"), || "Y".into());
            let z = name_value(p("-a*b - 1"), || "Z".into());
            let t = name_value(p("-a"), || "T".into());
            (x, y, z, t)
        });
        assert_eq!(asg.len(), 1);
        assert_eq!(asg[0].name, "X");
        assert_eq!(out.0, p("X"));
        assert_eq!(out.1, p("X"));
        assert_eq!(out.2, p("-X"));
        assert_eq!(out.3, p("-a"));
        assert!(!is_recording());
        // without a recording nothing is named
        assert_eq!(name_value(p("a*b"), || "X".into()), p("a*b"));
    }

    #[test]
    fn optimisation_keeps_values_and_lowers_counts() {
        let prog = Program {
            name: "t".into(),
            assignments: vec![
                Assignment {
                    name: "A".into(),
                    expr: p("x*y*z + w"),
                },
                Assignment {
                    name: "B".into(),
                    expr: p("x*y*u - w"),
                },
                Assignment {
                    name: "DEAD".into(),
                    expr: p("x*x*x"),
                },
            ],
            outputs: vec![
                Assignment {
                    name: "o1".into(),
                    expr: p("A*B + x*y*z"),
                },
                Assignment {
                    name: "o2".into(),
                    expr: p("2*B"),
                },
            ],
            ..Default::default()
        };
        let mut opt = prog.clone();
        opt.optimize();
        assert!(opt.assignments.iter().all(|a| a.name != "DEAD"));
        let before = prog.count();
        let after = opt.count();
        assert!(after.mul + after.add < before.mul + before.add - 1);
        let a = prog.evaluate(&env).unwrap();
        let b = opt.evaluate(&env).unwrap();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-14 * (1.0 + x.abs()), "{x} vs {y}");
        }
    }

    #[test]
    fn outputs_copying_an_intermediate_take_its_place() {
        let a = |n: &str, e: &str| Assignment {
            name: n.into(),
            expr: p(e),
        };
        let mut prog = Program {
            name: "t".into(),
            assignments: vec![a("X1", "x*y + z"), a("X2", "X1*w - u")],
            outputs: vec![a("W1", "X1"), a("W2", "X2*x"), a("W3", "X1")],
            ..Default::default()
        };
        let (before, values) = (prog.count(), prog.evaluate(&env).unwrap());
        prog.name_outputs();
        assert_eq!(prog.assignments[0].name, "W1");
        assert_eq!(prog.assignments[1].expr, p("W1*w - u"));
        assert!(prog.output_is_named(&prog.outputs[0]));
        // a second copy of the same intermediate keeps copying it
        assert_eq!(prog.outputs[2].expr, p("W1"));
        assert_eq!(prog.count(), before);
        assert_eq!(prog.evaluate(&env).unwrap(), values);
        // the text form writes W1 once
        let text = crate::emit(&prog, crate::Lang::Text);
        assert_eq!(text.matches("W1 = ").count(), 1, "{text}");
    }
}
