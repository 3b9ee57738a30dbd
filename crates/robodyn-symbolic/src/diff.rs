//! Symbolic differentiation: of an expression ([`Expr::diff`], [`Expr::derivative`]) and, in
//! forward mode, of a straight-line [`Program`] ([`Program::differentiate`]).
//!
//! Rules (each through the canonicalising constructors, so that products with constants fold
//! and zero terms vanish): sums term by term, products by the product rule over the factors
//! that have a derivative, `x^n` -> `n x^(n-1) dx`, `sin` -> `cos dx`, `cos` -> `-sin dx`,
//! `tan` -> `(1 + tan^2) dx`, `sqrt(x)` -> `dx / (2 sqrt(x))`, `abs(x)` -> `sign(x) dx`,
//! `atan2(y, x)` -> `(x dy - y dx) / (x^2 + y^2)`. `sign(x)` (Coulomb friction) has derivative
//! 0 where it is smooth (x != 0); at x = 0 it has none, and 0 is what is written.

use crate::expr::{grow, Expr, Func, Node};
use crate::program::{is_trivial, Assignment, Program};
use std::collections::{HashMap, HashSet};

impl Expr {
    /// The derivative with respect to the symbol `x` (every other symbol constant).
    ///
    /// ```
    /// use robodyn_symbolic::Expr;
    /// let e = Expr::parse("a*sin(q)^2 + q").unwrap();
    /// let d = e.diff("q"); // 2*a*cos(q)*sin(q) + 1
    /// let at = |s: &str| match s { "a" => Some(3.0), "q" => Some(0.5), _ => None };
    /// let expected = 2.0 * 3.0 * 0.5f64.cos() * 0.5f64.sin() + 1.0;
    /// assert!((d.eval(&at).unwrap() - expected).abs() < 1e-15);
    /// assert!(e.diff("b").is_zero());
    /// ```
    pub fn diff(&self, x: &str) -> Expr {
        self.derivative(&|s| (s == x).then(Expr::one))
    }

    /// The derivative along a direction given per symbol: `d(s)` is the derivative of symbol
    /// `s` (`None` for 0), and the chain rule does the rest. With `d` giving the derivatives of
    /// the intermediates of a program this is one step of forward-mode differentiation.
    pub fn derivative(&self, d: &dyn Fn(&str) -> Option<Expr>) -> Expr {
        grow(|| self.derivative_node(d))
    }

    fn derivative_node(&self, d: &dyn Fn(&str) -> Option<Expr>) -> Expr {
        match self.node() {
            Node::Rational(_) | Node::Float(_) | Node::Pi => Expr::zero(),
            Node::Symbol(s) => d(s).unwrap_or_else(Expr::zero),
            Node::Add(v) => Expr::sum(v.iter().map(|t| t.derivative(d))),
            Node::Mul(v) => {
                let mut terms = Vec::new();
                for (i, f) in v.iter().enumerate() {
                    let df = f.derivative(d);
                    if df.is_zero() {
                        continue;
                    }
                    let others = v
                        .iter()
                        .enumerate()
                        .filter(|(j, _)| *j != i)
                        .map(|(_, g)| g.clone());
                    terms.push(Expr::product(others.chain(std::iter::once(df))));
                }
                Expr::sum(terms)
            }
            Node::Pow(b, n) => {
                let db = b.derivative(d);
                if db.is_zero() {
                    return Expr::zero();
                }
                Expr::product([Expr::int(i64::from(*n)), b.powi(n - 1), db])
            }
            Node::Func(f, a) => {
                let da = a.derivative(d);
                if da.is_zero() {
                    return Expr::zero();
                }
                let outer = match f {
                    Func::Sin => a.cos(),
                    Func::Cos => -a.sin(),
                    Func::Tan => Expr::one() + Expr::func(Func::Tan, a.clone()).powi(2),
                    Func::Sqrt => Expr::product([Expr::rational((1, 2).into()), a.sqrt().powi(-1)]),
                    Func::Abs => Expr::func(Func::Sign, a.clone()),
                    // piecewise constant: 0 wherever it is differentiable
                    Func::Sign => return Expr::zero(),
                };
                outer * da
            }
            Node::Atan2(y, x) => {
                let (dy, dx) = (y.derivative(d), x.derivative(d));
                if dy.is_zero() && dx.is_zero() {
                    return Expr::zero();
                }
                let r2 = x.powi(2) + y.powi(2);
                (x.clone() * dy - y.clone() * dx) * r2.powi(-1)
            }
        }
    }
}

/// The values a program names, for the derivatives to refer to: a derivative's
/// sub-expression equal to the value of an assignment already written becomes its name; one
/// equal to a later assignment that reads no intermediate (`C2 = cos(q2)` in the derivative of
/// `S2 = sin(q2)`, written first) is moved up, written before the derivative that uses it.
struct Known<'a> {
    program: &'a [Assignment],
    by_value: HashMap<&'a Expr, usize>,
    intermediates: HashSet<&'a str>,
    written: Vec<bool>,
}

impl<'a> Known<'a> {
    fn new(program: &'a [Assignment]) -> Self {
        let mut by_value = HashMap::new();
        for (i, a) in program.iter().enumerate() {
            by_value.entry(&a.expr).or_insert(i);
        }
        Known {
            program,
            by_value,
            intermediates: program.iter().map(|a| a.name.as_str()).collect(),
            written: vec![false; program.len()],
        }
    }

    /// `e` with the named values replaced by their names; the assignments moved up are
    /// appended to `out`.
    fn share(&mut self, e: &Expr, out: &mut Vec<Assignment>) -> Expr {
        if let Some(&i) = self.by_value.get(e) {
            if !self.written[i]
                && !e
                    .symbols()
                    .iter()
                    .any(|s| self.intermediates.contains(s.as_str()))
            {
                self.written[i] = true;
                out.push(self.program[i].clone());
            }
            if self.written[i] {
                return Expr::symbol(self.program[i].name.clone());
            }
        }
        grow(|| match e.node() {
            Node::Add(v) => Expr::sum(v.iter().map(|t| self.share(t, out)).collect::<Vec<_>>()),
            Node::Mul(v) => Expr::product(v.iter().map(|t| self.share(t, out)).collect::<Vec<_>>()),
            Node::Pow(b, n) => self.share(b, out).powi(*n),
            Node::Func(f, a) => Expr::func(*f, self.share(a, out)),
            Node::Atan2(y, x) => {
                let y = self.share(y, out);
                Expr::atan2(y, self.share(x, out))
            }
            _ => e.clone(),
        })
    }
}

/// The forward-mode derivatives of a [`Program`] (see [`Program::differentiate`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Tangents {
    /// The program's assignments with the derivative assignments interleaved (each right after
    /// the value it differentiates), in evaluation order.
    pub assignments: Vec<Assignment>,
    /// `outputs[k][i]`: the derivative of output i with respect to variable k (over the
    /// names of `assignments` and the program's inputs).
    pub outputs: Vec<Vec<Expr>>,
}

impl Program {
    /// Forward-mode derivatives of the outputs with respect to the input symbols `vars`: each
    /// assignment `v = f(args)` gives `dv/dx = sum of df/darg * darg/dx` over the arguments that
    /// depend on x. Structural zeros are never written: an intermediate that does not depend on
    /// x (most depend on few joints) has no derivative with respect to it, and a derivative that
    /// is trivial (a number, a symbol, a negated symbol) is used inline. A derivative assignment
    /// is named `D<name>_<var>`; a sub-expression equal to a value the program already names
    /// (`cos(q2)` in the derivative of `S2 = sin(q2)`) refers to that name. No optimisation is
    /// run: see [`Program::optimize`].
    pub fn differentiate(&self, vars: &[String]) -> Tangents {
        let var_index: HashMap<&str, usize> = vars
            .iter()
            .enumerate()
            .map(|(k, v)| (v.as_str(), k))
            .collect();
        let mut taken: HashSet<String> = self.input_symbols().into_iter().collect();
        for a in self.assignments.iter().chain(&self.outputs) {
            taken.insert(a.name.clone());
            a.expr.for_each_symbol(&mut |s| {
                taken.insert(s.to_string());
            });
        }
        // the variables each intermediate depends on
        let mut deps: HashMap<&str, Vec<bool>> = HashMap::new();
        let deps_of = |e: &Expr, deps: &HashMap<&str, Vec<bool>>| -> Vec<bool> {
            let mut m = vec![false; vars.len()];
            e.for_each_symbol(&mut |s| {
                if let Some(&k) = var_index.get(s) {
                    m[k] = true;
                } else if let Some(d) = deps.get(s) {
                    m.iter_mut().zip(d).for_each(|(a, b)| *a |= *b);
                }
            });
            m
        };
        // derivative of each intermediate along each variable (absent: zero)
        let mut tangent: Vec<HashMap<String, Expr>> = vec![HashMap::new(); vars.len()];
        let mut known = Known::new(&self.assignments);
        let mut assignments = Vec::with_capacity(self.assignments.len());
        for (i, a) in self.assignments.iter().enumerate() {
            let m = deps_of(&a.expr, &deps);
            if !known.written[i] {
                known.written[i] = true;
                assignments.push(a.clone());
            }
            for (k, x) in vars.iter().enumerate() {
                if !m[k] {
                    continue;
                }
                let t = &tangent[k];
                let da = a.expr.derivative(&|s| {
                    if s == x {
                        Some(Expr::one())
                    } else {
                        t.get(s).cloned()
                    }
                });
                if da.is_zero() {
                    continue;
                }
                let da = known.share(&da, &mut assignments);
                let value = if is_trivial(&da) {
                    da
                } else {
                    let name = unique(&mut taken, format!("D{}_{x}", a.name));
                    assignments.push(Assignment {
                        name: name.clone(),
                        expr: da,
                    });
                    Expr::symbol(name)
                };
                tangent[k].insert(a.name.clone(), value);
            }
            deps.insert(a.name.as_str(), m);
        }
        let outputs = vars
            .iter()
            .zip(&tangent)
            .map(|(x, t)| {
                self.outputs
                    .iter()
                    .map(|o| {
                        let d = o.expr.derivative(&|s| {
                            if s == x {
                                Some(Expr::one())
                            } else {
                                t.get(s).cloned()
                            }
                        });
                        known.share(&d, &mut assignments)
                    })
                    .collect()
            })
            .collect();
        Tangents {
            assignments,
            outputs,
        }
    }
}

/// `base`, or `base_2`, `base_3`... the first not in `taken` (then taken).
fn unique(taken: &mut HashSet<String>, base: String) -> String {
    if taken.insert(base.clone()) {
        return base;
    }
    (2..)
        .map(|k| format!("{base}_{k}"))
        .find(|n| taken.insert(n.clone()))
        .expect("an unused name")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Expr {
        Expr::parse(s).unwrap()
    }

    /// Values of the test symbols at point `k` (a few points away from the functions'
    /// singularities).
    fn point(k: usize) -> impl Fn(&str) -> Option<f64> {
        let pts = [
            [0.3, -1.2, 0.7, 2.1],
            [1.4, 0.2, -0.9, 0.6],
            [-0.8, 2.5, 1.3, -1.7],
        ];
        move |s: &str| {
            let i = ["x", "y", "z", "w"].iter().position(|&n| n == s)?;
            Some(pts[k][i])
        }
    }

    /// Central difference of `e` along `x` at `env`: step h, truncation error O(h^2).
    fn central(e: &Expr, x: &str, env: &dyn Fn(&str) -> Option<f64>, h: f64) -> f64 {
        let at = |dx: f64| {
            e.eval(&|s| env(s).map(|v| if s == x { v + dx } else { v }))
                .unwrap()
        };
        (at(h) - at(-h)) / (2.0 * h)
    }

    #[test]
    fn derivatives_equal_central_differences() {
        let cases = [
            "x*y*z + 3*x^2*w - y/x",
            "sin(x)*cos(y)^3 - 2*sin(x*y + z)",
            "tan(x/3) + sqrt(x^2 + y^2 + 1)*z",
            "atan2(y*z, x - w) + abs(x - 2)*w",
            "x^-3*y + (x + y)^2*(z - w)^-2",
            "cos(pi/2 + x)*y - sin(pi - z)",
            "2.5*x*sign(y) + y*sign(x)",
        ];
        let mut worst = 0.0f64;
        for s in cases {
            let e = p(s);
            for k in 0..3 {
                let env = point(k);
                for x in ["x", "y", "z", "w"] {
                    let exact = e.diff(x).eval(&env).unwrap();
                    // two steps: the error of h must be ~4x that of h/2 when the derivative
                    // is right (truncation O(h^2)); a wrong one stays off by a constant
                    let (d1, d2) = (central(&e, x, &env, 1e-3), central(&e, x, &env, 5e-4));
                    assert!((d1 - exact).abs() + 1e-12 >= (d2 - exact).abs(), "{s} {x}");
                    // Richardson: (4 d(h/2) - d(h)) / 3 has truncation error O(h^4)
                    let fd = (4.0 * d2 - d1) / 3.0;
                    let err = (exact - fd).abs() / (1.0 + exact.abs());
                    assert!(err < 1e-7, "d({s})/d{x} at {k}: {exact} vs {fd}");
                    worst = worst.max(err);
                }
            }
        }
        assert!(
            worst > 0.0,
            "differences must differ from exact derivatives somewhere"
        );
    }

    #[test]
    fn structural_zeros_and_folded_constants() {
        assert!(p("sin(y)*z + 4").diff("x").is_zero());
        assert!(p("3*sign(x)").diff("x").is_zero());
        assert_eq!(p("5*x").diff("x"), p("5"));
        assert_eq!(p("cos(x)").diff("x"), p("-sin(x)"));
        assert_eq!(p("x^3").diff("x"), p("3*x^2"));
        // a symbol whose derivative is given (chain rule through an intermediate)
        let d = p("S*y + S^2").derivative(&|s| (s == "S").then(|| p("C")));
        assert_eq!(d, p("C*y + 2*C*S"));
    }

    #[test]
    fn forward_mode_over_a_program_equals_differences() {
        let a = |n: &str, e: &str| Assignment {
            name: n.into(),
            expr: p(e),
        };
        let prog = Program {
            name: "t".into(),
            inputs: vec![crate::InputGroup {
                name: "v".into(),
                doc: String::new(),
                symbols: vec![Some("x".into()), Some("y".into())],
                by_name: false,
            }],
            assignments: vec![
                a("S", "sin(x)"),
                a("C", "cos(x)"),
                a("U", "S*y + z"),
                a("V", "U*C - w*U^2"),
                a("K", "z*w + 1"),
            ],
            outputs: vec![a("o1", "V*S"), a("o2", "K*y"), a("o3", "K")],
            ..Default::default()
        };
        let vars = vec!["x".to_string(), "y".to_string()];
        let t = prog.differentiate(&vars);
        // K depends on neither variable: no derivative assignment
        assert!(t.assignments.iter().all(|a| !a.name.starts_with("DK")));
        assert!(t.outputs[0][2].is_zero() && t.outputs[1][2].is_zero());
        // the derivative of S is the already named C
        assert!(t.assignments.iter().all(|a| a.name != "DS_x"));
        let dprog = Program {
            assignments: t.assignments.clone(),
            outputs: t
                .outputs
                .iter()
                .flatten()
                .enumerate()
                .map(|(i, e)| Assignment {
                    name: format!("d{i}"),
                    expr: e.clone(),
                })
                .collect(),
            ..prog.clone()
        };
        for k in 0..3 {
            let env = point(k);
            let d = dprog.evaluate(&env).unwrap();
            for (v, x) in vars.iter().enumerate() {
                let at = |h: f64| {
                    prog.evaluate(&|s| env(s).map(|u| if s == x { u + h } else { u }))
                        .unwrap()
                };
                let (plus, minus) = (at(1e-5), at(-1e-5));
                for i in 0..3 {
                    let fd = (plus[i] - minus[i]) / 2e-5;
                    let exact = d[v * 3 + i];
                    assert!(
                        (fd - exact).abs() < 1e-8 * (1.0 + exact.abs()),
                        "d o{}/d{x}: {exact} vs {fd}",
                        i + 1
                    );
                }
            }
        }
    }
}
