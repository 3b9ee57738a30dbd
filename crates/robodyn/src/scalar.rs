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
    /// The constant x.
    fn from_f64(x: f64) -> Self;
    /// sin(x).
    fn sin(&self) -> Self;
    /// cos(x).
    fn cos(&self) -> Self;
    /// (sin(x), cos(x)); cos is taken first (the symbolic model names `C<j>` before `S<j>`). `f64`
    /// computes both with one argument reduction.
    #[inline]
    fn sin_cos(&self) -> (Self, Self) {
        let c = self.cos();
        (self.sin(), c)
    }
    /// sign(x) in {-1, 0, 1} (Coulomb friction).
    fn sign(&self) -> Self;
    /// The sine or cosine of a constant angle with its rounding residue removed: `f64` returns
    /// exactly 0 below 1e-15 in magnitude (cos(pi/2) is 6.1e-17 in floating point; an angle
    /// error below 1e-15 rad), so that the constant rotations of alpha, gamma in {0, ±pi/2, pi}
    /// have exact zeros the recursions can rely on ([`crate::model::RotationForm`]). The
    /// identity for other scalars.
    #[inline(always)]
    fn snap_zero(self) -> Self {
        self
    }
    /// False for an infinite or NaN number; true for a scalar that is not a number (an
    /// expression).
    #[inline(always)]
    fn is_finite(&self) -> bool {
        true
    }
    /// True for a scalar that records named intermediate values (the symbolic program builder):
    /// the recursions skip their naming hooks entirely when false.
    const NAMED: bool = false;
    /// Name an intermediate value as SYMORO does (`WI12`, `VP32`, `E13`...): the symbolic scalar
    /// turns a non-trivial value into an assignment and returns its symbol; numbers are unchanged.
    #[inline(always)]
    fn named(self, _name: impl FnOnce() -> String) -> Self {
        self
    }
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
    /// One argument reduction for both (the `libm` crate's `sincos`): about 40 % cheaper than
    /// `sin` and `cos` apart, once per joint in every recursion.
    #[inline]
    fn sin_cos(&self) -> (Self, Self) {
        libm::sincos(*self)
    }
    #[inline]
    fn is_finite(&self) -> bool {
        f64::is_finite(*self)
    }
    #[inline]
    fn snap_zero(self) -> Self {
        if self.abs() < 1e-15 {
            0.0
        } else {
            self
        }
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
    const NAMED: bool = true;
    fn from_f64(x: f64) -> Self {
        Expr::num(x)
    }
    /// While a program is recorded, sin of a joint variable becomes the intermediate `S<j>`.
    fn sin(&self) -> Self {
        robodyn_symbolic::program::name_trig(Expr::sin(self))
    }
    /// While a program is recorded, cos of a joint variable becomes the intermediate `C<j>`.
    fn cos(&self) -> Self {
        robodyn_symbolic::program::name_trig(Expr::cos(self))
    }
    fn named(self, name: impl FnOnce() -> String) -> Self {
        robodyn_symbolic::program::name_value(self, name)
    }
    fn sign(&self) -> Self {
        Expr::func(robodyn_symbolic::Func::Sign, self.clone())
    }
}

/// The recursions on num-dual's forward-mode numbers: `$t` is a dual type whose real part is
/// `re` (`Dual64`: one exact directional derivative; `HyperDual64`: two, and the mixed second
/// derivative). The sign is the real part's, with a zero derivative (away from 0).
macro_rules! dual_scalar {
    ($($t:ty),*) => {$(
        impl DynScalar for $t {
            #[inline]
            fn from_f64(x: f64) -> Self {
                <$t>::from_re(x)
            }
            #[inline]
            fn sin(&self) -> Self {
                num_dual::DualNum::sin(self)
            }
            #[inline]
            fn cos(&self) -> Self {
                num_dual::DualNum::cos(self)
            }
            #[inline]
            fn sign(&self) -> Self {
                <$t>::from_re(DynScalar::sign(&self.re))
            }
        }
    )*};
}

dual_scalar!(num_dual::Dual64, num_dual::HyperDual64);
