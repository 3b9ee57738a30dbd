//! The dynamic model is linear in the standard parameters (§10.2.4):
//! Gamma_tr = Phi(q, qd, qdd) K + Gamma_e, with K = [XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV] per link (13 NL entries, link 1
//! first) and Phi the regressor.
//!
//! Phi is computed recursively, not by finite differences: after the forward Newton–Euler
//! recursion (eqs 10.3–10.6) the wrench of link j is linear in its 10 inertial parameters
//! (eqs 10.7–10.8): [jF_j; jM_j] = Y_j [J; MS; M] with Y_j a 6x10 matrix. Y_j is projected on
//! joint j and carried to the ancestors k of j with the backward transformation (10.10)–(10.11);
//! its z row (moment for a revolute joint k, force for a prismatic one) is the block of Phi in row
//! k and the columns of link j. IA_j, FS_j, FV_j add qdd_j, sign(qd_j), qd_j in row j (10.12).
//!
//! External wrenches are not parameters: [`regressor`] gives Phi with Phi K = Gamma - Gamma_e,
//! and [`wrench_torques`] gives Gamma_e, the torques that the external wrenches (fe_j, me_j) alone
//! produce. For a closed chain, Gamma_cl = G^T Gamma_tr (10.40), so its regressor is G^T Phi
//! ([`closed_chain_regressor`]).

use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::{
    DynModel, Environment, JointType, Robot, RobotDescription, STANDARD_PARAMETERS,
};
use nalgebra::{DMatrix, Matrix3, SMatrix, Vector3};

use super::floating_base::v3;
use super::inverse_dynamics::{
    add_folded_wrenches, check_state, forward_links, forward_pass, on_tree_arrays, set_base_motion,
    tree_vector_map, State,
};

pub use crate::model::{RotorMode, PARAMS_PER_LINK};

/// Name of standard parameter `index` of the vector K (0-based, 13 per link): `XX1`, ..., `FV<NL>`.
pub fn parameter_name(index: usize) -> String {
    format!(
        "{}{}",
        STANDARD_PARAMETERS[index % PARAMS_PER_LINK],
        index / PARAMS_PER_LINK + 1
    )
}

/// What a parameter written as a literal `0` in the robot file means.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ZeroParameters {
    /// SYMORO's meaning (SYMORO+, OpenSYMORO): the parameter does not exist; it is not a column
    /// of the regressor and not a base parameter. A symbol whose value is 0 stays a parameter.
    Absent,
    /// A number like any other: the parameter exists and its value is 0 (URDF inertias, the
    /// numeric values of robodyn's TOML files).
    Value,
}

impl ZeroParameters {
    /// Both meanings (what a command line or a binding offers).
    pub const ALL: [ZeroParameters; 2] = [ZeroParameters::Absent, ZeroParameters::Value];

    /// The meaning's name: `absent`, `value` ([`ZeroParameters::from_name`] reads it back).
    pub fn name(self) -> &'static str {
        match self {
            ZeroParameters::Absent => "absent",
            ZeroParameters::Value => "value",
        }
    }

    /// The meaning of a name of [`ZeroParameters::name`].
    pub fn from_name(name: &str) -> Option<ZeroParameters> {
        ZeroParameters::ALL.into_iter().find(|z| z.name() == name)
    }

    /// The meaning in a few words.
    pub fn describe(self) -> &'static str {
        match self {
            ZeroParameters::Absent => {
                "a parameter written as a literal 0 does not exist (SYMORO's meaning)"
            }
            ZeroParameters::Value => "a literal 0 is a value: the parameter exists",
        }
    }

    /// The meaning of the file format (by extension): `.par` -> [`ZeroParameters::Absent`],
    /// `.toml` and `.urdf` -> [`ZeroParameters::Value`] (see docs/robot-format.md).
    pub fn for_path(path: &std::path::Path) -> ZeroParameters {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("par") => ZeroParameters::Absent,
            _ => ZeroParameters::Value,
        }
    }
}

/// Whether the Coulomb and viscous friction FS_j, FV_j are parameters of a model (passive joints
/// of closed loops are assumed frictionless).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Friction {
    /// FS_j and FV_j for the actuated joints.
    Actuated,
    /// No friction parameter.
    None,
}

/// Which of the drive parameters IA, FS, FV are kept, joint by joint (index j-1), and which
/// standard parameters do not exist (`absent`, K indices: written as a literal 0 in a SYMORO
/// file). The ten inertial parameters of every link are in K unless absent.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParameterSelection {
    /// IA_j is a parameter (index j-1).
    pub rotor: Vec<bool>,
    /// FS_j and FV_j are parameters (index j-1).
    pub friction: Vec<bool>,
    /// K indices (13 per link) of the parameters that do not exist.
    pub absent: std::collections::BTreeSet<usize>,
}

impl ParameterSelection {
    /// Rotor inertias by `rotor`, Coulomb and viscous friction by `friction`
    /// ([`Friction::Actuated`]: on the actuated joints).
    pub fn new(robot: &Robot, rotor: RotorMode, friction: Friction) -> Self {
        Self::from_description(robot.description(), rotor, friction)
    }

    /// As [`ParameterSelection::new`], from a description (symbols may lack values).
    pub fn from_description(desc: &RobotDescription, rotor: RotorMode, friction: Friction) -> Self {
        let friction = friction == Friction::Actuated;
        let nl = desc.nl;
        let f = |j: usize| desc.frame(j);
        ParameterSelection {
            rotor: (1..=nl)
                .map(|j| match rotor {
                    RotorMode::Actuated => f(j).actuated && f(j).joint.is_movable(),
                    RotorMode::All => f(j).joint.is_movable(),
                    RotorMode::None => false,
                })
                .collect(),
            friction: (1..=nl)
                .map(|j| friction && f(j).actuated && f(j).joint.is_movable())
                .collect(),
            absent: Default::default(),
        }
    }

    /// Apply `zeros` to the parameters of `desc` written as a literal 0: with
    /// [`ZeroParameters::Absent`] they leave K (a symbol, even one whose value is 0, stays).
    pub fn with_zero_parameters(mut self, desc: &RobotDescription, zeros: ZeroParameters) -> Self {
        self.absent.clear();
        if zeros == ZeroParameters::Absent {
            for (j, l) in desc.links.iter().enumerate() {
                for (p, e) in l.params.iter().enumerate() {
                    if e.is_zero() {
                        self.absent.insert(PARAMS_PER_LINK * j + p);
                    }
                }
            }
        }
        self
    }

    /// Whether standard parameter `index` (K index) is in the selection for its drive part
    /// (rotor, friction), whether or not it exists.
    pub fn slot(&self, index: usize) -> bool {
        let j = index / PARAMS_PER_LINK;
        match index % PARAMS_PER_LINK {
            10 => self.rotor[j],
            11 | 12 => self.friction[j],
            _ => true,
        }
    }

    /// Every drive parameter of every link.
    pub fn all(nl: usize) -> Self {
        ParameterSelection {
            rotor: vec![true; nl],
            friction: vec![true; nl],
            absent: Default::default(),
        }
    }

    /// Indices in K (13 per link) of the selected parameters that exist, in K's order.
    pub fn columns(&self) -> Vec<usize> {
        (0..PARAMS_PER_LINK * self.rotor.len())
            .filter(|&i| self.slot(i) && !self.absent.contains(&i))
            .collect()
    }
}

/// Unit inertia tensor of inertial parameter p (0..6: XX XY XZ YY YZ ZZ).
fn unit_inertia(p: usize) -> Matrix3<f64> {
    let (r, c) = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)][p];
    let mut m = Matrix3::zeros();
    m[(r, c)] = 1.0;
    m[(c, r)] = 1.0;
    m
}

/// Y_j: [F; M] = Y_j [XX XY XZ YY YZ ZZ MX MY MZ M]^T (eqs 10.7–10.8).
fn link_wrench_map(w: &Vector3<f64>, wd: &Vector3<f64>, vd: &Vector3<f64>) -> SMatrix<f64, 6, 10> {
    let mut y = SMatrix::<f64, 6, 10>::zeros();
    for p in 0..6 {
        let j = unit_inertia(p);
        let m = j * wd + w.cross(&(j * w));
        y.fixed_view_mut::<3, 1>(3, p).copy_from(&m);
    }
    for a in 0..3 {
        let mut e = Vector3::zeros();
        e[a] = 1.0;
        // F = U MS, M = MS x vd
        let f = wd.cross(&e) + w.cross(&w.cross(&e));
        y.fixed_view_mut::<3, 1>(0, 6 + a).copy_from(&f);
        y.fixed_view_mut::<3, 1>(3, 6 + a).copy_from(&e.cross(vd));
    }
    y.fixed_view_mut::<3, 1>(0, 9).copy_from(vd);
    y
}

/// Regressor of the tree on tree arrays, Phi (NL x 13 NL), written into `phi`, such that
/// Phi K = Gamma_tr - Gamma_e under `env` (its gravity and base motion; the wrenches are Gamma_e):
/// the kernel. Allocation-free: intermediate values live in `ws` (the forward recursion runs
/// first; the parameters of `model` only affect buffers the regressor does not read). Rows of
/// fixed frames are zero.
///
/// # Panics
/// If `phi` is not NL x 13 NL.
#[allow(clippy::too_many_arguments)]
pub fn tree_regressor(
    model: &DynModel<f64>,
    ws: &mut Data,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    phi: &mut DMatrix<f64>,
) {
    let nl = model.nl;
    assert_eq!(phi.shape(), (nl, PARAMS_PER_LINK * nl), "regressor size");
    forward_pass(model, env, ws, q, qd, qdd, &[]);
    phi.as_mut_slice().fill(0.0); // contiguous: nalgebra's `fill` walks a strided iterator
    link_columns(model, ws, qd, qdd, phi, 0, false);
}

/// The columns of links 1..NL of Phi after the forward recursion: Y_j of every link carried to
/// its ancestors (rows `r0 + k - 1`), then IA_j, FS_j, FV_j in row `r0 + j - 1`. `to_base`
/// (a floating base): Y_j is carried on into R_0 and written in rows 0..6 (the base wrench:
/// force, moment about O_0).
fn link_columns(
    model: &DynModel<f64>,
    ws: &Data,
    qd: &[f64],
    qdd: &[f64],
    phi: &mut DMatrix<f64>,
    r0: usize,
    to_base: bool,
) {
    for j in 1..=model.nl {
        let mut y = link_wrench_map(&ws.w[j], &ws.wd[j], &ws.vd[j]);
        let col = PARAMS_PER_LINK * (j - 1);
        let mut k = j;
        loop {
            let fr = model.frame(k);
            let row = match fr.joint {
                JointType::Revolute => Some(5),
                JointType::Prismatic => Some(2),
                JointType::Fixed => None,
            };
            if let Some(r) = row {
                for c in 0..10 {
                    phi[(r0 + k - 1, col + c)] = y[(r, c)];
                }
            }
            let i = fr.ant;
            if i == 0 && !to_base {
                break;
            }
            // (10.10)–(10.11): iF = iA_k kF, iM = iA_k kM + iP_k x iF
            let rot = &ws.rot[k];
            let pos = &ws.pos[k];
            for c in 0..10 {
                let f = rot * y.fixed_view::<3, 1>(0, c);
                let m = rot * y.fixed_view::<3, 1>(3, c) + pos.cross(&f);
                y.fixed_view_mut::<3, 1>(0, c).copy_from(&f);
                y.fixed_view_mut::<3, 1>(3, c).copy_from(&m);
            }
            if i == 0 {
                phi.view_mut((0, col), (6, 10)).copy_from(&y);
                break;
            }
            k = i;
        }
        if model.frame(j).joint.is_movable() {
            let s = qd[j - 1];
            phi[(r0 + j - 1, col + 10)] = qdd[j - 1];
            phi[(r0 + j - 1, col + 11)] = if s > 0.0 {
                1.0
            } else if s < 0.0 {
                -1.0
            } else {
                0.0
            };
            phi[(r0 + j - 1, col + 12)] = s;
        }
    }
}

/// Number of regressor columns (standard parameters) of a floating base's own body (link 0):
/// XX0 XY0 XZ0 YY0 YZ0 ZZ0 MX0 MY0 MZ0 M0 (no drive parameter).
pub const BASE_LINK_PARAMETERS: usize = 10;

/// Number of standard parameters in K (regressor columns) of `robot`: 13 NL, plus the 10 of
/// link 0 (after the links' 13 NL) for a floating base.
pub fn parameter_count(robot: &Robot) -> usize {
    PARAMS_PER_LINK * robot.nl()
        + if robot.is_floating() {
            BASE_LINK_PARAMETERS
        } else {
            0
        }
}

/// The standard parameters K of the regressor's columns ([`parameter_count`] entries): 13 per
/// link (link 1 first, [`Robot::standard_parameters`]), then for a floating base link 0's 10
/// (XX0 ... M0 of the description's base link, the links fixed on it not folded in: they are
/// links of K).
pub fn regressor_parameters(robot: &Robot) -> Vec<f64> {
    let mut k = robot.standard_parameters();
    if let Some(l) = &robot.description().floating_base {
        for e in &l.params[..BASE_LINK_PARAMETERS] {
            k.push(robot.value(e).expect("validated"));
        }
    }
    k
}

/// The floating base's motion (in R_0) for the regressor: twist `v` = (v_0, w_0) and its
/// derivative `a`, and wR_0.
#[derive(Clone, Copy, Debug)]
pub struct FloatingBaseState<'a> {
    /// wR_0, the base orientation in the world.
    pub rot: &'a Matrix3<f64>,
    /// v_0 (3), w_0 (3), in R_0.
    pub v: &'a [f64],
    /// The derivative of `v`.
    pub a: &'a [f64],
}

/// Regressor of a floating tree on tree arrays, ((6 + NL) x (13 NL + 10)), written into `phi`,
/// such that Phi K = [base wrench (force, moment about O_0, in R_0); Gamma_tr] (no external
/// wrench; `env`'s gravity in the world): the kernel. Columns: link 1..NL (13 each) then link
/// 0's 10 ([`BASE_LINK_PARAMETERS`]). The base is the root of the recursion with the motion
/// [w_0, wd_0, a_0 + w_0 x v_0 - R' g], as the floating inverse dynamics.
///
/// # Panics
/// If `phi` is not (6 + NL) x (13 NL + 10) or the base slices have fewer than 6 entries.
#[allow(clippy::too_many_arguments)]
pub fn floating_tree_regressor(
    model: &DynModel<f64>,
    ws: &mut Data,
    env: &Environment,
    base: FloatingBaseState<'_>,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    phi: &mut DMatrix<f64>,
) {
    let nl = model.nl;
    let cols = PARAMS_PER_LINK * nl;
    assert_eq!(
        phi.shape(),
        (6 + nl, cols + BASE_LINK_PARAMETERS),
        "regressor size"
    );
    let (lin, w) = (v3(&base.v[0..3]), v3(&base.v[3..6]));
    let (alin, wd) = (v3(&base.a[0..3]), v3(&base.a[3..6]));
    let vd0 = alin + w.cross(&lin) - base.rot.tr_mul(&env.gravity);
    set_base_motion(ws, w, wd, vd0);
    forward_links(model, env, ws, q, qd, qdd, &[]);
    phi.as_mut_slice().fill(0.0);
    link_columns(model, ws, qd, qdd, phi, 6, true);
    let y0 = link_wrench_map(&w, &wd, &vd0);
    phi.view_mut((0, cols), (6, BASE_LINK_PARAMETERS))
        .copy_from(&y0);
}

/// Gamma_e on tree arrays: torques of the tree joints produced by the external wrenches of
/// `env` alone, at configuration q (they do not depend on qd, qdd): the kernel. Overwrites the
/// buffers of `ws`.
pub fn tree_wrench_torques(
    model: &DynModel<f64>,
    ws: &mut Data,
    env: &Environment,
    q: &[f64],
    tau: &mut [f64],
) {
    let nl = model.nl;
    for j in 1..=nl {
        let (rot, pos) = model.frame(j).transform(&q[j - 1]);
        ws.rot[j] = rot;
        ws.pos[j] = pos;
        let e = env.wrench(model.wrench_link(j));
        ws.f[j] = e.force;
        ws.m[j] = e.moment;
    }
    add_folded_wrenches(model, env, &mut ws.f, &mut ws.m);
    for j in (1..=nl).rev() {
        let fr = model.frame(j);
        tau[j - 1] = match fr.joint {
            JointType::Revolute => ws.m[j].z,
            JointType::Prismatic => ws.f[j].z,
            JointType::Fixed => 0.0,
        };
        let i = fr.ant;
        if i > 0 {
            let fi = ws.rot[j] * ws.f[j];
            let mi = ws.rot[j] * ws.m[j] + ws.pos[j].cross(&fi);
            ws.f[i] += fi;
            ws.m[i] += mi;
        }
    }
}

/// Regressor of a closed chain: G^T Phi (eq 10.40), with G = d q_tr / d q_a (NL x N) given by
/// the loop-closure solver (identity for a tree).
pub fn closed_chain_regressor(g: &DMatrix<f64>, phi: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    if g.nrows() != phi.nrows() {
        return Err(Error::Input(format!(
            "G has {} rows, the regressor has {} (one per tree joint)",
            g.nrows(),
            phi.nrows()
        )));
    }
    Ok(g.transpose() * phi)
}

/// Regressor Phi (N x 13 NL: rows over the movable joints, columns the standard parameters K,
/// 13 per link, link 1 first) into `phi`, such that Gamma = Phi K + Gamma_e under `env`
/// (gravity, base motion). `q`, `qd`, `qdd` over the movable joints. Allocation-free.
///
/// A floating robot (docs/models/floating_base.md): `q` (nq), `qd` = v and `qdd` = a (nv), and
/// Phi is nv x (13 NL + 10): rows the base wrench (force, moment about O_0, in R_0) then the
/// joints, columns the links' 13 NL parameters then link 0's 10 (XX0 ... M0, see
/// [`parameter_count`]), so that Phi K = the floating inverse model's nv forces (an external
/// wrench is refused: its Gamma_e over the base rows is not available yet).
#[allow(clippy::too_many_arguments)]
pub fn regressor_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    phi: &mut DMatrix<f64>,
) -> Result<()> {
    if robot.is_floating() {
        return floating_regressor_into(robot, data, env, q, qd, qdd, phi);
    }
    check_state(robot, data, ["q", "qd", "qdd"], [q, qd, qdd])?;
    env.check(robot.nl())?;
    let c = robot.coordinates();
    let (n, nl) = (c.len(), robot.nl());
    if phi.shape() != (n, PARAMS_PER_LINK * nl) {
        return Err(Error::dimension(
            "Phi",
            n * PARAMS_PER_LINK * nl,
            phi.len(),
            format!(
                "{n} x {} (movable joints x 13 standard parameters per link)",
                PARAMS_PER_LINK * nl
            ),
        ));
    }
    let model = robot.numeric();
    on_tree_arrays(robot, data, [q, qd, qdd], |data, q, qd, qdd| {
        let mut full = std::mem::replace(&mut data.phi, DMatrix::zeros(0, 0));
        if full.shape() != (nl, PARAMS_PER_LINK * nl) {
            full = DMatrix::zeros(nl, PARAMS_PER_LINK * nl); // first call only
        }
        tree_regressor(model, data, env, q, qd, qdd, &mut full);
        for (r, &j) in c.frames().iter().enumerate() {
            phi.row_mut(r).copy_from(&full.row(j - 1));
        }
        data.phi = full;
    });
    crate::error::check_finite_matrix("Phi", phi)
}

/// [`regressor_into`] for a floating robot: the floating state's checks (nq, nv, the
/// quaternion), then [`floating_tree_regressor`] on the tree arrays, rows gathered to the base
/// and the movable joints.
#[allow(clippy::too_many_arguments)]
fn floating_regressor_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    phi: &mut DMatrix<f64>,
) -> Result<()> {
    let vs = [("qd", v), ("qdd", a)];
    let nv = robot.nv();
    let rot = super::floating_base::check_state(robot, data, Some(env), q, &vs, ("Phi", nv))?;
    let (nl, cols) = (robot.nl(), parameter_count(robot));
    if phi.shape() != (nv, cols) {
        return Err(Error::dimension(
            "Phi",
            nv * cols,
            phi.len(),
            format!(
                "{nv} x {cols} (nv = 6 + {} rows; 13 standard parameters per link, then link \
                 0's 10)",
                robot.dof()
            ),
        ));
    }
    if env.has_wrenches() {
        return Err(Error::Input(
            "the regressor of a floating robot with external wrenches is not supported yet \
             (their part of the base wrench is not computed): remove the wrenches"
                .into(),
        ));
    }
    let model = robot.numeric();
    let c = robot.coordinates();
    let base = FloatingBaseState {
        rot: &rot,
        v: &v[..6],
        a: &a[..6],
    };
    on_tree_arrays(
        robot,
        data,
        [&q[7..], &v[6..], &a[6..]],
        |data, q, qd, qdd| {
            let mut full = std::mem::replace(&mut data.phi, DMatrix::zeros(0, 0));
            if full.shape() != (6 + nl, cols) {
                full = DMatrix::zeros(6 + nl, cols); // first call only
            }
            floating_tree_regressor(model, data, env, base, q, qd, qdd, &mut full);
            phi.rows_mut(0, 6).copy_from(&full.rows(0, 6));
            for (r, &j) in c.frames().iter().enumerate() {
                phi.row_mut(6 + r).copy_from(&full.row(5 + j));
            }
            data.phi = full;
        },
    );
    crate::error::check_finite_matrix("Phi", phi)
}

/// [`regressor_into`] with the state as named fields ([`State`]): Phi (N x 13 NL) into `phi`.
/// Allocation-free; the same checks and errors.
///
/// # Example
///
/// Phi K is the inverse model's torque (with the environment's wrenches, Gamma_e):
///
/// ```
/// use robodyn::nalgebra::{DMatrix, DVector};
/// use robodyn::{inverse_dynamics, regressor_state_into, Data, State};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.toml");
/// let robot = robodyn::io::load(path)?;
/// let mut data = Data::new(&robot);
/// let (q, qd, qdd) = ([0.1; 6], [0.2; 6], [0.3; 6]);
/// let mut phi = DMatrix::zeros(robot.dof(), 13 * robot.nl());
/// let state = State { q: &q, qd: &qd, qdd: &qdd };
/// regressor_state_into(&robot, &mut data, robot.environment(), state, &mut phi)?;
/// let by_phi = &phi * DVector::from_vec(robot.standard_parameters());
/// let tau = inverse_dynamics(&robot, &q, &qd, &qdd)?;
/// assert!((by_phi - tau).amax() < 1e-9); // no external wrench: Gamma_e = 0
/// # Ok(())
/// # }
/// ```
pub fn regressor_state_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    state: State<'_>,
    phi: &mut DMatrix<f64>,
) -> Result<()> {
    regressor_into(robot, data, env, state.q, state.qd, state.qdd, phi)
}

/// Gamma_e into `tau_e` (movable joints): the torques the external wrenches of `env` alone
/// produce at q (N m, N). Allocation-free.
pub fn wrench_torques_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    q: &[f64],
    tau_e: &mut [f64],
) -> Result<()> {
    let names = ["q", "q", "q"];
    tree_vector_map(
        robot,
        data,
        env,
        names,
        [q, q, q],
        "tau_e",
        tau_e,
        |m, d, q, _, _, t| {
            tree_wrench_torques(m, d, env, q, t);
            Ok(())
        },
    )
}

/// The regressor (N x 13 NL; nv x (13 NL + 10) for a floating robot, see [`regressor_into`]) at
/// one state with the robot's environment; allocates.
///
/// # Example
///
/// Gamma = Phi K + Gamma_e with K the standard parameters (§10.2.4):
///
/// ```
/// use robodyn::{inverse_dynamics, regressor, wrench_torques};
/// # fn main() -> robodyn::Result<()> {
/// let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
/// let robot = robodyn::io::load(urdf)?;
/// let (q, qd, qdd) = ([0.3, -0.2, 0.9, 0.1, 0.4, -0.5], [0.2; 6], [-0.4; 6]);
/// let phi = regressor(&robot, &q, &qd, &qdd)?; // 6 x 78
/// let k = nalgebra::DVector::from_vec(robot.standard_parameters());
/// let tau = phi * k + wrench_torques(&robot, &q)?;
/// let newton_euler = inverse_dynamics(&robot, &q, &qd, &qdd)?;
/// assert!((tau - newton_euler).amax() < 1e-9);
/// # Ok(())
/// # }
/// ```
pub fn regressor(robot: &Robot, q: &[f64], qd: &[f64], qdd: &[f64]) -> Result<DMatrix<f64>> {
    let mut data = Data::new(robot);
    let mut phi = DMatrix::zeros(robot.nv(), parameter_count(robot));
    regressor_into(robot, &mut data, robot.environment(), q, qd, qdd, &mut phi)?;
    Ok(phi)
}

/// Gamma_e (movable joints) at q with the robot's environment; allocates.
pub fn wrench_torques(robot: &Robot, q: &[f64]) -> Result<nalgebra::DVector<f64>> {
    let mut data = Data::new(robot);
    let mut t = nalgebra::DVector::zeros(robot.dof());
    wrench_torques_into(robot, &mut data, robot.environment(), q, t.as_mut_slice())?;
    Ok(t)
}
