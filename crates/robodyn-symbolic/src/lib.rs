//! Symbolic expressions for robodyn.
//!
//! A small computer-algebra kernel sized for robot models: named symbols (`d3`, `RL4`, `XX2`),
//! exact rational constants, `pi`, `sin`/`cos`, canonicalising constructors that fold trivial
//! algebra on construction, expansion, substitution, numeric evaluation, parsing and printing.

#![deny(missing_docs)]

pub mod emit;
mod expr;
mod optimize;
mod parse;
mod print;
pub mod program;

pub use emit::{emit, Lang};
pub use expr::{cmp_expr, EvalError, Expr, Func, Node};
pub use parse::ParseError;
pub use program::{count_ops, Assignment, InputGroup, OpCount, Program};

#[cfg(test)]
mod tests;
