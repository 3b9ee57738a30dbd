//! Loop closure of closed kinematic chains (§10.3.1, eqs 10.25–10.30).
//!
//! Loop l is cut at joint k (NL < k <= NJ): frame R_k sits on link i = a(k) and carries the cut
//! joint's variable q_k; frame R_{k+B} is fixed on link j = a(k+B). The loop is closed when
//! 0T_i iT_k(q_k) = 0T_j jT_{k+B} (§7.3).
//!
//! **Elimination of the cut-joint variable.** q_k only turns R_k about z_k (revolute) or slides it
//! along z_k (prismatic), so with ρ = R_k^T (P_{k+B} - P_k), u = R_k^T z_{k+B} and
//! R_rel = R_k^T R_{k+B} (R_k taken at q_k = 0) the closure conditions free of q_k are
//! - revolute cut: ρ = 0 and u = e_z, written as the 5 functions [ρ; (e_z × u)_x; (e_z × u)_y];
//! - prismatic cut: R_rel = I and ρ_x = ρ_y = 0, written as [vee(R_rel - R_rel^T)/2; ρ_x; ρ_y].
//!
//! Of these 5 candidate equations per loop only the independent ones are kept, chosen BY RANK (a
//! planar loop keeps 2: with the cut variable included it has the 3 equations of a plane motion,
//! one of which gives q_k). The choice is made once per robot at a random configuration (the
//! generic rank) and checked at a second one; over-constrained loops whose rank drops only on the
//! closure manifold (Bennett linkages) are not supported.
//!
//! **Derivatives (analytic, eqs 10.27–10.28).** The derivative of the candidates with respect to a
//! tree joint m of the branch to j (s = +1) or to i (s = -1) is, with a = s R_k^T σ̄_m z_m,
//! dρ/dq_m = s R_k^T (σ̄_m z_m × (P_{k+B} - O_m) + σ_m z_m) and du/dq_m = a × u; at closure this is
//! the difference of the twists of R_{k+B} and R_k projected on the directions the cut joint does
//! not free, so [Wa Wp] of (10.27) are these columns at the solution. Ψ of (10.28) is the second
//! time derivative of the candidates at qdd = 0, from the velocity-product accelerations of both
//! branches (forward kinematic recursion with qdd = 0).

//!
//! This module holds the loop-closure model (`LoopClosure`, internal to the closed-chain
//! model [`crate::ClosedChain`]) and its equations; the public way to solve the loops is the
//! branch tracker ([`crate::Branch`], [`crate::algorithms::closed_chain::loop_closure`]).

use crate::error::{check_vector, Error, Result};
use crate::model::{ClosedLoop, DynModel, JointType, Robot};
use crate::scalar::DynScalar;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use rand::Rng;

/// Candidate equations per loop after eliminating the cut-joint variable.
pub const CANDIDATES: usize = 5;

/// One loop and the candidate equations kept for it.
#[derive(Clone, Debug)]
pub struct LoopConstraint {
    /// Loop number l (1-based, in cut-joint order).
    pub number: usize,
    /// Cut joint, twin frame, branches and root of the loop.
    pub topology: ClosedLoop,
    /// Type of the cut joint.
    pub cut_joint: JointType,
    /// Indices (0..5) of the kept candidate equations.
    pub rows: Vec<usize>,
}

impl LoopConstraint {
    /// "loop 1 (cut joint 9 between links 8 and 3)".
    pub fn label(&self) -> String {
        format!(
            "loop {} (cut joint {} between links {} and {})",
            self.number, self.topology.cut, self.topology.link_i, self.topology.link_j
        )
    }
}

/// Loop-closure model of a closed-chain robot: built once from a [`Robot`], immutable.
#[derive(Clone, Debug)]
pub(crate) struct LoopClosure {
    robot: Robot,
    actuated: Vec<usize>,
    passive: Vec<usize>,
    loops: Vec<LoopConstraint>,
    /// Number of kept equations: p.
    p: usize,
    /// Offset of each loop's kept rows in the stacked equations.
    offsets: Vec<usize>,
    /// Newton settings.
    pub max_iterations: usize,
    /// Convergence threshold on the largest kept equation (m or rad).
    pub tolerance: f64,
}

/// Buffers of the loop-closure computations (absolute kinematics in R_0, frames 0..NF), in
/// numbers (`f64`) or in another scalar (the dual numbers of the closed-chain derivatives).
#[derive(Clone, Debug)]
pub(crate) struct LoopWorkspace<T: DynScalar = f64> {
    pub rot: Vec<Matrix3<T>>,
    pub pos: Vec<Vector3<T>>,
    /// Angular velocity, velocity of the origin, angular and linear acceleration of links 0..NL.
    pub w: Vec<Vector3<T>>,
    pub v: Vec<Vector3<T>>,
    pub wd: Vec<Vector3<T>>,
    pub vd: Vec<Vector3<T>>,
    q: Vec<f64>,
    /// Candidate-equation columns of the Jacobian (one per tree joint).
    cols: Vec<[T; CANDIDATES]>,
}

/// A solution of the closure equations from a guess (damped Newton; internal: the start of a
/// branch).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct GuessSolution {
    /// q_tr: joints 1..NL at index j-1 (fixed frames 0).
    pub q_tr: Vec<f64>,
    /// q_p in [`LoopClosure::passive_joints`] order.
    pub q_p: Vec<f64>,
    /// Cut-joint variables q_c (NL+1..NJ).
    pub q_c: Vec<f64>,
    pub iterations: usize,
    /// Largest residual of all candidate equations at the solution.
    pub residual: f64,
}

fn skew<T: DynScalar + Copy>(a: &Vector3<T>) -> Matrix3<T> {
    let z = T::zero();
    Matrix3::new(z, -a.z, a.y, a.z, z, -a.x, -a.y, a.x, z)
}

fn vee_antisym<T: DynScalar + Copy>(m: &Matrix3<T>) -> Vector3<T> {
    // vee((M - M^T) / 2)
    let h = T::from_f64(0.5);
    Vector3::new(
        h * (m[(2, 1)] - m[(1, 2)]),
        h * (m[(0, 2)] - m[(2, 0)]),
        h * (m[(1, 0)] - m[(0, 1)]),
    )
}

/// Joint values in messages: six significant digits, the shortest form (`1e300`, not 300
/// digits).
pub(crate) fn fmt_vec(v: &[f64]) -> String {
    crate::report::number::vector(v, 6)
}

/// What [`LoopClosure::solve_from_guess`]'s damped Newton reached.
struct NewtonResult {
    q_p: Vec<f64>,
    /// Largest kept closure equation at `q_p`.
    residual: f64,
    iterations: usize,
    converged: bool,
}

/// Rank of a matrix by SVD (singular values above `tol` times the largest, or above `tol`).
fn rank(m: &DMatrix<f64>, tol: f64) -> usize {
    if m.nrows() == 0 || m.ncols() == 0 {
        return 0;
    }
    let sv = m.clone().svd(false, false).singular_values;
    let smax = sv.max();
    sv.iter().filter(|&&s| s > tol * smax.max(1.0)).count()
}

impl LoopClosure {
    /// Build the loop-closure model: choose the independent equations by rank and check that
    /// their number equals the number of passive tree joints.
    pub fn new(robot: &Robot) -> Result<LoopClosure> {
        let actuated = robot.actuated_joints();
        let passive = robot.passive_joints();
        let nl = robot.nl();
        let loops: Vec<LoopConstraint> = robot
            .structure()
            .loops
            .iter()
            .enumerate()
            .map(|(l, lp)| LoopConstraint {
                number: l + 1,
                topology: lp.clone(),
                cut_joint: robot.frame(lp.cut).joint,
                rows: (0..CANDIDATES).collect(),
            })
            .collect();
        let mut lc = LoopClosure {
            robot: robot.clone(),
            actuated,
            passive,
            p: 0,
            offsets: vec![0; loops.len()],
            loops,
            max_iterations: 100,
            tolerance: 1e-12,
        };
        if lc.loops.is_empty() {
            return Err(Error::Input(format!(
                "robot `{}` has no closed loop (NJ = NL): use the tree models",
                robot.name()
            )));
        }
        // Generic rank at random configurations (fixed seed: the choice is reproducible).
        let mut rng = crate::sampling::rng(0x100b_c105);
        let mut ws = lc.workspace();
        let mut random_jacobian = |lc: &LoopClosure, ws: &mut LoopWorkspace| {
            let q: Vec<f64> = (0..nl).map(|_| rng.random_range(-3.0..3.0)).collect();
            lc.kinematics(ws, &q, None, None);
            lc.all_candidates_jacobian(ws)
        };
        let j1 = random_jacobian(&lc, &mut ws);
        let tol = 1e-8;
        let mut kept: Vec<usize> = Vec::new();
        let mut current = 0;
        for r in 0..j1.nrows() {
            let mut trial = kept.clone();
            trial.push(r);
            let rk = rank(&j1.select_rows(trial.iter()), tol);
            if rk > current {
                kept = trial;
                current = rk;
            }
        }
        let j2 = random_jacobian(&lc, &mut ws);
        let full = rank(&j2, tol);
        let sel = rank(&j2.select_rows(kept.iter()), tol);
        if full != kept.len() || sel != kept.len() {
            return Err(Error::Numerical(format!(
                "robot `{}`: the rank of the loop-closure equations changes between random \
                 configurations ({} then {full}): the loops are over-constrained or degenerate",
                robot.name(),
                kept.len()
            )));
        }
        let mut off = 0;
        for (l, lp) in lc.loops.iter_mut().enumerate() {
            lp.rows = kept
                .iter()
                .filter(|&&r| r / CANDIDATES == l)
                .map(|&r| r % CANDIDATES)
                .collect();
            lc.offsets[l] = off;
            off += lp.rows.len();
        }
        lc.p = off;
        if lc.p != lc.passive.len() {
            let per_loop: Vec<String> = lc
                .loops
                .iter()
                .map(|l| format!("{}: {}", l.label(), l.rows.len()))
                .collect();
            return Err(Error::Input(format!(
                "robot `{}`: the loops give {} independent closure equations ({}) but the tree \
                 has {} passive joints {:?}: the actuated joints (mu = 1) must be as many as \
                 the mechanism's degrees of freedom ({} here)",
                robot.name(),
                lc.p,
                per_loop.join(", "),
                lc.passive.len(),
                lc.passive,
                robot.movable_joints().len() as i64 - lc.p as i64
            )));
        }
        Ok(lc)
    }

    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// The loops with their kept equations.
    pub fn loops(&self) -> &[LoopConstraint] {
        &self.loops
    }

    /// q_a: actuated tree joints in increasing order.
    pub fn actuated_joints(&self) -> &[usize] {
        &self.actuated
    }

    /// q_p: passive tree joints in increasing order.
    pub fn passive_joints(&self) -> &[usize] {
        &self.passive
    }

    /// Columns of the passive joints in vectors by joint number (j - 1).
    pub fn passive_columns(&self) -> Vec<usize> {
        self.passive.iter().map(|j| j - 1).collect()
    }

    /// p, the number of independent closure equations (= passive joints).
    pub fn n_equations(&self) -> usize {
        self.p
    }

    pub fn workspace(&self) -> LoopWorkspace {
        self.workspace_in()
    }

    /// [`Self::workspace`] in scalar `T`.
    pub fn workspace_in<T: DynScalar + Copy>(&self) -> LoopWorkspace<T> {
        let nf = self.robot.nf();
        let nl = self.robot.nl();
        let z = || vec![Vector3::zeros(); nl + 1];
        LoopWorkspace {
            rot: vec![Matrix3::identity(); nf + 1],
            pos: vec![Vector3::zeros(); nf + 1],
            w: z(),
            v: z(),
            wd: z(),
            vd: z(),
            q: vec![0.0; nl],
            cols: vec![[T::zero(); CANDIDATES]; nl],
        }
    }

    /// Absolute placements of frames 1..NF (cut frames at q_k = 0) and, if given, the velocities
    /// and accelerations of links 1..NL in R_0 (base fixed: relative motion is all that counts).
    pub fn kinematics(
        &self,
        ws: &mut LoopWorkspace,
        q: &[f64],
        qd: Option<&[f64]>,
        qdd: Option<&[f64]>,
    ) {
        self.kinematics_in(self.robot.numeric(), ws, q, qd, qdd);
    }

    /// [`Self::kinematics`] in scalar `T`, with `model` the robot's numeric model in `T`
    /// ([`crate::algorithms::energy::convert_model`]).
    pub fn kinematics_in<T: DynScalar + Copy>(
        &self,
        model: &DynModel<T>,
        ws: &mut LoopWorkspace<T>,
        q: &[T],
        qd: Option<&[T]>,
        qdd: Option<&[T]>,
    ) {
        let nl = self.robot.nl();
        for j in 1..=self.robot.nf() {
            let fr = model.frame(j);
            let i = fr.ant;
            let qj = if j <= nl { q[j - 1] } else { T::zero() };
            let (a, p) = fr.transform(&qj);
            ws.pos[j] = ws.pos[i] + ws.rot[i] * p;
            ws.rot[j] = ws.rot[i] * a;
            if j > nl {
                continue;
            }
            let Some(qd) = qd else { continue };
            let z = ws.rot[j].column(2).into_owned();
            let r = ws.pos[j] - ws.pos[i];
            let (wi, vi, wdi, vdi) = (ws.w[i], ws.v[i], ws.wd[i], ws.vd[i]);
            let a = qdd.map_or(T::zero(), |x| x[j - 1]);
            let mut w = wi;
            let mut v = vi + wi.cross(&r);
            let mut wd = wdi;
            let mut vd = vdi + wdi.cross(&r) + wi.cross(&wi.cross(&r));
            match fr.joint {
                JointType::Revolute => {
                    w += z * qd[j - 1];
                    wd += z * a + wi.cross(&z) * qd[j - 1];
                }
                JointType::Prismatic => {
                    v += z * qd[j - 1];
                    vd += z * a + wi.cross(&z) * (qd[j - 1] + qd[j - 1]);
                }
                JointType::Fixed => {}
            }
            ws.w[j] = w;
            ws.v[j] = v;
            ws.wd[j] = wd;
            ws.vd[j] = vd;
        }
    }

    /// All 5 candidate equations of loop `l` at the placements in `ws`.
    fn candidates(&self, ws: &LoopWorkspace, l: usize) -> [f64; CANDIDATES] {
        let lp = &self.loops[l];
        let (k, t) = (lp.topology.cut, lp.topology.twin);
        let rk = &ws.rot[k];
        let rho = rk.transpose() * (ws.pos[t] - ws.pos[k]);
        match lp.cut_joint {
            JointType::Prismatic => {
                let e = vee_antisym(&(rk.transpose() * ws.rot[t]));
                [e.x, e.y, e.z, rho.x, rho.y]
            }
            _ => {
                let u = rk.transpose() * ws.rot[t].column(2);
                [rho.x, rho.y, rho.z, -u.y, u.x]
            }
        }
    }

    /// Derivative of the candidates of loop `l` with respect to the tree joints (5 x NL): exact
    /// at every configuration, closed or not (the derivative of R_k^T in rho combines with
    /// that of P_k into the lever arm P_{k+B} - O_m).
    fn candidates_jacobian<T: DynScalar + Copy>(
        &self,
        ws: &LoopWorkspace<T>,
        l: usize,
        out: &mut [[T; CANDIDATES]],
    ) {
        let lp = &self.loops[l];
        let (k, t) = (lp.topology.cut, lp.topology.twin);
        let rkt = ws.rot[k].transpose();
        let rrel = rkt * ws.rot[t];
        let u = rrel.column(2).into_owned();
        for o in out.iter_mut() {
            *o = [T::zero(); CANDIDATES];
        }
        let branches = [
            (&lp.topology.branch_j, T::one()),
            (&lp.topology.branch_i, -T::one()),
        ];
        for (branch, s) in branches {
            for &m in branch.iter() {
                let fr = self.robot.numeric().frame(m);
                let zm = ws.rot[m].column(2).into_owned();
                let (lin, a) = match fr.joint {
                    JointType::Revolute => {
                        (rkt * zm.cross(&(ws.pos[t] - ws.pos[m])) * s, rkt * zm * s)
                    }
                    JointType::Prismatic => (rkt * zm * s, Vector3::zeros()),
                    JointType::Fixed => continue,
                };
                out[m - 1] = match lp.cut_joint {
                    JointType::Prismatic => {
                        // d/dq vee((R - R^T)/2) = vee of the antisymmetric part of dR = [a]x R
                        let de = vee_antisym(&(skew(&a) * rrel));
                        [de.x, de.y, de.z, lin.x, lin.y]
                    }
                    _ => {
                        let du = a.cross(&u);
                        [lin.x, lin.y, lin.z, -du.y, du.x]
                    }
                };
            }
        }
    }

    /// Jacobian of all 5B candidate equations (5B x NL) at the placements in `ws`.
    fn all_candidates_jacobian(&self, ws: &LoopWorkspace) -> DMatrix<f64> {
        let nl = self.robot.nl();
        let mut m = DMatrix::zeros(CANDIDATES * self.loops.len(), nl);
        let mut cols = vec![[0.0; CANDIDATES]; nl];
        for l in 0..self.loops.len() {
            self.candidates_jacobian(ws, l, &mut cols);
            for (c, col) in cols.iter().enumerate() {
                for r in 0..CANDIDATES {
                    m[(CANDIDATES * l + r, c)] = col[r];
                }
            }
        }
        m
    }

    /// The kept equations phi(q_tr) (p entries) at the placements in `ws`.
    pub fn residual(&self, ws: &LoopWorkspace, out: &mut DVector<f64>) {
        for (l, lp) in self.loops.iter().enumerate() {
            let c = self.candidates(ws, l);
            for (r, &row) in lp.rows.iter().enumerate() {
                out[self.offsets[l] + r] = c[row];
            }
        }
    }

    /// d phi / d q_tr (p x NL, columns by joint number) at the placements in `ws`: at a closed
    /// configuration this is [Wa Wp] of (10.27) with the columns in joint order.
    pub fn constraint_jacobian<T: DynScalar + Copy>(
        &self,
        ws: &mut LoopWorkspace<T>,
        out: &mut DMatrix<T>,
    ) {
        let mut cols = std::mem::take(&mut ws.cols);
        for (l, lp) in self.loops.iter().enumerate() {
            self.candidates_jacobian(ws, l, &mut cols);
            for (r, &row) in lp.rows.iter().enumerate() {
                for (c, col) in cols.iter().enumerate() {
                    out[(self.offsets[l] + r, c)] = col[row];
                }
            }
        }
        ws.cols = cols;
    }

    /// Ψ of (10.28) (p entries): d²phi/dt² at qdd = 0, after [`Self::kinematics`] with the state's
    /// velocities and qdd = 0 (at any configuration, closed or not).
    pub fn psi<T: DynScalar + Copy>(&self, ws: &LoopWorkspace<T>, out: &mut DVector<T>) {
        for (l, lp) in self.loops.iter().enumerate() {
            let (k, t) = (lp.topology.cut, lp.topology.twin);
            let (i, j) = (lp.topology.link_i, lp.topology.link_j);
            let rkt = ws.rot[k].transpose();
            // point velocities/accelerations of O_k (on link i) and O_{k+B} (on link j)
            let pv = |link: usize, x: &Vector3<T>| {
                let r = x - ws.pos[link];
                let w = ws.w[link];
                (
                    ws.v[link] + w.cross(&r),
                    ws.vd[link] + ws.wd[link].cross(&r) + w.cross(&w.cross(&r)),
                )
            };
            let (vk, ak) = pv(i, &ws.pos[k]);
            let (vt, at) = pv(j, &ws.pos[t]);
            let rho = rkt * (ws.pos[t] - ws.pos[k]);
            let wb = rkt * ws.w[i];
            let ab = rkt * ws.wd[i];
            let dv = rkt * (vt - vk);
            let rho_d = dv - wb.cross(&rho);
            // rho'' = R^T D'' - w_b x R^T D' - wd_b x rho - w_b x rho'
            let rho_dd = rkt * (at - ak) - wb.cross(&dv) - ab.cross(&rho) - wb.cross(&rho_d);
            let wrel = rkt * (ws.w[j] - ws.w[i]);
            let wrel_d = rkt * (ws.wd[j] - ws.wd[i]) - wb.cross(&wrel);
            let rrel = rkt * ws.rot[t];
            let c: [T; CANDIDATES] = match lp.cut_joint {
                JointType::Prismatic => {
                    // R_rel'' = [wrel']x R_rel + [wrel]x [wrel]x R_rel
                    let s = skew(&wrel);
                    let rdd = (skew(&wrel_d) + s * s) * rrel;
                    let e = vee_antisym(&rdd);
                    [e.x, e.y, e.z, rho_dd.x, rho_dd.y]
                }
                _ => {
                    let u = rrel.column(2).into_owned();
                    let ud = wrel.cross(&u);
                    let udd = wrel_d.cross(&u) + wrel.cross(&ud);
                    [rho_dd.x, rho_dd.y, rho_dd.z, -udd.y, udd.x]
                }
            };
            for (r, &row) in lp.rows.iter().enumerate() {
                out[self.offsets[l] + r] = c[row];
            }
        }
    }

    /// Build q_tr from q_a and q_p.
    pub fn assemble(&self, q_a: &[f64], q_p: &[f64], q_tr: &mut [f64]) {
        q_tr.iter_mut().for_each(|x| *x = 0.0);
        for (&j, &x) in self.actuated.iter().zip(q_a) {
            q_tr[j - 1] = x;
        }
        for (&j, &x) in self.passive.iter().zip(q_p) {
            q_tr[j - 1] = x;
        }
    }

    /// Solve the closure equations for q_p given q_a by damped Newton (Levenberg–Marquardt),
    /// starting from `guess` (q_p): the start of a branch (allocates).
    pub fn solve_from_guess(
        &self,
        ws: &mut LoopWorkspace,
        q_a: &[f64],
        guess: &[f64],
    ) -> Result<GuessSolution> {
        let (n, p) = (self.actuated.len(), self.p);
        check_vector("q_a", q_a, n, || {
            format!("actuated joints {:?}", self.actuated)
        })?;
        check_vector("guess", guess, p, || {
            format!("passive joints {:?}", self.passive)
        })?;
        let mut q = std::mem::take(&mut ws.q);
        let newton = self.damped_newton(ws, &mut q, q_a, guess);
        // restore placements of the current qp
        self.assemble(q_a, &newton.q_p, &mut q);
        self.kinematics(ws, &q, None, None);
        let (worst, worst_loop) = self.worst_candidate(ws);
        ws.q = q;
        if !newton.converged || worst > 1e3 * self.tolerance.max(1e-12) {
            return Err(Error::LoopNotClosed {
                loop_label: self.loops[worst_loop].label(),
                residual: worst.max(newton.residual),
                tolerance: self.tolerance,
                at: q_a.to_vec(),
                guess: guess.to_vec(),
                iterations: newton.iterations,
            });
        }
        // A revolute cut also vanishes with z_{k+B} = -z_k: reject that flipped assembly.
        for lp in &self.loops {
            if lp.cut_joint == JointType::Revolute {
                let (k, t) = (lp.topology.cut, lp.topology.twin);
                if ws.rot[k].column(2).dot(&ws.rot[t].column(2)) < 0.0 {
                    return Err(Error::Numerical(format!(
                        "{} converged to a flipped assembly (z_{k} = -z_{t}) at q_a = {}: give a \
                         better guess",
                        lp.label(),
                        fmt_vec(q_a)
                    )));
                }
            }
        }
        Ok(GuessSolution {
            q_c: self.cut_variables(ws),
            q_tr: ws.q.clone(),
            q_p: newton.q_p,
            iterations: newton.iterations,
            residual: worst,
        })
    }

    /// Damped Newton (Levenberg–Marquardt) on the kept closure equations from `guess`, at most
    /// `max_iterations` steps; `q` is the tree configuration buffer.
    fn damped_newton(
        &self,
        ws: &mut LoopWorkspace,
        q: &mut [f64],
        q_a: &[f64],
        guess: &[f64],
    ) -> NewtonResult {
        let p = self.p;
        let mut qp: Vec<f64> = guess.to_vec();
        let mut r = DVector::zeros(p);
        let mut jac = DMatrix::zeros(p, self.robot.nl());
        let mut lambda = 1e-6;
        self.assemble(q_a, &qp, q);
        self.kinematics(ws, q, None, None);
        self.residual(ws, &mut r);
        let mut norm = r.norm();
        let mut it = 0;
        let mut converged = r.amax() <= self.tolerance;
        while !converged && it < self.max_iterations {
            it += 1;
            self.constraint_jacobian(ws, &mut jac);
            let jp = jac.select_columns(self.passive_columns().iter());
            let jtj = jp.transpose() * &jp;
            let g = jp.transpose() * &r;
            let mut accepted = false;
            while lambda < 1e12 {
                let mut m = jtj.clone();
                let scale = jtj.diagonal().max().max(1e-12);
                for d in 0..p {
                    m[(d, d)] += lambda * scale;
                }
                let Some(step) = m.lu().solve(&(-&g)) else {
                    lambda *= 10.0;
                    continue;
                };
                let trial: Vec<f64> = qp.iter().zip(step.iter()).map(|(a, b)| a + b).collect();
                self.assemble(q_a, &trial, q);
                self.kinematics(ws, q, None, None);
                let mut rt = DVector::zeros(p);
                self.residual(ws, &mut rt);
                let nt = rt.norm();
                if nt < norm || (nt <= norm && step.amax() < 1e-15) {
                    qp = trial;
                    r = rt;
                    norm = nt;
                    lambda = (lambda * 0.1).max(1e-15);
                    accepted = true;
                    break;
                }
                lambda *= 10.0;
            }
            converged = r.amax() <= self.tolerance;
            if !accepted {
                break;
            }
        }
        NewtonResult {
            q_p: qp,
            residual: r.amax(),
            iterations: it,
            converged,
        }
    }

    /// The largest candidate closure equation over all loops at the placements in `ws`, and its
    /// loop.
    fn worst_candidate(&self, ws: &LoopWorkspace) -> (f64, usize) {
        let mut worst = (0.0_f64, 0usize);
        for l in 0..self.loops.len() {
            let c = self.candidates(ws, l);
            let m = c.iter().fold(0.0_f64, |a, &b| a.max(b.abs()));
            if m > worst.0 {
                worst = (m, l);
            }
        }
        worst
    }

    /// A revolute cut's equations also vanish with z_{k+B} = -z_k: the loop label of a loop
    /// closed that way at the placements in `ws`, if any.
    pub fn flipped_loop(&self, ws: &LoopWorkspace) -> Option<String> {
        self.loops.iter().find_map(|lp| {
            let (k, t) = (lp.topology.cut, lp.topology.twin);
            (lp.cut_joint == JointType::Revolute
                && ws.rot[k].column(2).dot(&ws.rot[t].column(2)) < 0.0)
                .then(|| lp.label())
        })
    }

    /// Largest absolute value of all candidate equations of every loop (the closure residual, m
    /// or rad) at the placements in `ws`.
    pub fn max_residual(&self, ws: &LoopWorkspace) -> f64 {
        (0..self.loops.len())
            .flat_map(|l| self.candidates(ws, l))
            .fold(0.0_f64, |a, b| a.max(b.abs()))
    }

    /// Cut-joint variables at the (closed) placements in `ws`: the angle about z_k from x_k(0) to
    /// x_{k+B}, or the slide along z_k.
    pub fn cut_variables(&self, ws: &LoopWorkspace) -> Vec<f64> {
        self.loops
            .iter()
            .map(|lp| {
                let (k, t) = (lp.topology.cut, lp.topology.twin);
                let rkt = ws.rot[k].transpose();
                match lp.cut_joint {
                    JointType::Prismatic => (rkt * (ws.pos[t] - ws.pos[k])).z,
                    _ => {
                        let x = rkt * ws.rot[t].column(0);
                        x.y.atan2(x.x)
                    }
                }
            })
            .collect()
    }
}
