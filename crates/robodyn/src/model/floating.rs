//! The base of a robot: fixed, mobile (its motion imposed, SYMORO's `is_mobile`) or floating
//! (its motion results from the dynamics, SYMORO's `is_floating`): link 0 then has its own
//! standard inertial parameters and the state holds the base pose and twist in Pinocchio's
//! free-flyer convention (docs/models/floating_base.md).

use super::{inertia_to_antecedent, DynModel, FoldedLink, LinkConstants};
use crate::scalar::DynScalar;
use nalgebra::{Matrix3, Vector3};

/// What moves the base.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BaseKind {
    /// The base frame R_0 is fixed (gravity in R_0).
    Fixed,
    /// The base moves as the per-call [`crate::BaseMotion`] imposes (W0, WP0, V0, VP0).
    Mobile,
    /// The base is a free body (link 0) whose motion results from the dynamics: q has
    /// nq = 7 + N entries, velocities and accelerations nv = 6 + N.
    Floating,
}

impl BaseKind {
    /// `fixed`, `mobile` or `floating`.
    pub fn name(self) -> &'static str {
        match self {
            BaseKind::Fixed => "fixed",
            BaseKind::Mobile => "mobile",
            BaseKind::Floating => "floating",
        }
    }
}

/// Names of the 7 base entries of a floating robot's configuration q: the position of O_0 in
/// the world (m), then the unit quaternion of the base orientation (x, y, z, w).
pub const BASE_CONFIGURATION_NAMES: [&str; 7] = [
    "base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw",
];

/// Names of the 6 base entries of a floating robot's velocity v (and of accelerations and
/// generalized forces): the linear velocity of O_0 (m/s), then the angular velocity (rad/s),
/// both in the base frame R_0.
pub const BASE_VELOCITY_NAMES: [&str; 6] = [
    "base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz",
];

/// Largest | |quaternion| - 1 | accepted on entry (the quaternion is then normalized); a
/// larger gap is an error, not a silent renormalization of a wrong input.
pub const QUATERNION_TOLERANCE: f64 = 1e-6;

/// The refusal of a function that does not support floating bases yet (`what` names it),
/// for a description whose base floats: an error, never a fixed-base answer.
pub fn require_fixed_base(desc: &super::RobotDescription, what: &str) -> crate::Result<()> {
    if desc.floating_base.is_some() {
        return Err(crate::Error::Input(format!(
            "{what}: robot `{}` has a floating base, which {what} does not support yet (the \
             floating-base models are inverse_dynamics, inertia_matrix, h_vector and \
             direct_dynamics and the kinematics (placements, frame Jacobians, centre of mass) over nq / nv vectors)",
            desc.name
        )));
    }
    Ok(())
}

/// The floating base: the body of link 0 with every link rigidly attached to it (through fixed
/// frames only) folded in, and those links (for their external wrenches). Generic over the
/// scalar: the numeric robot's (`f64`, [`crate::Robot::floating_base`]) and the customized
/// symbolic model's (`Expr`, the generated floating inverse dynamic model).
#[derive(Clone, Debug)]
pub struct FloatingBase<T: DynScalar = f64> {
    /// Inertial parameters of the base body about O_0 in R_0 (link 0 and the links fixed on
    /// it); its `ia`, `fs`, `fv` are zero.
    pub body: LinkConstants<T>,
    /// The description links fixed on the base (host 0), with their placement in R_0.
    pub attached: Vec<FoldedLink<T>>,
}

impl<T: DynScalar> FloatingBase<T> {
    /// From link 0's 13 standard parameters (IA, FS, FV ignored) and the full model (every
    /// frame, not folded), whose links fixed on the base are folded into the body by the exact
    /// rigid-body transfer ([`inertia_to_antecedent`]).
    pub fn new(link0: [T; super::PARAMS_PER_LINK], model: &DynModel<T>) -> Self {
        let mut p = link0;
        p[super::param::IA] = T::zero();
        p[super::param::FS] = T::zero();
        p[super::param::FV] = T::zero();
        let mut body = LinkConstants::new(p);
        let nl = model.nl;
        // placement in R_0 of the fixed frames whose chain of antecedents ends on the base
        let mut place: Vec<Option<(Matrix3<T>, Vector3<T>)>> = vec![None; nl + 1];
        place[0] = Some((Matrix3::identity(), Vector3::zeros()));
        let mut attached = Vec::new();
        for j in 1..=nl {
            let fr = model.frame(j);
            if fr.joint.is_movable() {
                continue;
            }
            let Some((ra, pa)) = &place[fr.ant] else {
                continue;
            };
            let (r, p) = fr.transform(&T::zero());
            let (rot, pos) = (ra * &r, pa + ra * &p);
            let l = model.link(j);
            let (jj, ms) = inertia_to_antecedent(&rot, &pos, &l.inertia, &l.ms, &l.mass);
            body.inertia += jj;
            body.ms += ms;
            body.mass += l.mass.clone();
            attached.push(FoldedLink {
                host: 0,
                link: j,
                rot: rot.clone(),
                pos: pos.clone(),
            });
            place[j] = Some((rot, pos));
        }
        let i = &body.inertia;
        body.inertia_diff = Vector3::new(
            i[(2, 2)].clone() - i[(1, 1)].clone(),
            i[(0, 0)].clone() - i[(2, 2)].clone(),
            i[(1, 1)].clone() - i[(0, 0)].clone(),
        );
        FloatingBase { body, attached }
    }
}
