//! The customized inverse dynamic model of a floating-base robot (issue 27): the generic
//! Newton–Euler with the base as the root ([`floating_rnea`]) run on symbols, in Pinocchio's
//! free-flyer convention (docs/models/floating_base.md). The generated function takes
//! q (nq = 7 + N: the base position, not read, the quaternion x y z w, the joints),
//! qd (nv = 6 + N: V0 and W0 in R_0, the joint rates) and qdd (nv: their derivatives) and
//! returns nv generalized forces: the base wrench E0, N0 (force, moment about O_0, in R_0), then
//! the joint torques. The base orientation wR_0 is built from the quaternion normalized in the
//! code; gravity (the description's G) is in the world frame.

use super::{joint_symbol, GenOptions, ModelKind};
use crate::algorithms::floating_base::floating_rnea;
use crate::data::Data;
use crate::error::{Error, Item, Result};
use crate::model::{DynModel, FloatingBase, RobotDescription, STANDARD_PARAMETERS};
use crate::scalar::DynScalar as _;
use nalgebra::Matrix3;
use robodyn_symbolic::{Assignment, Expr, InputGroup};

/// Symbols of the quaternion x y z w of the base orientation wR_0: entries 3..7 of `q`.
pub const BASE_QUATERNION: [&str; 4] = ["QX0", "QY0", "QZ0", "QW0"];
/// Symbols of the base twist in R_0, entries 0..6 of `qd`: V0 (the velocity of O_0), W0.
pub const BASE_VELOCITY: [&str; 6] = ["V10", "V20", "V30", "W10", "W20", "W30"];
/// Symbols of the derivative of the base twist, entries 0..6 of `qdd`: DV0 = d(V0)/dt (not
/// the classical acceleration VP0 = DV0 + W0 x V0 of O_0), WP0 = d(W0)/dt.
pub const BASE_ACCELERATION: [&str; 6] = ["DV10", "DV20", "DV30", "WP10", "WP20", "WP30"];
/// Names of the base wrench, outputs 0..6: the force E0 and the moment N0 about O_0, in R_0.
pub const BASE_WRENCH: [&str; 6] = ["E10", "E20", "E30", "N10", "N20", "N30"];

/// The refusal of what the generator does not do for a floating robot (every model but the
/// inverse dynamic model, base parameters, closed chains, a mobile base, a wrench on link 0):
/// an error that names what is supported. Ok for a fixed or mobile base.
pub(super) fn check(desc: &RobotDescription, opt: &GenOptions) -> Result<()> {
    let Some(link0) = &desc.floating_base else {
        return Ok(());
    };
    let refuse = |what: String| {
        Err(Error::Input(format!(
            "code generation: robot `{}` has a floating base: {what}; for a floating robot the \
             generator writes the inverse dynamic model (`idm`: the base wrench and the joint \
             torques over q of nq = 7 + N entries, qd and qdd of nv = 6 + N) with the standard \
             parameters, and the numeric inertia_matrix, h_vector and direct_dynamics take \
             floating robots",
            desc.name
        )))
    };
    if opt.model != ModelKind::Idm {
        return refuse(format!(
            "the `{}` model of a floating robot is not generated yet",
            opt.model.name()
        ));
    }
    if opt.base.is_some() {
        return refuse("base parameters of a floating robot are not supported yet".into());
    }
    if desc.nj > desc.nl {
        return refuse("closed chains with a floating base are not supported yet".into());
    }
    if desc.mobile_base {
        return Err(Error::invalid(
            Item::Base("is_mobile".into()),
            "a base cannot be both mobile (its motion imposed) and floating (its motion \
             resulting from the dynamics)",
        ));
    }
    if let Some(k) = link0.wrench.iter().position(|e| !e.is_zero()) {
        return Err(Error::invalid(
            Item::Link(0, Some(crate::model::WRENCH_COMPONENTS[k].into())),
            "an external wrench on the floating base (link 0) is not supported yet: put it on a \
             link fixed to the base",
        ));
    }
    Ok(())
}

/// wR_0 from the quaternion (x, y, z, w) normalized: R = I + s (w [v]x + [v]x^2) with
/// s = 2 / (x^2 + y^2 + z^2 + w^2) (`QN0`), so that a quaternion of any nonzero norm gives the
/// rotation of its normalized form, as the library's entry check normalizes it.
fn base_rotation(x: Expr, y: Expr, z: Expr, w: Expr) -> Matrix3<Expr> {
    let sq = |a: &Expr| a.clone() * a.clone();
    let (xx, yy, zz) = (sq(&x), sq(&y), sq(&z));
    let s =
        (Expr::num(2.0) / (xx.clone() + yy.clone() + zz.clone() + sq(&w))).named(|| "QN0".into());
    let p = |a: &Expr, b: &Expr| a.clone() * b.clone();
    let one = Expr::one;
    let t = |e: Expr| s.clone() * e;
    Matrix3::new(
        one() - t(yy.clone() + zz.clone()),
        t(p(&x, &y) - p(&z, &w)),
        t(p(&x, &z) + p(&y, &w)),
        t(p(&x, &y) + p(&z, &w)),
        one() - t(xx.clone() + zz),
        t(p(&y, &z) - p(&x, &w)),
        t(p(&x, &z) - p(&y, &w)),
        t(p(&y, &z) + p(&x, &w)),
        one() - t(xx + yy),
    )
}

/// Record the floating inverse dynamic model on the folded symbolic `model` (link k the k-th
/// movable joint) with its base body `base`: outputs E0, N0, then `GAM<j>`.
pub(super) fn record_idm(
    model: &DynModel<Expr>,
    base: &FloatingBase<Expr>,
    q: &[Expr],
    qd: &[Expr],
    qdd: &[Expr],
) -> Vec<Assignment> {
    let [x, y, z, w] = BASE_QUATERNION.map(Expr::symbol);
    let rot = base_rotation(x, y, z, w);
    let with_base = |names: &[&str], joints: &[Expr]| -> Vec<Expr> {
        names
            .iter()
            .map(|&s| Expr::symbol(s))
            .chain(joints.iter().cloned())
            .collect()
    };
    let v = with_base(&BASE_VELOCITY, qd);
    let a = with_base(&BASE_ACCELERATION, qdd);
    let mut ws = Data::from_model(model);
    let mut tau = vec![Expr::zero(); model.nl + 6];
    floating_rnea(model, base, &model.env, &mut ws, &rot, q, &v, &a, &mut tau);
    let names = BASE_WRENCH
        .iter()
        .map(|s| s.to_string())
        .chain((1..=model.nl).map(|k| joint_symbol("GAM", model.wrench_link(k))));
    names
        .zip(tau)
        .map(|(name, expr)| Assignment { name, expr })
        .collect()
}

/// The input arrays of the floating inverse dynamic model: q (nq), qd and qdd (nv), the base's
/// entries first; `joints` are the movable joints in frame order.
pub(super) fn inputs(joints: &[usize]) -> Vec<InputGroup> {
    let group = |name: &str, doc: &str, base: Vec<Option<String>>, kind: &str| InputGroup {
        name: name.into(),
        doc: format!("{doc}, then the movable joints in frame order: {kind}<frame number>"),
        symbols: base
            .into_iter()
            .chain(joints.iter().map(|&j| Some(joint_symbol(kind, j))))
            .collect(),
        by_name: false,
    };
    let named = |names: &[&str]| names.iter().map(|s| Some(s.to_string())).collect();
    let mut q = vec![None; 3];
    q.extend(BASE_QUATERNION.iter().map(|s| Some(s.to_string())));
    vec![
        group(
            "q",
            "configuration, nq = 7 + N: base position in the world (not read), quaternion x y z w \
             of the base orientation (normalized here)",
            q,
            "q",
        ),
        group(
            "qd",
            "velocities, nv = 6 + N: V0 (velocity of O_0) and W0, both in the base frame",
            named(&BASE_VELOCITY),
            "QP",
        ),
        group(
            "qdd",
            "accelerations, nv = 6 + N: DV0 = d(V0)/dt, WP0 = d(W0)/dt",
            named(&BASE_ACCELERATION),
            "QDP",
        ),
    ]
}

/// Header lines of a floating robot's model: the conventions of its inputs and outputs.
pub(super) fn describe() -> Vec<String> {
    vec![
        "Floating base (Pinocchio's free flyer): out = [E0 (force), N0 (moment about O_0), both \
         in the base frame R_0; joint torques GAM<j>], the wrench the base needs and the joint \
         torques."
            .into(),
        "Base motion: VP0 - G = DV0 + W0 x V0 - R' G (VP<c>0), G the gravity in the world frame, \
         R = wR_0 from the quaternion; E0, N0 = link 0's own wrench + what its children \
         transmit."
            .into(),
    ]
}

/// Names intermediates may not take on a floating robot: the base's inputs and link 0's
/// standard parameters.
pub(super) fn reserved_names() -> Vec<String> {
    BASE_QUATERNION
        .iter()
        .chain(&BASE_VELOCITY)
        .chain(&BASE_ACCELERATION)
        .map(|s| s.to_string())
        .chain(STANDARD_PARAMETERS.iter().map(|p| format!("{p}0")))
        .collect()
}
