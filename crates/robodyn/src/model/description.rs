//! The robot description as written in a file: every entry an expression over named symbols.

use crate::error::{Error, Item, Result};
use robodyn_symbolic::Expr;
use serde::Serialize;
use std::collections::BTreeMap;

/// Joint type sigma_j (0 revolute, 1 prismatic, 2 fixed).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum JointType {
    /// sigma = 0: a rotation about z_j by the variable q_j = theta_j (rad).
    Revolute,
    /// sigma = 1: a translation along z_j by q_j = r_j (m).
    Prismatic,
    /// sigma = 2: no joint variable.
    Fixed,
}

impl JointType {
    /// sigma_j as in the notation (0, 1, 2).
    pub fn sigma(self) -> u8 {
        match self {
            JointType::Revolute => 0,
            JointType::Prismatic => 1,
            JointType::Fixed => 2,
        }
    }

    /// From sigma_j (0, 1, 2); None otherwise.
    pub fn from_sigma(s: i64) -> Option<JointType> {
        match s {
            0 => Some(JointType::Revolute),
            1 => Some(JointType::Prismatic),
            2 => Some(JointType::Fixed),
            _ => None,
        }
    }

    /// sigma_bar_j = 1 - sigma_j for movable joints, 0 for fixed ones.
    pub fn is_revolute(self) -> bool {
        self == JointType::Revolute
    }

    /// sigma_j = 1.
    pub fn is_prismatic(self) -> bool {
        self == JointType::Prismatic
    }

    /// sigma_j != 2: the frame carries a joint variable.
    pub fn is_movable(self) -> bool {
        self != JointType::Fixed
    }
}

/// The six geometric parameters of a frame, in the order of the transformation
/// iT_j = Rot(z,gamma) Trans(z,b) Rot(x,alpha) Trans(x,d) Rot(z,theta) Trans(z,r).
pub const GEOMETRIC_PARAMETERS: [&str; 6] = ["gamma", "b", "alpha", "d", "theta", "r"];

/// Frame j of the Khalil–Kleinfinger description.
///
/// `theta` and `r` hold the *constant* part only: for a revolute joint the joint variable q_j is
/// added to `theta`, for a prismatic joint to `r` (q_j = sigma_bar theta_j + sigma r_j).
#[derive(Clone, Debug, PartialEq)]
pub struct FrameDesc {
    /// Name (URDF joint name, or `j<j>` when the file gives none).
    pub name: String,
    /// Antecedent a(j): 0 for the base.
    pub ant: usize,
    /// sigma_j.
    pub joint: JointType,
    /// mu_j: true when the joint is actuated.
    pub actuated: bool,
    /// gamma_j (rad).
    pub gamma: Expr,
    /// b_j (m).
    pub b: Expr,
    /// alpha_j (rad).
    pub alpha: Expr,
    /// d_j (m).
    pub d: Expr,
    /// Constant part of theta_j (rad).
    pub theta: Expr,
    /// Constant part of r_j (m).
    pub r: Expr,
}

impl FrameDesc {
    /// A frame with all six parameters zero.
    pub fn new(name: impl Into<String>, ant: usize, joint: JointType, actuated: bool) -> Self {
        FrameDesc {
            name: name.into(),
            ant,
            joint,
            actuated,
            gamma: Expr::zero(),
            b: Expr::zero(),
            alpha: Expr::zero(),
            d: Expr::zero(),
            theta: Expr::zero(),
            r: Expr::zero(),
        }
    }

    /// The six parameters in [`GEOMETRIC_PARAMETERS`] order.
    pub fn geometric(&self) -> [&Expr; 6] {
        [
            &self.gamma,
            &self.b,
            &self.alpha,
            &self.d,
            &self.theta,
            &self.r,
        ]
    }

    /// The six parameters, mutable, in [`GEOMETRIC_PARAMETERS`] order.
    pub fn geometric_mut(&mut self) -> [&mut Expr; 6] {
        [
            &mut self.gamma,
            &mut self.b,
            &mut self.alpha,
            &mut self.d,
            &mut self.theta,
            &mut self.r,
        ]
    }
}

/// The ten inertial standard parameters (XX XY XZ YY YZ ZZ MX MY MZ M) of a body of mass `m`
/// whose centre of mass is at `c` and whose inertia about the centre of mass is `j_com`, both in
/// the link frame: the inertia about the frame origin by Huygens-Steiner, and MS = m c.
pub fn inertial_parameters(
    m: f64,
    c: &nalgebra::Vector3<f64>,
    j_com: &nalgebra::Matrix3<f64>,
) -> [f64; 10] {
    let jo = j_com + m * (c.dot(c) * nalgebra::Matrix3::identity() - c * c.transpose());
    [
        jo[(0, 0)],
        jo[(0, 1)],
        jo[(0, 2)],
        jo[(1, 1)],
        jo[(1, 2)],
        jo[(2, 2)],
        m * c.x,
        m * c.y,
        m * c.z,
        m,
    ]
}

/// Number of standard parameters per link (XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV): the vector K
/// of the regressor has `PARAMS_PER_LINK * NL` entries, link 1 first.
pub const PARAMS_PER_LINK: usize = 13;

/// Which rotor inertias IA_j are parameters of a model (the regressor's columns, the base
/// parameters, identification).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RotorMode {
    /// IA_j for the actuated joints (mu_j = 1).
    Actuated,
    /// IA_j for every movable joint.
    All,
    /// No rotor inertia.
    None,
}

impl RotorMode {
    /// Every mode (what a command line or a binding offers; [`RotorMode::name`] names each).
    pub const ALL: [RotorMode; 3] = [RotorMode::Actuated, RotorMode::All, RotorMode::None];

    /// The mode's name: `actuated`, `all`, `none` ([`RotorMode::from_name`] reads it back).
    pub fn name(self) -> &'static str {
        match self {
            RotorMode::Actuated => "actuated",
            RotorMode::All => "all",
            RotorMode::None => "none",
        }
    }

    /// The mode of a name of [`RotorMode::name`].
    pub fn from_name(name: &str) -> Option<RotorMode> {
        RotorMode::ALL.into_iter().find(|m| m.name() == name)
    }

    /// What the mode makes parameters, in a few words.
    pub fn describe(self) -> &'static str {
        match self {
            RotorMode::Actuated => "rotor inertia IA_j of the actuated joints",
            RotorMode::All => "rotor inertia IA_j of every movable joint",
            RotorMode::None => "no rotor inertia",
        }
    }
}

/// Names of the 13 standard parameters of a link, in SYMORO's order.
pub const STANDARD_PARAMETERS: [&str; PARAMS_PER_LINK] = [
    "XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA", "FS", "FV",
];

/// Index of each standard parameter in [`STANDARD_PARAMETERS`].
pub mod param {
    /// XX: inertia about x_j (kg m²).
    pub const XX: usize = 0;
    /// XY: product of inertia (kg m²).
    pub const XY: usize = 1;
    /// XZ: product of inertia (kg m²).
    pub const XZ: usize = 2;
    /// YY: inertia about y_j (kg m²).
    pub const YY: usize = 3;
    /// YZ: product of inertia (kg m²).
    pub const YZ: usize = 4;
    /// ZZ: inertia about z_j (kg m²).
    pub const ZZ: usize = 5;
    /// MX: first moment along x_j (kg m).
    pub const MX: usize = 6;
    /// MY: first moment along y_j (kg m).
    pub const MY: usize = 7;
    /// MZ: first moment along z_j (kg m).
    pub const MZ: usize = 8;
    /// M: mass (kg).
    pub const M: usize = 9;
    /// IA: rotor inertia (kg m² or kg).
    pub const IA: usize = 10;
    /// FS: Coulomb friction (N m or N).
    pub const FS: usize = 11;
    /// FV: viscous friction (N m s/rad or N s/m).
    pub const FV: usize = 12;

    /// The SI unit of standard parameter `k` (an index above) of a link whose joint is
    /// prismatic or not: `kg m^2`, `kg m`, `kg`; IA `kg m^2` or `kg`, FS `N m` or `N`, FV
    /// `N m s/rad` or `N s/m`.
    pub fn unit(k: usize, prismatic: bool) -> &'static str {
        match (k, prismatic) {
            (XX..=ZZ, _) | (IA, false) => "kg m^2",
            (MX..=MZ, _) => "kg m",
            (M, _) | (IA, true) => "kg",
            (FS, false) => "N m",
            (FS, true) => "N",
            (FV, false) => "N m s/rad",
            (FV, true) => "N s/m",
            _ => "",
        }
    }
}

/// Names of the external wrench components (exerted by the link on the environment, in R_j).
pub const WRENCH_COMPONENTS: [&str; 6] = ["FX", "FY", "FZ", "CX", "CY", "CZ"];

/// Link j: 13 standard inertial/drive parameters and the external wrench.
#[derive(Clone, Debug, PartialEq)]
pub struct LinkDesc {
    /// Link name.
    pub name: String,
    /// XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV, about O_j in R_j.
    pub params: [Expr; PARAMS_PER_LINK],
    /// FX FY FZ CX CY CZ: force and moment the link exerts on the environment, in R_j.
    pub wrench: [Expr; 6],
}

impl LinkDesc {
    /// A link whose parameters are the symbols `XX<j>`, ..., `FV<j>` (SYMORO's default).
    pub fn symbolic(j: usize) -> Self {
        LinkDesc {
            name: format!("link{j}"),
            params: std::array::from_fn(|k| Expr::symbol(format!("{}{j}", STANDARD_PARAMETERS[k]))),
            wrench: std::array::from_fn(|_| Expr::zero()),
        }
    }

    /// A link with all parameters zero.
    pub fn zero(name: impl Into<String>) -> Self {
        LinkDesc {
            name: name.into(),
            params: std::array::from_fn(|_| Expr::zero()),
            wrench: std::array::from_fn(|_| Expr::zero()),
        }
    }
}

/// A complete robot description: what a file says. Validate it with [`crate::Robot::new`].
#[derive(Clone, Debug, PartialEq)]
pub struct RobotDescription {
    /// Robot name.
    pub name: String,
    /// NL: number of links (the equivalent tree has joints 1..NL).
    pub nl: usize,
    /// NJ: number of joints, NJ - NL = B cut joints.
    pub nj: usize,
    /// Frames 1..NF (index j-1), NF = 2 NJ - NL.
    pub frames: Vec<FrameDesc>,
    /// Links 1..NL (index j-1).
    pub links: Vec<LinkDesc>,
    /// Gravity acceleration g in frame 0 (e.g. [0, 0, -9.81]).
    pub gravity: [Expr; 3],
    /// Base angular velocity, angular acceleration, linear velocity and acceleration, in R_0.
    pub w0: [Expr; 3],
    /// Base angular acceleration (rad/s²).
    pub wp0: [Expr; 3],
    /// Base linear velocity (m/s).
    pub v0: [Expr; 3],
    /// Base linear acceleration (m/s²).
    pub vp0: [Expr; 3],
    /// Whether the base is mobile (SYMORO's `is_mobile`).
    pub mobile_base: bool,
    /// `Some(link 0)` when the base floats (SYMORO's `is_floating`): link 0's standard
    /// inertial parameters (XX..M about O_0 in R_0; its IA, FS, FV are not used) and its
    /// external wrench. Its motion then results from the dynamics: the state holds the base
    /// pose and twist (docs/models/floating_base.md), and W0 WP0 V0 VP0 are not used.
    pub floating_base: Option<LinkDesc>,
    /// Numeric values of the symbols used in the expressions.
    pub symbols: BTreeMap<String, f64>,
    /// Joint values of the tree joints 1..NL at an assembled configuration (closed loops
    /// closed): the default starting point of loop closure, which picks the assembly branch.
    pub assembly: Option<Vec<f64>>,
    /// Notes carried with the description (source of numbers, comments).
    pub notes: Vec<String>,
    /// Linear transmission between motors and actuated joints (coupled wrists); `None`: each
    /// actuated joint has its own motor and IA, FS, FV are joint-side values.
    pub transmission: Option<Transmission>,
    /// Joint limits by frame number (used by excitation design); absent: no limit known.
    pub limits: BTreeMap<usize, JointLimits>,
    /// Named frames fixed on frames of the description (tool centre points, sensor frames, the
    /// body frames of URDF links whose axes differ from R_j): TOML's `[[tool]]` tables.
    pub tools: Vec<Tool>,
}

/// A named frame fixed on frame `frame` (0 the base, 1..NF): its placement in that frame is
/// the translation `xyz` (m) then the rotation `rpy` (rad) in URDF's convention,
/// Rot = Rz(yaw) Ry(pitch) Rx(roll).
#[derive(Clone, Debug, PartialEq)]
pub struct Tool {
    /// The frame's name (unique among the robot's frame, link and tool names it may shadow).
    pub name: String,
    /// The frame it is fixed on: 0 (base) .. NF.
    pub frame: usize,
    /// Origin of the tool frame in R_frame (m).
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw of the tool frame in R_frame (rad), URDF's `rpy`.
    pub rpy: [f64; 3],
}

/// Motor positions m = R q over the actuated joints `joints` (R square, motors x joints). With a
/// transmission, IA, FS, FV of link `joints[k]` are the parameters of motor k (row k of R), in
/// motor units, and the joint torques they produce are
/// tau = R^T (IA m_dd + FV m_d + FS sign(m_d)), m = R q.
#[derive(Clone, Debug, PartialEq)]
pub struct Transmission {
    /// Actuated joints (frame numbers), the columns of R, in order.
    pub joints: Vec<usize>,
    /// R, one row per motor.
    pub matrix: Vec<Vec<f64>>,
}

/// Limits of one joint (rad or m, per second, per second squared; N m or N).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointLimits {
    /// Lower position limit.
    pub q_min: Option<f64>,
    /// Upper position limit.
    pub q_max: Option<f64>,
    /// Largest speed |qd|.
    pub qd: Option<f64>,
    /// Largest acceleration |qdd|.
    pub qdd: Option<f64>,
    /// Largest torque or force |tau|.
    pub tau: Option<f64>,
}

impl RobotDescription {
    /// An empty description with NL links and NJ joints: frames default to revolute, actuated
    /// (cut-joint frames passive, their twins fixed), all geometric parameters zero, symbolic
    /// inertial parameters, gravity `[0, 0, -G3]` with G3 = 9.81.
    pub fn new(name: impl Into<String>, nl: usize, nj: usize) -> Self {
        let nf = 2 * nj - nl;
        let frames = (1..=nf)
            .map(|j| {
                let (joint, actuated) = if j <= nl {
                    (JointType::Revolute, true)
                } else if j <= nj {
                    (JointType::Revolute, false)
                } else {
                    (JointType::Fixed, false)
                };
                FrameDesc::new(format!("j{j}"), j.saturating_sub(1), joint, actuated)
            })
            .collect();
        let zero3 = || std::array::from_fn(|_| Expr::zero());
        RobotDescription {
            name: name.into(),
            nl,
            nj,
            frames,
            links: (1..=nl).map(LinkDesc::symbolic).collect(),
            gravity: [Expr::zero(), Expr::zero(), Expr::num(-9.81)],
            w0: zero3(),
            wp0: zero3(),
            v0: zero3(),
            vp0: zero3(),
            mobile_base: false,
            floating_base: None,
            symbols: BTreeMap::new(),
            assembly: None,
            notes: Vec::new(),
            transmission: None,
            limits: BTreeMap::new(),
            tools: Vec::new(),
        }
    }

    /// NF = 2 NJ - NL.
    pub fn nf(&self) -> usize {
        2 * self.nj - self.nl
    }

    /// Frame j (1-based).
    pub fn frame(&self, j: usize) -> &FrameDesc {
        &self.frames[j - 1]
    }

    /// Frame j (1-based), mutable.
    pub fn frame_mut(&mut self, j: usize) -> &mut FrameDesc {
        &mut self.frames[j - 1]
    }

    /// Error when a `[transmission]` lists a joint whose IA, FS or FV is not the literal 0: the
    /// motors' drive parameters, in motor units. Models built from the description that read
    /// these per joint (generated code, base parameters; `what` names it) refuse such a robot
    /// rather than take them for joint-side values ([`crate::Robot`]'s models apply them).
    pub fn require_no_motor_drive_parameters(&self, what: &str) -> Result<()> {
        let Some(t) = &self.transmission else {
            return Ok(());
        };
        let drives = |&j: &usize| {
            (1..=self.nl).contains(&j)
                && [param::IA, param::FS, param::FV]
                    .iter()
                    .any(|&k| !self.link(j).params[k].is_zero())
        };
        match t.joints.iter().find(|j| drives(j)) {
            Some(j) => Err(Error::invalid(
                Item::Base("transmission".into()),
                format!(
                    "{what} does not apply motor-joint transmissions yet: joint {j}'s motor has \
                     IA, FS or FV (motor units), which it would read as joint-side values"
                ),
            )),
            None => Ok(()),
        }
    }

    /// Link j (1-based).
    pub fn link(&self, j: usize) -> &LinkDesc {
        &self.links[j - 1]
    }

    /// Link j (1-based), mutable.
    pub fn link_mut(&mut self, j: usize) -> &mut LinkDesc {
        &mut self.links[j - 1]
    }

    /// Tree joints 1..NL that are movable (not fixed).
    pub fn movable_joints(&self) -> Vec<usize> {
        (1..=self.nl)
            .filter(|&j| self.frame(j).joint.is_movable())
            .collect()
    }

    /// Actuated tree joints (mu = 1), in increasing order: q_a.
    pub fn actuated_joints(&self) -> Vec<usize> {
        (1..=self.nl).filter(|&j| self.frame(j).actuated).collect()
    }

    /// Passive movable tree joints (mu = 0): q_p.
    pub fn passive_joints(&self) -> Vec<usize> {
        (1..=self.nl)
            .filter(|&j| !self.frame(j).actuated && self.frame(j).joint.is_movable())
            .collect()
    }

    /// Every symbol the expressions use (geometry, inertial and drive parameters, wrenches,
    /// gravity and base motion), each once, in order of first use; `symbols` may give values
    /// of others too.
    pub fn used_symbols(&self) -> Vec<String> {
        let mut seen = std::collections::BTreeSet::new();
        let mut out = Vec::new();
        let mut add = |e: &Expr| {
            e.for_each_symbol(&mut |s| {
                if seen.insert(s.to_string()) {
                    out.push(s.to_string());
                }
            })
        };
        for f in &self.frames {
            f.geometric().into_iter().for_each(&mut add);
        }
        for l in self.floating_base.iter().chain(&self.links) {
            l.params.iter().chain(&l.wrench).for_each(&mut add);
        }
        for v in [&self.gravity, &self.w0, &self.wp0, &self.v0, &self.vp0] {
            v.iter().for_each(&mut add);
        }
        out
    }
}
