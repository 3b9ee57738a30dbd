//! The signs physics fixes, checked on the estimate.
//!
//! A friction coefficient, a rotor inertia, a mass or a moment of inertia about an axis cannot be
//! negative; nor can a base parameter that is, whatever the links' mass distributions, a
//! non-negative combination of them (`ZZR1 = ZZ1 + YY2 + ... + 1024 IA1`). Precisely: x_r =
//! sum_i c_i K_i is non-negative on every physically consistent K (each link's pseudo-inertia
//! J_l positive semidefinite, IA, FS, FV >= 0) iff, for every link, the linear function of its
//! inertial parameters is tr(C_l J_l) with C_l positive semidefinite (the cone of PSD matrices
//! is self-dual) and its IA, FS, FV coefficients are >= 0; non-positive iff every C_l is
//! negative semidefinite and those coefficients are <= 0.
//!
//! With J = [Σ h; h^T m] (Σ = tr(I)/2 1 - I, h = MS, m = M) and XX = Σyy + Σzz, XY = -Σxy, ...,
//! the coefficients b of (XX XY XZ YY YZ ZZ MX MY MZ M) give
//!
//! ```text
//! C = [ bYY+bZZ  -bXY/2   -bXZ/2   bMX/2 ]
//!     [ -bXY/2   bXX+bZZ  -bYZ/2   bMY/2 ]
//!     [ -bXZ/2   -bYZ/2   bXX+bYY  bMZ/2 ]
//!     [ bMX/2    bMY/2    bMZ/2    bM    ]
//! ```
//!
//! An estimate of the other sign is reported ([`WarningKind::PhysicallyImpossible`]) when it is
//! significant (at least 2 standard deviations from zero, i.e. a relative standard deviation of
//! at most 50 %: below that the poorly-identified warning already says the value is not
//! significant) and not at rounding level (its torques above 1e-9 of the measured ones).

use super::estimators::output_sq;
use super::parameters::ParameterModel;
use super::{Warning, WarningKind};
use crate::algorithms::regressor::PARAMS_PER_LINK;
use crate::model::param::{FS, FV, IA};
use faer::Mat;
use nalgebra::Matrix4;

/// The sign physics gives a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sign {
    /// x >= 0 for every physically consistent robot.
    NonNegative,
    /// x <= 0 for every physically consistent robot.
    NonPositive,
}

/// A parameter's sign fixed by physics, with the reason in words.
#[derive(Clone, Debug, PartialEq)]
pub struct SignConstraint {
    /// Index of the parameter.
    pub parameter: usize,
    /// Its sign.
    pub sign: Sign,
    /// Why ("a Coulomb friction coefficient", ...).
    pub reason: String,
}

/// Relative tolerance on the eigenvalues of C_l and on the drive coefficients (the grouping
/// coefficients of the numerical method carry rounding errors).
const TOLERANCE: f64 = 1e-9;

/// The parameters of `model` whose sign physics fixes.
pub fn constraints(model: &ParameterModel) -> Vec<SignConstraint> {
    model
        .params
        .iter()
        .enumerate()
        .filter(|(_, p)| !p.kind.is_free())
        .filter_map(|(r, _)| {
            let terms = &model.map[r];
            let sign = sign_of(terms)?;
            Some(SignConstraint {
                parameter: r,
                sign,
                reason: reason(terms, sign),
            })
        })
        .collect()
}

/// The sign of sum_i c K_i over the physically consistent K, if fixed.
fn sign_of(terms: &[(usize, f64)]) -> Option<Sign> {
    let scale = terms.iter().fold(0.0f64, |m, (_, c)| m.max(c.abs()));
    if scale == 0.0 {
        return None;
    }
    let tol = TOLERANCE * scale;
    let mut links: Vec<usize> = terms.iter().map(|(i, _)| i / PARAMS_PER_LINK).collect();
    links.sort_unstable();
    links.dedup();
    let (mut nonneg, mut nonpos) = (true, true);
    for l in links {
        let mut b = [0.0; PARAMS_PER_LINK];
        for (i, c) in terms.iter().filter(|(i, _)| i / PARAMS_PER_LINK == l) {
            b[i % PARAMS_PER_LINK] += c;
        }
        for d in [IA, FS, FV] {
            nonneg &= b[d] >= -tol;
            nonpos &= b[d] <= tol;
        }
        let eig = pseudo_inertia_functional(&b).symmetric_eigenvalues();
        nonneg &= eig.min() >= -tol;
        nonpos &= eig.max() <= tol;
    }
    match (nonneg, nonpos) {
        (true, false) => Some(Sign::NonNegative),
        (false, true) => Some(Sign::NonPositive),
        _ => None,
    }
}

/// C with tr(C J) = sum_k b_k K_k over a link's ten inertial parameters (module documentation).
fn pseudo_inertia_functional(b: &[f64; PARAMS_PER_LINK]) -> Matrix4<f64> {
    let [xx, xy, xz, yy, yz, zz, mx, my, mz, m, ..] = *b;
    Matrix4::new(
        yy + zz,
        -xy / 2.0,
        -xz / 2.0,
        mx / 2.0,
        -xy / 2.0,
        xx + zz,
        -yz / 2.0,
        my / 2.0,
        -xz / 2.0,
        -yz / 2.0,
        xx + yy,
        mz / 2.0,
        mx / 2.0,
        my / 2.0,
        mz / 2.0,
        m,
    )
}

fn reason(terms: &[(usize, f64)], sign: Sign) -> String {
    // terms at rounding level (grouping coefficients of the numerical method) do not count
    let scale = terms.iter().fold(0.0f64, |m, (_, c)| m.max(c.abs()));
    let terms: Vec<(usize, f64)> = terms
        .iter()
        .copied()
        .filter(|(_, c)| c.abs() > TOLERANCE * scale)
        .collect();
    let what = match terms.as_slice() {
        [(i, _)] => match i % PARAMS_PER_LINK {
            FS => Some("a Coulomb friction coefficient"),
            FV => Some("a viscous friction coefficient"),
            IA => Some("a rotor inertia"),
            9 => Some("a mass"),
            0 | 3 | 5 => Some("a moment of inertia about an axis"),
            _ => None,
        },
        _ => None,
    };
    let word = match sign {
        Sign::NonNegative => "negative",
        Sign::NonPositive => "positive",
    };
    match what {
        Some(w) => format!("{w} cannot be {word}"),
        None => format!(
            "its grouping equation cannot be {word} for rigid bodies (it is a {} combination of \
             masses, moments of inertia and drive parameters for every mass distribution: \
             pseudo-inertias positive semidefinite)",
            if sign == Sign::NonNegative {
                "non-negative"
            } else {
                "non-positive"
            }
        ),
    }
}

/// The warnings of the estimate `x` (standard deviations `std`, relative ones `relative_std`
/// in %) against the signs of [`constraints`]; `factors` are the triangular factors of the fit
/// rows (one per joint), for the size of each parameter's torques.
pub fn warnings(
    model: &ParameterModel,
    x: &[f64],
    std: &[f64],
    relative_std: &[f64],
    factors: &[Mat<f64>],
) -> Vec<Warning> {
    let y_norm = factors.iter().map(output_sq).sum::<f64>().sqrt();
    let column_norm = |c: usize| {
        factors
            .iter()
            .map(|t| (0..t.nrows()).map(|i| t[(i, c)] * t[(i, c)]).sum::<f64>())
            .sum::<f64>()
            .sqrt()
    };
    constraints(model)
        .into_iter()
        .filter_map(|c| {
            let r = c.parameter;
            let wrong = match c.sign {
                Sign::NonNegative => x[r] < 0.0,
                Sign::NonPositive => x[r] > 0.0,
            };
            let significant = relative_std[r] <= 50.0;
            let visible = x[r].abs() * column_norm(r) > 1e-9 * y_norm;
            (wrong && significant && visible).then(|| {
                let name = &model.params[r].name;
                Warning::new(
                    WarningKind::PhysicallyImpossible,
                    vec![name.clone()],
                    format!(
                        "{name} = {:.4e} ({:.1} standard deviations from zero) is physically \
                         impossible: {} (a torque channel of the wrong sign, an offset left out, \
                         or an effect the model lacks?)",
                        x[r],
                        x[r].abs() / std[r].max(f64::MIN_POSITIVE),
                        c.reason
                    ),
                )
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::model::param::{M, MX, MZ, XX, XY, YY, ZZ};

    fn at(link: usize, k: usize) -> usize {
        PARAMS_PER_LINK * (link - 1) + k
    }

    #[test]
    fn single_physical_quantities_have_their_signs() {
        for k in [XX, YY, ZZ, M, IA, FS, FV] {
            assert_eq!(sign_of(&[(at(2, k), 1.0)]), Some(Sign::NonNegative), "{k}");
            assert_eq!(sign_of(&[(at(2, k), -3.0)]), Some(Sign::NonPositive), "{k}");
        }
        for k in [XY, MX, MZ, 2, 4, 7] {
            assert_eq!(sign_of(&[(at(1, k), 1.0)]), None, "{k}");
        }
    }

    /// Sums of moments of inertia and masses (ZZR1-like) are non-negative; a difference of
    /// moments (XXR = XX - YY) is free; MZ with a mass and moments: non-negative exactly when
    /// the second moment bounds it (MZ^2 <= M Σzz for a rigid body).
    #[test]
    fn combinations_follow_the_pseudo_inertia() {
        let zzr1 = [
            (at(1, ZZ), 1.0),
            (at(2, YY), 1.0),
            (at(3, YY), 1.0),
            (at(3, M), 0.05),
            (at(1, IA), 1024.0),
        ];
        assert_eq!(sign_of(&zzr1), Some(Sign::NonNegative));
        assert_eq!(sign_of(&[(at(2, XX), 1.0), (at(2, YY), -1.0)]), None);
        // ZZ + 2 d MZ + d^2 M = the moment about an axis shifted by d along z... of x^2 + y^2:
        // the moment of inertia about a parallel axis, non-negative
        let d = 0.3;
        let shifted = [(at(3, XX), 1.0), (at(3, MZ), 2.0 * d), (at(3, M), d * d)];
        // XX = Σyy + Σzz and Σzz + 2 d hz + d^2 m = ∫(z + d)^2 dm >= 0
        assert_eq!(sign_of(&shifted), Some(Sign::NonNegative));
        // with a smaller mass coefficient it can be negative (a thin body far along z)
        let too_little_mass = [
            (at(3, XX), 1.0),
            (at(3, MZ), 2.0 * d),
            (at(3, M), 0.5 * d * d),
        ];
        assert_eq!(sign_of(&too_little_mass), None);
    }

    /// The standard parameters (XX XY XZ YY YZ ZZ MX MY MZ M) of point masses (m, r), from
    /// their definitions (XX = sum m (y^2 + z^2), XY = -sum m x y, MX = sum m x, ...).
    fn point_masses(points: &[(f64, [f64; 3])]) -> [f64; 10] {
        let mut k = [0.0; 10];
        for &(m, [x, y, z]) in points {
            let add = [
                m * (y * y + z * z),
                -m * x * y,
                -m * x * z,
                m * (x * x + z * z),
                -m * y * z,
                m * (x * x + y * y),
                m * x,
                m * y,
                m * z,
                m,
            ];
            for (a, b) in k.iter_mut().zip(add) {
                *a += b;
            }
        }
        k
    }

    /// The characterization checked against the definitions: for random C (PSD or not), the
    /// functional b it stands for is found non-negative iff C is PSD; when it is, no cloud of
    /// point masses gives it a negative value; when it is not, the point mass built from the
    /// eigenvector of the negative eigenvalue (J = v v^T) does.
    #[test]
    fn signs_agree_with_point_masses() {
        use rand::Rng;
        let mut rng = crate::sampling::rng(3);
        let (mut psd, mut indefinite) = (0, 0);
        for trial in 0..400 {
            let a = Matrix4::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let shift = if trial % 2 == 0 { 0.0 } else { 0.8 };
            let c = a * a.transpose() - Matrix4::identity() * shift;
            // b from C (the inverse of pseudo_inertia_functional)
            let mut b = [0.0; PARAMS_PER_LINK];
            b[XX] = (c[(1, 1)] + c[(2, 2)] - c[(0, 0)]) / 2.0;
            b[YY] = (c[(0, 0)] + c[(2, 2)] - c[(1, 1)]) / 2.0;
            b[ZZ] = (c[(0, 0)] + c[(1, 1)] - c[(2, 2)]) / 2.0;
            b[XY] = -2.0 * c[(0, 1)];
            b[2] = -2.0 * c[(0, 2)];
            b[4] = -2.0 * c[(1, 2)];
            b[MX] = 2.0 * c[(0, 3)];
            b[7] = 2.0 * c[(1, 3)];
            b[MZ] = 2.0 * c[(2, 3)];
            b[M] = c[(3, 3)];
            let terms: Vec<(usize, f64)> = (0..10).map(|k| (at(2, k), b[k])).collect();
            let value = |k: &[f64; 10]| (0..10).map(|i| b[i] * k[i]).sum::<f64>();
            let eig = c.symmetric_eigen();
            let (lo, arg) =
                eig.eigenvalues
                    .iter()
                    .enumerate()
                    .fold(
                        (f64::INFINITY, 0),
                        |a, (i, &v)| if v < a.0 { (v, i) } else { a },
                    );
            if lo > 1e-6 {
                psd += 1;
                assert_ne!(sign_of(&terms), None, "C PSD, sign not found");
                for _ in 0..20 {
                    let cloud: Vec<(f64, [f64; 3])> = (0..3)
                        .map(|_| {
                            (
                                rng.random_range(0.0..2.0),
                                std::array::from_fn(|_| rng.random_range(-1.0..1.0)),
                            )
                        })
                        .collect();
                    assert!(value(&point_masses(&cloud)) >= -1e-12);
                }
            } else if lo < -1e-6 {
                indefinite += 1;
                let v = eig.eigenvectors.column(arg);
                if v[3].abs() > 1e-3 && eig.eigenvalues.max() > 1e-6 {
                    assert_eq!(sign_of(&terms), None, "C indefinite, sign claimed");
                    let r = [v[0] / v[3], v[1] / v[3], v[2] / v[3]];
                    let k = point_masses(&[(v[3] * v[3], r)]);
                    assert!(value(&k) < 0.0, "no negative value at the eigenvector");
                }
            }
        }
        assert!(
            psd > 50 && indefinite > 50,
            "{psd} PSD, {indefinite} indefinite"
        );
    }
}
