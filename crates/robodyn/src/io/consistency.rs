//! Physical consistency of the inertial parameters of a description: what a real rigid body
//! can have. The loaders run it and return what it finds as warnings (a file may describe
//! parameters that are not a body's on purpose, e.g. base parameters; a command that needs a
//! body decides whether a warning is an error).
//!
//! Link j's standard parameters about O_j in R_j (J = ∫(r'r I - r r') dm, MS = ∫ r dm, M) are
//! those of a body with a non-negative mass density exactly when its pseudo-inertia
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
//! two). Rotor inertia and friction coefficients must be non-negative.

use crate::error::Item;
use crate::io::Warning;
use crate::model::{param, RobotDescription, STANDARD_PARAMETERS};
use nalgebra::{Matrix3, Matrix4, Vector3};

/// Relative tolerance of the checks (against the largest entry of the link's P).
const TOL: f64 = 1e-9;

/// Check every link whose inertial parameters have numeric values (links with a symbol without
/// a value are skipped). One warning per problem, naming the link.
pub fn physical_consistency(desc: &RobotDescription) -> Vec<Warning> {
    let env = |s: &str| desc.symbols.get(s).copied();
    let mut out = Vec::new();
    for (idx, l) in desc.links.iter().enumerate() {
        let j = idx + 1;
        let v: Vec<Option<f64>> = l.params.iter().map(|e| e.eval(&env).ok()).collect();
        for k in [param::M, param::IA, param::FS, param::FV] {
            if let Some(x) = v[k].filter(|x| *x < 0.0) {
                let name = STANDARD_PARAMETERS[k];
                out.push(Warning::new(
                    Item::Link(j, Some(name.into())),
                    format!("{name} = {x} is negative"),
                ));
            }
        }
        let inertial: Option<Vec<f64>> = v[..=param::M].iter().copied().collect();
        if let Some(p) = inertial {
            if let Some(reason) = body_inconsistency(&p) {
                out.push(Warning::new(Item::Link(j, None), reason));
            }
        }
    }
    out
}

/// Why the ten inertial parameters `XX XY XZ YY YZ ZZ MX MY MZ M` are not a rigid body's, if
/// they are not.
pub fn body_inconsistency(p: &[f64]) -> Option<String> {
    let [xx, xy, xz, yy, yz, zz, mx, my, mz, m] = p.try_into().ok()?;
    let j = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    let ms = Vector3::new(mx, my, mz);
    let sigma = Matrix3::identity() * (j.trace() / 2.0) - j;
    let mut pseudo = Matrix4::zeros();
    pseudo.fixed_view_mut::<3, 3>(0, 0).copy_from(&sigma);
    pseudo.fixed_view_mut::<3, 1>(0, 3).copy_from(&ms);
    pseudo
        .fixed_view_mut::<1, 3>(3, 0)
        .copy_from(&ms.transpose());
    pseudo[(3, 3)] = m;
    let scale = pseudo.amax();
    if !scale.is_finite() {
        return Some("the inertial parameters are not finite".into());
    }
    let tol = TOL * scale;
    let smallest = pseudo.symmetric_eigenvalues().min();
    if smallest >= -tol {
        return None;
    }
    if m < 0.0 {
        return Some(format!("the mass M = {m} is negative"));
    }
    if m <= tol {
        return Some(format!(
            "a link without mass (M = {m}) must have no first moments and no inertia \
             (MX MY MZ = {mx} {my} {mz})"
        ));
    }
    let c = ms / m;
    let jg = j - (Matrix3::identity() * c.dot(&c) - c * c.transpose()) * m;
    let mut l: Vec<f64> = jg.symmetric_eigenvalues().iter().copied().collect();
    l.sort_by(f64::total_cmp);
    if l[0] < -tol {
        return Some(format!(
            "the inertia about the centre of mass has a negative principal moment \
             ({:.6e}, {:.6e}, {:.6e})",
            l[0], l[1], l[2]
        ));
    }
    if l[2] > l[0] + l[1] + tol {
        return Some(format!(
            "the principal moments about the centre of mass ({:.6e}, {:.6e}, {:.6e}) violate \
             the triangle inequality {:.6e} <= {:.6e} + {:.6e}",
            l[0], l[1], l[2], l[2], l[0], l[1]
        ));
    }
    Some(format!(
        "the pseudo-inertia matrix is not positive semi-definite (smallest eigenvalue \
         {smallest:.6e})"
    ))
}
