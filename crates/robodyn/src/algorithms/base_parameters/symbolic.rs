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

use super::super::regressor::{ParameterSelection, BASE_LINK_PARAMETERS, PARAMS_PER_LINK};
use super::names::ParameterNames;
use crate::model::param::{IA, M, MX, MY, MZ, XX, XY, XZ, YY, YZ, ZZ};

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
    /// Terms dropped as rounding noise of the file's floats ([`FLOAT_TERM_TOLERANCE`]).
    pub dropped_float_terms: usize,
    /// The robot's length scale L (m) the float terms were measured against: the largest
    /// |b|, |d|, |r| of its frames (1 when every length is 0). See [`FLOAT_TERM_TOLERANCE`].
    pub length_scale: f64,
}

/// Relative tolerance below which a grouping term with a float coefficient is rounding noise.
///
/// Which scale: a term `c*P` in the equation of a base parameter `T` has a coefficient with the
/// unit m^(n_T - n_P), n the length power of a parameter's unit (kg m^2 for XX..ZZ and a
/// revolute IA: 2; kg m for MX, MY, MZ: 1; kg for M and a prismatic IA: 0; friction: 0). The
/// term is noise when its float coefficient (times the values of the geometric symbols it
/// carries) satisfies |c| < tol * L^(n_T - n_P), L the robot's largest length
/// ([`SymbolicBase::length_scale`]). The test is unit-free: the same robot in mm drops the same
/// terms.
///
/// Why 1e-12 (first principles): every coefficient is a polynomial in the rotation entries
/// (cos, sin of the file's angles, |entry| <= 1) and in lengths (|length| <= L), of degree
/// n_T - n_P in the lengths; divided by L^(n_T - n_P) it is a sum of products of numbers of
/// magnitude <= 1. An angle read as a float carries a relative error u = 2^-53 = 1.1e-16, so
/// an entry that is exactly 0 (cos(pi/2)) comes out as ~6e-17 and every entry carries an
/// absolute error of a few u; one transfer of a parameter to the antecedent (R J R^T, P P^T:
/// sums of at most 9 products of two entries) adds ~20 u, and a parameter grouped across k
/// links has gone through k transfers. A coefficient that is exactly 0 therefore comes out
/// below ~20 k u * (number of grouped parameters summed, <= 13 per link) ~ 1e-13 for the
/// chains of real robots (k <= 30): 1e-12 = 9000 u leaves an order of magnitude of margin,
/// while a real coefficient is a length ratio or an angle the file gives to far fewer
/// digits (1e-12 of a 1 m robot is a picometre). Not noise, and kept: a file's own rounding
/// of an angle, e.g. the UR URDFs' `1.57079632679` for pi/2 (cos = 4.9e-12): that is the
/// geometry the file describes. Exact coefficients (rationals, symbols, `pi/2`) are never
/// dropped: the tolerance applies to float coefficients only.
pub const FLOAT_TERM_TOLERANCE: f64 = 1e-12;

/// Length power n of a parameter's unit (kg m^n): XX..ZZ 2, MX..MZ 1, M 0; IA 2 on a revolute
/// joint, 0 on a prismatic one; FS, FV 0 (never grouped with the inertial ones).
fn length_power(p: usize, joint: JointType) -> i32 {
    match p {
        XX..=ZZ => 2,
        MX..=MZ => 1,
        IA if joint == JointType::Revolute => 2,
        _ => 0,
    }
}

/// The robot's length scale: largest |b|, |d|, |r| of its frames (symbols at their values or
/// generic values), 1 when every length is 0.
fn length_scale(desc: &RobotDescription) -> f64 {
    let env = |s: &str| Some(symbol_value(desc, s));
    let l = desc
        .frames
        .iter()
        .flat_map(|f| [&f.b, &f.d, &f.r])
        .filter_map(|e| e.eval(&env).ok())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    if l > 0.0 {
        l
    } else {
        1.0
    }
}

/// The value of a geometric symbol for the numeric decisions: the file's, else a generic one.
fn symbol_value(desc: &RobotDescription, s: &str) -> f64 {
    desc.symbols
        .get(s)
        .copied()
        .unwrap_or_else(|| generic_value(s))
}

/// `e` (expanded, the equation of base parameter `target`) without its float-noise terms (see
/// [`FLOAT_TERM_TOLERANCE`] for the scale), and how many were dropped.
fn drop_float_noise(e: Expr, target: usize, desc: &RobotDescription, scale: f64) -> (Expr, usize) {
    let terms: Vec<Expr> = match e.node() {
        Node::Add(v) => v.clone(),
        _ => return (e, 0),
    };
    let nl = desc.nl;
    let power = |k: usize| {
        let j = k / PARAMS_PER_LINK + 1;
        // a floating base's link 0 (K indices 13 NL..) has no drive parameter
        let joint = if j > nl {
            JointType::Fixed
        } else {
            desc.frame(j).joint
        };
        length_power(k % PARAMS_PER_LINK, joint)
    };
    let n_target = power(target);
    let env = |s: &str| Some(symbol_value(desc, s));
    // noise: a float leading coefficient, one parameter, |coefficient| < tol L^(n_T - n_P)
    let is_noise = |t: &Expr| -> bool {
        let Node::Mul(f) = t.node() else {
            return false;
        };
        if !matches!(f[0].node(), Node::Float(_)) {
            return false;
        }
        let params: Vec<usize> = f[1..]
            .iter()
            .filter_map(|x| x.as_symbol().and_then(|s| standard_index(s, nl)))
            .collect();
        let [param] = params[..] else {
            return false;
        };
        let geometric = Expr::product(
            f.iter()
                .filter(|x| x.as_symbol().and_then(|s| standard_index(s, nl)).is_none())
                .cloned(),
        );
        match geometric.eval(&env) {
            Ok(c) => c.abs() < FLOAT_TERM_TOLERANCE * scale.powi(n_target - power(param)),
            Err(_) => false,
        }
    };
    let keep: Vec<Expr> = terms.iter().filter(|t| !is_noise(t)).cloned().collect();
    let dropped = terms.len() - keep.len();
    if dropped == 0 {
        (e, 0)
    } else {
        (Expr::sum(keep), dropped)
    }
}

impl SymbolicBase {
    /// Number of base parameters.
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

/// Index in K of a standard parameter symbol such as `XX2`, `IA1`; a floating base's `XX0` ..
/// `M0` after the links' (13 NL + p).
pub fn standard_index(name: &str, nl: usize) -> Option<usize> {
    let split = name.find(|c: char| c.is_ascii_digit())?;
    let (p, j) = name.split_at(split);
    let pi = STANDARD_PARAMETERS.iter().position(|&x| x == p)?;
    if j == "0" {
        return (pi < BASE_LINK_PARAMETERS).then_some(PARAMS_PER_LINK * nl + pi);
    }
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

/// The generic value given to a symbol without value: deterministic from its name, in
/// [0.3, 1.67], never 0 and never a multiple of pi/2 (so it is never taken to be special).
pub fn generic_value(name: &str) -> f64 {
    // deterministic "generic" value from the name: never 0, never a multiple of pi/2
    let h = name.bytes().fold(1469598103934665603u64, |h, b| {
        (h ^ b as u64).wrapping_mul(1099511628211)
    });
    0.3 + (h % 1000) as f64 * 1.37e-3
}

impl Geo {
    fn new(desc: &RobotDescription, ant: &[usize]) -> Result<Geo> {
        let env = |s: &str| Some(symbol_value(desc, s));
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
        let mut rng = crate::sampling::rng(0x5eed);
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
    /// A floating base's link 0 (its 10 inertial parameters, every one a base parameter):
    /// what is grouped into link 0 lands here; None for a fixed base (no effect there).
    base: Option<[Expr; BASE_LINK_PARAMETERS]>,
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
        if e.is_zero() {
            return;
        }
        if j == 0 {
            // grouped into a floating base's link 0; into a fixed base: no effect
            if let Some(b) = self.base.as_mut() {
                let cur = b[p].clone();
                b[p] = cur + e;
            }
            return;
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

/// Position of frame `f` in the link carrying it: a(f)P_f, composed down a chain of twin frames
/// (OpenSYMORO's TwoLoops: frame 12 fixed on frame 11, fixed on link 8).
fn position_on_link(desc: &RobotDescription, f: usize) -> Vector3<Expr> {
    let (_, mut p) = frame_expr(desc, f);
    let mut a = desc.frame(f).ant;
    while a > desc.nl {
        let (ra, pa) = frame_expr(desc, a);
        p = pa + ra * p;
        a = desc.frame(a).ant;
    }
    p
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

/// A detected parallelogram loop (§10.3.5): pairs (low, high, lowA_high) of parallel links
/// (eq 10.54: equal angular velocities), the joints of the loop whose velocities are equal or
/// opposite, and the cut joint.
#[derive(Clone, Debug)]
pub struct Parallelogram {
    /// Cut joint k of the loop.
    pub cut: usize,
    /// Couples of tree joints of the loop whose velocities are +-qd of each other (their drive
    /// parameters group into the lowest one's).
    pub coupled: Vec<(usize, usize)>,
    /// (low, high, lowA_high): link `high` keeps the orientation lowA_high with respect to link
    /// `low` (0 = the base).
    pub pairs: Vec<(usize, usize, Matrix3<Expr>)>,
}

/// Parallelogram loops of `desc` (symbols without value take generic values), by cut joint.
pub fn parallelograms(desc: &RobotDescription) -> Result<Vec<Parallelogram>> {
    let st = validate_structure(desc)?;
    let geo = Geo::new(desc, &st.ant)?;
    Ok(st
        .loops
        .iter()
        .filter_map(|l| detect_parallelogram(desc, &geo, l))
        .collect())
}

/// Planar side vector of a link: O_x -> O_next in the frame of the link (x, y components).
fn planar(p: &Vector3<f64>) -> nalgebra::Vector2<f64> {
    nalgebra::Vector2::new(p.x, p.y)
}

/// Position of the origin of frame `x` in the frame of its antecedent.
fn offset(geo: &Geo, x: usize) -> Vector3<f64> {
    geo.frames[x - 1].transform(&0.0).1
}

/// Position of frame `x` in the link carrying it: [`offset`], composed down a chain of twin
/// frames (OpenSYMORO's TwoLoops: frame 12 fixed on frame 11, fixed on link 8).
fn offset_on_link(geo: &Geo, nl: usize, x: usize) -> Vector3<f64> {
    let mut p = offset(geo, x);
    let mut a = geo.frames[x - 1].ant;
    while a > nl {
        let (r, t) = geo.frames[a - 1].transform(&0.0);
        p = t + r * p;
        a = geo.frames[a - 1].ant;
    }
    p
}

/// Detect a parallelogram loop from the geometry (§10.3.5, Figure 10.2). Every joint of the
/// loop (tree joints and the cut joint) is revolute, with its axis parallel to the others in
/// the same direction. The loop is read as a polygon in the plane of the axes: each link of the
/// loop carries one side, from its joint O_x to the next joint of its branch (or to the cut
/// joint and its twin, which coincide), and the root link r carries the side between the first
/// joints of the two branches (read in the frame of the first joint of the cut's branch at
/// q = 0, a frame fixed on r whose z is the axis). Sides of zero length (two joints on one
/// point: SR400's O_2 = O_7, the older TwoLoops' O_3 = O_8) are dropped. The loop is a
/// parallelogram when four sides remain, opposite ones of equal length: the links carrying
/// opposite sides then keep their relative orientation (eq 10.54, w_x = w_y). With psi_x the
/// angle of link x about the axis and phi'_x the angle of its side in its frame (plus pi when
/// the polygon runs the side backwards, on the twin's branch), opposite sides satisfy
/// psi_x + phi'_x = psi_y + phi'_y + pi, so xA_y = Rz(phi'_x - phi'_y - pi) (derived).
fn detect_parallelogram(
    desc: &RobotDescription,
    geo: &Geo,
    l: &crate::model::ClosedLoop,
) -> Option<Parallelogram> {
    let (k, tw) = (l.cut, l.twin);
    let revolute = |x: usize| desc.frame(x).joint == JointType::Revolute;
    let joints: Vec<usize> = l.tree_joints().chain([k]).collect();
    if !joints.iter().all(|&x| revolute(x)) {
        return None;
    }
    let (&first_i, &first_j) = (l.branch_i.first()?, l.branch_j.first()?);
    let same_axis = |x: usize| {
        (0..geo.configs.len())
            .all(|c| (geo.z(c, x) - geo.z(c, first_i)).norm() < GEOMETRY_TOLERANCE)
    };
    if !joints.iter().chain([&tw]).all(|&x| same_axis(x)) {
        return None;
    }
    // sides: (link, planar vector in the link's frame, run backwards)
    let mut sides: Vec<(usize, Vector3<f64>, bool)> = Vec::new();
    // root side O_first_j -> O_first_i, in the frame of joint first_i at q = 0
    let a0 = geo.frames[first_i - 1].transform(&0.0).0;
    sides.push((
        l.root,
        a0.transpose() * (offset(geo, first_i) - offset(geo, first_j)),
        false,
    ));
    let next = |branch: &[usize], n: usize, end: usize| branch.get(n + 1).copied().unwrap_or(end);
    for (n, &x) in l.branch_i.iter().enumerate() {
        sides.push((x, offset(geo, next(&l.branch_i, n, k)), false));
    }
    for (n, &x) in l.branch_j.iter().enumerate().rev() {
        sides.push((
            x,
            offset_on_link(geo, desc.nl, next(&l.branch_j, n, tw)),
            true,
        ));
    }
    sides.retain(|(_, v, _)| planar(v).norm() > GEOMETRY_TOLERANCE);
    if sides.len() != 4 {
        return None;
    }
    let len = |n: usize| planar(&sides[n].1).norm();
    if (len(0) - len(2)).abs() > GEOMETRY_TOLERANCE || (len(1) - len(3)).abs() > GEOMETRY_TOLERANCE
    {
        return None;
    }
    let angle = |n: usize| {
        let v = planar(&sides[n].1);
        v.y.atan2(v.x)
            + if sides[n].2 {
                std::f64::consts::PI
            } else {
                0.0
            }
    };
    let pair = |m: usize, n: usize| {
        let (x, y) = (sides[m].0, sides[n].0);
        let (lo, hi, d) = if x < y {
            (x, y, angle(m) - angle(n) - std::f64::consts::PI)
        } else {
            (y, x, angle(n) - angle(m) - std::f64::consts::PI)
        };
        // the root side is read in the frame of joint first_i at q = 0: rA_hi = rA_first_i(0) Rz
        let rot = rz(&exact_angle(d));
        let a = if x == l.root || y == l.root {
            frame_expr(desc, first_i).0 * rot
        } else {
            rot
        };
        (lo, hi, a)
    };
    let pairs = vec![pair(0, 2), pair(1, 3)];
    Some(Parallelogram {
        cut: k,
        coupled: coupled_joints(l, &pairs),
        pairs,
    })
}

/// Tree joints of a loop whose velocities are +-qd of each other: the pairs give w_y - w_x =
/// sum of qd_j on the path root -> y minus those on root -> x (every joint of the loop turns
/// about the same axis; the joints before the root cancel). A joint couple (u, v) is coupled
/// when qd_u + s qd_v (s = +-1) is a combination of these relations.
fn coupled_joints(
    l: &crate::model::ClosedLoop,
    pairs: &[(usize, usize, Matrix3<Expr>)],
) -> Vec<(usize, usize)> {
    let joints: Vec<usize> = l.tree_joints().collect();
    let n = joints.len();
    let path = |x: usize| -> Vec<usize> {
        for b in [&l.branch_i, &l.branch_j] {
            if let Some(p) = b.iter().position(|&y| y == x) {
                return b[..=p].to_vec();
            }
        }
        Vec::new() // the root
    };
    let rel: Vec<nalgebra::DVector<f64>> = pairs
        .iter()
        .map(|(x, y, _)| {
            let mut v = nalgebra::DVector::zeros(n);
            for j in path(*y) {
                v[joints.iter().position(|&q| q == j).unwrap()] += 1.0;
            }
            for j in path(*x) {
                v[joints.iter().position(|&q| q == j).unwrap()] -= 1.0;
            }
            v
        })
        .collect();
    let m = nalgebra::DMatrix::from_columns(&rel);
    let in_span = |t: &nalgebra::DVector<f64>| {
        let svd = m.clone().svd(true, true);
        svd.solve(t, 1e-9)
            .map(|c| (&m * c - t).norm() < 1e-9)
            .unwrap_or(false)
    };
    let mut out = Vec::new();
    for u in 0..n {
        for v in u + 1..n {
            if [1.0, -1.0].into_iter().any(|s| {
                let mut t = nalgebra::DVector::zeros(n);
                t[u] = 1.0;
                t[v] = s;
                in_span(&t)
            }) {
                out.push((joints[u].min(joints[v]), joints[u].max(joints[v])));
            }
        }
    }
    out
}

/// Classes of links with equal angular velocities over every parallelogram (eq 10.54 is
/// transitive: the older TwoLoops has w_4 = w_8 in one loop and w_8 = w_1 in the other): for
/// each link, the lowest link of its class and loA_link (composed along the pairs), None for
/// the lowest itself. Eqs 10.55–10.56 then move J_link into J_lowest.
fn parallel_classes(ps: &[Parallelogram], nl: usize) -> Vec<Option<(usize, Matrix3<Expr>)>> {
    let mut adj: Vec<Vec<(usize, Matrix3<Expr>)>> = vec![Vec::new(); nl + 1];
    for p in ps {
        for (lo, hi, a) in &p.pairs {
            adj[*lo].push((*hi, a.clone()));
            adj[*hi].push((*lo, a.transpose()));
        }
    }
    let mut out: Vec<Option<(usize, Matrix3<Expr>)>> = vec![None; nl + 1];
    let mut seen = vec![false; nl + 1];
    for lo in 0..=nl {
        if seen[lo] || adj[lo].is_empty() {
            continue;
        }
        seen[lo] = true;
        let mut queue = std::collections::VecDeque::from([(lo, Matrix3::<Expr>::identity())]);
        while let Some((x, ax)) = queue.pop_front() {
            for (y, a) in adj[x].clone() {
                if !seen[y] {
                    seen[y] = true;
                    let ay = (&ax * a).map(|e| e.expand());
                    out[y] = Some((lo, ay.clone()));
                    queue.push_back((y, ay));
                }
            }
        }
    }
    out
}

/// Classes of coupled joints over every parallelogram (union of the couples).
fn coupled_classes(ps: &[Parallelogram]) -> Vec<Vec<usize>> {
    let mut classes: Vec<BTreeSet<usize>> = Vec::new();
    for p in ps {
        for &(u, v) in &p.coupled {
            let hits: Vec<usize> = (0..classes.len())
                .filter(|&c| classes[c].contains(&u) || classes[c].contains(&v))
                .collect();
            let mut merged: BTreeSet<usize> = [u, v].into_iter().collect();
            for &c in hits.iter().rev() {
                merged.extend(classes.remove(c));
            }
            classes.push(merged);
        }
    }
    classes
        .into_iter()
        .map(|c| c.into_iter().collect())
        .collect()
}

/// What the rules need to know about the robot: its topology, numeric geometry and, per link,
/// the joint r1 of its branch and whether it lies between r1 and r2.
struct Context<'a> {
    desc: &'a RobotDescription,
    st: Structure,
    geo: Geo,
    /// r1 of the branch through j (first revolute joint from the base), per link.
    r1: Vec<Option<usize>>,
    /// r1 <= j < r2: no revolute joint not parallel to r1 on the path up to j.
    between: Vec<bool>,
}

impl<'a> Context<'a> {
    fn new(desc: &'a RobotDescription) -> Result<Context<'a>> {
        let st = validate_structure(desc)?;
        let geo = Geo::new(desc, &st.ant)?;
        let nl = desc.nl;
        let mut r1 = vec![None; nl + 1];
        let mut between = vec![false; nl + 1];
        for j in 1..=nl {
            let path = path_from_base(&st.ant, j);
            r1[j] = path
                .iter()
                .copied()
                .find(|&k| desc.frame(k).joint == JointType::Revolute);
            between[j] = r1[j].is_some_and(|r| {
                !path.iter().any(|&k| {
                    k > r && desc.frame(k).joint == JointType::Revolute && !geo.parallel(k, r)
                })
            });
        }
        Ok(Context {
            desc,
            st,
            geo,
            r1,
            between,
        })
    }

    fn joint(&self, j: usize) -> JointType {
        self.desc.frame(j).joint
    }

    fn path(&self, j: usize) -> Vec<usize> {
        path_from_base(&self.st.ant, j)
    }
}

/// Run the symbolic method on a description (symbols may lack values). Parameters outside
/// `sel` (drive parameters not selected) are not parameters; absent ones (`sel.absent`, a
/// literal 0 in a SYMORO file) start at 0 but can still receive grouped parameters (as in
/// SYMORO: MXR2 = d3*M3 when MX2 is written 0).
pub fn symbolic_base_parameters(
    desc: &RobotDescription,
    sel: &ParameterSelection,
) -> Result<SymbolicBase> {
    let nl = desc.nl;
    let floating = desc.floating_base.is_some();
    if floating && desc.nj != nl {
        return Err(Error::Input(format!(
            "{}: the symbolic base parameters of a floating robot with closed loops are not \
             supported yet",
            desc.name
        )));
    }
    if sel.rotor.len() != nl || sel.friction.len() != nl {
        return Err(Error::Input(format!(
            "the parameter selection has {} entries, the robot has NL = {nl} links",
            sel.rotor.len()
        )));
    }
    check_geometry_names(desc)?;
    let ctx = Context::new(desc)?;
    let mut s = State::new(nl, sel, floating);
    if floating {
        floating_rules(&ctx, &mut s);
        return Ok(s.finish(desc, sel, Vec::new(), &[]));
    }
    rotor_inertias(&ctx, &mut s);
    let mut parallelograms = Vec::new();
    let mut unhandled_loops = Vec::new();
    for l in &ctx.st.loops {
        match detect_parallelogram(desc, &ctx.geo, l) {
            Some(p) => parallelograms.push((p, l.clone())),
            None => unhandled_loops.push(l.cut),
        }
    }
    let ps: Vec<Parallelogram> = parallelograms.iter().map(|(p, _)| p.clone()).collect();
    for class in coupled_classes(&ps) {
        parallelogram_drive_parameters(&class, &mut s);
    }
    let classes = parallel_classes(&ps, nl);
    for j in (1..=nl).rev() {
        for (_, l) in &parallelograms {
            cut_joint_relation(desc, l, j, &mut s);
        }
        let tensor_moved = parallel_links(&classes, j, &mut s);
        match ctx.joint(j) {
            JointType::Revolute => theorem_10_1(&ctx, j, tensor_moved, &mut s),
            JointType::Prismatic => {
                if !tensor_moved {
                    theorem_10_2(&ctx, j, &mut s);
                }
                prismatic_first_moments(&ctx, j, &mut s);
            }
            JointType::Fixed => fixed_frame(&ctx, j, &mut s),
        }
        if ctx.joint(j) == JointType::Revolute && ctx.between[j] {
            rules_5_6(&ctx, j, &mut s);
        }
    }
    Ok(s.finish(desc, sel, unhandled_loops, &parallelograms))
}

/// The rules of a floating base (a tree): link 0 moves freely (6 degrees of freedom), so every
/// link follows the general rules of the links beyond r2 and none of the special rules of the
/// links next to a fixed base apply (rules 3–7, the rotor inertias grouped into ZZ_j or M_j:
/// w_j . z_j = qd_j never holds identically, the base rotates). For j = n..1: Theorem 10.1
/// (revolute: YY_j into XX_j, YY_j MZ_j M_j into a(j)), Theorem 10.2 (prismatic: J_j into
/// J_a(j)), a fixed frame's ten parameters into a(j); what reaches a(j) = 0 lands on link 0's
/// ten parameters, which are all base parameters.
fn floating_rules(ctx: &Context, s: &mut State) {
    for j in (1..=ctx.desc.nl).rev() {
        match ctx.joint(j) {
            JointType::Revolute => theorem_10_1(ctx, j, false, s),
            JointType::Prismatic => theorem_10_2(ctx, j, s),
            JointType::Fixed => fixed_frame(ctx, j, s),
        }
    }
}

/// The standard parameter symbols (`XX2`, `M3`...) are the unknowns of the equations: a
/// geometric symbol of the same name would make the equations ambiguous.
fn check_geometry_names(desc: &RobotDescription) -> Result<()> {
    let mut exprs: Vec<&Expr> = Vec::new();
    for f in &desc.frames {
        exprs.extend(f.geometric());
    }
    exprs.extend(desc.gravity.iter().chain(&desc.vp0));
    for e in exprs {
        if let Some(n) = e
            .symbols()
            .into_iter()
            .find(|n| standard_index(n, desc.nl).is_some())
        {
            return Err(Error::Input(format!(
                "the geometric symbol `{n}` has the name of a standard parameter; rename it \
                 (the grouping equations use the standard parameters as unknowns)"
            )));
        }
    }
    Ok(())
}

impl State {
    fn new(nl: usize, sel: &ParameterSelection, floating: bool) -> State {
        let index = |j: usize, p: usize| PARAMS_PER_LINK * (j - 1) + p;
        State {
            kr: (1..=nl)
                .map(|j| {
                    std::array::from_fn(|p| {
                        let i = index(j, p);
                        if sel.slot(i) && !sel.absent.contains(&i) {
                            sym(j, p)
                        } else {
                            Expr::zero()
                        }
                    })
                })
                .collect(),
            alive: (1..=nl)
                .map(|j| std::array::from_fn(|p| sel.slot(index(j, p))))
                .collect(),
            base: floating.then(|| std::array::from_fn(|p| sym(0, p))),
        }
    }

    /// Base parameters: the live parameters whose expression is not zero.
    fn finish(
        self,
        desc: &RobotDescription,
        sel: &ParameterSelection,
        unhandled_loops: Vec<usize>,
        parallelograms: &[(Parallelogram, crate::model::ClosedLoop)],
    ) -> SymbolicBase {
        let nl = self.kr.len();
        let mut columns = sel.columns();
        // a floating base's link 0 after the links (K indices 13 NL..)
        let link0 = self.base.as_ref().map_or(0, |_| BASE_LINK_PARAMETERS);
        columns.extend((0..link0).map(|p| PARAMS_PER_LINK * nl + p));
        let mut base = Vec::new();
        let mut equations = Vec::new();
        let mut used = BTreeSet::new();
        let mut dropped_float_terms = 0;
        let scale = length_scale(desc);
        let params = (1..=nl)
            .flat_map(|j| (0..PARAMS_PER_LINK).map(move |p| (j, p)))
            .chain((0..link0).map(|p| (0, p)));
        for (j, p) in params {
            let target = if j == 0 {
                PARAMS_PER_LINK * nl + p
            } else if self.alive[j - 1][p] {
                PARAMS_PER_LINK * (j - 1) + p
            } else {
                continue;
            };
            let current = match (j, &self.base) {
                (0, Some(b)) => b[p].clone(),
                _ => self.get(j, p),
            };
            let (e, dropped) = drop_float_noise(current.expand(), target, desc, scale);
            dropped_float_terms += dropped;
            if e.is_zero() {
                continue;
            }
            for name in e.symbols() {
                if let Some(k) = standard_index(&name, nl) {
                    used.insert(k);
                }
            }
            base.push(target);
            equations.push(e);
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
        SymbolicBase {
            columns,
            base,
            equations,
            grouped,
            no_effect,
            unhandled_loops,
            parallelograms: parallelograms.iter().map(|(p, _)| p.cut).collect(),
            dropped_float_terms,
            length_scale: scale,
        }
    }
}

/// Rotor inertias (§9.4.2.5, derived): IA_j into ZZ_j when w_j . z_j = qd_j identically (every
/// revolute axis before j perpendicular to z_j); IA_j of a prismatic joint into M_j when every
/// revolute axis before j is parallel to z_j, every prismatic one perpendicular and z_j is
/// perpendicular to gravity: the column of M_j is then qdd_j in row j plus that of a point mass
/// fixed on a(j) at q_j = 0, so MR_j = M_j + IA_j and a point mass -IA_j goes to a(j).
fn rotor_inertias(ctx: &Context, s: &mut State) {
    let geo = &ctx.geo;
    for j in 1..=ctx.desc.nl {
        if !s.alive[j - 1][IA] {
            continue;
        }
        let before: Vec<usize> = ctx.path(j).into_iter().filter(|&k| k != j).collect();
        let group = match ctx.joint(j) {
            JointType::Revolute => before
                .iter()
                .filter(|&&k| ctx.joint(k) == JointType::Revolute)
                .all(|&k| geo.perpendicular(k, j)),
            JointType::Prismatic => {
                before.iter().all(|&k| match ctx.joint(k) {
                    JointType::Revolute => geo.parallel(k, j),
                    JointType::Prismatic => geo.perpendicular(k, j),
                    JointType::Fixed => true,
                }) && geo.perpendicular_to_gravity(j)
            }
            JointType::Fixed => false,
        };
        if !group {
            continue;
        }
        let e = s.get(j, IA);
        s.kill(j, IA);
        if ctx.joint(j) == JointType::Revolute {
            s.add(j, ZZ, e);
        } else {
            s.add(j, M, e.clone());
            let (a, p) = frame_expr(ctx.desc, j);
            let z = Matrix3::from_element(Expr::zero());
            let zv = Vector3::from_element(Expr::zero());
            s.add_all(ctx.st.ant[j], transfer(&a, &p, &z, &zv, &-e));
        }
    }
}

/// Joints of a parallelogram whose velocities are equal or opposite (from 10.54: w_b = w_c and
/// w_e = w_a give qd_e = -qd_b; with a side on the root link, qd_c = qd_a = -qd_b): their drive
/// parameters (energy 1/2 IA qd^2; FV qd and FS sign(qd) through G^T, both even in the sign of
/// the velocity) group into the lowest joint's.
fn parallelogram_drive_parameters(class: &[usize], s: &mut State) {
    for q in [IA, IA + 1, IA + 2] {
        let live: Vec<usize> = class
            .iter()
            .copied()
            .filter(|&j| s.alive[j - 1][q])
            .collect();
        if let Some((&lo, rest)) = live.split_first() {
            for &hi in rest {
                let e = s.get(hi, q);
                s.kill(hi, q);
                s.add(lo, q, e);
            }
        }
    }
}

/// lambda^10 of frame `frame` (eqs 10.15–10.17: the coefficients of the ten inertial
/// parameters of a(frame) in the energy function of link `frame` at q = 0).
fn lambda10(desc: &RobotDescription, frame: usize) -> [Expr; 10] {
    let pp = position_on_link(desc, frame);
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
}

/// Rule 1, eq 10.51c at the higher of the two links holding the cut joint and its twin:
/// h_i lambda_k^10 = h_j lambda_{k+B}^10 eliminates MX (or MY) of that link.
fn cut_joint_relation(
    desc: &RobotDescription,
    l: &crate::model::ClosedLoop,
    j: usize,
    s: &mut State,
) {
    let (li, lj) = (l.link_i, l.link_j);
    if j != li.max(lj) {
        return;
    }
    let (ci, cj) = (lambda10(desc, l.cut), lambda10(desc, l.twin));
    // relation sum_p ci_p h_{li,p} - sum_p cj_p h_{lj,p} = 0
    let (own, own_c, other, other_c) = if j == li {
        (li, ci, lj, cj)
    } else {
        (lj, cj, li, ci)
    };
    let Some(pstar) = [MX, MY]
        .into_iter()
        .find(|&q| !own_c[q].is_zero() && s.alive[own - 1][q])
    else {
        return;
    };
    let kstar = s.get(own, pstar);
    let cstar = own_c[pstar].clone();
    s.kill(own, pstar);
    for q in 0..10 {
        if q != pstar && !own_c[q].is_zero() {
            s.add(own, q, -(own_c[q].clone() / cstar.clone()) * kstar.clone());
        }
        if !other_c[q].is_zero() {
            s.add(
                other,
                q,
                (other_c[q].clone() / cstar.clone()) * kstar.clone(),
            );
        }
    }
}

/// Eqs 10.55–10.56: the inertia tensor of a link whose angular velocity equals that of a
/// lower link (its class in [`parallel_classes`]) into the lower one's, JR_lo = J_lo +
/// loA_j J_j jA_lo (into the base: no effect). Returns whether link j's tensor moved.
fn parallel_links(classes: &[Option<(usize, Matrix3<Expr>)>], j: usize, s: &mut State) -> bool {
    let Some((lo, a)) = &classes[j] else {
        return false;
    };
    let t = a * s.j_matrix(j) * a.transpose();
    for q in 0..6 {
        s.kill(j, q);
    }
    s.add_tensor(*lo, &t);
    true
}

/// Theorem 10.1 (revolute j, eqs 10.14–10.19, any gamma and b): YY_j into XX_j, and YY_j, MZ_j,
/// M_j into link a(j) by the rigid transfer of (diag(YY, YY, 0), (0, 0, MZ), M). When the
/// tensor of j moved to a parallel link (10.55), only MZ_j and M_j move.
fn theorem_10_1(ctx: &Context, j: usize, tensor_moved: bool, s: &mut State) {
    let (a, p) = frame_expr(ctx.desc, j);
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
    s.add_all(ctx.st.ant[j], transfer(&a, &p, &jj, &ms, &m));
}

/// Theorem 10.2 (prismatic j, eq 10.20b): iJR_i = iJ_i + iA_j jJ_j jA_i.
fn theorem_10_2(ctx: &Context, j: usize, s: &mut State) {
    let (a, _) = frame_expr(ctx.desc, j);
    let jm = s.j_matrix(j);
    for q in 0..6 {
        s.kill(j, q);
    }
    s.add_tensor(ctx.st.ant[j], &(&a * jm * a.transpose()));
}

/// Rules 3, 4 and 7 on the first moments of a prismatic link j: before r1 (rule 7) they have
/// no effect; between r1 and r2, parallel to r1 (rule 3, eq 10.23 derived from first
/// principles: with z_j parallel to every rotation axis of a(j) the q_j-dependent terms
/// vanish), MZ_j has no effect and MX_j, MY_j go to a(j) as a rigid first moment at q_j = 0;
/// not parallel (rule 4, Table 10.1), the relation jA_r1 z . MS_j = const removes one of them.
fn prismatic_first_moments(ctx: &Context, j: usize, s: &mut State) {
    let Some(r1) = ctx.r1[j] else {
        for q in [MX, MY, MZ] {
            s.kill(j, q);
        }
        return;
    };
    if !ctx.between[j] {
        return;
    }
    let (a, p) = frame_expr(ctx.desc, j);
    if ctx.geo.parallel(j, r1) {
        let ms = Vector3::new(s.get(j, MX), s.get(j, MY), Expr::zero());
        for q in [MX, MY, MZ] {
            s.kill(j, q);
        }
        let zero = Matrix3::from_element(Expr::zero());
        s.add_all(ctx.st.ant[j], transfer(&a, &p, &zero, &ms, &Expr::zero()));
        return;
    }
    let mut rot = Matrix3::<Expr>::identity();
    for k in ctx.path(j).into_iter().filter(|&k| k > r1) {
        rot *= frame_expr(ctx.desc, k).0;
    }
    // z_r1 in R_j = (r1 A_j)^T e3
    let u: Vec<Expr> = (0..3).map(|c| rot[(2, c)].clone()).collect();
    let un = {
        let (ra, _) = &ctx.geo.poses[0][j];
        let (rr, _) = &ctx.geo.poses[0][r1];
        ra.transpose() * rr.column(2)
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

/// A fixed frame (sigma = 2) moves all ten parameters of its link into a(j) (rigid body).
fn fixed_frame(ctx: &Context, j: usize, s: &mut State) {
    let (a, p) = frame_expr(ctx.desc, j);
    let jm = s.j_matrix(j);
    let ms = Vector3::new(s.get(j, MX), s.get(j, MY), s.get(j, MZ));
    let m = s.get(j, M);
    for q in 0..10 {
        s.kill(j, q);
    }
    s.add_all(ctx.st.ant[j], transfer(&a, &p, &jm, &ms, &m));
}

/// Rules 5 and 6 (revolute j with r1 <= j < r2): XX XY XZ YZ have no effect (rule 5); MX MY
/// too when a_j is on the line of a_r1 (not only parallel: an offset parallel axis keeps them,
/// found by the random-tree cross-check) and every axis before is parallel to gravity (rule 6).
fn rules_5_6(ctx: &Context, j: usize, s: &mut State) {
    for q in [XX, XY, XZ, YZ] {
        s.kill(j, q);
    }
    let geo = &ctx.geo;
    let r1 = ctx.r1[j].expect("between r1 and r2");
    let coaxial = (0..geo.configs.len()).all(|c| {
        let z = geo.z(c, r1);
        let dp = geo.poses[c][j].1 - geo.poses[c][r1].1;
        geo.parallel(j, r1) && dp.cross(&z).norm() < GEOMETRY_TOLERANCE
    });
    let all_vertical = coaxial
        && ctx
            .path(j)
            .into_iter()
            .filter(|&k| ctx.joint(k) != JointType::Fixed)
            .all(|k| geo.parallel(k, r1) && (geo.g.norm() == 0.0 || geo.parallel_to_gravity(k)));
    if all_vertical {
        s.kill(j, MX);
        s.kill(j, MY);
    }
}

/// Collect an expanded grouping equation by standard parameter and then by coefficient, for
/// display: `d3^2*(M3 + M4 + M5 + M6)`. `nl` tells which symbols are standard parameters.
pub fn collect_by_coefficient(e: &Expr, names: &ParameterNames) -> String {
    let nl = names.nl();
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
    let name = |k: usize| names.name(k).to_string();
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
        let t = names.rename(&t);
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
