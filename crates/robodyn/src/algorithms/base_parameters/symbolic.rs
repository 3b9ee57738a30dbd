//! Symbolic method for the base parameters (§10.2.4, §10.3.4–10.3.6).
//!
//! Every standard parameter K_j^p starts as its own symbol (`XX2`, `M3`, ...). Links are visited
//! for j = n, ..., 1 and the rules of §10.3.6 move (group) or drop (eliminate) the *current*
//! expression of a parameter, KR_j^p, into the parameters of other links:
//!
//! - rule 1, parallelogram loops (§10.3.5): eq 10.51c eliminates MX (or MY) of the
//!   higher-numbered of the two links holding the cut joint and its twin; eqs 10.55–10.56 group
//!   the inertia tensor of the higher-numbered link of each pair of parallel links into the lower;
//!   the rotor inertia (and friction) of the higher of the two joints inside the loop is grouped
//!   into the lower one's, as their velocities are opposite (derived from 10.54);
//! - rule 2: Theorem 10.1 (revolute j: YY_j, MZ_j, M_j into XX_j and link a(j), eqs 10.14–10.19,
//!   any gamma and b) and Theorem 10.2 (prismatic j: J_j into J_a(j), eq 10.20b). A fixed frame
//!   (sigma = 2) moves all ten parameters of its link into a(j) (rigid body, the full lambda);
//! - rules 3–4: prismatic j between r1 and r2 of its branch: parallel to r1, MZ_j is eliminated
//!   and MX_j, MY_j are grouped into link a(j) as a rigid body at q_j = 0 (eq 10.23, derived
//!   from first principles: with z_j parallel to every rotation axis of a(j) the q_j-dependent
//!   terms vanish); not parallel, Table 10.1 (eq 10.21 relation);
//! - rules 5–7 eliminate XX XY XZ YZ (rule 5), MX MY (rule 6: axis on the line of r1's) of
//!   revolute links between r1 and r2, and the first moments of prismatic links before r1 (rule 7);
//! - rotor inertias (§9.4.2.5, derived): IA_j is grouped into ZZ_j when w_j . z_j = qd_j
//!   identically, i.e. every revolute axis before j on its branch is perpendicular to z_j (r1
//!   always; r2 when perpendicular to r1). IA_j of a prismatic joint is grouped into M_j when
//!   every revolute axis before j is parallel to z_j, every prismatic axis before j is
//!   perpendicular to it and z_j is perpendicular to the effective gravity: then the column of
//!   M_j is qdd_j in row j plus that of a point mass fixed on a(j) at q_j = 0 (derived), so
//!   MR_j = M_j + IA_j and a point mass -IA_j is added to link a(j).
//!
//! The geometric conditions (parallel or perpendicular axes, parallelogram shape) are evaluated
//! numerically at random configurations with the robot's symbol values; a symbol without value
//! takes a generic value (so it is never taken to be special).
//!
//! Limits: the relations (10.51) of a cut joint are used only for parallelogram loops (for other
//! loops "there is no general systematic choice", §10.3.4: the result is then the tree's base
//! parameters and the numerical method is the arbiter); prismatic cut joints (10.52–10.53) are not
//! used; a mobile base is treated as fixed (its velocity is ignored).

use crate::error::{Error, Result};
use crate::model::{
    path_from_base, validate_structure, FrameConstants, JointType, RobotDescription, Structure,
    STANDARD_PARAMETERS,
};
use nalgebra::{Matrix3, Vector3};
use robodyn_symbolic::{Expr, Node};
use std::collections::{BTreeMap, BTreeSet};

use super::super::regressor::{ParameterSelection, PARAMS_PER_LINK};

const XX: usize = 0;
const XY: usize = 1;
const XZ: usize = 2;
const YY: usize = 3;
const YZ: usize = 4;
const ZZ: usize = 5;
const MX: usize = 6;
const MY: usize = 7;
const MZ: usize = 8;
const M: usize = 9;
const IA: usize = 10;

/// Geometric tolerance of the parallel/perpendicular tests (unit vectors).
pub const GEOMETRY_TOLERANCE: f64 = 1e-9;

/// Result of the symbolic method. Indices are indices in K (13 per link).
#[derive(Clone, Debug)]
pub struct SymbolicBase {
    /// Selected standard parameters, K order.
    pub columns: Vec<usize>,
    /// Base parameters, K order.
    pub base: Vec<usize>,
    /// Grouping equation of each base parameter (same order as `base`), expanded.
    pub equations: Vec<Expr>,
    /// Parameters grouped into base parameters.
    pub grouped: Vec<usize>,
    /// Parameters with no effect.
    pub no_effect: Vec<usize>,
    /// Loops whose cut-joint relations were not used (not parallelograms).
    pub unhandled_loops: Vec<usize>,
    /// Parallelogram loops detected (cut joint numbers).
    pub parallelograms: Vec<usize>,
}

impl SymbolicBase {
    pub fn count(&self) -> usize {
        self.base.len()
    }

    /// Whether base parameter number `r` is a grouped one (its equation is not its own symbol).
    pub fn is_regrouped(&self, r: usize) -> bool {
        self.equations[r].as_symbol().is_none()
    }

    /// Numeric value of each base parameter from the standard parameter values `k` (13 per
    /// link) and the robot's symbols. `None` where a symbol has no value.
    pub fn values(&self, desc: &RobotDescription, k: &[Option<f64>]) -> Vec<Option<f64>> {
        let env = |s: &str| -> Option<f64> {
            if let Some(i) = standard_index(s, desc.nl) {
                return k.get(i).copied().flatten();
            }
            desc.symbols.get(s).copied()
        };
        self.equations.iter().map(|e| e.eval(&env).ok()).collect()
    }
}

/// Index in K of a standard parameter symbol such as `XX2`, `IA1`.
pub fn standard_index(name: &str, nl: usize) -> Option<usize> {
    let split = name.find(|c: char| c.is_ascii_digit())?;
    let (p, j) = name.split_at(split);
    let pi = STANDARD_PARAMETERS.iter().position(|&x| x == p)?;
    let j: usize = j.parse().ok()?;
    (j >= 1 && j <= nl).then(|| PARAMS_PER_LINK * (j - 1) + pi)
}

fn sym(j: usize, p: usize) -> Expr {
    Expr::symbol(format!("{}{j}", STANDARD_PARAMETERS[p]))
}

/// Numeric geometry used to decide the conditions of the rules.
struct Geo {
    frames: Vec<FrameConstants<f64>>,
    /// Effective gravity (VP0 - G) direction in R_0, or zero.
    g: Vector3<f64>,
    /// Random configurations (values of the tree joints).
    configs: Vec<Vec<f64>>,
    /// 0A_j, 0P_j for each configuration, frames 1..NF at index j.
    poses: Vec<Vec<(Matrix3<f64>, Vector3<f64>)>>,
}

fn generic_value(name: &str) -> f64 {
    // deterministic "generic" value from the name: never 0, never a multiple of pi/2
    let h = name.bytes().fold(1469598103934665603u64, |h, b| {
        (h ^ b as u64).wrapping_mul(1099511628211)
    });
    0.3 + (h % 1000) as f64 * 1.37e-3
}

impl Geo {
    fn new(desc: &RobotDescription, ant: &[usize]) -> Result<Geo> {
        let env = |s: &str| {
            Some(
                desc.symbols
                    .get(s)
                    .copied()
                    .unwrap_or_else(|| generic_value(s)),
            )
        };
        let ev = |e: &Expr| -> Result<f64> {
            e.eval(&env)
                .map_err(|err| Error::Input(format!("cannot evaluate `{e}`: {err}")))
        };
        let mut frames = Vec::new();
        for f in &desc.frames {
            let g = [
                ev(&f.gamma)?,
                ev(&f.b)?,
                ev(&f.alpha)?,
                ev(&f.d)?,
                ev(&f.theta)?,
                ev(&f.r)?,
            ];
            frames.push(FrameConstants::new(f.ant, f.joint, g));
        }
        let gv = Vector3::new(
            ev(&desc.vp0[0])? - ev(&desc.gravity[0])?,
            ev(&desc.vp0[1])? - ev(&desc.gravity[1])?,
            ev(&desc.vp0[2])? - ev(&desc.gravity[2])?,
        );
        let g = if gv.norm() > 0.0 { gv.normalize() } else { gv };
        let mut rng = crate::testing::rng(0x5eed);
        let nf = frames.len();
        let mut configs = Vec::new();
        let mut poses = Vec::new();
        for _ in 0..3 {
            use rand::Rng;
            let q: Vec<f64> = (0..nf).map(|_| rng.random_range(-3.0..3.0)).collect();
            let mut p = vec![(Matrix3::identity(), Vector3::zeros()); nf + 1];
            for j in 1..=nf {
                let (r, t) = frames[j - 1].transform(&q[j - 1]);
                let (ra, ta) = p[ant[j]];
                p[j] = (ra * r, ta + ra * t);
            }
            configs.push(q);
            poses.push(p);
        }
        Ok(Geo {
            frames,
            g,
            configs,
            poses,
        })
    }

    fn z(&self, c: usize, j: usize) -> Vector3<f64> {
        if j == 0 {
            return Vector3::z();
        }
        self.poses[c][j].0.column(2).into_owned()
    }

    fn parallel(&self, a: usize, b: usize) -> bool {
        (0..self.configs.len())
            .all(|c| self.z(c, a).cross(&self.z(c, b)).norm() < GEOMETRY_TOLERANCE)
    }

    fn perpendicular(&self, a: usize, b: usize) -> bool {
        (0..self.configs.len()).all(|c| self.z(c, a).dot(&self.z(c, b)).abs() < GEOMETRY_TOLERANCE)
    }

    fn parallel_to_gravity(&self, a: usize) -> bool {
        (0..self.configs.len()).all(|c| self.z(c, a).cross(&self.g).norm() < GEOMETRY_TOLERANCE)
    }

    fn perpendicular_to_gravity(&self, a: usize) -> bool {
        (0..self.configs.len()).all(|c| self.z(c, a).dot(&self.g).abs() < GEOMETRY_TOLERANCE)
    }
}

/// Contribution of (J, MS, M), given in R_j, to the parameters of link i when R_j is rigidly
/// placed by (iA_j, iP_j): the lambda transformation of Appendix 6 (eqs 10.15–10.17 are its
/// columns 1+4, 9 and 10): iJ = A J A^T + M (P'P I - P P') + 2 (P's) I - P s' - s P' (about O_i,
/// s = A MS), iMS = s + M P, iM = M. Derived from the definition of J about a point.
fn transfer(
    a: &Matrix3<Expr>,
    p: &Vector3<Expr>,
    j: &Matrix3<Expr>,
    ms: &Vector3<Expr>,
    m: &Expr,
) -> (Matrix3<Expr>, Vector3<Expr>, Expr) {
    let s = a * ms;
    let pp = p.dot(p);
    let ps = p.dot(&s);
    let mut ji = a * j * a.transpose();
    for r in 0..3 {
        for c in 0..3 {
            let mut t = -(m.clone() * p[r].clone() * p[c].clone())
                - p[r].clone() * s[c].clone()
                - s[r].clone() * p[c].clone();
            if r == c {
                t += m.clone() * pp.clone() + Expr::int(2) * ps.clone();
            }
            ji[(r, c)] += t;
        }
    }
    let msi = s + p * m.clone();
    (ji, msi, m.clone())
}

const JIDX: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

struct State {
    kr: Vec<[Expr; PARAMS_PER_LINK]>,
    alive: Vec<[bool; PARAMS_PER_LINK]>,
}

impl State {
    fn get(&self, j: usize, p: usize) -> Expr {
        self.kr[j - 1][p].clone()
    }
    fn kill(&mut self, j: usize, p: usize) {
        self.alive[j - 1][p] = false;
        self.kr[j - 1][p] = Expr::zero();
    }
    fn add(&mut self, j: usize, p: usize, e: Expr) {
        if j == 0 || e.is_zero() {
            return; // grouped into the base: no effect
        }
        if !self.alive[j - 1][p] {
            // grouped into an eliminated parameter: no effect
            return;
        }
        let cur = self.kr[j - 1][p].clone();
        self.kr[j - 1][p] = cur + e;
    }
    fn j_matrix(&self, j: usize) -> Matrix3<Expr> {
        let mut m = Matrix3::from_element(Expr::zero());
        for (k, &(r, c)) in JIDX.iter().enumerate() {
            m[(r, c)] = self.get(j, k);
            m[(c, r)] = self.get(j, k);
        }
        m
    }
    fn add_tensor(&mut self, i: usize, ji: &Matrix3<Expr>) {
        for (k, &(r, c)) in JIDX.iter().enumerate() {
            self.add(i, k, ji[(r, c)].clone());
        }
    }
    fn add_all(&mut self, i: usize, t: (Matrix3<Expr>, Vector3<Expr>, Expr)) {
        self.add_tensor(i, &t.0);
        for a in 0..3 {
            self.add(i, MX + a, t.1[a].clone());
        }
        self.add(i, M, t.2);
    }
}

/// Symbolic frame constants (exact where the description is exact).
fn frame_expr(desc: &RobotDescription, j: usize) -> (Matrix3<Expr>, Vector3<Expr>) {
    let f = desc.frame(j);
    let fc = FrameConstants::<Expr>::new(f.ant, f.joint, f.geometric().map(|e| e.clone()));
    fc.transform(&Expr::zero())
}

fn exact_angle(x: f64) -> Expr {
    let k = x / std::f64::consts::FRAC_PI_2;
    if (k - k.round()).abs() < 1e-12 {
        Expr::int(k.round() as i64) * Expr::pi() / Expr::int(2)
    } else {
        Expr::num(x)
    }
}

fn rz(delta: &Expr) -> Matrix3<Expr> {
    let (c, s) = (delta.cos(), delta.sin());
    let z = Expr::zero;
    Matrix3::new(c.clone(), -s.clone(), z(), s, c, z(), z(), z(), Expr::one())
}

/// A detected parallelogram loop (§10.3.5): pairs (low, high, lowA_high) of parallel links and
/// the two links holding the cut joint and its twin.
struct Parallelogram {
    cut: usize,
    /// The two tree joints inside the loop (of links b and e): qd_b = -qd_e.
    inner: (usize, usize),
    pairs: Vec<(usize, usize, Matrix3<Expr>)>,
}

fn detect_parallelogram(
    desc: &RobotDescription,
    st: &Structure,
    geo: &Geo,
    l: &crate::model::ClosedLoop,
) -> Option<Parallelogram> {
    if l.branch_i.len() != 2 || l.branch_j.len() != 2 {
        return None;
    }
    let (a, b, c, e) = (l.branch_i[0], l.branch_i[1], l.branch_j[0], l.branch_j[1]);
    let (k, tw) = (l.cut, l.twin);
    for x in [a, b, c, e, k] {
        if desc.frame(x).joint != JointType::Revolute {
            return None;
        }
    }
    // all axes parallel, same direction
    for cfg in 0..geo.configs.len() {
        let z0 = geo.z(cfg, a);
        for x in [b, c, e, k, tw] {
            if (geo.z(cfg, x) - z0).norm() > GEOMETRY_TOLERANCE {
                return None;
            }
        }
        // O_a = O_c
        if (geo.poses[cfg][a].1 - geo.poses[cfg][c].1).norm() > GEOMETRY_TOLERANCE {
            return None;
        }
    }
    let _ = st;
    // side vectors in the frames of their links (planar part)
    let side = |x: usize| {
        let (_, p) = geo.frames[x - 1].transform(&0.0);
        nalgebra::Vector2::new(p.x, p.y)
    };
    // link a carries joint b, link b the cut joint k, link c carries e, link e the twin
    let (sa, sb, sc, se) = (side(b), side(k), side(e), side(tw));
    // theta offsets of the joint frames do not change the side vector (P does not depend on theta)
    if (sa.norm() - se.norm()).abs() > GEOMETRY_TOLERANCE
        || (sb.norm() - sc.norm()).abs() > GEOMETRY_TOLERANCE
        || sa.norm() < GEOMETRY_TOLERANCE
        || sb.norm() < GEOMETRY_TOLERANCE
    {
        return None;
    }
    let phi = |v: nalgebra::Vector2<f64>| v.y.atan2(v.x);
    // sides in the frames of their links, angles measured from x of the link frame: links with
    // parallel sides have world angles psi_x + phi_x = psi_y + phi_y, so xA_y = Rz(phi_x - phi_y)
    let mut pairs = Vec::new();
    for (x, px, y, py) in [(a, phi(sa), e, phi(se)), (b, phi(sb), c, phi(sc))] {
        let (lo, plo, hi, phi_hi) = if x < y {
            (x, px, y, py)
        } else {
            (y, py, x, px)
        };
        pairs.push((lo, hi, rz(&exact_angle(plo - phi_hi))));
    }
    Some(Parallelogram {
        cut: k,
        inner: (b.min(e), b.max(e)),
        pairs,
    })
}

/// Run the symbolic method on a description (symbols may lack values).
pub fn symbolic_base_parameters(
    desc: &RobotDescription,
    sel: &ParameterSelection,
) -> Result<SymbolicBase> {
    let st = validate_structure(desc)?;
    let nl = desc.nl;
    if sel.rotor.len() != nl || sel.friction.len() != nl {
        return Err(Error::Input(format!(
            "the parameter selection has {} entries, the robot has NL = {nl} links",
            sel.rotor.len()
        )));
    }
    let geo = Geo::new(desc, &st.ant)?;
    let columns = sel.columns();
    let colset: BTreeSet<usize> = columns.iter().copied().collect();
    let mut s = State {
        kr: (1..=nl)
            .map(|j| {
                std::array::from_fn(|p| {
                    if colset.contains(&(PARAMS_PER_LINK * (j - 1) + p)) {
                        sym(j, p)
                    } else {
                        Expr::zero()
                    }
                })
            })
            .collect(),
        alive: (1..=nl)
            .map(|j| std::array::from_fn(|p| colset.contains(&(PARAMS_PER_LINK * (j - 1) + p))))
            .collect(),
    };
    let joint = |j: usize| desc.frame(j).joint;
    let path = |j: usize| path_from_base(&st.ant, j);
    // r1 of the branch through j, and whether an r2 occurs on the path up to j
    let r1_of = |j: usize| {
        path(j)
            .into_iter()
            .find(|&k| joint(k) == JointType::Revolute)
    };
    let has_r2 = |j: usize| -> bool {
        match r1_of(j) {
            None => false,
            Some(r1) => path(j)
                .into_iter()
                .any(|k| k > r1 && joint(k) == JointType::Revolute && !geo.parallel(k, r1)),
        }
    };
    let between = |j: usize| r1_of(j).is_some() && !has_r2(j);

    // rotor inertias (§9.4.2.5)
    for j in 1..=nl {
        if !s.alive[j - 1][IA] {
            continue;
        }
        let before: Vec<usize> = path(j).into_iter().filter(|&k| k != j).collect();
        let group = match joint(j) {
            JointType::Revolute => before
                .iter()
                .filter(|&&k| joint(k) == JointType::Revolute)
                .all(|&k| geo.perpendicular(k, j)),
            JointType::Prismatic => {
                before.iter().all(|&k| match joint(k) {
                    JointType::Revolute => geo.parallel(k, j),
                    JointType::Prismatic => geo.perpendicular(k, j),
                    JointType::Fixed => true,
                }) && geo.perpendicular_to_gravity(j)
            }
            JointType::Fixed => false,
        };
        if group {
            let e = s.get(j, IA);
            s.kill(j, IA);
            if joint(j) == JointType::Revolute {
                s.add(j, ZZ, e);
            } else {
                // the mass column of j is qdd_j in row j plus that of a point mass fixed on a(j)
                // at q_j = 0: MR_j = M_j + IA_j and a point mass -IA_j on a(j)
                s.add(j, M, e.clone());
                let (a, p) = frame_expr(desc, j);
                let z = Matrix3::from_element(Expr::zero());
                let zv = Vector3::from_element(Expr::zero());
                s.add_all(st.ant[j], transfer(&a, &p, &z, &zv, &-e));
            }
        }
    }

    // parallelogram loops
    let mut parallelograms = Vec::new();
    let mut unhandled_loops = Vec::new();
    for l in &st.loops {
        match detect_parallelogram(desc, &st, &geo, l) {
            Some(p) => parallelograms.push((p, l.clone())),
            None => unhandled_loops.push(l.cut),
        }
    }

    // inner joints of a parallelogram: w_b = w_c and w_e = w_a give qd_e = -qd_b, so the drive
    // parameters (energy 1/2 IA qd^2, friction through G^T) of the higher joint group into the
    // lower one's (derived from 10.54)
    for (p, _) in &parallelograms {
        let (lo, hi) = p.inner;
        for q in [IA, IA + 1, IA + 2] {
            if s.alive[hi - 1][q] && s.alive[lo - 1][q] {
                let e = s.get(hi, q);
                s.kill(hi, q);
                s.add(lo, q, e);
            }
        }
    }

    for j in (1..=nl).rev() {
        let i = st.ant[j];
        let mut tensor_moved = false;
        for (p, l) in &parallelograms {
            // rule 1, eq 10.51c: h_i lambda_k^10 = h_j lambda_{k+B}^10
            let (li, lj) = (l.link_i, l.link_j);
            if j == li.max(lj) {
                let lam10 = |frame: usize| -> [Expr; 10] {
                    let (_, pp) = frame_expr(desc, frame);
                    let (x, y, z) = (pp.x.clone(), pp.y.clone(), pp.z.clone());
                    [
                        y.clone() * y.clone() + z.clone() * z.clone(),
                        -(x.clone() * y.clone()),
                        -(x.clone() * z.clone()),
                        x.clone() * x.clone() + z.clone() * z.clone(),
                        -(y.clone() * z.clone()),
                        x.clone() * x.clone() + y.clone() * y.clone(),
                        x,
                        y,
                        z,
                        Expr::one(),
                    ]
                };
                let ci = lam10(l.cut);
                let cj = lam10(l.twin);
                // relation sum_p ci_p h_{li,p} - sum_p cj_p h_{lj,p} = 0
                let (own, own_c, other, other_c) = if j == li {
                    (li, ci, lj, cj)
                } else {
                    (lj, cj, li, ci)
                };
                if let Some(pstar) = [MX, MY]
                    .into_iter()
                    .find(|&q| !own_c[q].is_zero() && s.alive[own - 1][q])
                {
                    let kstar = s.get(own, pstar);
                    let cstar = own_c[pstar].clone();
                    s.kill(own, pstar);
                    for q in 0..10 {
                        if q != pstar && !own_c[q].is_zero() {
                            let e = -(own_c[q].clone() / cstar.clone()) * kstar.clone();
                            s.add(own, q, e);
                        }
                        if !other_c[q].is_zero() {
                            let e = (other_c[q].clone() / cstar.clone()) * kstar.clone();
                            s.add(other, q, e);
                        }
                    }
                }
            }
            // eqs 10.55-10.56: J_high into J_low
            for (lo, hi, a) in &p.pairs {
                if *hi == j {
                    let jm = s.j_matrix(j);
                    let t = a * jm * a.transpose();
                    for q in 0..6 {
                        s.kill(j, q);
                    }
                    s.add_tensor(*lo, &t);
                    tensor_moved = true;
                }
            }
        }
        let (a, p) = frame_expr(desc, j);
        let zero3 = || Vector3::from_element(Expr::zero());
        match joint(j) {
            JointType::Revolute => {
                // Theorem 10.1
                let yy = if tensor_moved {
                    Expr::zero()
                } else {
                    s.get(j, YY)
                };
                let (mz, m) = (s.get(j, MZ), s.get(j, M));
                if !tensor_moved {
                    s.add(j, XX, -yy.clone());
                    s.kill(j, YY);
                }
                s.kill(j, MZ);
                s.kill(j, M);
                let jj = Matrix3::from_diagonal(&Vector3::new(yy.clone(), yy, Expr::zero()));
                let ms = Vector3::new(Expr::zero(), Expr::zero(), mz);
                s.add_all(i, transfer(&a, &p, &jj, &ms, &m));
            }
            JointType::Prismatic => {
                // Theorem 10.2 (10.20b)
                if !tensor_moved {
                    let jm = s.j_matrix(j);
                    for q in 0..6 {
                        s.kill(j, q);
                    }
                    s.add_tensor(i, &(&a * jm * a.transpose()));
                }
                if r1_of(j).is_none() {
                    // rule 7
                    for q in [MX, MY, MZ] {
                        s.kill(j, q);
                    }
                } else if between(j) {
                    let r1 = r1_of(j).unwrap();
                    if geo.parallel(j, r1) {
                        // rule 3 (10.23): MZ_j eliminated, MX_j MY_j grouped into a(j)
                        let ms = Vector3::new(s.get(j, MX), s.get(j, MY), Expr::zero());
                        for q in [MX, MY, MZ] {
                            s.kill(j, q);
                        }
                        let t = transfer(
                            &a,
                            &p,
                            &Matrix3::from_element(Expr::zero()),
                            &ms,
                            &Expr::zero(),
                        );
                        s.add_all(i, t);
                    } else {
                        // rule 4, Table 10.1: relation jA_r1 z . h_MS = const
                        let mut rot = Matrix3::<Expr>::identity();
                        for k in path(j).into_iter().filter(|&k| k > r1) {
                            let (ak, _) = frame_expr(desc, k);
                            rot *= ak;
                        }
                        // z_r1 in R_j = (r1 A_j)^T e3
                        let u: Vec<Expr> = (0..3).map(|c| rot[(2, c)].clone()).collect();
                        let un: Vec<f64> = {
                            let (ra, _) = &geo.poses[0][j];
                            let (rr, _) = &geo.poses[0][r1];
                            let v = ra.transpose() * rr.column(2);
                            vec![v.x, v.y, v.z]
                        };
                        if let Some(e) = [2usize, 1, 0]
                            .into_iter()
                            .find(|&c| un[c].abs() > GEOMETRY_TOLERANCE)
                        {
                            let ke = s.get(j, MX + e);
                            s.kill(j, MX + e);
                            for c in 0..3 {
                                if c != e && un[c].abs() > GEOMETRY_TOLERANCE {
                                    s.add(j, MX + c, -(u[c].clone() / u[e].clone()) * ke.clone());
                                }
                            }
                        }
                    }
                }
            }
            JointType::Fixed => {
                let jm = s.j_matrix(j);
                let ms = Vector3::new(s.get(j, MX), s.get(j, MY), s.get(j, MZ));
                let m = s.get(j, M);
                for q in 0..10 {
                    s.kill(j, q);
                }
                let _ = zero3;
                s.add_all(i, transfer(&a, &p, &jm, &ms, &m));
            }
        }
        if joint(j) == JointType::Revolute && between(j) {
            // rule 5
            for q in [XX, XY, XZ, YZ] {
                s.kill(j, q);
            }
            // rule 6
            let r1 = r1_of(j).unwrap();
            // "a_j along a_r1": the same line, not only parallel
            let coaxial = (0..geo.configs.len()).all(|c| {
                let z = geo.z(c, r1);
                let dp = geo.poses[c][j].1 - geo.poses[c][r1].1;
                geo.parallel(j, r1) && dp.cross(&z).norm() < GEOMETRY_TOLERANCE
            });
            let all_vertical = coaxial
                && path(j)
                    .into_iter()
                    .filter(|&k| joint(k) != JointType::Fixed)
                    .all(|k| {
                        geo.parallel(k, r1) && (geo.g.norm() == 0.0 || geo.parallel_to_gravity(k))
                    });
            if all_vertical {
                s.kill(j, MX);
                s.kill(j, MY);
            }
        }
    }

    let mut base = Vec::new();
    let mut equations = Vec::new();
    let mut used = BTreeSet::new();
    for j in 1..=nl {
        for p in 0..PARAMS_PER_LINK {
            if s.alive[j - 1][p] {
                let e = s.get(j, p).expand();
                for name in e.symbols() {
                    if let Some(k) = standard_index(&name, nl) {
                        used.insert(k);
                    }
                }
                base.push(PARAMS_PER_LINK * (j - 1) + p);
                equations.push(e);
            }
        }
    }
    let baseset: BTreeSet<usize> = base.iter().copied().collect();
    let grouped = columns
        .iter()
        .copied()
        .filter(|c| !baseset.contains(c) && used.contains(c))
        .collect();
    let no_effect = columns
        .iter()
        .copied()
        .filter(|c| !baseset.contains(c) && !used.contains(c))
        .collect();
    Ok(SymbolicBase {
        columns,
        base,
        equations,
        grouped,
        no_effect,
        unhandled_loops,
        parallelograms: parallelograms.iter().map(|(p, _)| p.cut).collect(),
    })
}

/// Collect an expanded grouping equation by standard parameter and then by coefficient, for
/// display: `d3^2*(M3 + M4 + M5 + M6)`. `nl` tells which symbols are standard parameters.
pub fn collect_by_coefficient(e: &Expr, nl: usize) -> String {
    let e = e.expand();
    let terms: Vec<Expr> = match e.node() {
        Node::Add(v) => v.clone(),
        _ => vec![e.clone()],
    };
    // per parameter: sum of geometric coefficients
    let mut per_param: BTreeMap<usize, Expr> = BTreeMap::new();
    let mut rest = Vec::new();
    for t in terms {
        let factors: Vec<Expr> = match t.node() {
            Node::Mul(v) => v.clone(),
            _ => vec![t.clone()],
        };
        let mut param = None;
        let mut coef = Vec::new();
        for f in factors {
            match f.as_symbol().and_then(|n| standard_index(n, nl)) {
                Some(k) if param.is_none() => param = Some(k),
                _ => coef.push(f),
            }
        }
        match param {
            Some(k) => {
                let c = Expr::product(coef);
                let cur = per_param.remove(&k).unwrap_or_else(Expr::zero);
                per_param.insert(k, cur + c);
            }
            None => rest.push(t),
        }
    }
    // group parameters by identical coefficient, in K order of first appearance
    let mut groups: Vec<(Expr, Vec<usize>)> = Vec::new();
    for (k, c) in per_param {
        if c.is_zero() {
            continue;
        }
        if let Some(g) = groups.iter_mut().find(|(gc, _)| *gc == c) {
            g.1.push(k);
        } else {
            groups.push((c, vec![k]));
        }
    }
    let name = |k: usize| {
        format!(
            "{}{}",
            STANDARD_PARAMETERS[k % PARAMS_PER_LINK],
            k / PARAMS_PER_LINK + 1
        )
    };
    let mut out = String::new();
    for (c, ks) in &groups {
        let (neg, mag) = match c.as_f64() {
            Some(v) if v < 0.0 => (true, -c.clone()),
            _ => match c.node() {
                Node::Mul(f) if f[0].as_f64().is_some_and(|v| v < 0.0) => (true, -c.clone()),
                _ => (false, c.clone()),
            },
        };
        let body = if ks.len() == 1 {
            name(ks[0])
        } else {
            format!(
                "({})",
                ks.iter().map(|&k| name(k)).collect::<Vec<_>>().join(" + ")
            )
        };
        let term = if mag.is_one() {
            body.trim_start_matches('(')
                .trim_end_matches(')')
                .to_string()
        } else {
            format!("{}*{body}", paren(&mag))
        };
        let term = if mag.is_one() && ks.len() > 1 && neg {
            format!("({term})")
        } else {
            term
        };
        if out.is_empty() {
            out = if neg { format!("-{term}") } else { term };
        } else {
            out.push_str(if neg { " - " } else { " + " });
            out.push_str(&term);
        }
    }
    for t in rest {
        if out.is_empty() {
            out = t.to_string();
        } else {
            out.push_str(&format!(" + {t}"));
        }
    }
    if out.is_empty() {
        "0".into()
    } else {
        out
    }
}

fn paren(e: &Expr) -> String {
    match e.node() {
        Node::Add(_) => format!("({e})"),
        _ => e.to_string(),
    }
}
