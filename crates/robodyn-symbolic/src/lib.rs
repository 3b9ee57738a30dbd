//! Symbolic expressions for robodyn.
//!
//! A small computer-algebra kernel sized for robot models: named symbols (`d3`, `RL4`, `XX2`),
//! exact rational constants, `pi`, `sin`/`cos`, canonicalising constructors that fold trivial
//! algebra on construction, expansion, substitution, numeric evaluation, parsing and printing.

mod expr;
mod parse;
mod print;

pub use expr::{cmp_expr, EvalError, Expr, Func, Node};
pub use parse::ParseError;

#[cfg(test)]
mod tests;
