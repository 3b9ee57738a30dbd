//! Per-call inputs other than the joint state: gravity, base motion and external wrenches.

use crate::error::{check_vector, Error, Result};
use crate::scalar::DynScalar;
use nalgebra::Vector3;

/// Motion of the base frame R_0, components in R_0: angular velocity `w0` (rad/s), angular
/// acceleration `wp0` (rad/s²), velocity `v0` (m/s) and acceleration `vp0` (m/s²) of its origin.
#[derive(Clone, Debug, PartialEq)]
pub struct BaseMotion<T: DynScalar = f64> {
    /// Angular velocity of the base (rad/s).
    pub w0: Vector3<T>,
    /// Angular acceleration of the base (rad/s²).
    pub wp0: Vector3<T>,
    /// Velocity of O_0 (m/s).
    pub v0: Vector3<T>,
    /// Acceleration of O_0 (m/s²).
    pub vp0: Vector3<T>,
}

impl<T: DynScalar> BaseMotion<T> {
    /// A fixed base.
    pub fn fixed() -> Self {
        BaseMotion {
            w0: Vector3::zeros(),
            wp0: Vector3::zeros(),
            v0: Vector3::zeros(),
            vp0: Vector3::zeros(),
        }
    }
}

/// A wrench exerted BY a link ON the environment (SYMORO's FX..CZ): force (N) and moment about
/// O_j (N m), components in R_j.
#[derive(Clone, Debug, PartialEq)]
pub struct Wrench<T: DynScalar = f64> {
    /// Force exerted by the link on the environment (N), in R_j.
    pub force: Vector3<T>,
    /// Moment about O_j exerted by the link on the environment (N m), in R_j.
    pub moment: Vector3<T>,
}

impl<T: DynScalar> Wrench<T> {
    /// Every component finite ([`DynScalar::is_finite`]).
    pub fn is_finite(&self) -> bool {
        self.force
            .iter()
            .chain(self.moment.iter())
            .all(T::is_finite)
    }

    /// Every component exactly zero.
    pub fn is_zero(&self) -> bool {
        self.force.iter().chain(self.moment.iter()).all(T::is_zero)
    }

    /// No wrench.
    pub fn zero() -> Self {
        Wrench {
            force: Vector3::zeros(),
            moment: Vector3::zeros(),
        }
    }
}

/// Per-call inputs of the dynamic models other than the joint state. A robot's default
/// ([`crate::Robot::environment`]) holds the values of its description; change a clone of it for
/// a call (a contact force that changes every millisecond is a field set before the call).
#[derive(Clone, Debug, PartialEq)]
pub struct Environment<T: DynScalar = f64> {
    /// Gravity acceleration g in R_0 (m/s², e.g. [0, 0, -9.81]).
    pub gravity: Vector3<T>,
    /// Motion of the base.
    pub base: BaseMotion<T>,
    /// Wrench exerted by link j on the environment at index j-1 (NL entries).
    wrenches: Vec<Wrench<T>>,
    /// How many of `wrenches` have a component that is not finite (kept by the setters, so
    /// that the per-call check does not scan every link).
    non_finite: usize,
    /// How many of `wrenches` are not zero (kept by the setters: the recursions skip the
    /// wrenches when there is none).
    non_zero: usize,
}

impl<T: DynScalar> Environment<T> {
    /// Gravity g, base motion and no external wrench on NL links.
    pub fn new(gravity: Vector3<T>, base: BaseMotion<T>, nl: usize) -> Self {
        Environment {
            gravity,
            base,
            wrenches: vec![Wrench::zero(); nl],
            non_finite: 0,
            non_zero: 0,
        }
    }

    /// Number of links (NL) the wrenches are given for.
    pub fn n_links(&self) -> usize {
        self.wrenches.len()
    }

    /// The wrench exerted by link j (1-based) on the environment.
    ///
    /// # Panics
    /// If j is not a link number (1..=NL).
    #[inline]
    pub fn wrench(&self, j: usize) -> &Wrench<T> {
        &self.wrenches[j - 1]
    }

    /// True when some link has a nonzero external wrench.
    #[inline]
    pub fn has_wrenches(&self) -> bool {
        self.non_zero > 0
    }

    /// All wrenches, link 1 first.
    pub fn wrenches(&self) -> &[Wrench<T>] {
        &self.wrenches
    }

    /// Set the wrench exerted BY link j on the environment (robodyn's and SYMORO's convention):
    /// force (N) and moment about O_j (N m), components in R_j.
    pub fn set_wrench_by_link(
        &mut self,
        j: usize,
        force: Vector3<T>,
        moment: Vector3<T>,
    ) -> Result<()> {
        self.check_link(j)?;
        let w = Wrench { force, moment };
        let old = &self.wrenches[j - 1];
        self.non_finite =
            self.non_finite + usize::from(!w.is_finite()) - usize::from(!old.is_finite());
        self.non_zero = self.non_zero + usize::from(!w.is_zero()) - usize::from(!old.is_zero());
        self.wrenches[j - 1] = w;
        Ok(())
    }

    /// Set the wrench exerted ON link j by the environment (Pinocchio's `fext` convention):
    /// force (N) and moment about O_j (N m), components in R_j. Stored as its opposite.
    pub fn set_wrench_on_link(
        &mut self,
        j: usize,
        force: Vector3<T>,
        moment: Vector3<T>,
    ) -> Result<()> {
        self.set_wrench_by_link(j, -force, -moment)
    }

    /// Remove every external wrench.
    pub fn clear_wrenches(&mut self) {
        for w in self.wrenches.iter_mut() {
            *w = Wrench::zero();
        }
        self.non_finite = 0;
        self.non_zero = 0;
    }

    fn check_link(&self, j: usize) -> Result<()> {
        if j == 0 || j > self.wrenches.len() {
            return Err(Error::Input(format!(
                "link {j} does not exist (links 1..{})",
                self.wrenches.len()
            )));
        }
        Ok(())
    }
}

impl Environment<f64> {
    /// Check that the environment fits a robot of NL links and is finite.
    pub(crate) fn check(&self, nl: usize) -> Result<()> {
        if self.wrenches.len() != nl {
            return Err(Error::dimension(
                "environment wrenches",
                nl,
                self.wrenches.len(),
                "one per link",
            ));
        }
        // one branch-free pass over gravity and base motion (early-exit scans per vector cost
        // as much as a 6-joint NE), the wrenches' count kept by their setters; the offending
        // vector is looked for only on failure
        let b = &self.base;
        let finite = |v: &Vector3<f64>| v.iter().fold(true, |ok, x| ok & x.is_finite());
        let base_ok = finite(&self.gravity) & finite(&b.w0) & finite(&b.wp0);
        if base_ok & finite(&b.v0) & finite(&b.vp0) & (self.non_finite == 0) {
            Ok(())
        } else {
            self.locate_non_finite()
        }
    }

    /// The error naming the first vector that is not finite.
    #[cold]
    fn locate_non_finite(&self) -> Result<()> {
        let b = &self.base;
        for (what, v) in [
            ("gravity", &self.gravity),
            ("w0", &b.w0),
            ("wp0", &b.wp0),
            ("v0", &b.v0),
            ("vp0", &b.vp0),
        ] {
            check_vector(what, v.as_slice(), 3, String::new)?;
        }
        for (k, w) in self.wrenches.iter().enumerate() {
            if w.force
                .iter()
                .chain(w.moment.iter())
                .any(|x| !x.is_finite())
            {
                return Err(Error::Input(format!(
                    "the external wrench of link {} is not finite",
                    k + 1
                )));
            }
        }
        Ok(())
    }
}
