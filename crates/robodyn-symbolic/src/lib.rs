//! Symbolic expressions for robodyn.
//!
//! A small computer-algebra kernel sized for robot models: named symbols (`d3`, `RL4`, `XX2`),
//! exact rational constants, `pi`, `sin`/`cos`, canonicalising constructors that fold trivial
//! algebra on construction, expansion, substitution, numeric evaluation, parsing and printing.
//! [`Program`] is a straight-line list of named assignments (what `robodyn::codegen` records
//! from the dynamic models), with common subexpressions removed, operation counts and
//! emitters ([`emit()`]) for text, LaTeX, Rust, C, Python, Julia and MATLAB.
//!
//! # Example
//!
//! ```
//! use robodyn_symbolic::{count_ops, Expr};
//! let e = Expr::parse("(d3 + RL4)*(d3 - RL4) + d12*cos(g12)").expect("a valid expression");
//! let expanded = e.expand(); // d3^2 - RL4^2 + d12*cos(g12)
//! let values = |s: &str| match s {
//!     "d3" => Some(0.5),
//!     "RL4" => Some(0.3),
//!     "d12" => Some(2.0),
//!     "g12" => Some(0.0),
//!     _ => None,
//! };
//! let x = expanded.eval(&values).expect("every symbol has a value");
//! assert!((x - (0.25 - 0.09 + 2.0)).abs() < 1e-15);
//! // substitution keeps the exact rationals: RL4 = 0 leaves d3^2 + d12*cos(g12)
//! let s = expanded.substitute(&|s| (s == "RL4").then(Expr::zero));
//! assert!(!s.depends_on("RL4"));
//! let ops = count_ops(&expanded);
//! println!("{expanded}: {} multiplications, {} additions", ops.mul, ops.add);
//! // an error says where: position and reason
//! assert!(Expr::parse("d3 + * 2").is_err());
//! ```

#![deny(missing_docs)]

mod diff;
pub mod emit;
mod expr;
mod optimize;
mod parse;
mod print;
pub mod program;

pub use diff::Tangents;
pub use emit::{check_function_name, emit, parameter_fields, parameter_type, Lang};
pub use expr::{cmp_expr, EvalError, Expr, Func, Node};
pub use parse::ParseError;
pub use program::{count_ops, Assignment, InputGroup, OpCount, Program};

#[cfg(test)]
mod tests;
