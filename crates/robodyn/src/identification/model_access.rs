//! The one place where identification calls the library's algorithms (the regressor, the
//! closed-chain Jacobian G, the base parameters, the inverse and direct dynamic models, the
//! simulator). The other files of this module see only [`ModelAccess`], [`BaseSet`],
//! [`TrackingModel`] and plain vectors (with the model's parameter indices,
//! [`crate::model::param`], and the library's number formats), so that a change of an
//! algorithm's API changes this file only. Robot files are read by [`crate::io`].

use crate::algorithms::base_parameters::{
    numeric_base_parameters, standard_values, ClosedChainSampler, NumericOptions, ParameterNames,
    Sampler, Summary, TreeSampler,
};
use crate::algorithms::closed_chain::{closed_state, Branch, ClosedChain};
use crate::algorithms::direct_dynamics::{direct_dynamics_into, Method};
use crate::algorithms::inertia_matrix::inertia_matrix;
use crate::algorithms::inverse_dynamics::inverse_dynamics_into;
use crate::algorithms::regressor::{
    regressor_into, wrench_torques_into, Friction, ParameterSelection, PARAMS_PER_LINK,
};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::param::FS;
use crate::model::{JointLimits, JointType, RobotDescription, Transmission};
use crate::simulation::{
    simulate, ClosedChainDynamics, Dynamics, Integrator, Recorder, SimOptions, TimeSeries,
    TorqueInput, TreeDynamics,
};
use crate::Robot;
use nalgebra::{DMatrix, DVector};

/// The sign of a velocity in the Coulomb friction Fs sign(v), with a dead band: 0 where
/// |v| <= `band` (rad/s or m/s), so that rounding noise of an estimated velocity at rest does not
/// flip the friction between -Fs and +Fs. `band` = 0 is the exact sign (0 at v = 0).
pub fn coulomb_sign(v: f64, band: f64) -> f64 {
    if v.abs() <= band {
        0.0
    } else {
        v.signum()
    }
}

/// Which rotor inertias the base set includes: the library's one rotor enum.
pub use crate::model::RotorMode as Rotors;

/// The base parameters of the selected standard parameters (numerical method of
/// `base-params`, the arbiter): K_base = K1 + beta K2.
#[derive(Clone, Debug)]
pub struct BaseSet {
    /// Indices in K of the base parameters (kept columns), in K order.
    pub base: Vec<usize>,
    /// Indices in K of the grouped parameters.
    pub grouped: Vec<usize>,
    /// Selected standard parameters.
    pub columns: Vec<usize>,
    /// beta (base x grouped).
    pub beta: DMatrix<f64>,
    /// Display names (`XXR2` when regrouped) and grouping equations, as `base-params` prints.
    pub names: Vec<String>,
    /// Grouping equation of each base parameter (`XXR2 = XX2 + ...`).
    pub equations: Vec<String>,
}

/// A closed chain's branch tracker carried from one sample of a log to the next (every sample
/// is reached from the previous one on the assembly branch, or the log is refused).
struct Closed {
    chain: ClosedChain,
    branch: Option<Branch>,
}

/// Access to a robot's models for identification.
pub struct ModelAccess {
    robot: Robot,
    /// The description as given (with its transmission).
    desc: RobotDescription,
    transmission: Option<Transmission>,
    actuated: Vec<usize>,
    closed: Option<Closed>,
    ws: Data,
    phi: DMatrix<f64>,
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    tau_e: Vec<f64>,
}

impl ModelAccess {
    /// From a description: validated into the library's robot (the transmission is kept aside).
    pub fn new(desc: RobotDescription) -> Result<ModelAccess> {
        crate::model::require_fixed_base(&desc, "identification")?;
        // the library's robot without the transmission: the identification's parameter model
        // applies it itself (its motor columns), its models read IA, FS, FV per link
        let full = desc.clone();
        let mut desc = desc;
        let transmission = desc.transmission.take();
        let robot = Robot::new(desc)?;
        let (n, nl) = (robot.dof(), robot.nl());
        let (actuated, closed) = if robot.is_tree() {
            let movable = robot.movable_joints();
            if let Some(j) = movable.iter().find(|&&j| !robot.frame(j).actuated) {
                return Err(Error::Input(format!(
                    "{}: tree joint {j} is movable but passive (mu = 0): identification of \
                     under-actuated trees is not supported",
                    robot.name()
                )));
            }
            (movable, None)
        } else {
            let chain = ClosedChain::new(&robot)?;
            (
                chain.coordinates().frames().to_vec(),
                Some(Closed {
                    chain,
                    branch: None,
                }),
            )
        };
        if let Some(t) = &transmission {
            if t.joints != actuated {
                return Err(Error::Input(format!(
                    "{}: the transmission's joints {:?} must be the actuated joints {:?} in order",
                    robot.name(),
                    t.joints,
                    actuated
                )));
            }
        }
        Ok(ModelAccess {
            ws: Data::new(&robot),
            phi: DMatrix::zeros(n, PARAMS_PER_LINK * nl),
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            tau_e: vec![0.0; n],
            robot,
            desc: full,
            transmission,
            actuated,
            closed,
        })
    }

    /// Robot name.
    pub fn name(&self) -> &str {
        self.robot.name()
    }

    /// The robot's description (with its transmission).
    pub fn description(&self) -> &RobotDescription {
        &self.desc
    }

    /// NL.
    pub fn nl(&self) -> usize {
        self.robot.nl()
    }

    /// True for a tree (no closed loop).
    pub fn is_tree(&self) -> bool {
        self.robot.is_tree()
    }

    /// The joints whose positions and torques a log holds: the movable joints of a tree, the
    /// actuated joints of a closed chain.
    pub fn actuated_joints(&self) -> &[usize] {
        &self.actuated
    }

    /// Frame names of the actuated joints.
    pub fn joint_names(&self) -> Vec<String> {
        self.actuated
            .iter()
            .map(|&j| self.robot.frame(j).name.clone())
            .collect()
    }

    /// Whether joint j is prismatic.
    pub fn is_prismatic(&self, j: usize) -> bool {
        self.robot.frame(j).joint == JointType::Prismatic
    }

    /// The robot's transmission (motor side to joint side), if it has one.
    pub fn transmission(&self) -> Option<&Transmission> {
        self.transmission.as_ref()
    }

    /// Limits of joint j from the robot file.
    pub fn limits(&self, j: usize) -> JointLimits {
        self.robot
            .description()
            .limits
            .get(&j)
            .cloned()
            .unwrap_or_default()
    }

    /// Name of standard parameter `index` of K as the base-parameter report names it (the
    /// file's own names when it gives them, else `XX1`, ..., `FV<NL>`).
    pub fn standard_name(&self, index: usize) -> String {
        ParameterNames::of(self.robot.description())
            .name(index)
            .to_string()
    }

    /// The robot's standard parameters K (13 per link).
    pub fn standard_parameters(&self) -> Vec<f64> {
        self.robot.standard_parameters()
    }

    /// The reference configuration of the actuated joints: the start of the assembly branch
    /// for a closed chain (the file's `assembly`), else zeros.
    pub fn reference_actuated(&self) -> Result<Vec<f64>> {
        match &self.closed {
            Some(c) => Ok(c.chain.assembly_branch()?.q_a().to_vec()),
            None => Ok(vec![0.0; self.actuated.len()]),
        }
    }

    /// Base parameters by the numerical method (the set `base-params --method numeric` prints,
    /// with the same names and equations).
    pub fn base_parameters(&self, rotors: Rotors, friction: bool, seed: u64) -> Result<BaseSet> {
        let opt = NumericOptions {
            selection: ParameterSelection::new(
                &self.robot,
                rotors,
                if friction {
                    Friction::Actuated
                } else {
                    Friction::None
                },
            ),
            samples: None,
            seed,
        };
        let nb = if self.robot.is_tree() {
            numeric_base_parameters(&self.robot, &mut TreeSampler, &opt)?
        } else {
            let mut sampler = ClosedChainSampler::new(&self.robot)?;
            numeric_base_parameters(&self.robot, &mut sampler, &opt)?
        };
        let desc = self.robot.description();
        let report =
            Summary::from_numeric(desc, &nb, &ParameterNames::of(desc), &standard_values(desc));
        Ok(BaseSet {
            names: report.base.iter().map(|b| b.name.clone()).collect(),
            equations: report.base.iter().map(|b| b.equation.clone()).collect(),
            base: nb.base,
            grouped: nb.grouped,
            columns: nb.columns,
            beta: nb.beta,
        })
    }

    /// `count` random consistent states in the actuated coordinates (q_a, qd_a, qdd_a) with the
    /// regressor rows of the standard parameters `cols` at each (N x cols, row-major): the states
    /// of the numerical base-parameter method (loop closure for a closed chain).
    #[allow(clippy::type_complexity)]
    pub fn sample_rows(
        &mut self,
        count: usize,
        seed: u64,
        cols: &[usize],
    ) -> Result<Vec<([Vec<f64>; 3], Vec<f64>)>> {
        let mut rng = crate::sampling::rng(seed);
        let mut sampler: Box<dyn Sampler> = if self.robot.is_tree() {
            Box::new(TreeSampler)
        } else {
            Box::new(ClosedChainSampler::new(&self.robot)?)
        };
        let n = self.actuated.len();
        let env = self.robot.environment().clone();
        let mut out = Vec::with_capacity(count);
        for _ in 0..count {
            let s = sampler.sample(&self.robot, &mut rng)?;
            // the sample's tree arrays (NL) on the movable joints, the checked path's vectors
            let movable = self.robot.coordinates().frames();
            let gather = |v: &[f64]| -> Vec<f64> { movable.iter().map(|&j| v[j - 1]).collect() };
            let (q, qd, qdd) = (gather(&s.q), gather(&s.qd), gather(&s.qdd));
            regressor_into(
                &self.robot,
                &mut self.ws,
                &env,
                &q,
                &qd,
                &qdd,
                &mut self.phi,
            )?;
            let pick = |v: &[f64]| self.actuated.iter().map(|&j| v[j - 1]).collect();
            let state = [pick(&s.q), pick(&s.qd), pick(&s.qdd)];
            let mut rows = vec![0.0; n * cols.len()];
            match &s.g {
                Some(g) => {
                    let g =
                        DMatrix::from_fn(movable.len(), g.ncols(), |k, c| g[(movable[k] - 1, c)]);
                    let y = g.transpose() * &self.phi;
                    for r in 0..n {
                        for (c, &k) in cols.iter().enumerate() {
                            rows[r * cols.len() + c] = y[(r, k)];
                        }
                    }
                }
                None => {
                    // a tree: the actuated joints are its movable joints
                    for r in 0..n {
                        for (c, &k) in cols.iter().enumerate() {
                            rows[r * cols.len() + c] = self.phi[(r, k)];
                        }
                    }
                }
            }
            out.push((state, rows));
        }
        Ok(out)
    }

    /// Start a new pass over a log: a closed chain's first sample is solved from the assembly.
    pub fn restart(&mut self) {
        if let Some(c) = &mut self.closed {
            c.branch = None;
        }
    }

    /// The equivalent tree's state for (q_a, qd_a, qdd_a) into `self.q`, `self.qd`, `self.qdd`
    /// (the movable joints, the checked path's vectors); for a closed chain q_p by the branch
    /// tracker (continuation from the previous sample, the first from the assembly) and G
    /// (movable joints x N) returned.
    fn tree_state(
        &mut self,
        qa: &[f64],
        qda: &[f64],
        qdda: &[f64],
    ) -> Result<Option<DMatrix<f64>>> {
        match &mut self.closed {
            None => {
                // a tree: the actuated joints are its movable joints, in the same order
                self.q.copy_from_slice(qa);
                self.qd.copy_from_slice(qda);
                self.qdd.copy_from_slice(qdda);
                Ok(None)
            }
            Some(c) => {
                if c.branch.is_none() {
                    c.branch = Some(c.chain.assembly_branch()?);
                }
                let branch = c.branch.as_mut().expect("set above");
                let st = closed_state(&c.chain, branch, qa, qda, qdda)?;
                self.q.copy_from_slice(st.q.as_slice());
                self.qd.copy_from_slice(st.qd.as_slice());
                self.qdd.copy_from_slice(st.qdd.as_slice());
                Ok(Some(st.g))
            }
        }
    }

    /// Regressor rows of the standard parameters `cols` in the actuated coordinates at one
    /// sample (N x cols, row-major into `rows`), and the torques of the external wrenches
    /// `tau_e` (N): Gamma_a = rows K + tau_e (G^T Phi and G^T Gamma_e for a closed chain,
    /// eq 10.40). The Coulomb columns are [`coulomb_sign`] of the joint velocities with the dead
    /// band `coulomb_band` (0: the exact sign).
    #[allow(clippy::too_many_arguments)]
    pub fn rows(
        &mut self,
        qa: &[f64],
        qda: &[f64],
        qdda: &[f64],
        cols: &[usize],
        coulomb_band: f64,
        rows: &mut [f64],
        tau_e: &mut [f64],
    ) -> Result<()> {
        let g = self.tree_state(qa, qda, qdda)?;
        let (robot, env) = (&self.robot, self.robot.environment());
        let (q, qd, qdd) = (&self.q, &self.qd, &self.qdd);
        regressor_into(robot, &mut self.ws, env, q, qd, qdd, &mut self.phi)?;
        if coulomb_band > 0.0 {
            // the FS_j column is sign(qd_j) in joint j's row alone (10.12)
            for (k, &j) in robot.coordinates().frames().iter().enumerate() {
                let col = PARAMS_PER_LINK * (j - 1) + FS;
                self.phi[(k, col)] = coulomb_sign(qd[k], coulomb_band);
            }
        }
        wrench_torques_into(robot, &mut self.ws, env, q, &mut self.tau_e)?;
        let m = cols.len();
        match g {
            None => {
                for r in 0..self.actuated.len() {
                    for (c, &k) in cols.iter().enumerate() {
                        rows[r * m + c] = self.phi[(r, k)];
                    }
                    tau_e[r] = self.tau_e[r];
                }
            }
            Some(g) => {
                for r in 0..g.ncols() {
                    for (c, &k) in cols.iter().enumerate() {
                        let mut s = 0.0;
                        for i in 0..g.nrows() {
                            s += g[(i, r)] * self.phi[(i, k)];
                        }
                        rows[r * m + c] = s;
                    }
                    tau_e[r] = (0..g.nrows()).map(|i| g[(i, r)] * self.tau_e[i]).sum();
                }
            }
        }
        Ok(())
    }

    /// Inverse dynamic model in the actuated coordinates with the robot file's parameters (the
    /// transmission not applied): Newton–Euler, G^T Gamma_tr for a closed chain.
    pub fn inverse_dynamics(&mut self, qa: &[f64], qda: &[f64], qdda: &[f64]) -> Result<Vec<f64>> {
        let g = self.tree_state(qa, qda, qdda)?;
        let mut tau = vec![0.0; self.robot.dof()];
        let (robot, env) = (&self.robot, self.robot.environment());
        inverse_dynamics_into(
            robot,
            &mut self.ws,
            env,
            &self.q,
            &self.qd,
            &self.qdd,
            &mut tau,
        )?;
        Ok(match g {
            None => tau,
            Some(g) => (g.transpose() * DVector::from_column_slice(&tau))
                .iter()
                .copied()
                .collect(),
        })
    }

    /// The description with standard parameters `k` (13 per link), checked by the library's
    /// loader (non-negative masses, rotor inertias and friction).
    pub fn description_with(&self, k: &[f64]) -> Result<RobotDescription> {
        let mut desc = self.robot.with_standard_parameters(k)?.into_description();
        desc.transmission = self.transmission.clone();
        Ok(desc)
    }

    /// Smallest eigenvalue of the inertia matrix A(q) (over the movable tree joints) of the
    /// robot with standard parameters `k` at `count` random configurations, and the
    /// configuration where it is smallest.
    pub fn min_inertia_eigenvalue(&self, k: &[f64], count: usize, seed: u64) -> Result<f64> {
        let robot = self.robot.with_standard_parameters(k)?;
        let mut rng = crate::sampling::rng(seed);
        let mut sampler: Box<dyn Sampler> = if robot.is_tree() {
            Box::new(TreeSampler)
        } else {
            Box::new(ClosedChainSampler::new(&robot)?)
        };
        let movable = robot.movable_joints();
        let mut lo = f64::INFINITY;
        for _ in 0..count {
            let s = sampler.sample(&robot, &mut rng)?;
            let a = match &s.g {
                Some(g) => g.transpose() * inertia_matrix(&robot, &s.q)? * g,
                // a tree's sample has a value per frame: A(q) takes the movable joints'
                None => {
                    let q: Vec<f64> = movable.iter().map(|j| s.q[j - 1]).collect();
                    inertia_matrix(&robot, &q)?
                }
            };
            lo = lo.min(a.symmetric_eigenvalues().min());
        }
        Ok(lo)
    }

    /// A model of the robot with standard parameters `k` for simulation in the actuated
    /// coordinates. Used by the instrumental variables, whose model is an estimate: masses,
    /// rotor inertias and friction coefficients below zero are taken as zero. The Coulomb
    /// friction is smoothed as Fs tanh(qd / smoothing).
    pub fn tracking_model(&self, k: &[f64], smoothing: f64) -> Result<TrackingModel> {
        let mut k = k.to_vec();
        for (i, v) in k.iter_mut().enumerate() {
            if matches!(i % PARAMS_PER_LINK, 9..=12) && *v < 0.0 {
                *v = 0.0;
            }
        }
        if self.robot.is_tree() {
            let robot = self.robot.with_standard_parameters(&k)?;
            let n = robot.dof();
            Ok(TrackingModel::Tree {
                smoothing,
                ws: Box::new(Data::new(&robot)),
                robot: Box::new(robot),
                tau: vec![0.0; n],
            })
        } else {
            let robot = self.robot.with_standard_parameters(&k)?;
            let chain = ClosedChain::new(&robot)?;
            let branch = chain.assembly_branch()?;
            let dynamics =
                ClosedChainDynamics::new(chain, branch).with_coulomb_smoothing(Some(smoothing));
            Ok(TrackingModel::Closed(Box::new(dynamics)))
        }
    }

    /// Simulate the robot (its file's parameters) under a PD controller tracking the reference
    /// positions `reference(t)` (N values) from rest at `reference(0)`, recording t, q, qd, qdd
    /// and the joint torques every `dt` over `duration`. Each recorded row satisfies the direct
    /// (hence the inverse) dynamic model exactly: qdd is the model's response to the recorded
    /// torque. Coulomb friction is exact (sign), as in the model identified.
    #[allow(clippy::type_complexity)]
    pub fn simulate_tracking(
        &self,
        reference: &dyn Fn(f64) -> Vec<f64>,
        duration: f64,
        dt: f64,
        kp: &[f64],
        kd: &[f64],
    ) -> Result<Vec<(f64, [Vec<f64>; 4])>> {
        let n = self.actuated.len();
        let fine = (duration / dt).ceil() as usize * 4;
        let times: Vec<f64> = (0..=fine)
            .map(|k| duration * k as f64 / fine as f64)
            .collect();
        let values: Vec<Vec<f64>> = times.iter().map(|&t| reference(t)).collect();
        let input = TorqueInput::Pd {
            reference: TimeSeries::new(times, values)?,
            with_velocity: false,
            kp: kp.to_vec(),
            kd: kd.to_vec(),
        };
        let q0 = reference(0.0);
        let opts = SimOptions {
            duration,
            integrator: Integrator::Rk4 { dt: dt / 4.0 },
            output_dt: dt,
            max_steps: None,
        };
        let mut rec = Recorder::default();
        let mut dynamics: Box<dyn Dynamics + '_> = if self.robot.is_tree() {
            Box::new(TreeDynamics::new(&self.robot, Method::ArticulatedBody))
        } else {
            let chain = ClosedChain::new(&self.robot)?;
            let branch = chain.assembly_branch()?;
            Box::new(ClosedChainDynamics::new(chain, branch))
        };
        simulate(
            dynamics.as_mut(),
            &input,
            &q0,
            &vec![0.0; n],
            &opts,
            &mut rec,
            &mut |_| {},
        )?;
        Ok(rec
            .rows
            .iter()
            .map(|r| {
                let part = |k: usize| r[1 + k * n..1 + (k + 1) * n].to_vec();
                (r[0], [part(0), part(1), part(2), part(3)])
            })
            .collect())
    }
}

/// A model simulated in the actuated coordinates: qdd_a = f(q_a, qd_a, tau_a).
pub enum TrackingModel {
    /// A tree: its direct dynamics by composite links.
    Tree {
        /// Coulomb friction sign(qd) replaced by tanh(qd / smoothing) (rad/s or m/s).
        smoothing: f64,
        /// The robot with the current parameters.
        robot: Box<Robot>,
        /// Its buffers.
        ws: Box<Data>,
        /// Scratch: the torques with the smoothed Coulomb friction (movable joints).
        tau: Vec<f64>,
    },
    /// A closed chain: qdd_a = A_cl^-1 (Gamma_cl - H_cl) on its assembly branch (10.46–10.48).
    Closed(Box<ClosedChainDynamics>),
}

impl TrackingModel {
    /// Diagonal of the inertia matrix A(q_a) (actuated coordinates) from the accelerations of
    /// unit torques at rest: qdd(e_k) - qdd(0) = A^-1 e_k.
    pub fn inertia_diagonal(&mut self, qa: &[f64]) -> Result<Vec<f64>> {
        let n = qa.len();
        let zero = vec![0.0; n];
        let mut a0 = vec![0.0; n];
        self.accel(qa, &zero, &zero, &mut a0)?;
        let mut inv = DMatrix::zeros(n, n);
        let mut e = vec![0.0; n];
        let mut a = vec![0.0; n];
        for k in 0..n {
            e.iter_mut().for_each(|v| *v = 0.0);
            e[k] = 1.0;
            self.accel(qa, &zero, &e, &mut a)?;
            for i in 0..n {
                inv[(i, k)] = a[i] - a0[i];
            }
        }
        let m = inv.try_inverse().ok_or_else(|| {
            Error::Numerical("the current model's inertia matrix is singular".into())
        })?;
        Ok((0..n).map(|k| m[(k, k)]).collect())
    }

    /// qdd_a for the state (q_a, qd_a) under the actuated torques tau_a (Coulomb friction
    /// smoothed: the exact sign makes the motion chatter).
    pub fn accel(&mut self, qa: &[f64], qda: &[f64], taua: &[f64], qdda: &mut [f64]) -> Result<()> {
        match self {
            TrackingModel::Tree {
                smoothing,
                robot,
                ws,
                tau,
            } => {
                // a tree's actuated joints are its movable joints: the vectors pass through
                let frames = robot.coordinates().frames();
                for (k, &j) in frames.iter().enumerate() {
                    let (fs, s) = (robot.numeric().link(j).fs, qda[k]);
                    tau[k] =
                        taua[k] + fs * (s.signum() * f64::from(s != 0.0) - (s / *smoothing).tanh());
                }
                let env = robot.environment();
                let method = Method::Composite;
                direct_dynamics_into(robot, ws, env, qa, qda, tau, method, qdda)
            }
            TrackingModel::Closed(d) => d.accel(0.0, qa, qda, taua, qdda),
        }
    }
}
