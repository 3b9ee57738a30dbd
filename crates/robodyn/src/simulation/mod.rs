//! Simulation: integrate a direct dynamic model from an initial state under a torque input and
//! stream the trajectory (`t, q<j>, qd<j>, qdd<j>, tau<j>`, energy, extra columns).
//!
//! The integrators only see a [`Dynamics`]: [`TreeDynamics`] for tree robots and
//! [`ClosedChainDynamics`] for closed chains (actuated coordinates, passive joints re-solved at
//! every evaluation, extra columns `closure_residual` and the passive `q<j>`).
//!
//! # Example
//!
//! A frictionless double pendulum released from rest: its mechanical energy stays constant.
//!
//! ```
//! use robodyn::simulation::{
//!     simulate, Integrator, Recorder, SimOptions, TorqueInput, TreeDynamics,
//! };
//! use robodyn::Method;
//! # fn main() -> robodyn::Result<()> {
//! let robot = robodyn::io::toml_format::parse_robot(
//!     r#"
//!     gravity = [0, -9.81, 0]
//!     [[frame]]
//!     j = 1
//!     ant = 0
//!     [[frame]]
//!     j = 2
//!     ant = 1
//!     d = 0.5
//!     [[link]]
//!     j = 1
//!     ZZ = 0.1
//!     MX = 0.25
//!     M = 1.0
//!     [[link]]
//!     j = 2
//!     ZZ = 0.05
//!     MX = 0.2
//!     M = 0.8
//!     "#,
//!     None,
//! )?;
//! let mut dynamics = TreeDynamics::new(&robot, Method::ArticulatedBody);
//! let opts = SimOptions {
//!     duration: 2.0,
//!     integrator: Integrator::Dopri5 { rtol: 1e-10, atol: 1e-12, h0: None, h_max: None },
//!     output_dt: 0.01,
//!     max_steps: None,
//! };
//! let mut rec = Recorder::default();
//! let input = TorqueInput::Constant(vec![0.0, 0.0]);
//! simulate(&mut dynamics, &input, &[0.3, 0.5], &[0.0; 2], &opts, &mut rec, &mut |_| {})?;
//! let e = rec.column("energy").expect("an energy column");
//! let (first, last) = (rec.rows[0][e], rec.rows.last().unwrap()[e]);
//! assert_eq!(rec.rows.len(), 201);
//! assert!((last - first).abs() < 1e-6 * first.abs().max(1.0));
//! # Ok(())
//! # }
//! ```

pub mod closed;
pub(crate) mod energy;
pub mod floating;
pub mod input;
pub mod integrators;
pub mod output;
#[cfg(feature = "plot")]
pub mod plot;

pub use closed::ClosedChainDynamics;
pub use input::{TimeSeries, TorqueInput};
pub use integrators::{Integrator, Ode, Stats, Stepper};
pub use output::{format_number, CsvSink, Recorder, Tee, TrajectorySink};
#[cfg(feature = "plot")]
pub use plot::{plot_svg, EnergyBalance, PlotInfo};

use crate::algorithms::direct_dynamics::{direct_dynamics_into, Method};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::{Environment, Robot};
use crate::scalar::DynScalar;
use energy::mechanical_energy;

/// A mechanical system with `dof` velocity coordinates as the simulator sees it.
///
/// The integrators work on y = [x; qd] where x are coordinates of a chart of the configuration
/// space (dof entries): x = q for joints; a floating base's pose is carried in local
/// coordinates ([`floating`]), so that its quaternion is integrated on the group.
pub trait Dynamics {
    /// Number of velocity coordinates (length of qd, qdd, tau; of q too unless the base
    /// floats).
    fn dof(&self) -> usize;
    /// Length of a configuration q (dof, or 7 + joints with a floating base).
    fn nq(&self) -> usize {
        self.dof()
    }
    /// Label of each coordinate in the column names (`q<label>`); joint frame numbers.
    fn labels(&self) -> Vec<String>;
    /// Column names of q, qd, qdd and tau (default: `q<label>`, `qd<label>`, ...).
    fn column_names(&self) -> [Vec<String>; 4] {
        let labels = self.labels();
        ["q", "qd", "qdd", "tau"].map(|p| labels.iter().map(|l| format!("{p}{l}")).collect())
    }
    /// Anchor the chart at the configuration q (nq entries) and write its chart coordinates
    /// into x (dof entries); default x = q.
    fn anchor(&mut self, q: &[f64], x: &mut [f64]) -> Result<()> {
        x.copy_from_slice(q);
        Ok(())
    }
    /// The configuration q (nq) at chart coordinates x (dof); default q = x.
    fn configuration(&self, x: &[f64], q: &mut [f64]) {
        q.copy_from_slice(x);
    }
    /// dx/dt at chart coordinates x for the velocity qd; default qd.
    fn chart_rate(&self, _x: &[f64], qd: &[f64], dx: &mut [f64]) {
        dx.copy_from_slice(qd);
    }
    /// After an accepted step: move the chart if x has gone far from its origin (rewriting x);
    /// true when x changed.
    fn reanchor(&mut self, _x: &mut [f64]) -> bool {
        false
    }
    /// qdd for the state (q, qd) under tau at time t (allocation-free in hot loops).
    fn accel(&mut self, t: f64, q: &[f64], qd: &[f64], tau: &[f64], qdd: &mut [f64]) -> Result<()>;
    /// Total (kinetic + potential) energy.
    fn energy(&mut self, q: &[f64], qd: &[f64]) -> Result<f64>;
    /// Names of extra output columns (e.g. a loop-closure residual).
    fn extra_columns(&self) -> Vec<String> {
        Vec::new()
    }
    /// Values of the extra columns at (q, qd).
    fn extra_values(&mut self, _q: &[f64], _qd: &[f64], _out: &mut [f64]) -> Result<()> {
        Ok(())
    }
}

/// A system built on another ([`Wrapper::inner`]) that changes a few of its calls: a torque
/// source, relabelled columns, a check for interruption. Every wrapper is a [`Dynamics`] whose
/// calls go to the inner system unless the wrapper overrides them here: a call added to
/// [`Dynamics`] reaches the inner system through every wrapper (a wrapper that kept a chart
/// call's default would integrate a floating base's quaternion as a vector).
pub trait Wrapper {
    /// The system wrapped.
    fn inner(&self) -> &dyn Dynamics;
    /// The system wrapped, mutably.
    fn inner_mut(&mut self) -> &mut dyn Dynamics;
    /// [`Dynamics::accel`]; default the inner system's.
    fn accel(&mut self, t: f64, q: &[f64], qd: &[f64], tau: &[f64], qdd: &mut [f64]) -> Result<()> {
        self.inner_mut().accel(t, q, qd, tau, qdd)
    }
    /// [`Dynamics::labels`]; default the inner system's.
    fn labels(&self) -> Vec<String> {
        self.inner().labels()
    }
    /// [`Dynamics::column_names`]; default the inner system's.
    fn column_names(&self) -> [Vec<String>; 4] {
        self.inner().column_names()
    }
    /// [`Dynamics::extra_columns`]; default the inner system's.
    fn extra_columns(&self) -> Vec<String> {
        self.inner().extra_columns()
    }
}

impl<W: Wrapper> Dynamics for W {
    fn dof(&self) -> usize {
        self.inner().dof()
    }
    fn nq(&self) -> usize {
        self.inner().nq()
    }
    fn labels(&self) -> Vec<String> {
        Wrapper::labels(self)
    }
    fn column_names(&self) -> [Vec<String>; 4] {
        Wrapper::column_names(self)
    }
    fn anchor(&mut self, q: &[f64], x: &mut [f64]) -> Result<()> {
        self.inner_mut().anchor(q, x)
    }
    fn configuration(&self, x: &[f64], q: &mut [f64]) {
        self.inner().configuration(x, q)
    }
    fn chart_rate(&self, x: &[f64], qd: &[f64], dx: &mut [f64]) {
        self.inner().chart_rate(x, qd, dx)
    }
    fn reanchor(&mut self, x: &mut [f64]) -> bool {
        self.inner_mut().reanchor(x)
    }
    fn accel(&mut self, t: f64, q: &[f64], qd: &[f64], tau: &[f64], qdd: &mut [f64]) -> Result<()> {
        Wrapper::accel(self, t, q, qd, tau, qdd)
    }
    fn energy(&mut self, q: &[f64], qd: &[f64]) -> Result<f64> {
        self.inner_mut().energy(q, qd)
    }
    fn extra_columns(&self) -> Vec<String> {
        Wrapper::extra_columns(self)
    }
    fn extra_values(&mut self, q: &[f64], qd: &[f64], out: &mut [f64]) -> Result<()> {
        self.inner_mut().extra_values(q, qd, out)
    }
}

/// A tree robot: the coordinates are its movable joints (fixed frames carry no state). The
/// accelerations come from the checked direct model on the movable-joint vectors
/// ([`direct_dynamics_into`]), the path of every other consumer.
pub struct TreeDynamics<'a> {
    robot: &'a Robot,
    method: Method,
    ws: Data,
    env: Environment,
    /// The torque given to the direct model (smoothed Coulomb friction added), movable joints.
    tau: Vec<f64>,
    coulomb_smoothing: Option<f64>,
    /// The chart of a floating base's pose (None for a fixed or mobile base).
    chart: Option<floating::BaseChart>,
    /// Energy and momenta of a floating robot.
    balance: Option<floating::FloatingBalance>,
}

impl<'a> TreeDynamics<'a> {
    /// The simulated system of a tree robot under its own environment (gravity, base motion,
    /// wrenches), with direct model `method`.
    pub fn new(robot: &'a Robot, method: Method) -> Self {
        TreeDynamics {
            robot,
            method,
            ws: Data::new(robot),
            env: robot.environment().clone(),
            tau: vec![0.0; robot.nv()],
            coulomb_smoothing: None,
            chart: None,
            balance: robot
                .is_floating()
                .then(|| floating::FloatingBalance::new(robot)),
        }
    }

    /// Replace the Coulomb friction Fs sign(qd) by Fs tanh(qd / v) in the simulated motion
    /// (v > 0, in rad/s or m/s). The exact sign makes the right-hand side discontinuous: a
    /// sticking joint then chatters and the step size collapses. Done by adding
    /// Fs (sign(qd) - tanh(qd / v)) to the torque given to the direct model.
    pub fn with_coulomb_smoothing(mut self, v: Option<f64>) -> Self {
        self.coulomb_smoothing = v.filter(|v| *v > 0.0);
        self
    }

    /// The movable joints, in frame order: coordinate k is joint `joints()[k]`.
    pub fn joints(&self) -> &[usize] {
        self.robot.coordinates().frames()
    }
}

impl TreeDynamics<'_> {
    /// `tau` with the smoothed Coulomb friction: Fs (sign(qd) - tanh(qd / v)) added on every
    /// movable joint (after the 6 base entries of a floating robot).
    fn smooth_into_tau(&mut self, qd: &[f64], tau: &[f64], v: f64) -> Result<()> {
        let nv = self.robot.nv();
        for (what, x) in [("qd", qd), ("tau", tau)] {
            if x.len() != nv {
                return Err(Error::dimension(
                    what,
                    nv,
                    x.len(),
                    format!("the robot's {nv} velocity coordinates"),
                ));
            }
        }
        let off = nv - self.robot.dof();
        let model = self.robot.numeric();
        self.tau.copy_from_slice(tau);
        for (k, &j) in self.robot.coordinates().frames().iter().enumerate() {
            let (fs, s) = (model.link(j).fs, qd[off + k]);
            self.tau[off + k] += fs * (s.sign() - (s / v).tanh());
        }
        if let Some(drives) = self.robot.motor_drives() {
            // a transmission's motors (their velocities scaled by their gear ratios)
            drives.add_coulomb_smoothing(&qd[off..], v, &mut self.tau[off..]);
        }
        Ok(())
    }
}

impl Dynamics for TreeDynamics<'_> {
    fn dof(&self) -> usize {
        self.robot.nv()
    }
    fn nq(&self) -> usize {
        self.robot.nq()
    }
    fn labels(&self) -> Vec<String> {
        self.joints().iter().map(|j| j.to_string()).collect()
    }
    fn column_names(&self) -> [Vec<String>; 4] {
        let labels = self.labels();
        let base = self.robot.is_floating();
        let mut names = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
        for (k, p) in ["q", "qd", "qdd", "tau"].iter().enumerate() {
            if base {
                let count = if k == 0 { 7 } else { 6 };
                names[k].extend(
                    floating::BASE_COLUMNS[k][..count]
                        .iter()
                        .map(|s| s.to_string()),
                );
            }
            names[k].extend(labels.iter().map(|l| format!("{p}{l}")));
        }
        names
    }
    fn anchor(&mut self, q: &[f64], x: &mut [f64]) -> Result<()> {
        if !self.robot.is_floating() {
            x.copy_from_slice(q);
            return Ok(());
        }
        self.chart = Some(floating::BaseChart::anchored(q, x)?);
        Ok(())
    }
    fn configuration(&self, x: &[f64], q: &mut [f64]) {
        match &self.chart {
            Some(c) => c.configuration(x, q),
            None => q.copy_from_slice(x),
        }
    }
    fn chart_rate(&self, x: &[f64], qd: &[f64], dx: &mut [f64]) {
        match &self.chart {
            Some(c) => c.rate(x, qd, dx),
            None => dx.copy_from_slice(qd),
        }
    }
    fn reanchor(&mut self, x: &mut [f64]) -> bool {
        self.chart.as_mut().is_some_and(|c| c.reanchor(x))
    }
    fn accel(
        &mut self,
        _t: f64,
        q: &[f64],
        qd: &[f64],
        tau: &[f64],
        qdd: &mut [f64],
    ) -> Result<()> {
        let tau = match self.coulomb_smoothing {
            None => tau,
            Some(v) => {
                self.smooth_into_tau(qd, tau, v)?;
                &self.tau
            }
        };
        direct_dynamics_into(
            self.robot,
            &mut self.ws,
            &self.env,
            q,
            qd,
            tau,
            self.method,
            qdd,
        )
    }
    fn energy(&mut self, q: &[f64], qd: &[f64]) -> Result<f64> {
        match &mut self.balance {
            Some(b) => b.evaluate(self.robot, &mut self.ws, q, qd, &mut [0.0; 9]),
            None => mechanical_energy(self.robot, &mut self.ws, q, qd),
        }
    }
    fn extra_columns(&self) -> Vec<String> {
        match self.balance {
            Some(_) => floating::MOMENTUM_COLUMNS.map(String::from).to_vec(),
            None => Vec::new(),
        }
    }
    fn extra_values(&mut self, q: &[f64], qd: &[f64], out: &mut [f64]) -> Result<()> {
        if let Some(b) = &mut self.balance {
            let mut m = [0.0; 9];
            b.evaluate(self.robot, &mut self.ws, q, qd, &mut m)?;
            out.copy_from_slice(&m);
        }
        Ok(())
    }
}

/// The step limit of a simulation unless its caller gives another ([`SimOptions::max_steps`]):
/// a run that needs more steps (a stiff motion, a duration far too long for the step) stops
/// with an error instead of running for hours.
pub const DEFAULT_MAX_STEPS: usize = 5_000_000;

/// How to run a simulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimOptions {
    /// Simulated time span [0, duration].
    pub duration: f64,
    /// The integration scheme.
    pub integrator: Integrator,
    /// Time between output rows (the integrators land exactly on these times).
    pub output_dt: f64,
    /// Stop with [`Error::Numerical`] after this many integration steps (None: no limit).
    pub max_steps: Option<usize>,
}

/// What happened.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SimSummary {
    /// Time reached (s).
    pub t_end: f64,
    /// Rows written.
    pub rows: usize,
    /// Integrator counters.
    pub stats: Stats,
}

/// y = [x; qd] (x the chart coordinates of q), y' = [dx/dt(x, qd); qdd(t, q, qd, tau(t, x,
/// qd))].
struct StateOde<'d, 'i> {
    dynamics: &'d mut dyn Dynamics,
    input: &'i TorqueInput,
    tau: Vec<f64>,
    /// The configuration q (nq) of the current x.
    q: Vec<f64>,
}

impl Ode for StateOde<'_, '_> {
    fn dim(&self) -> usize {
        2 * self.dynamics.dof()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        let n = self.dynamics.dof();
        let (x, qd) = y.split_at(n);
        self.dynamics.configuration(x, &mut self.q);
        self.input.torque(t, x, qd, &mut self.tau);
        let (dx, dqd) = dy.split_at_mut(n);
        self.dynamics.chart_rate(x, qd, dx);
        self.dynamics.accel(t, &self.q, qd, &self.tau, dqd)
    }
    fn accepted(&mut self, y: &mut [f64]) -> bool {
        let n = self.dynamics.dof();
        self.dynamics.reanchor(&mut y[..n])
    }
}

/// Column names of the trajectory: `t, q<l>, qd<l>, qdd<l>, tau<l>` (a floating base's
/// columns first, [`floating::BASE_COLUMNS`]), energy, extras.
pub fn trajectory_headers(dynamics: &dyn Dynamics) -> Vec<String> {
    let mut h = vec!["t".to_string()];
    for names in dynamics.column_names() {
        h.extend(names);
    }
    h.push("energy".into());
    h.extend(dynamics.extra_columns());
    h
}

/// Integrate from (q0, qd0) at t = 0 to `duration`, writing a row at t = 0 and at every
/// multiple of `output_dt` (and at `duration`). `progress(t)` is called after each row.
///
/// A non-finite state, a step-size underflow or a numerical error of the model stops the run
/// with [`Error::Numerical`] saying when; the rows written so far stay in the sink (flushed).
pub fn simulate(
    dynamics: &mut dyn Dynamics,
    input: &TorqueInput,
    q0: &[f64],
    qd0: &[f64],
    opts: &SimOptions,
    sink: &mut dyn TrajectorySink,
    progress: &mut dyn FnMut(f64),
) -> Result<SimSummary> {
    let (n, nq) = (dynamics.dof(), dynamics.nq());
    for (name, v, len) in [("q0", q0, nq), ("qd0", qd0, n)] {
        if v.len() != len {
            return Err(Error::Input(format!(
                "{name} has {} values, the system has {len} {} coordinates",
                v.len(),
                if name == "q0" {
                    "configuration"
                } else {
                    "velocity"
                }
            )));
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Err(Error::Input(format!("{name} has a non-finite value")));
        }
    }
    for (name, v) in [("duration", opts.duration), ("output step", opts.output_dt)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::Input(format!(
                "{name} = {v} must be a positive finite number"
            )));
        }
    }
    opts.integrator.validate()?;
    check_step_budget(opts)?;
    input.validate(n)?;
    if nq != n && matches!(input, TorqueInput::Pd { .. }) {
        return Err(Error::Input(
            "a PD torque input acts on joint positions: with a floating base give torques \
             (constant or a series over the velocity coordinates) instead"
                .into(),
        ));
    }
    sink.begin(&trajectory_headers(dynamics))?;
    let result = run(dynamics, input, q0, qd0, opts, sink, progress);
    let flushed = sink.finish();
    let summary = result?;
    flushed?;
    Ok(summary)
}

/// A run that cannot end within its step limit is refused before it starts: every output
/// interval takes at least one step, and fixed-step RK4 at least duration / dt.
fn check_step_budget(opts: &SimOptions) -> Result<()> {
    let Some(m) = opts.max_steps else {
        return Ok(());
    };
    let steps = |h: f64| (opts.duration / h).ceil();
    let (least, why) = match opts.integrator {
        Integrator::Rk4 { dt } if steps(dt) >= steps(opts.output_dt) => {
            (steps(dt), format!("the step {dt} s"))
        }
        _ => (
            steps(opts.output_dt),
            format!(
                "the output step {} s, one step at least per row",
                opts.output_dt
            ),
        ),
    };
    if least > m as f64 {
        return Err(Error::Numerical(format!(
            "the run needs at least {least:e} integration steps (duration {} s over {why}), more \
             than the step limit (max_steps = {m}): shorten the run, lengthen the step or raise \
             the limit",
            opts.duration
        )));
    }
    Ok(())
}

fn run(
    dynamics: &mut dyn Dynamics,
    input: &TorqueInput,
    q0: &[f64],
    qd0: &[f64],
    opts: &SimOptions,
    sink: &mut dyn TrajectorySink,
    progress: &mut dyn FnMut(f64),
) -> Result<SimSummary> {
    let (n, nq) = (dynamics.dof(), dynamics.nq());
    let n_extra = dynamics.extra_columns().len();
    let mut y = vec![0.0; 2 * n];
    dynamics.anchor(q0, &mut y[..n])?;
    y[n..].copy_from_slice(qd0);
    let mut row = vec![0.0; 1 + nq + 3 * n + 1 + n_extra];
    let mut stepper = Stepper::new(opts.integrator, 2 * n);
    stepper.max_steps = opts.max_steps;
    let mut ode = StateOde {
        dynamics,
        input,
        tau: vec![0.0; n],
        q: vec![0.0; nq],
    };
    let mut t = 0.0;
    let mut k = 0usize;
    let mut summary = SimSummary::default();
    loop {
        write_row(&mut ode, t, &y, &mut row)?;
        sink.row(&row)?;
        summary.rows += 1;
        summary.t_end = t;
        summary.stats = stepper.stats;
        progress(t);
        if t >= opts.duration {
            break;
        }
        k += 1;
        let t_next = (k as f64 * opts.output_dt).min(opts.duration);
        let t_next = if opts.duration - t_next < 1e-9 * opts.output_dt {
            opts.duration
        } else {
            t_next
        };
        stepper
            .advance(&mut ode, &mut t, &mut y, t_next)
            .map_err(|e| stopped(t, e))?;
    }
    Ok(summary)
}

/// A model error during the run, said with the time it happened.
fn stopped(t: f64, e: Error) -> Error {
    match e {
        Error::Io { .. } | Error::Input(_) | Error::Dimension { .. } => e,
        other => Error::Numerical(format!(
            "simulation stopped at t = {}: {other}",
            output::Number(t)
        )),
    }
}

/// The output row at (t, y): t, q (nq), qd, qdd, tau, energy, extras; every value finite.
fn write_row(ode: &mut StateOde, t: f64, y: &[f64], row: &mut [f64]) -> Result<()> {
    let (n, nq) = (ode.dynamics.dof(), ode.q.len());
    let (x, qd) = y.split_at(n);
    ode.dynamics.configuration(x, &mut ode.q);
    row[0] = t;
    row[1..1 + nq].copy_from_slice(&ode.q);
    row[1 + nq..1 + nq + n].copy_from_slice(qd);
    let (head, rest) = row.split_at_mut(1 + nq + 2 * n);
    let tau = &mut rest[..n];
    ode.input.torque(t, x, qd, tau);
    ode.dynamics
        .accel(t, &ode.q, qd, tau, &mut head[1 + nq + n..])
        .map_err(|e| stopped(t, e))?;
    rest[n] = ode.dynamics.energy(&ode.q, qd).map_err(|e| stopped(t, e))?;
    ode.dynamics
        .extra_values(&ode.q, qd, &mut rest[n + 1..])
        .map_err(|e| stopped(t, e))?;
    if row.iter().any(|x| !x.is_finite()) {
        return Err(stopped(
            t,
            Error::Numerical("an output value is not finite".into()),
        ));
    }
    Ok(())
}
