//! Customized closed-chain models: Gamma_cl = G^T Gamma_tr (10.40) and W = d q_p / d q_a (10.30).
//!
//! **Constant G.** Closed chains whose loop constraints are linear (parallelograms such as the
//! SR400's, Example 10.1) have a constant G, which costs no operation beyond G^T Gamma_tr. G is found numerically and then checked to be constant: at several random actuated
//! configurations the loop closure (frame R_k on link a(k) coincides with its twin R_{k+B}) is
//! solved for the passive and cut-joint variables by Gauss–Newton, the constraint Jacobian
//! [J_p J_a] (central differences) gives W = -J_p^+ J_a (10.38–10.39), G = [I; W] in tree order.
//! When the entries differ between configurations, or are not simple rationals, there is no
//! constant G and the generator writes the general form instead: the constraint Jacobian on
//! symbols ([`constraint_jacobian`], eq 10.27) and the elimination of Wp written out
//! (`Gamma_cl = Gamma_a + Wa^T lambda`, eqs 10.36–10.37; W = -Wp^-1 Wa, eq 10.30).

use super::linear::lu_solve;
use super::GenOptions;
use crate::algorithms::closed_chain::ClosedChain;
use crate::algorithms::loop_closure::LoopClosure;
use crate::error::{Error, Item, Result};
use crate::geometry::frame_transforms_per_frame;
use crate::model::{DynModel, JointType, RobotDescription};
use crate::Robot;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use rand::Rng;
use robodyn_symbolic::program::name_value;
use robodyn_symbolic::{Assignment, Expr};
use std::collections::BTreeMap;

/// Loop-closure residual: for each cut joint k, position and orientation difference between
/// R_k and R_{k+B} (12 entries per loop).
fn residual(robot: &Robot, q: &[f64]) -> DVector<f64> {
    let t = frame_transforms_per_frame(robot, q);
    let (nl, nj) = (robot.nl(), robot.nj());
    let b = nj - nl;
    let mut r = Vec::with_capacity(12 * b);
    for k in nl + 1..=nj {
        let (tk, tt) = (&t[k - 1], &t[k + b - 1]);
        r.extend((tk.pos - tt.pos).iter());
        r.extend((tk.rot - tt.rot).iter());
    }
    DVector::from_vec(r)
}

fn jacobian(robot: &Robot, q: &[f64], cols: &[usize]) -> DMatrix<f64> {
    let h = 1e-6;
    let r0 = residual(robot, q);
    let mut jac = DMatrix::zeros(r0.len(), cols.len());
    let mut qq = q.to_vec();
    for (c, &j) in cols.iter().enumerate() {
        qq[j - 1] = q[j - 1] + h;
        let rp = residual(robot, &qq);
        qq[j - 1] = q[j - 1] - h;
        let rm = residual(robot, &qq);
        qq[j - 1] = q[j - 1];
        jac.set_column(c, &((rp - rm) / (2.0 * h)));
    }
    jac
}

/// Solve the loop closure for the unknown variables `unk` (1-based, tree or cut joints).
fn close_loops<R: Rng>(robot: &Robot, q: &mut [f64], unk: &[usize], rng: &mut R) -> bool {
    for attempt in 0..20 {
        if attempt > 0 {
            for &j in unk {
                q[j - 1] = rng.random_range(-3.0..3.0);
            }
        }
        for _ in 0..60 {
            let r = residual(robot, q);
            if r.norm() < 1e-13 {
                return true;
            }
            let jac = jacobian(robot, q, unk);
            let Ok(pinv) = jac.pseudo_inverse(1e-9) else {
                break;
            };
            let dx = pinv * r;
            for (c, &j) in unk.iter().enumerate() {
                q[j - 1] -= dx[c];
            }
        }
        if residual(robot, q).norm() < 1e-11 {
            return true;
        }
    }
    false
}

/// The constant G (NL rows in tree-joint order, one column per actuated joint in increasing
/// order), or an error when G depends on the configuration.
pub fn constant_g(robot: &Robot) -> Result<DMatrix<f64>> {
    let (nl, nj) = (robot.nl(), robot.nj());
    if nj == nl {
        return Err(Error::Input(
            "the robot has no closed loop (NJ = NL)".into(),
        ));
    }
    let act = robot.actuated_joints();
    let mut unk = robot.passive_joints();
    unk.extend(nl + 1..=nj);
    let mut rng = crate::sampling::rng(7);
    let g_at = |q: &[f64]| -> Result<DMatrix<f64>> {
        let ja = jacobian(robot, q, &act);
        let jp = jacobian(robot, q, &unk);
        let pinv = jp
            .pseudo_inverse(1e-9)
            .map_err(|e| Error::Numerical(format!("singular loop-closure Jacobian: {e}")))?;
        let w = -(pinv * ja);
        let mut g = DMatrix::zeros(nl, act.len());
        for (c, &a) in act.iter().enumerate() {
            g[(a - 1, c)] = 1.0;
        }
        for (r, &p) in unk.iter().enumerate() {
            if p <= nl {
                for c in 0..act.len() {
                    g[(p - 1, c)] = w[(r, c)];
                }
            }
        }
        Ok(g)
    };
    let mut qa0 = vec![0.0; nj];
    for &a in &act {
        qa0[a - 1] = rng.random_range(-1.0..1.0);
    }
    // Several assembly modes may exist (a parallelogram and its crossed form): follow each
    // solution found from a random start along a path of q_a (continuation keeps the mode) and
    // accept the first mode whose G stays constant.
    let mut found = None;
    'starts: for _ in 0..8 {
        let mut q = qa0.clone();
        for &p in &unk {
            q[p - 1] = rng.random_range(-3.0..3.0);
        }
        if !close_loops(robot, &mut q, &unk, &mut rng) {
            continue;
        }
        let g0 = g_at(&q)?;
        let dir: Vec<f64> = act.iter().map(|_| rng.random_range(-0.2..0.2)).collect();
        for _ in 0..4 {
            for (c, &a) in act.iter().enumerate() {
                q[a - 1] += dir[c];
            }
            if !close_loops(robot, &mut q, &unk, &mut rng) {
                continue 'starts;
            }
            if (g_at(&q)? - &g0).amax() > 1e-6 {
                continue 'starts;
            }
        }
        found = Some(g0);
        break;
    }
    let Some(g0) = found else {
        return Err(Error::Input(
            "G is not constant: no assembly mode with a constant G was found (loops such as \
             parallelograms have one; `generate` writes the general form W(q) otherwise)"
                .into(),
        ));
    };
    // exact small rationals (0, +-1, +-1/2, ...)
    let mut out = g0.clone();
    for x in out.iter_mut() {
        let r = (*x * 12.0).round() / 12.0;
        if (*x - r).abs() > 1e-6 {
            return Err(Error::Input(format!(
                "G is not constant in exact form: it has the non-rational entry {x} \
                 (`generate` writes the general form W(q))"
            )));
        }
        *x = r;
    }
    Ok(out)
}

/// A loop-closure model and a closed reference configuration: what the general closed-chain
/// models (G depending on q) need at generation time.
pub(crate) struct ClosureReference {
    pub lc: LoopClosure,
    /// Wp at the reference configuration (fixes the row order of the written-out elimination).
    pub wp: DMatrix<f64>,
}

impl ClosureReference {
    /// The loops closed at the robot's reference configuration (its `assembly`, else q = 0,
    /// continued to the reference actuated values) and Wp there.
    pub fn new(robot: &Robot) -> Result<ClosureReference> {
        let cc = ClosedChain::new(robot)?;
        let mut branch = cc.assembly_branch().map_err(|e| {
            Error::Numerical(format!(
                "robot `{}`: the loops do not close at the reference configuration, which \
                 fixes the elimination order of the generated W: {e}",
                robot.name()
            ))
        })?;
        let qa = branch.q_a().to_vec();
        let zeros = vec![0.0; qa.len()];
        let s =
            crate::algorithms::closed_chain::closed_state(&cc, &mut branch, &qa, &zeros, &zeros)?;
        Ok(ClosureReference {
            lc: cc.closure().clone(),
            wp: s.wp,
        })
    }
}

/// The constraint Jacobian d phi / d q_tr (p x NL, columns by joint number) of the kept
/// loop-closure equations (eq 10.27, rows as [`LoopClosure`] keeps them) on symbols, at a
/// closed configuration.
///
/// Written in the cut frame R_k (taken at q_k = 0, as the numeric model does): for a tree joint
/// m of the branch to j = a(k+B) (s = +1) or to i = a(k) (s = -1), with kz_m, kO_m the axis and
/// origin of frame m in R_k,
/// - revolute m: linear column s kz_m x (0 - kO_m), angular column s kz_m;
/// - prismatic m: linear column s kz_m, angular column 0.
///
/// The linear columns are the velocities of the point O_k. For a revolute cut this is where the
/// numeric model's twin origin P_{k+B} lies on a closed configuration (and its u = e_z there, so
/// the two angular rows are the x and y angular components). For a prismatic cut the twin origin
/// lies at q_k along z_k, but the three angular rows are constraints: moving the reference point
/// by c adds (angular column) x c, a combination of the angular rows, which the kept rows span,
/// so W is the same and q_k is not needed. (Derived from 10.27; not in the chapter's text.)
///
/// kT_m is propagated from the cut frame up branch i to the loop's root and down branch j, so
/// only the loop's own joints enter. Intermediates: `KR<k>_<m>_<r><c>` = entry (r, c) of kR_m,
/// `KP<k>_<m>_<r>` of kO_m, `JC<row>_<m>` the Jacobian entries.
pub(crate) fn constraint_jacobian(
    model: &DynModel<Expr>,
    lc: &LoopClosure,
    q: &[Expr],
) -> DMatrix<Expr> {
    let nl = model.nl;
    let mut jac = DMatrix::from_element(lc.n_equations(), nl, Expr::zero());
    let mut row0 = 0;
    for lp in lc.loops() {
        let t = &lp.topology;
        let k = t.cut;
        let name_frame = |m: usize, rot: Matrix3<Expr>, pos: Vector3<Expr>| {
            let rot = Matrix3::from_fn(|r, c| {
                name_value(rot[(r, c)].clone(), || {
                    format!("KR{k}_{m}_{}{}", r + 1, c + 1)
                })
            });
            let pos = Vector3::from_fn(|r, _| {
                name_value(pos[r].clone(), || format!("KP{k}_{m}_{}", r + 1))
            });
            (rot, pos)
        };
        // kT_i = (iT_k(q_k = 0))^-1, then up to the root: kT_a(m) = kT_m (a(m)T_m)^-1
        let mut placed: BTreeMap<usize, (Matrix3<Expr>, Vector3<Expr>)> = BTreeMap::new();
        let (ak, pk) = model.frame(k).transform(&Expr::zero());
        let rot_i = ak.transpose();
        let pos_i = -(&rot_i * pk);
        placed.insert(t.link_i, name_frame(t.link_i, rot_i, pos_i));
        for &m in t.branch_i.iter().rev() {
            let (am, pm) = model.frame(m).transform(&q[m - 1]);
            let (rot_m, pos_m) = placed[&m].clone();
            let rot_a = rot_m * am.transpose();
            let pos_a = pos_m - &rot_a * pm;
            let a = model.frame(m).ant;
            placed.insert(a, name_frame(a, rot_a, pos_a));
        }
        // down branch j: kT_m = kT_a(m) a(m)T_m
        for &m in &t.branch_j {
            let (am, pm) = model.frame(m).transform(&q[m - 1]);
            let (rot_a, pos_a) = placed[&model.frame(m).ant].clone();
            let pos = pos_a + &rot_a * pm;
            placed.insert(m, name_frame(m, rot_a * am, pos));
        }
        let branches = [(&t.branch_j, Expr::one()), (&t.branch_i, -Expr::one())];
        for (branch, s) in branches {
            for &m in branch.iter() {
                let (rot, pos) = &placed[&m];
                let z = rot.column(2).into_owned() * s.clone();
                let (lin, ang) = match model.frame(m).joint {
                    JointType::Revolute => (pos.cross(&z), z),
                    JointType::Prismatic => (z, Vector3::from_element(Expr::zero())),
                    JointType::Fixed => continue,
                };
                let candidates = match lp.cut_joint {
                    JointType::Prismatic => [&ang[0], &ang[1], &ang[2], &lin[0], &lin[1]],
                    _ => [&lin[0], &lin[1], &lin[2], &ang[0], &ang[1]],
                };
                for (r, &row) in lp.rows.iter().enumerate() {
                    jac[(row0 + r, m - 1)] = name_value(candidates[row].clone(), || {
                        format!("JC{}_{m}", row0 + r + 1)
                    });
                }
            }
        }
        row0 += lp.rows.len();
    }
    jac
}

/// How a closed-chain model projects the tree on the actuated joints.
pub(crate) enum ClosedForm {
    /// Not a closed-chain model.
    Tree,
    /// G constant (rows q_1..q_NL, columns the actuated joints in increasing order); the
    /// passive joints are the movable tree joints that are not actuated.
    Constant {
        g: DMatrix<Expr>,
        actuated: Vec<usize>,
        passive: Vec<usize>,
    },
    /// G = [I; W(q)] with the loop-closure Jacobian written out.
    General(Box<ClosureReference>),
}

/// The closed-chain form of a robot: the given G, else a constant G when the loops have one,
/// else the general form. `robot` is the description validated as a numeric robot (needed
/// unless G is given).
pub(crate) fn closed_form(
    desc: &RobotDescription,
    opt: &GenOptions,
    robot: std::result::Result<&Robot, &Error>,
) -> Result<ClosedForm> {
    let nl = desc.nl;
    if desc.nj == nl {
        return Err(Error::invalid(
            Item::Robot,
            format!(
                "the {} model needs a robot with closed loops (NJ > NL)",
                opt.model.name()
            ),
        ));
    }
    let (actuated, passive) = (desc.actuated_joints(), desc.passive_joints());
    if let Some(g) = &opt.g {
        if g.nrows() != nl || g.ncols() != actuated.len() {
            return Err(Error::Input(format!(
                "G is {} x {}, {nl} x {} expected (NL rows, one column per actuated joint)",
                g.nrows(),
                g.ncols(),
                actuated.len()
            )));
        }
        return Ok(ClosedForm::Constant {
            g: g.clone(),
            actuated,
            passive,
        });
    }
    let robot = robot.map_err(Clone::clone)?;
    match constant_g(robot) {
        Ok(g) => Ok(ClosedForm::Constant {
            g: g.map(Expr::num),
            actuated,
            passive,
        }),
        Err(_) => Ok(ClosedForm::General(Box::new(ClosureReference::new(robot)?))),
    }
}

impl ClosedForm {
    /// Header lines of the generated model.
    pub fn describe(&self, nl: usize) -> Vec<String> {
        match self {
            ClosedForm::Tree => Vec::new(),
            ClosedForm::Constant { g, actuated, .. } => {
                let mut v = vec![format!(
                    "G = d q_tr / d q_a (constant; rows q1..q{nl}, columns q_a = {actuated:?}):"
                )];
                for r in 0..g.nrows() {
                    let row: Vec<String> = g.row(r).iter().map(|e| e.to_string()).collect();
                    v.push(format!("  q{}: [{}]", r + 1, row.join(", ")));
                }
                v
            }
            ClosedForm::General(r) => vec![
                format!(
                    "G = [I; W(q)], W = -Wp^-1 Wa (eq 10.30), q_a = {:?}, q_p = {:?}: the \
                     Jacobian of the kept loop-closure equations (JC, eq 10.27) is written in \
                     the cut frames (KR, KP) and is valid on closed configurations only",
                    r.lc.actuated_joints(),
                    r.lc.passive_joints()
                ),
                "Gamma_cl = Gamma_a + Wa^T LAM with Wp^T LAM = -Gamma_p (eqs 10.36-10.37); \
                 Gaussian elimination with the row order of partial pivoting at the robot's \
                 reference configuration (valid while those pivots stay away from zero)"
                    .into(),
            ],
        }
    }
}

/// Wp (p x p, columns the passive joints) and Wa (p x N, columns the actuated joints) of the
/// symbolic constraint Jacobian.
fn split_jacobian(jac: &DMatrix<Expr>, lc: &LoopClosure) -> (Vec<Vec<Expr>>, Vec<Vec<Expr>>) {
    let cols = |joints: &[usize]| -> Vec<Vec<Expr>> {
        (0..jac.nrows())
            .map(|r| joints.iter().map(|&j| jac[(r, j - 1)].clone()).collect())
            .collect()
    };
    (cols(lc.passive_joints()), cols(lc.actuated_joints()))
}

/// GAMCL<a> for every actuated joint a from the tree torques `gam` (by joint number).
pub(crate) fn closed_torques(
    model: &DynModel<Expr>,
    form: &ClosedForm,
    q: &[Expr],
    gam: &[Expr],
) -> Result<Vec<Assignment>> {
    let out = |a: usize, expr: Expr| Assignment {
        name: format!("GAMCL{a}"),
        expr,
    };
    match form {
        ClosedForm::Tree => Ok(Vec::new()),
        ClosedForm::Constant { g, actuated, .. } => Ok(actuated
            .iter()
            .enumerate()
            .map(|(c, &a)| {
                out(
                    a,
                    Expr::sum((0..g.nrows()).map(|r| g[(r, c)].clone() * gam[r].clone())),
                )
            })
            .collect()),
        ClosedForm::General(reference) => {
            let lc = &reference.lc;
            let jac = constraint_jacobian(model, lc, q);
            let (wp, wa) = split_jacobian(&jac, lc);
            let p = wp.len();
            // Wp^T LAM = -Gamma_p (10.37)
            let wpt: Vec<Vec<Expr>> = (0..p)
                .map(|i| (0..p).map(|j| wp[j][i].clone()).collect())
                .collect();
            let rhs: Vec<Vec<Expr>> = lc
                .passive_joints()
                .iter()
                .map(|&j| vec![-gam[j - 1].clone()])
                .collect();
            let lam = lu_solve(&wpt, &rhs, &reference.wp.transpose(), &|r, _| {
                format!("LAM{}", r + 1)
            })?;
            // Gamma_cl = Gamma_a + Wa^T LAM (10.36)
            Ok(lc
                .actuated_joints()
                .iter()
                .enumerate()
                .map(|(c, &a)| {
                    let terms = (0..p).map(|r| wa[r][c].clone() * lam[r][0].clone());
                    out(
                        a,
                        Expr::sum(std::iter::once(gam[a - 1].clone()).chain(terms)),
                    )
                })
                .collect())
        }
    }
}

/// W<p>_<a> = d q_p / d q_a for every passive joint p and actuated joint a.
pub(crate) fn closed_w(
    model: &DynModel<Expr>,
    form: &ClosedForm,
    q: &[Expr],
) -> Result<Vec<Assignment>> {
    let out = |p: usize, a: usize, expr: Expr| Assignment {
        name: format!("W{p}_{a}"),
        expr,
    };
    match form {
        ClosedForm::Tree => Ok(Vec::new()),
        ClosedForm::Constant {
            g,
            actuated,
            passive,
        } => Ok(passive
            .iter()
            .flat_map(|&p| {
                actuated
                    .iter()
                    .enumerate()
                    .map(move |(c, &a)| out(p, a, g[(p - 1, c)].clone()))
            })
            .collect()),
        ClosedForm::General(reference) => {
            let lc = &reference.lc;
            let jac = constraint_jacobian(model, lc, q);
            let (wp, wa) = split_jacobian(&jac, lc);
            let rhs: Vec<Vec<Expr>> = wa
                .iter()
                .map(|row| row.iter().map(|x| -x.clone()).collect())
                .collect();
            let w = lu_solve(&wp, &rhs, &reference.wp, &|r, c| {
                format!("X{}_{}", r + 1, c + 1)
            })?;
            let (pj, aj) = (lc.passive_joints(), lc.actuated_joints());
            Ok(pj
                .iter()
                .enumerate()
                .flat_map(|(r, &p)| {
                    let w = &w;
                    aj.iter()
                        .enumerate()
                        .map(move |(c, &a)| out(p, a, w[r][c].clone()))
                })
                .collect())
        }
    }
}
