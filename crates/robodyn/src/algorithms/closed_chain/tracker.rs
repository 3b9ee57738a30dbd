//! The branch tracker and the kinematic constraints (§10.3.1): [`Branch`] (the assembly branch
//! and the last closed point reached on it), starting a branch, W = -Wp^-1 Wa (10.30),
//! G = d q_tr / d q_a (10.40), the consistent tree state (10.29, 10.42) and the loop-closure
//! functions. Moving the tracker is [`super::continuation`].

use super::{ClosedChain, ClosedData, Conditioning};
use crate::error::{Configuration, Error, Result};
use nalgebra::{DMatrix, DVector};

/// The branch tracker of a closed chain: the assembly branch (sign of det Wp) and the last
/// closed configuration reached on it, owned by the caller. Made by
/// [`ClosedChain::assembly_branch`] or [`ClosedChain::branch_from`]; every closed-chain
/// evaluation moves it to its q_a (on error it stays where it was).
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    pub(super) q_a: Vec<f64>,
    pub(super) q_p: Vec<f64>,
    /// W at (q_a, q_p): the predictor of the next step.
    pub(super) w: DMatrix<f64>,
    pub(super) sign: f64,
    pub(super) rcond: f64,
}

impl Branch {
    pub(super) fn zeros(n: usize, p: usize) -> Branch {
        Branch {
            q_a: vec![0.0; n],
            q_p: vec![0.0; p],
            w: DMatrix::zeros(p, n),
            sign: 1.0,
            rcond: 0.0,
        }
    }

    /// The actuated values of the tracker's point (after a long move, revolute loop joints hold
    /// the equivalent angle in (-pi, pi]: see [`ClosedChain::step_budget`]).
    pub fn q_a(&self) -> &[f64] {
        &self.q_a
    }

    /// The passive values of the tracker's point.
    pub fn q_p(&self) -> &[f64] {
        &self.q_p
    }

    /// Sign of det Wp on the branch (+1 or -1): the branch invariant.
    pub fn det_sign(&self) -> f64 {
        self.sign
    }

    /// Reciprocal condition number of Wp at the tracker's point.
    pub fn rcond(&self) -> f64 {
        self.rcond
    }
}

impl ClosedChain {
    /// A tracker on the branch of the robot's assembly configuration (its `assembly`, else
    /// q = 0). Errors: [`Error::LoopNotClosed`] when the loops do not close near it,
    /// [`Error::SingularStart`] when the robot has no assembly and Wp is singular at q = 0
    /// (the start does not define a branch), [`Error::Singular`] for a singular assembly.
    pub fn assembly_branch(&self) -> Result<Branch> {
        let robot = self.robot();
        let reference = robot
            .description()
            .assembly
            .clone()
            .unwrap_or_else(|| vec![0.0; robot.nl()]);
        let qa: Vec<f64> = self
            .coords
            .frames()
            .iter()
            .map(|&j| reference[j - 1])
            .collect();
        let qp: Vec<f64> = self
            .passive
            .frames()
            .iter()
            .map(|&j| reference[j - 1])
            .collect();
        match self.branch_from(&qa, &qp) {
            Err(Error::Singular { rcond, .. }) if robot.description().assembly.is_none() => {
                Err(Error::SingularStart {
                    robot: robot.name().to_string(),
                    rcond,
                })
            }
            r => r,
        }
    }

    /// A tracker on the branch through (q_a, q_p ≈ `q_p_guess`): the loops are closed at q_a
    /// from the guess (damped Newton) and Wp must be regular there. Allocates.
    pub fn branch_from(&self, q_a: &[f64], q_p_guess: &[f64]) -> Result<Branch> {
        self.coords.check("q_a", q_a, "actuated joints")?;
        self.passive
            .check("q_p guess", q_p_guess, "passive joints")?;
        let mut d = ClosedData::new(self);
        let sol = self.closure.solve_from_guess(&mut d.lw, q_a, q_p_guess)?;
        d.qa.copy_from_slice(q_a);
        d.qp.copy_from_slice(&sol.q_p);
        self.closure.assemble(&d.qa, &d.qp, &mut d.q_tr);
        self.factor_wp(&mut d);
        let rcond = d.lu.rcond();
        if rcond < self.limits.wp_hard {
            return Err(self.singular_wp(rcond, &d.q_tr));
        }
        let mut b = Branch {
            q_a: q_a.to_vec(),
            q_p: sol.q_p,
            w: DMatrix::zeros(self.n_equations(), self.dof()),
            sign: d.lu.det_sign(),
            rcond,
        };
        self.compute_w(&mut d);
        b.w.copy_from(&d.w);
        Ok(b)
    }

    pub(super) fn singular_wp(&self, rcond: f64, q_tr: &[f64]) -> Error {
        let labels: Vec<String> = self.loops().iter().map(|l| l.label()).collect();
        Error::Singular {
            what: format!(
                "Wp (derivative of the closure equations of {} with respect to the passive \
                 joints {:?})",
                labels.join(", "),
                self.passive.frames()
            ),
            rcond,
            limit: self.limits.wp_hard,
            at: Configuration::Joints {
                name: "q_tr",
                values: q_tr.to_vec(),
            },
            hint: "the mechanism is at a singular configuration: q_p is not determined by q_a"
                .into(),
        }
    }

    /// Kinematics at d.q_tr, the constraint Jacobian and the LU of Wp (in d.lu).
    pub(super) fn factor_wp(&self, d: &mut ClosedData) {
        let lc = &self.closure;
        lc.kinematics(&mut d.lw, &d.q_tr, None, None);
        lc.constraint_jacobian(&mut d.lw, &mut d.jac);
        for (c, &j) in lc.passive_joints().iter().enumerate() {
            for r in 0..d.p {
                d.lu.lu[(r, c)] = d.jac[(r, j - 1)];
            }
        }
        d.lu.factor();
    }

    /// W = -Wp^-1 Wa into d.w (after [`Self::factor_wp`]) and G = [I; W] into d.g (tree rows).
    pub(super) fn compute_w(&self, d: &mut ClosedData) {
        let lc = &self.closure;
        for (c, &j) in lc.actuated_joints().iter().enumerate() {
            for r in 0..d.p {
                d.w[(r, c)] = -d.jac[(r, j - 1)];
            }
        }
        let mut w = std::mem::replace(&mut d.w, DMatrix::zeros(0, 0));
        d.lu.solve_matrix(&mut w);
        d.w = w;
        d.g.as_mut_slice().fill(0.0);
        for (c, &j) in lc.actuated_joints().iter().enumerate() {
            d.g[(j - 1, c)] = 1.0;
        }
        for (r, &j) in lc.passive_joints().iter().enumerate() {
            for c in 0..d.n {
                d.g[(j - 1, c)] = d.w[(r, c)];
            }
        }
    }

    /// Check the inputs, move the tracker to q_a and fill the consistent tree state for
    /// (qd_a, qdd_a) into d.q_tr, d.qd_tr, d.qdd_tr (10.29, 10.42).
    pub(super) fn state_into(
        &self,
        d: &mut ClosedData,
        b: &mut Branch,
        x: [(&str, &[f64]); 3],
    ) -> Result<()> {
        self.check_data(d, b)?;
        for (name, v) in x {
            self.coords.check(name, v, "actuated joints")?;
        }
        let (q_a, qd_a, qdd_a) = (x[0].1, x[1].1, x[2].1);
        self.track(d, b, q_a)?;
        let lc = &self.closure;
        lc.assemble(&b.q_a, &b.q_p, &mut d.q_tr);
        for r in 0..d.nl {
            let (mut v, mut a) = (0.0, 0.0);
            for c in 0..d.n {
                v += d.g[(r, c)] * qd_a[c];
                a += d.g[(r, c)] * qdd_a[c];
            }
            d.qd_tr[r] = v;
            d.qdd_tr[r] = a;
        }
        lc.kinematics(&mut d.lw, &d.q_tr, Some(&d.qd_tr), None);
        lc.psi(&d.lw, &mut d.psi);
        // qdd_p += -Wp^-1 Ψ (10.42)
        for (x, p) in d.dx.iter_mut().zip(d.psi.iter()) {
            *x = -p;
        }
        d.lu.solve(&mut d.dx);
        for (r, &j) in lc.passive_joints().iter().enumerate() {
            d.qdd_tr[j - 1] += d.dx[r];
        }
        Ok(())
    }

    /// Γ_cl = G^T Γ_tr into `out` after [`Self::state_into`] and the tree torques in d.tau_tr.
    pub(super) fn project(d: &ClosedData, tree: &[f64], out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate() {
            *o = (0..d.nl).map(|r| d.g[(r, c)] * tree[r]).sum();
        }
    }

    pub(super) fn state_result(
        &self,
        d: &ClosedData,
        b: &Branch,
        cond: Conditioning,
    ) -> ClosedState {
        let c = self.robot().coordinates();
        let lc = &self.closure;
        let g = DMatrix::from_fn(c.len(), d.n, |r, col| d.g[(c.frame(r) - 1, col)]);
        let wa = DMatrix::from_fn(d.p, d.n, |r, col| d.jac[(r, lc.actuated_joints()[col] - 1)]);
        let wp = DMatrix::from_fn(d.p, d.p, |r, col| d.jac[(r, lc.passive_joints()[col] - 1)]);
        ClosedState {
            q_a: DVector::from_column_slice(&b.q_a),
            q_p: DVector::from_column_slice(&b.q_p),
            q: self.tree_vector(&d.q_tr),
            qd: self.tree_vector(&d.qd_tr),
            qdd: self.tree_vector(&d.qdd_tr),
            psi: d.psi.clone(),
            wa,
            wp,
            w: d.w.clone(),
            g,
            conditioning: cond,
        }
    }
}

/// A closed configuration on the tracker's branch.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosureSolution {
    /// q_a (actuated joints).
    pub q_a: DVector<f64>,
    /// q_p (passive joints, [`ClosedChain::passive_coordinates`]).
    pub q_p: DVector<f64>,
    /// Cut-joint variables q_c (NL+1..NJ), rad or m.
    pub q_c: DVector<f64>,
    /// q_tr over the movable joints of the equivalent tree.
    pub q_tree: DVector<f64>,
    /// W = d q_p / d q_a (p x N, 10.30).
    pub w: DMatrix<f64>,
    /// Largest residual of all candidate closure equations (m or rad).
    pub residual: f64,
    /// Conditioning of Wp.
    pub conditioning: Conditioning,
}

/// A consistent state of the equivalent tree (10.29, 10.42) with its constraint matrices.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedState {
    /// q_a.
    pub q_a: DVector<f64>,
    /// q_p.
    pub q_p: DVector<f64>,
    /// q_tr over the movable joints of the equivalent tree.
    pub q: DVector<f64>,
    /// qd_tr = G qd_a.
    pub qd: DVector<f64>,
    /// qdd_tr = G qdd_a + [0; -Wp^-1 Ψ].
    pub qdd: DVector<f64>,
    /// Ψ of (10.28) (p entries).
    pub psi: DVector<f64>,
    /// Wa (p x N), columns in actuated order.
    pub wa: DMatrix<f64>,
    /// Wp (p x p), columns in passive order.
    pub wp: DMatrix<f64>,
    /// W = -Wp^-1 Wa (p x N).
    pub w: DMatrix<f64>,
    /// G = d q_tr / d q_a (movable joints x N).
    pub g: DMatrix<f64>,
    /// Conditioning of Wp.
    pub conditioning: Conditioning,
}

/// Loop closure on the tracker's branch into `q_p` (passive joints): moves `branch` to `q_a`
/// (actuated joints, rad or m). Allocation-free on the branch.
///
/// Errors: [`Error::Dimension`] / [`Error::NotFinite`] for bad inputs, [`Error::BranchLost`]
/// when q_a cannot be reached on the branch, [`Error::Singular`] when Wp is singular at q_a.
pub fn loop_closure_into(
    chain: &ClosedChain,
    data: &mut ClosedData,
    branch: &mut Branch,
    q_a: &[f64],
    q_p: &mut [f64],
) -> Result<Conditioning> {
    chain.check_data(data, branch)?;
    chain.coords.check("q_a", q_a, "actuated joints")?;
    chain.passive.check_output("q_p", q_p, "passive joints")?;
    chain.track(data, branch, q_a)?;
    q_p.copy_from_slice(&branch.q_p);
    Ok(chain.conditioning(branch, None))
}

/// Loop closure on the tracker's branch: q_p, the cut-joint variables, W and the conditioning
/// at q_a. Allocates.
///
/// # Example
///
/// A four-bar linkage (`robots/fourbar.toml`: crank 1 actuated, joints 2 and 3 passive, cut
/// joint 4 with its twin frame 5 on the rocker) driven to crank angles far apart: each is
/// reached from the previous one on the same assembly branch, and the cut joint's frame 4 meets
/// its twin 5.
///
/// ```
/// use robodyn::{geometry::frame_transforms_with_cuts, loop_closure, ClosedChain};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/fourbar.toml");
/// let robot = robodyn::io::load(path)?;
/// let chain = ClosedChain::new(&robot)?;
/// let mut branch = chain.assembly_branch()?; // closed at q = 0
/// for q1 in [2.5, -2.0, 0.7] {
///     let s = loop_closure(&chain, &mut branch, &[q1])?;
///     assert!(!s.conditioning.warning);
///     // an independent check: compose the frames of the tree (joints 1..3, cut joint 4)
///     let t = frame_transforms_with_cuts(&robot, s.q_tree.as_slice(), s.q_c.as_slice())?;
///     assert!((t[3].pos - t[4].pos).norm() < 1e-9); // O_4 = O_5
///     println!("q1 = {q1}: q_p = {}, W = {}", s.q_p, s.w);
/// }
/// # Ok(())
/// # }
/// ```
pub fn loop_closure(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
) -> Result<ClosureSolution> {
    let mut d = ClosedData::new(chain);
    let mut q_p = vec![0.0; chain.n_equations()];
    let cond = loop_closure_into(chain, &mut d, branch, q_a, &mut q_p)?;
    let lc = &chain.closure;
    lc.assemble(&branch.q_a, &branch.q_p, &mut d.q_tr);
    lc.kinematics(&mut d.lw, &d.q_tr, None, None);
    Ok(ClosureSolution {
        q_a: DVector::from_column_slice(q_a),
        q_p: DVector::from_vec(q_p),
        q_c: DVector::from_vec(lc.cut_variables(&d.lw)),
        q_tree: chain.tree_vector(&d.q_tr),
        w: d.w.clone(),
        residual: lc.max_residual(&d.lw),
        conditioning: cond,
    })
}

/// The consistent tree state for (q_a, qd_a, qdd_a) on the tracker's branch: q_p by loop
/// closure, qd_p = W qd_a (10.29), qdd_p = W qdd_a - Wp^-1 Ψ (10.42). Allocates.
pub fn closed_state(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
    qd_a: &[f64],
    qdd_a: &[f64],
) -> Result<ClosedState> {
    let mut d = ClosedData::new(chain);
    chain.state_into(
        &mut d,
        branch,
        [("q_a", q_a), ("qd_a", qd_a), ("qdd_a", qdd_a)],
    )?;
    let cond = chain.conditioning(branch, None);
    Ok(chain.state_result(&d, branch, cond))
}

/// Tree state (q_tr, qd_tr) of the last evaluation in `data`, over tree arrays (NL entries):
/// for the simulator's energy.
pub(crate) fn last_tree_state(data: &ClosedData) -> (&[f64], &[f64]) {
    (&data.q_tr, &data.qd_tr)
}

/// The closure residual (max over all loops' candidate equations) at the last evaluation.
pub(crate) fn last_residual(chain: &ClosedChain, data: &ClosedData) -> f64 {
    chain.closure.max_residual(&data.lw)
}

/// Newton steps on the kept closure equations (q_p -= Wp^-1 phi) beyond the closure tolerance,
/// until the residual stops decreasing: q_p at q_a to the rounding level (for the numerical
/// base parameters, whose rank decision would see the solver's 1e-12).
pub(crate) fn refine_closure(chain: &ClosedChain, q_a: &[f64], q_p: &[f64]) -> Vec<f64> {
    let lc = &chain.closure;
    let mut d = ClosedData::new(chain);
    let mut q_p = q_p.to_vec();
    let residual = |d: &mut ClosedData, q_p: &[f64]| {
        lc.assemble(q_a, q_p, &mut d.q_tr);
        chain.factor_wp(d);
        lc.residual(&d.lw, &mut d.r);
        d.r.amax()
    };
    let mut norm = residual(&mut d, &q_p);
    for _ in 0..6 {
        if norm == 0.0 || !d.lu.regular {
            break;
        }
        let mut step: Vec<f64> = d.r.iter().copied().collect();
        d.lu.solve(&mut step);
        let trial: Vec<f64> = q_p.iter().zip(&step).map(|(a, b)| a - b).collect();
        let nt = residual(&mut d, &trial);
        if nt >= norm {
            break;
        }
        q_p = trial;
        norm = nt;
    }
    q_p
}
