//! The scalar the recursive algorithms are written over: `f64` for numbers, [`Expr`] for the
//! customized symbolic model. "One recursion, two scalars": zeros and ones vanish by construction
//! when the recursion runs on expressions.

use nalgebra::{ClosedAddAssign, ClosedMulAssign, ClosedSubAssign};
use robodyn_symbolic::Expr;
use std::ops::Neg;

/// Arithmetic the dynamic recursions need.
pub trait DynScalar:
    nalgebra::Scalar
    + ClosedAddAssign
    + ClosedSubAssign
    + ClosedMulAssign
    + Neg<Output = Self>
    + num_traits::Zero
    + num_traits::One
{
    fn from_f64(x: f64) -> Self;
    fn sin(&self) -> Self;
    fn cos(&self) -> Self;
    /// sign(x) in {-1, 0, 1} (Coulomb friction).
    fn sign(&self) -> Self;
}

impl DynScalar for f64 {
    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline]
    fn sin(&self) -> Self {
        f64::sin(*self)
    }
    #[inline]
    fn cos(&self) -> Self {
        f64::cos(*self)
    }
    #[inline]
    fn sign(&self) -> Self {
        if *self > 0.0 {
            1.0
        } else if *self < 0.0 {
            -1.0
        } else {
            0.0
        }
    }
}

impl DynScalar for Expr {
    fn from_f64(x: f64) -> Self {
        Expr::num(x)
    }
    fn sin(&self) -> Self {
        Expr::sin(self)
    }
    fn cos(&self) -> Self {
        Expr::cos(self)
    }
    fn sign(&self) -> Self {
        Expr::func(robodyn_symbolic::Func::Sign, self.clone())
    }
}
