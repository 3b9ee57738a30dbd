//! Physical consistency of a link's inertial parameters: the one definition the library uses
//! (the load-time check of robot files, identification's consistent fit).
//!
//! Link j's ten inertial parameters about O_j in R_j (J = ∫(r'r I - r r') dm, MS = ∫ r dm, M)
//! are those of a body with a non-negative mass density (*density realizable*) exactly when its
//! pseudo-inertia
//!
//! ```text
//! P = [ Σ   MS ]     Σ = ∫ r r' dm = tr(J)/2 I - J,
//!     [ MS' M  ]
//! ```
//!
//! is positive semi-definite (Wensing, Kim and Slotine, "Linear matrix inequalities for
//! physically consistent inertial parameter identification", 2017). For M > 0 that is: the
//! inertia about the centre of mass J_G = J - M (c'c I - c c'), c = MS / M, has non-negative
//! principal moments satisfying the triangle inequalities (each at most the sum of the other
//! two). A tensor that is positive definite but violates a triangle inequality (principal
//! moments 0.1, 0.2, 0.5) belongs to no rigid body.

use crate::report::number::Sig;
use nalgebra::{Matrix3, Matrix4, Vector3};

/// Relative tolerance of [`body_inconsistency`] (against the largest entry of P).
pub const TOLERANCE: f64 = 1e-9;

/// The pseudo-inertia P (4 x 4) of the ten inertial parameters `XX XY XZ YY YZ ZZ MX MY MZ M`
/// (the first ten entries of `p`; see the [module](self)).
pub fn pseudo_inertia(p: &[f64]) -> Matrix4<f64> {
    let [xx, xy, xz, yy, yz, zz, mx, my, mz, m] =
        [p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9]];
    let t = 0.5 * (xx + yy + zz);
    #[rustfmt::skip]
    let pseudo = Matrix4::new(
        t - xx, -xy, -xz, mx,
        -xy, t - yy, -yz, my,
        -xz, -yz, t - zz, mz,
        mx, my, mz, m,
    );
    pseudo
}

/// Why ten inertial parameters are not a rigid body's.
#[derive(Clone, Debug, PartialEq)]
pub enum Inconsistency {
    /// Some parameter is not a finite number.
    NotFinite,
    /// M < 0.
    NegativeMass(f64),
    /// M = 0 with first moments or inertia (a point without mass cannot have them).
    Massless {
        /// MX, MY, MZ.
        first_moments: [f64; 3],
    },
    /// A principal moment of the inertia about the centre of mass is negative.
    NegativeMoment {
        /// The principal moments, increasing (the axes named when J_G is diagonal in R_j).
        moments: [f64; 3],
        /// `Ixx`, `Iyy`, `Izz` in that order when the principal axes are those of R_j.
        axes: Option<[&'static str; 3]>,
    },
    /// a + b < c for principal moments a <= b <= c about the centre of mass.
    Triangle {
        /// The principal moments, increasing.
        moments: [f64; 3],
        /// `Ixx`, `Iyy`, `Izz` in that order when the principal axes are those of R_j.
        axes: Option<[&'static str; 3]>,
    },
    /// The pseudo-inertia is not positive semi-definite (a case the above do not name).
    Pseudo {
        /// Its smallest eigenvalue.
        smallest: f64,
    },
}

impl std::fmt::Display for Inconsistency {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let g = |x: f64| Sig(x, 6);
        match self {
            Inconsistency::NotFinite => f.write_str("the inertial parameters are not finite"),
            Inconsistency::NegativeMass(m) => write!(f, "the mass M = {} is negative", g(*m)),
            Inconsistency::Massless {
                first_moments: [x, y, z],
            } => write!(
                f,
                "a link without mass (M = 0) must have no first moments and no inertia (MX MY \
                 MZ = {} {} {})",
                g(*x),
                g(*y),
                g(*z)
            ),
            Inconsistency::NegativeMoment { moments, axes } => {
                let [a, b, c] = moments;
                match axes {
                    Some(n) => write!(
                        f,
                        "{} < 0 at the centre of mass (the principal moments {} = {}, {} = {}, {} \
                         = {}): no rigid body has a negative moment of inertia",
                        n[0],
                        n[0],
                        g(*a),
                        n[1],
                        g(*b),
                        n[2],
                        g(*c)
                    ),
                    None => write!(
                        f,
                        "the inertia about the centre of mass has a negative principal moment \
                         ({}, {}, {}): no rigid body has one",
                        g(*a),
                        g(*b),
                        g(*c)
                    ),
                }
            }
            Inconsistency::Triangle { moments, axes } => {
                let [a, b, c] = moments;
                let (na, nb, nc) = match axes {
                    Some(n) => (n[0], n[1], n[2]),
                    None => ("I1", "I2", "I3"),
                };
                write!(
                    f,
                    "{na} + {nb} < {nc} at the centre of mass ({} + {} < {}){}: the moments of \
                     inertia of a rigid body satisfy the triangle inequalities (pseudo-inertia \
                     not positive semi-definite)",
                    g(*a),
                    g(*b),
                    g(*c),
                    if axes.is_none() {
                        ", principal moments I1 <= I2 <= I3"
                    } else {
                        ""
                    }
                )
            }
            Inconsistency::Pseudo { smallest } => write!(
                f,
                "the pseudo-inertia matrix is not positive semi-definite (smallest eigenvalue {})",
                g(*smallest)
            ),
        }
    }
}

/// Why the ten inertial parameters `XX XY XZ YY YZ ZZ MX MY MZ M` (the first ten entries of
/// `p`) are not a rigid body's, if they are not: the pseudo-inertia test of the
/// [module](self) with relative tolerance [`TOLERANCE`], and the violated condition named.
pub fn body_inconsistency(p: &[f64]) -> Option<Inconsistency> {
    if p[..10].iter().any(|x| !x.is_finite()) {
        return Some(Inconsistency::NotFinite);
    }
    let pseudo = pseudo_inertia(p);
    let scale = pseudo.amax();
    let tol = TOLERANCE * scale;
    let smallest = pseudo.symmetric_eigenvalues().min();
    if smallest >= -tol {
        return None;
    }
    let m = p[9];
    if m < 0.0 {
        return Some(Inconsistency::NegativeMass(m));
    }
    if m <= tol {
        return Some(Inconsistency::Massless {
            first_moments: [p[6], p[7], p[8]],
        });
    }
    let (moments, axes) = central_moments(p, tol);
    if moments[0] < -tol {
        return Some(Inconsistency::NegativeMoment { moments, axes });
    }
    if moments[2] > moments[0] + moments[1] + tol {
        return Some(Inconsistency::Triangle { moments, axes });
    }
    Some(Inconsistency::Pseudo { smallest })
}

/// The principal moments about the centre of mass (M > 0), increasing, with the names of their
/// axes (`Ixx`, `Iyy`, `Izz`) when J_G is diagonal in R_j (off-diagonal entries within `tol`).
fn central_moments(p: &[f64], tol: f64) -> ([f64; 3], Option<[&'static str; 3]>) {
    let [xx, xy, xz, yy, yz, zz, mx, my, mz, m] =
        [p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9]];
    let j = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    let c = Vector3::new(mx, my, mz) / m;
    let jg = j - (Matrix3::identity() * c.dot(&c) - c * c.transpose()) * m;
    let diagonal = [(0, 1), (0, 2), (1, 2)]
        .iter()
        .all(|&(r, k)| jg[(r, k)].abs() <= tol);
    if diagonal {
        let mut named = [
            (jg[(0, 0)], "Ixx"),
            (jg[(1, 1)], "Iyy"),
            (jg[(2, 2)], "Izz"),
        ];
        named.sort_by(|a, b| a.0.total_cmp(&b.0));
        return (named.map(|n| n.0), Some(named.map(|n| n.1)));
    }
    let mut l: Vec<f64> = jg.symmetric_eigenvalues().iter().copied().collect();
    l.sort_by(f64::total_cmp);
    ([l[0], l[1], l[2]], None)
}

#[cfg(test)]
mod tests {
    use super::{body_inconsistency, pseudo_inertia, Inconsistency};

    /// Standard parameters about O_j of a body of mass m, centre of mass c and inertia J_G
    /// (diagonal) about it: [`crate::identification::payload::rigid_body`].
    fn body(m: f64, c: [f64; 3], jg: [f64; 3]) -> [f64; 10] {
        let i_c = [[jg[0], 0.0, 0.0], [0.0, jg[1], 0.0], [0.0, 0.0, jg[2]]];
        crate::identification::payload::rigid_body(m, c, i_c)
    }

    #[test]
    fn triangle_inequality_is_named_with_the_values() {
        // positive definite about G, but 0.1 + 0.2 < 0.5: no body has it
        let p = body(2.0, [0.1, -0.05, 0.2], [0.1, 0.2, 0.5]);
        let e = body_inconsistency(&p).expect("inconsistent");
        assert!(
            matches!(e, Inconsistency::Triangle { axes: Some(_), .. }),
            "{e:?}"
        );
        let text = e.to_string();
        assert!(
            text.starts_with("Ixx + Iyy < Izz at the centre of mass (0.1 + 0.2 < 0.5)"),
            "{text}"
        );
        // the same body, realizable (0.2 + 0.35 >= 0.5), and a thin rod (equality) pass
        assert_eq!(
            body_inconsistency(&body(2.0, [0.1, 0.0, 0.2], [0.2, 0.35, 0.5])),
            None
        );
        assert_eq!(
            body_inconsistency(&body(1.0, [0.0; 3], [0.0, 0.3, 0.3])),
            None
        );
    }

    #[test]
    fn the_other_cases() {
        let neg = body(1.0, [0.0; 3], [-0.1, 0.3, 0.3]);
        assert!(body_inconsistency(&neg)
            .unwrap()
            .to_string()
            .starts_with("Ixx < 0 at the centre of mass"),);
        let mut p = body(1.0, [0.0; 3], [0.1, 0.1, 0.1]);
        p[9] = -1.0;
        assert_eq!(
            body_inconsistency(&p),
            Some(Inconsistency::NegativeMass(-1.0))
        );
        let mut p = [0.0; 10];
        p[6] = 0.5;
        assert!(matches!(
            body_inconsistency(&p),
            Some(Inconsistency::Massless { .. })
        ));
        p[0] = f64::NAN;
        assert_eq!(body_inconsistency(&p), Some(Inconsistency::NotFinite));
        // principal axes off the frame's: unnamed moments, still the triangle
        let mut p = body(1.0, [0.0; 3], [0.1, 0.2, 0.5]);
        let (s, c) = (0.6f64, 0.8f64);
        // rotate J about z by an angle with cos 0.8, sin 0.6
        let (a, b) = (p[0], p[3]);
        p[0] = c * c * a + s * s * b;
        p[3] = s * s * a + c * c * b;
        p[1] = c * s * (a - b);
        let e = body_inconsistency(&p).unwrap();
        assert!(
            matches!(e, Inconsistency::Triangle { axes: None, .. }),
            "{e:?}"
        );
        assert!(e
            .to_string()
            .starts_with("I1 + I2 < I3 at the centre of mass (0.1 + 0.2 < 0.5)"));
    }

    /// P's quadratic form is the second moment of the body's points in homogeneous
    /// coordinates: for two point masses, P = sum m_i [r_i; 1][r_i; 1]', PSD and singular
    /// along the direction orthogonal to both.
    #[test]
    fn pseudo_inertia_of_point_masses() {
        let pts = [(2.0, [0.3, -0.1, 0.2]), (0.5, [-0.2, 0.4, 0.1])];
        let mut p = [0.0; 10];
        let mut expected = nalgebra::Matrix4::zeros();
        for (m, r) in pts {
            let rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            let h = nalgebra::Vector4::new(r[0], r[1], r[2], 1.0);
            expected += h * h.transpose() * m;
            let j = [
                rr - r[0] * r[0],
                -r[0] * r[1],
                -r[0] * r[2],
                rr - r[1] * r[1],
                -r[1] * r[2],
                rr - r[2] * r[2],
            ];
            for k in 0..6 {
                p[k] += m * j[k];
            }
            for k in 0..3 {
                p[6 + k] += m * r[k];
            }
            p[9] += m;
        }
        assert!((pseudo_inertia(&p) - expected).amax() < 1e-15);
        // two points: a degenerate but realizable body
        assert_eq!(body_inconsistency(&p), None);
    }
}
