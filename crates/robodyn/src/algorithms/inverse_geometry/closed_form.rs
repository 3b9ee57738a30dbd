//! Closed-form inverse geometric model by Paul's method (Khalil & Dombre, ch. 7; SYMORO's
//! IGM) for the two classes of 6R chains it solves, detected from the axes of the chain:
//!
//! - [`IgmClass::SphericalWrist`]: axes 2 and 3 parallel, axis 1 not parallel to them, axes 4,
//!   5 and 6 through one point (RX-90, TX40, PUMA): the wrist centre gives theta1 (type 2),
//!   theta3 (type 2 on its distance to axis 2) and theta2 (atan2); the orientation then gives
//!   theta5 (type 2), theta4 and theta6 (atan2).
//! - [`IgmClass::OffsetWrist`]: axes 2, 3 and 4 parallel, axis 1 not parallel to them, axes 5
//!   and 6 through one point W (the UR family): W gives theta1, the direction of axis 6 theta5,
//!   the direction of axis 2 seen from frame 6 theta6, and the planar 2R arm theta3, theta2,
//!   theta4.
//!
//! Each level has at most two roots: up to 8 solutions. The equations are those of the
//! canonical chain T = C0 Rz(theta1) C1 ... Rz(theta6) C6 (`chain.rs`); the page
//! docs/models/inverse_geometry.md derives them.

use super::chain::{wrap_near, Chain};
use super::transform_of;
use crate::error::{Error, Result};
use crate::geometry::Transform;
use crate::model::Robot;
use nalgebra::{Matrix3, Matrix3x2, Matrix4, SMatrix, Vector3};
use std::f64::consts::PI;
use wide::f64x4;

/// Relative tolerance of the class detection (parallel axes, concurrent axes) and of the
/// singularity markers (a root whose equation's discriminant is within it of zero).
pub const CLOSED_FORM_TOLERANCE: f64 = 1e-9;

/// Largest error (rotation entries; lengths relative to the chain's scale) with which the
/// wrist's mirror identity must hold for the second wrist solution to be found as the mirror
/// of the first (`mirror_holds`): the orientation error it brings, well within the 1e-10 the
/// tests ask of every solution.
const MIRROR_TOLERANCE: f64 = 1e-13;

/// The smallest length of the xy part of the vectors of an atan2 step (relative, as
/// [`CLOSED_FORM_TOLERANCE`]) from which the angle is taken from them rather than given its
/// representative value: between it and the singularity's tolerance the step is marked
/// singular but still solved, which keeps the pose error at a few roundings (the angle's error,
/// eps / |xy|, moves the frame by |xy| times it); below it the representative moves the frame
/// by at most 2 |xy|.
const ATAN2_FLOOR: f64 = 1e-14;

/// The largest move of the frame (|n_xy| times theta6's move: relative, as
/// [`CLOSED_FORM_TOLERANCE`]) with which theta6 of the offset wrist near its singularity is
/// moved to bring O4 into the arm's reach ([`ClosedFormIgm::reaching_theta6`]): a thousand
/// roundings, what theta6's own error (eps / |n_xy|) moves it by, far below the 1e-10 the
/// solutions are checked to; a branch needing more is out of reach.
const NEAR_MOVE: f64 = 1e-12;

/// The class of 6R chain the closed form solves, found from its axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IgmClass {
    /// Axes 2 and 3 parallel, axes 4, 5 and 6 concurrent (a spherical wrist).
    SphericalWrist,
    /// Axes 2, 3 and 4 parallel, axes 5 and 6 concurrent (the UR family's offset wrist).
    OffsetWrist,
}

impl IgmClass {
    /// The class's name as the docs use it.
    pub fn name(self) -> &'static str {
        match self {
            IgmClass::SphericalWrist => "6R with a spherical wrist",
            IgmClass::OffsetWrist => "6R with axes 2, 3, 4 parallel (offset wrist)",
        }
    }
}

/// The singular cases a solution lies in (or within [`CLOSED_FORM_TOLERANCE`] of). A joint of
/// an infinite family of solutions is given one representative value (0 for the joint itself).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Singularity {
    /// The point that fixes theta1 (wrist centre, W) on axis 1 (theta1 free), or the point
    /// that fixes theta2 on axis 2 (theta2 free).
    pub shoulder: bool,
    /// The arm fully stretched or folded: the two elbow roots coincide.
    pub elbow: bool,
    /// The wrist's first and last axes aligned (axes 4 and 6; for the offset wrist axis 6
    /// parallel to axis 2): only their sum (difference) is fixed.
    pub wrist: bool,
}

impl Singularity {
    /// Whether any singular case applies.
    pub fn any(&self) -> bool {
        self.shoulder || self.elbow || self.wrist
    }
}

/// One solution of the closed-form inverse geometric model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IgmSolution {
    /// The chain's six joint values in the robot's movable-joint order ([`ClosedFormIgm::joints`]),
    /// each wrapped to (-pi, pi] or moved by a turn into its limits.
    pub q: [f64; 6],
    /// Whether every joint value lies within the description's `limits` (absent: no limit).
    pub within_limits: bool,
    /// The singular cases of this solution.
    pub singular: Singularity,
}

/// The solutions of one target (at most 8), without allocation.
#[derive(Clone, Copy, Debug, Default)]
pub struct IgmSolutions {
    items: [IgmSolution; 8],
    len: usize,
}

impl IgmSolutions {
    /// The solutions found (empty when the target is out of reach).
    pub fn as_slice(&self) -> &[IgmSolution] {
        &self.items[..self.len]
    }

    /// Their number.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the target is out of reach.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// The most angles one target brings (atan2 each): two theta1, each with one delta of theta3's
/// pair and per arm branch theta2 and up to two (theta4, theta5, theta6) (the spherical wrist:
/// 32; 36 when theta1 is free, one per arm branch), or with one delta of theta5's pair and per
/// theta5 theta6, the direction of the parallel joints' sum, one delta of theta3's pair and two
/// theta2 (the offset wrist: 24). 48 leaves room.
const MAX_ANGLES: usize = 48;

/// The most values derived from the angles found ([`Derived`]): per theta1 two theta3 (the
/// spherical wrist: 4 per target), or two theta5 and per theta5 two theta3 and a theta4 (the
/// offset wrist: 16). 24 leaves room.
const MAX_DERIVED: usize = 24;

/// The solutions of one target as found: the directions of the distinct angles (each solution
/// shares some with others), the values derived from them, and each solution's six joints as
/// slots into both. The angles' values are taken at the end, all at once ([`Self::angles`]).
#[derive(Clone, Copy)]
struct Found {
    ys: [f64; MAX_ANGLES],
    xs: [f64; MAX_ANGLES],
    n: usize,
    derived: [Derived; MAX_DERIVED],
    nd: usize,
    slots: [[Slot; 6]; 8],
    singular: [Singularity; 8],
    len: usize,
}

/// One joint of a solution: the k-th angle found (k < [`MAX_ANGLES`]) or the (k -
/// [`MAX_ANGLES`])-th value derived, as it is, plus a half turn or negated (the spherical
/// wrist's mirror solution).
#[derive(Clone, Copy, Default)]
struct Slot {
    k: u8,
    op: SlotOp,
}

/// See [`Slot`].
#[derive(Clone, Copy, Default)]
enum SlotOp {
    #[default]
    Same,
    HalfTurn,
    Neg,
}

impl Slot {
    fn new(k: usize) -> Slot {
        Slot {
            k: k as u8,
            op: SlotOp::Same,
        }
    }

    fn half_turn(self) -> Slot {
        Slot {
            op: SlotOp::HalfTurn,
            ..self
        }
    }

    fn neg(self) -> Slot {
        Slot {
            op: SlotOp::Neg,
            ..self
        }
    }
}

/// A value derived from an angle found: as it is or negated, plus an offset (phi of a root
/// pair phi ± delta found by its delta, the constant of [`ParallelSum`]).
#[derive(Clone, Copy, Default)]
struct Derived {
    from: u8,
    neg: bool,
    off: Offset,
}

/// What is added to a [`Derived`] value: an index into [`ClosedFormIgm::offsets`].
#[derive(Clone, Copy, Default, PartialEq, Eq)]
enum Offset {
    /// phi of the arm's (theta3) equation.
    #[default]
    Arm,
    /// phi of the wrist's (theta5) equation.
    Wrist,
    /// The constant of [`ParallelSum`] (theta4 of the offset wrist, before its terms in
    /// theta2 and theta3).
    Sum,
}

/// The number of [`Offset`]s.
const OFFSETS: usize = 3;

impl Found {
    fn new() -> Found {
        Found {
            ys: [0.0; MAX_ANGLES],
            xs: [0.0; MAX_ANGLES],
            n: 0,
            derived: [Derived::default(); MAX_DERIVED],
            nd: 0,
            slots: [[Slot::default(); 6]; 8],
            singular: [Singularity::default(); 8],
            len: 0,
        }
    }

    /// The slot of a new angle, of direction `d`.
    fn angle(&mut self, d: Direction) -> Slot {
        let k = self.n;
        (self.ys[k], self.xs[k]) = (d.y, d.x);
        self.n += 1;
        Slot::new(k)
    }

    /// The slot of a new value: the value of the angle of slot `from`, negated when `neg`, plus
    /// `off`.
    fn derive(&mut self, from: Slot, neg: bool, off: Offset) -> Slot {
        let k = self.nd;
        self.derived[k] = Derived {
            from: from.k,
            neg,
            off,
        };
        self.nd += 1;
        Slot::new(MAX_ANGLES + k)
    }

    /// The slot of delta of a root pair phi ± delta (a new angle), or of the free angle's
    /// representative when the pair is one.
    fn delta(&mut self, p: &RootPair) -> Slot {
        self.angle(p.delta.unwrap_or(p.roots[0].dir()))
    }

    /// The slot of the i-th root of the pair (phi + delta, phi - delta) of an equation whose
    /// phi is the constant `off`, from the slot `d` of [`Self::delta`].
    fn root(&mut self, p: &RootPair, d: Slot, i: usize, off: Offset) -> Slot {
        if p.delta.is_some() {
            self.derive(d, i == 1, off)
        } else {
            d
        }
    }

    /// The slots of both roots of a pair.
    fn pair(&mut self, p: &RootPair, off: Offset) -> [Slot; 2] {
        let d = self.delta(p);
        [self.root(p, d, 0, off), self.root(p, d, 1, off)]
    }

    fn push(&mut self, slots: [Slot; 6], singular: Singularity) {
        self.slots[self.len] = slots;
        self.singular[self.len] = singular;
        self.len += 1;
    }

    fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The angles theta = atan2(y, x), four at a time (`wide`'s atan2: Cephes' rational
    /// approximation, within 2 ulps), the derived values in order, then each solution's
    /// joint values (theta - theta0; theta4 of the offset wrist from the sum of the parallel
    /// joints, [`ParallelSum`]), each wrapped to (-pi, pi] or moved by a turn into its limits.
    fn angles(&self, igm: &ClosedFormIgm) -> IgmSolutions {
        let mut th = [0.0; MAX_ANGLES + MAX_DERIVED];
        atan2_all(&self.ys, &self.xs, self.n, &mut th);
        for (j, d) in self.derived[..self.nd].iter().enumerate() {
            let v = th[usize::from(d.from)];
            th[MAX_ANGLES + j] = if d.neg { -v } else { v } + igm.offsets[d.off as usize];
        }
        let mut out = IgmSolutions {
            len: self.len,
            ..IgmSolutions::default()
        };
        let offset = igm.class == IgmClass::OffsetWrist;
        for ((o, slots), &singular) in out.items[..self.len]
            .iter_mut()
            .zip(&self.slots)
            .zip(&self.singular)
        {
            let mut theta = [0.0; 6];
            if offset {
                // the offset wrist's slots are all `Same`
                for (t, s) in theta.iter_mut().zip(slots) {
                    *t = th[usize::from(s.k)];
                }
                theta[3] = wrap_near(theta[3] - igm.sum.a2 * theta[1] - igm.sum.a3 * theta[2]);
            } else {
                for (t, s) in theta.iter_mut().zip(slots) {
                    let v = th[usize::from(s.k)];
                    *t = match s.op {
                        SlotOp::Same => v,
                        SlotOp::HalfTurn => v + PI,
                        SlotOp::Neg => -v,
                    };
                }
            }
            let (q, within_limits) = igm.joint_values(&theta);
            *o = IgmSolution {
                q,
                within_limits,
                singular,
            };
        }
        out
    }
}

/// atan2(y_k, x_k) into `th` for the first `n` entries, four at a time.
fn atan2_all(ys: &[f64; MAX_ANGLES], xs: &[f64; MAX_ANGLES], n: usize, th: &mut [f64]) {
    const LANES: usize = 4;
    for ((t, y), x) in th[..n.next_multiple_of(LANES)]
        .chunks_exact_mut(LANES)
        .zip(ys.chunks_exact(LANES))
        .zip(xs.chunks_exact(LANES))
    {
        let y = f64x4::from([y[0], y[1], y[2], y[3]]);
        let x = f64x4::from([x[0], x[1], x[2], x[3]]);
        t.copy_from_slice(&y.atan2(x).to_array());
    }
}

/// theta4 of the offset wrist from the direction psi of (A1 C1)_r^T x4 (x4: A4's x axis) in
/// the plane of the parallel axes 2, 3, 4: C2r and C3r turn about z, or about z and then by a
/// half turn about a line of the plane (alpha = pi), each C_r^T mapping a direction psi of the
/// plane to sigma (psi - gamma); so theta4 = s psi - a2 theta2 - a3 theta3 + c with s = a2 =
/// sigma2 sigma3, a3 = sigma3, c = -(sigma2 sigma3 gamma2 + sigma3 gamma3).
#[derive(Clone, Copy, Debug, Default)]
struct ParallelSum {
    a2: f64,
    a3: f64,
    c: f64,
}

impl ParallelSum {
    fn new(c2: &Matrix3<f64>, c3: &Matrix3<f64>) -> ParallelSum {
        let sigma = |c: &Matrix3<f64>| c[(2, 2)].signum();
        let gamma = |c: &Matrix3<f64>| c[(1, 0)].atan2(c[(0, 0)]);
        let (s2, s3) = (sigma(c2), sigma(c3));
        ParallelSum {
            a2: s2 * s3,
            a3: s3,
            c: -(s2 * s3 * gamma(c2) + s3 * gamma(c3)),
        }
    }
}

/// An angle carried by its cosine and sine: the roots of Paul's equations come with theirs
/// (algebraically), and the equations downstream need only them. The angle's value is asked of
/// them once, for every solution at once ([`Found::angles`]).
#[derive(Clone, Copy, Debug)]
struct Angle {
    c: f64,
    s: f64,
}

/// An angle given by a direction (x, y) of its plane, not necessarily of unit length: its
/// value is atan2(y, x), found for all the solutions at once ([`Found::angles`]).
#[derive(Clone, Copy, Debug)]
struct Direction {
    y: f64,
    x: f64,
}

impl Angle {
    fn new(th: f64) -> Angle {
        let (s, c) = th.sin_cos();
        Angle { c, s }
    }

    /// Its direction (cos, sin).
    fn dir(&self) -> Direction {
        Direction {
            y: self.s,
            x: self.c,
        }
    }

    /// The angle opposite (-theta).
    fn neg(&self) -> Angle {
        Angle {
            c: self.c,
            s: -self.s,
        }
    }

    /// Rz(theta) v.
    #[inline]
    fn turn(&self, v: &Vector3<f64>) -> Vector3<f64> {
        Vector3::new(
            self.c * v.x - self.s * v.y,
            self.s * v.x + self.c * v.y,
            v.z,
        )
    }

    /// Rz(theta)^T v.
    #[inline]
    fn unturn(&self, v: &Vector3<f64>) -> Vector3<f64> {
        Vector3::new(
            self.c * v.x + self.s * v.y,
            self.c * v.y - self.s * v.x,
            v.z,
        )
    }

    /// Rz(theta) m (12 products: rows [c x - s y, s x + c y, z] for the rows x, y, z of m).
    #[inline]
    fn left_of(&self, m: &Matrix3<f64>) -> Matrix3<f64> {
        let (x, y) = (m.row(0), m.row(1));
        Matrix3::from_rows(&[
            x * self.c - y * self.s,
            x * self.s + y * self.c,
            m.row(2).into_owned(),
        ])
    }

    /// Rz(theta)^T m for a 3-row m (rows [c x + s y, c y - s x, z] for its rows x, y, z).
    #[inline]
    fn left_tr_of<const C: usize>(&self, m: &SMatrix<f64, 3, C>) -> SMatrix<f64, 3, C> {
        let (x, y) = (m.row(0), m.row(1));
        SMatrix::<f64, 3, C>::from_rows(&[
            x * self.c + y * self.s,
            y * self.c - x * self.s,
            m.row(2).into_owned(),
        ])
    }

    /// m Rz(theta) (12 products: [c x + s y, c y - s x, z] for the columns x, y, z of m).
    #[inline]
    fn right_of(&self, m: &Matrix3<f64>) -> Matrix3<f64> {
        let (x, y) = (m.column(0), m.column(1));
        Matrix3::from_columns(&[
            x * self.c + y * self.s,
            y * self.c - x * self.s,
            m.column(2).into_owned(),
        ])
    }
}

/// How far (rad) a root pair may be from a double root (delta or pi - delta) to be marked
/// singular: rounding in Z / rho moves a double root by ~sqrt(eps), so the roots count as one
/// within sqrt([`CLOSED_FORM_TOLERANCE`]) of each other (or of a half turn apart). Tested on
/// sin(delta), which differs from min(delta, pi - delta) there by its cube / 6 (5e-15 of it).
fn double_root_tolerance() -> f64 {
    CLOSED_FORM_TOLERANCE.sqrt()
}

/// Roots of the type-2 equation X sin(theta) + Y cos(theta) = Z.
#[derive(Clone, Copy, Debug)]
enum Roots {
    /// Two roots phi + delta and phi - delta (equal when `singular`: a double root, within the
    /// tolerance), and delta's direction (cos, sin).
    Two(Angle, Angle, bool, Direction),
    /// X = Y = Z = 0: any theta.
    Any,
    /// |Z| > sqrt(X^2 + Y^2): no root.
    None,
}

/// The type-2 equation a . Rz(theta) b = k of Paul's method for fixed a, b: X = a_y b_x -
/// a_x b_y, Y = a_x b_x + a_y b_y and Z = k - a_z b_z, so that rho = sqrt(X^2 + Y^2) and the
/// cosine and sine of phi = atan2(X, Y) are found once (at model build when a and b are
/// constants) and each k costs a square root: the roots phi ± delta, cos(delta) = Z / rho,
/// are given by their cosines and sines.
#[derive(Clone, Copy, Debug)]
struct DotEquation {
    rho: f64,
    cp: f64,
    sp: f64,
    azbz: f64,
    /// For unit a and b: 1 - rho - a_z b_z and 1 - rho + a_z b_z, the least of |a - Rz b|² / 2
    /// and of |a + Rz b|² / 2, from the differences of the parts (exact near 0, where the
    /// differences of 1 and rho lose their digits): see [`Self::roots_unit`].
    gap_minus: f64,
    gap_plus: f64,
}

impl DotEquation {
    fn new(a: &Vector3<f64>, b: &Vector3<f64>) -> DotEquation {
        let x = a.y * b.x - a.x * b.y;
        let y = a.x * b.x + a.y * b.y;
        let rho = (x * x + y * y).sqrt();
        let dxy = a.xy().norm() - b.xy().norm();
        DotEquation {
            rho,
            cp: y / rho,
            sp: x / rho,
            azbz: a.z * b.z,
            gap_minus: (dxy * dxy + (a.z - b.z).powi(2)) / 2.0,
            gap_plus: (dxy * dxy + (a.z + b.z).powi(2)) / 2.0,
        }
    }

    /// The roots of a . Rz(theta) b = k for unit a and b and a unit-vector product k, given
    /// with 1 - k and 1 + k found without cancellation (from the other components of the
    /// vectors whose product k is): 1 - cos(delta) = ((1 - k) - gap_minus) / rho and 1 +
    /// cos(delta) = ((1 + k) - gap_plus) / rho, sin(delta) from the smaller x by
    /// sqrt(x (2 - x)). Near a double root (the wrist near its singularity) delta is then exact
    /// to a few roundings, where sqrt(1 - (Z / rho)²) loses half the digits (sqrt(eps) ~ 1e-8).
    /// `tol` as in [`Self::roots`].
    fn roots_unit(&self, k: f64, one_minus_k: f64, one_plus_k: f64, tol: f64) -> Roots {
        let rho = self.rho;
        if rho <= tol {
            return self.roots(k, tol);
        }
        let (m, p) = (one_minus_k - self.gap_minus, one_plus_k - self.gap_plus);
        if m < -tol || p < -tol {
            return Roots::None;
        }
        let (m, p) = ((m / rho).clamp(0.0, 2.0), (p / rho).clamp(0.0, 2.0));
        let (cd, sd) = if m <= p {
            (1.0 - m, (m * (2.0 - m)).sqrt())
        } else {
            (p - 1.0, (p * (2.0 - p)).sqrt())
        };
        self.pair(cd, sd)
    }

    /// theta with a . Rz(theta) b = k; `tol` is the tolerance on Z (units of k) for X = Y = 0
    /// and for |Z| beyond rho. theta = phi ± delta with cos(delta) = Z / rho, their cosines and
    /// sines from X / rho, Y / rho and cos(delta).
    fn roots(&self, k: f64, tol: f64) -> Roots {
        let (rho, z) = (self.rho, k - self.azbz);
        if rho <= tol {
            return if z.abs() <= tol {
                Roots::Any
            } else {
                Roots::None
            };
        }
        if z.abs() > rho + tol {
            return Roots::None;
        }
        let mut cd = (z / rho).clamp(-1.0, 1.0);
        // a double root: cos(delta) within a few roundings of ±1 is ±1 (the sine would turn
        // that rounding into delta ~ 1e-8, and the pose error with it)
        if 1.0 - cd.abs() <= 4.0 * f64::EPSILON {
            cd = cd.signum();
        }
        // (1 - c)(1 + c): exact factors near c = ±1, where 1 - c² loses its digits
        let sd = ((1.0 - cd) * (1.0 + cd)).sqrt();
        self.pair(cd, sd)
    }

    /// The roots phi ± delta, with cos(delta) = cd and sin(delta) = sd >= 0.
    fn pair(&self, cd: f64, sd: f64) -> Roots {
        let singular = sd <= double_root_tolerance();
        let (cp, sp) = (self.cp, self.sp);
        let plus = Angle {
            c: cp * cd - sp * sd,
            s: sp * cd + cp * sd,
        };
        let minus = Angle {
            c: cp * cd + sp * sd,
            s: sp * cd - cp * sd,
        };
        Roots::Two(plus, minus, singular, Direction { y: sd, x: cd })
    }
}

/// The angle theta of Rz(theta) u = v in the xy plane; None when u or v lies on the z axis.
fn angle_between(u: &Vector3<f64>, v: &Vector3<f64>, tol: f64) -> Option<Angle> {
    angle_flagged(u, v, tol, 0.0).0
}

/// [`angle_between`] solved down to `floor` (None below it), and whether u or v is within
/// `tol` of the z axis (the step singular); the lengths of their xy parts found once for both.
fn angle_flagged(
    u: &Vector3<f64>,
    v: &Vector3<f64>,
    floor: f64,
    tol: f64,
) -> (Option<Angle>, bool) {
    let (nu, nv) = (u.x * u.x + u.y * u.y, v.x * v.x + v.y * v.y);
    let (lu, lv) = (nu.sqrt(), nv.sqrt());
    let singular = lu <= tol || lv <= tol;
    if lu <= floor || lv <= floor {
        return (None, singular);
    }
    let (c, s) = (u.x * v.x + u.y * v.y, u.x * v.y - u.y * v.x);
    let r = (nu * nv).sqrt();
    (Some(Angle { c: c / r, s: s / r }), singular)
}

/// 1 - k and 1 + k for k the z component of a unit vector b and s2 = b_x² + b_y²: the one
/// near 0 as s2 / (1 ± k) (1 - k² = s2), exact where 1 ∓ k cancels.
fn unit_complements(k: f64, s2: f64) -> (f64, f64) {
    if k >= 0.0 {
        (s2 / (1.0 + k), 1.0 + k)
    } else {
        (1.0 - k, s2 / (1.0 - k))
    }
}

/// The first root of eq = k, with k moved into eq's range when beyond it (None when eq is
/// degenerate: every theta or none).
fn mid_root(eq: &DotEquation, k: f64) -> Option<Angle> {
    let k = k.clamp(eq.azbz - eq.rho, eq.azbz + eq.rho);
    match eq.roots(k, eq.rho * CLOSED_FORM_TOLERANCE) {
        Roots::Two(a, ..) => Some(a),
        _ => None,
    }
}

/// The two roots of an equation: phi + delta and phi - delta with delta's direction, or a free
/// angle's representative twice (no delta); `singular` for a double root or a free angle.
#[derive(Clone, Copy, Debug)]
struct RootPair {
    roots: [Angle; 2],
    singular: bool,
    delta: Option<Direction>,
}

/// The planar arm's two branches: theta2, theta3 and their singular cases.
type ArmBranches = [(Angle, Angle, Singularity); 2];

/// A root pair, a free angle given as `free` (twice), or none.
fn roots_or(r: Roots, free: Angle) -> Option<RootPair> {
    match r {
        Roots::Two(a, b, singular, delta) => Some(RootPair {
            roots: [a, b],
            singular,
            delta: Some(delta),
        }),
        Roots::Any => Some(RootPair {
            roots: [free; 2],
            singular: true,
            delta: None,
        }),
        Roots::None => None,
    }
}

/// The closed-form inverse geometric model of one 6R chain: constants found once from the
/// robot, then [`Self::solve`] per target (no allocation).
#[derive(Clone, Debug)]
pub struct ClosedFormIgm {
    chain: Chain,
    class: IgmClass,
    /// The terminal frame.
    frame: usize,
    /// C0^-1.
    c0_inv: Transform,
    /// C6^-1.
    c6_inv: Transform,
    /// tool^-1 C6^-1 (C6^-1 without a tool), and whether C0 is the identity: a target costs one or two products.
    tail: Transform,
    c0_identity: bool,
    /// Axis 2's direction in frame A1 (C1 e_z).
    u2: Vector3<f64>,
    /// The class's point (wrist centre, W) in A1 at theta = 0, in A6, and in the link where
    /// the planar arm ends (A3: the wrist centre; A3 for O4 of the offset wrist).
    point0: Vector3<f64>,
    point6: Vector3<f64>,
    point3: Vector3<f64>,
    /// The representative value of each joint in an infinite family (its theta0).
    free: [Angle; 6],
    /// The planar arm's constants: |C2 origin|² + |point3|², and the theta3 equation
    /// arm_a . Rz(theta3) point3 = k with arm_a C2's origin in C2's axes.
    arm_k: f64,
    arm: DotEquation,
    /// The theta5 equation g . Rz(theta5) p6 = ... : g = C4^T e_z (spherical wrist) or
    /// C4^T e4 (offset wrist), p6 = C5 e_z.
    g: Vector3<f64>,
    p6: Vector3<f64>,
    wrist: DotEquation,
    /// C4r^T C4p (the offset wrist's A4).
    c4_origin: Vector3<f64>,
    /// The joints' theta0 (in (-pi, pi]), and whether every joint's limits hold the whole
    /// turn (then a solution's joint values are only wrapped, all within the limits).
    theta0: [f64; 6],
    wraps_within: bool,
    /// Whether the spherical wrist's second solution is the mirror (theta4 + pi, -theta5,
    /// theta6 + pi) of the first (`mirror_holds`).
    mirror: bool,
    /// The value of each [`Offset`] (by its index): phi of the arm's and the wrist's equations,
    /// and [`ParallelSum`]'s constant.
    offsets: [f64; OFFSETS],
    /// theta4 of the offset wrist from the sum of the parallel joints.
    sum: ParallelSum,
}

/// A geometric line: a point and a unit direction.
#[derive(Clone, Copy)]
struct Axis {
    p: Vector3<f64>,
    u: Vector3<f64>,
}

impl Axis {
    fn parallel(&self, o: &Axis) -> bool {
        self.u.cross(&o.u).norm() <= CLOSED_FORM_TOLERANCE
    }

    fn distance_to(&self, x: &Vector3<f64>) -> f64 {
        (x - self.p).cross(&self.u).norm()
    }

    /// The common point of two non-parallel axes, if they meet (within `tol`).
    fn meet(&self, o: &Axis, tol: f64) -> Option<Vector3<f64>> {
        // closest points p + s u, o.p + t o.u
        let w = self.p - o.p;
        let b = self.u.dot(&o.u);
        let (d, e) = (self.u.dot(&w), o.u.dot(&w));
        let den = 1.0 - b * b;
        if den <= CLOSED_FORM_TOLERANCE {
            return None;
        }
        let s = (b * e - d) / den;
        let t = (e - b * d) / den;
        let (x, y) = (self.p + self.u * s, o.p + o.u * t);
        ((x - y).norm() <= tol).then_some((x + y) / 2.0)
    }
}

impl ClosedFormIgm {
    /// The closed form for the placement of the robot's last frame (a serial robot).
    ///
    /// Errors: [`Error::Input`] when the robot is not a serial chain, or its chain is of no
    /// class handled (the message names the numeric inverse geometric model).
    pub fn new(robot: &Robot) -> Result<Self> {
        super::refuse_floating(robot, "the closed-form inverse geometric model")?;
        Self::for_frame(robot, super::chain::terminal_frame(robot)?)
    }

    /// The closed form for the placement of frame `frame` (the chain from the base to it must
    /// hold six revolute joints of one of the classes of [`IgmClass`]).
    pub fn for_frame(robot: &Robot, frame: usize) -> Result<Self> {
        let chain = Chain::new(robot, frame)?;
        if chain.n() != 6 {
            return Err(no_class(
                robot,
                &format!(
                    "{} joints on the path to frame {frame}, 6 needed",
                    chain.n()
                ),
            ));
        }
        // the axes at theta = 0, in the frame of C0 (P_1 = I, P_{k+1} = P_k C_k)
        let mut p = Transform::identity();
        let mut frames = [Transform::identity(); 6];
        let mut axes = [Axis {
            p: Vector3::zeros(),
            u: Vector3::z(),
        }; 6];
        for k in 0..6 {
            if k > 0 {
                p = p.compose(&chain.c[k]);
            }
            frames[k] = p;
            axes[k] = Axis {
                p: p.pos,
                u: p.rot.column(2).into(),
            };
        }
        let tol = CLOSED_FORM_TOLERANCE * chain.scale;
        let [a1, a2, a3, a4, a5, a6] = axes;
        let arm = a2.parallel(&a3) && !a1.parallel(&a2);
        let wrist = a4.meet(&a5, tol).filter(|c| a6.distance_to(c) <= tol);
        let (class, point0) =
            match wrist {
                Some(c) if arm && !a5.parallel(&a6) => (IgmClass::SphericalWrist, c),
                _ => match a5.meet(&a6, tol) {
                    Some(w) if arm && a3.parallel(&a4) && !a4.parallel(&a5) => {
                        (IgmClass::OffsetWrist, w)
                    }
                    _ => return Err(no_class(
                        robot,
                        "neither axes 2, 3 parallel with axes 4, 5, 6 concurrent nor axes 2, 3, 4 \
                         parallel with axes 5, 6 concurrent",
                    )),
                },
            };
        let inv = |t: &Transform, x: &Vector3<f64>| t.rot.tr_mul(&(x - t.pos));
        let u2: Vector3<f64> = chain.c[1].rot.column(2).into();
        let point3 = match class {
            IgmClass::SphericalWrist => inv(&frames[2], &point0),
            IgmClass::OffsetWrist => chain.c[3].pos,
        };
        let e4 = frames[3].rot.tr_mul(&u2);
        let (c2, c4) = (&chain.c[2], &chain.c[4]);
        let g = match class {
            IgmClass::SphericalWrist => c4.rot.tr_mul(&Vector3::z()),
            IgmClass::OffsetWrist => c4.rot.tr_mul(&e4),
        };
        let p6 = chain.c[5].rot * Vector3::z();
        let (arm, wrist) = (
            DotEquation::new(&c2.rot.tr_mul(&c2.pos), &point3),
            DotEquation::new(&g, &p6),
        );
        let sum = ParallelSum::new(&c2.rot, &chain.c[3].rot);
        let (phi_arm, phi_wrist) = (arm.sp.atan2(arm.cp), wrist.sp.atan2(wrist.cp));
        Ok(ClosedFormIgm {
            class,
            frame,
            c0_inv: chain.c[0].inverse(),
            c6_inv: chain.c[6].inverse(),
            tail: chain.c[6].inverse(),
            c0_identity: chain.c[0] == Transform::identity(),
            u2,
            point6: inv(&frames[5], &point0),
            point0,
            free: std::array::from_fn(|k| Angle::new(chain.theta0[k])),
            arm_k: c2.pos.norm_squared() + point3.norm_squared(),
            arm,
            point3,
            wrist,
            offsets: [phi_arm, phi_wrist, sum.c],
            sum,
            mirror: class == IgmClass::SphericalWrist && mirror_holds(&c4.rot, &chain.c[5].rot),
            g,
            p6,
            c4_origin: c4.rot.tr_mul(&c4.pos),
            theta0: std::array::from_fn(|k| chain.theta0[k]),
            wraps_within: chain.wraps_within_limits(),
            chain,
        })
    }

    /// The same model for a tool frame fixed on the terminal frame at `tool` (its 4x4 placement
    /// in the terminal frame): targets are then placements of the tool frame.
    ///
    /// Errors: as a target ([`Self::solve`]).
    pub fn with_tool(mut self, tool: &Matrix4<f64>) -> Result<Self> {
        self.tail = transform_of("tool", tool)?.inverse().compose(&self.c6_inv);
        Ok(self)
    }

    /// The class found.
    pub fn class(&self) -> IgmClass {
        self.class
    }

    /// The terminal frame (without the tool).
    pub fn frame(&self) -> usize {
        self.frame
    }

    /// The index of each solution entry in the robot's movable-joint vector.
    pub fn joints(&self) -> [usize; 6] {
        let mut j = [0; 6];
        j.copy_from_slice(&self.chain.coord);
        j
    }

    /// Every solution for the 4x4 placement `target` of the terminal (or tool) frame in the
    /// base frame; empty when it is out of reach.
    ///
    /// Errors: [`Error::NotFinite`] for a NaN or infinite entry, [`Error::Input`] when the
    /// rotation part is not orthonormal with determinant 1 or the last row is not (0, 0, 0, 1)
    /// (within 1e-9).
    pub fn solve(&self, target: &Matrix4<f64>) -> Result<IgmSolutions> {
        let t = transform_of("target", target)?;
        let mut m = t.compose(&self.tail);
        if !self.c0_identity {
            m = self.c0_inv.compose(&m);
        }
        let mut found = Found::new();
        match self.class {
            IgmClass::SphericalWrist => self.spherical(&m, &mut found),
            IgmClass::OffsetWrist => self.offset(&m, &mut found),
        }
        Ok(found.angles(self))
    }

    fn tol(&self) -> f64 {
        CLOSED_FORM_TOLERANCE * self.chain.scale
    }

    /// theta1 from the point's component along axis 2, invariant under joints 2, 3 (and 4):
    /// u2 . Rz(theta1)^T x_M = u2 . x(0); the roots, whether singular, and whether theta1 is
    /// free (the point on axis 1: its representative value given).
    fn theta1(&self, x_m: &Vector3<f64>) -> Option<([Angle; 2], bool, bool)> {
        let r = DotEquation::new(x_m, &self.u2).roots(self.u2.dot(&self.point0), self.tol());
        let free = matches!(r, Roots::Any);
        roots_or(r, self.free[0]).map(|p| (p.roots, p.singular, free))
    }

    /// The spherical wrist's centre on axis 1 (theta1 free: the arm does not depend on it):
    /// theta1 turns axis 4 (direction `a` in A1 before Rz(theta1)) about axis 1, and theta5's
    /// equation g . Rz(theta5) p6 = z . Rz(theta1) a (z: the target's e_z) has roots only for
    /// some theta1 when the wrist does not reach every angle between axes 4 and 6. The
    /// representative value when the wrist reaches from there; else the theta1 putting the
    /// equation mid-range, or as near as theta1 allows (when some theta1 reaches, this one does).
    fn reaching_theta1(&self, z: &Vector3<f64>, a: &Vector3<f64>) -> Angle {
        let rep = self.free[0];
        let (k, w) = (z.dot(&rep.turn(a)), &self.wrist);
        if (k - w.azbz).abs() <= w.rho {
            return rep;
        }
        mid_root(&DotEquation::new(z, a), w.azbz).unwrap_or(rep)
    }

    /// theta2, theta3 of the planar arm placing the point `point3` (fixed in A3) at `x_m`:
    /// theta3 from its distance to O2 (type 2), theta2 from atan2; and theta3's root pair.
    fn planar(&self, th1: &Angle, x_m: &Vector3<f64>) -> Option<(ArmBranches, RootPair)> {
        let (c1, c2) = (&self.chain.c[1], &self.chain.c[2]);
        let x2 = c1.rot.tr_mul(&(th1.unturn(x_m) - c1.pos));
        let b = &self.point3;
        let k = (x2.norm_squared() - self.arm_k) / 2.0;
        let tol2 = self.tol() * self.chain.scale;
        let t3 = roots_or(self.arm.roots(k, tol2), self.free[2])?;
        let elbow = t3.singular;
        let branch = |th3: Angle| {
            let v = c2.rot * th3.turn(b) + c2.pos;
            let (th2, shoulder) =
                angle_flagged(&v, &x2, ATAN2_FLOOR * self.chain.scale, self.tol());
            let singular = Singularity {
                shoulder,
                elbow,
                wrist: false,
            };
            (th2.unwrap_or(self.free[1]), th3, singular)
        };
        Some(([branch(t3.roots[0]), branch(t3.roots[1])], t3))
    }

    /// (A3 C3)_r^T M from m1 = C1_r^T Rz(theta1)^T M (shared by the branches of theta1), for
    /// the columns of M needed: C3_r^T Rz(theta3)^T C2_r^T Rz(theta2)^T m1.
    fn a3c3_tr<const C: usize>(
        &self,
        th2: &Angle,
        th3: &Angle,
        m1: &SMatrix<f64, 3, C>,
    ) -> SMatrix<f64, 3, C> {
        let c = &self.chain.c;
        let m2 = c[2].rot.tr_mul(&th2.left_tr_of(m1));
        c[3].rot.tr_mul(&th3.left_tr_of(&m2))
    }

    /// C1_r^T Rz(theta1)^T M: the part of (A3 C3)_r^T M shared by the branches of theta1.
    fn m1<const C: usize>(&self, th1: &Angle, m: &SMatrix<f64, 3, C>) -> SMatrix<f64, 3, C> {
        self.chain.c[1].rot.tr_mul(&th1.left_tr_of(m))
    }

    /// The joint values of the angles `th` of one solution, and whether all lie within the
    /// limits.
    fn joint_values(&self, th: &[f64]) -> ([f64; 6], bool) {
        let mut q = [0.0; 6];
        let mut within = true;
        if self.wraps_within {
            for k in 0..6 {
                q[k] = wrap_near(th[k] - self.theta0[k]);
            }
        } else {
            for k in 0..6 {
                let (v, inside) = self.chain.joint_value(k, th[k]);
                q[k] = v;
                within &= inside;
            }
        }
        (q, within)
    }

    /// The spherical wrist: the wrist centre gives theta1 and the planar arm (theta2,
    /// theta3), each arm branch the orientation R left to the wrist.
    fn spherical(&self, m: &Transform, out: &mut Found) {
        let c_m = m.rot * self.point6 + m.pos;
        let Some((t1, shoulder, free)) = self.theta1(&c_m) else {
            return;
        };
        // the wrist needs the first and last columns of R = (A3 C3)_r^T M_r
        let m_xz = Matrix3x2::from_columns(&[m.rot.column(0), m.rot.column(2)]);
        for th1 in t1 {
            let Some((arm, t3)) = self.planar(&th1, &c_m) else {
                continue;
            };
            let m1 = self.m1(&th1, &m_xz);
            let slot1 = out.angle(th1.dir());
            let slots3 = out.pair(&t3, Offset::Arm);
            for ((th2, th3, s), slot3) in arm.into_iter().zip(slots3) {
                // the point on axis 1: theta1 turns axis 4 only, chosen for the wrist to reach
                let (m1, slot1) = if free {
                    let c = &self.chain.c;
                    let a4 = c[1].rot
                        * th2.turn(&(c[2].rot * th3.turn(&c[3].rot.column(2).into_owned())));
                    let th1 = self.reaching_theta1(&m.rot.column(2).into_owned(), &a4);
                    (self.m1(&th1, &m_xz), out.angle(th1.dir()))
                } else {
                    (m1, slot1)
                };
                // R = Rz(theta4) C4 Rz(theta5) C5 Rz(theta6): its columns x and z
                let r = self.a3c3_tr(&th2, &th3, &m1);
                let singular = Singularity {
                    shoulder: shoulder || s.shoulder,
                    ..s
                };
                let arm = [slot1, out.angle(th2.dir()), slot3];
                self.spherical_wrist(&arm, &r, singular, out);
            }
        }
    }

    /// The two wrist solutions of R = Rz(theta4) C4 Rz(theta5) C5 Rz(theta6) for one arm
    /// branch: theta5 (type 2), theta4 and theta6 (atan2) per root; the second one as the
    /// mirror of the first when [`Self::mirror`] holds and the wrist is not singular.
    fn spherical_wrist(
        &self,
        arm: &[Slot; 3],
        r: &Matrix3x2<f64>,
        s: Singularity,
        out: &mut Found,
    ) {
        let (r0, b): (Vector3<f64>, Vector3<f64>) = (r.column(0).into(), r.column(1).into());
        let (one_minus, one_plus) = unit_complements(b.z, b.x * b.x + b.y * b.y);
        let t5 = self
            .wrist
            .roots_unit(b.z, one_minus, one_plus, CLOSED_FORM_TOLERANCE);
        let Some(t5) = roots_or(t5, self.free[4]) else {
            return;
        };
        let [a1, a2, a3] = *arm;
        // theta5 by its own atan2 (not phi ± delta): the mirror's needs no second one
        let (first, mut wrist) = self.wrist_angles(&r0, &b, &t5.roots[0]);
        let [th4, th6] = first.map(|d| out.angle(d));
        let th5 = out.angle(t5.roots[0].dir());
        out.push([a1, a2, a3, th4, th5, th6], Singularity { wrist, ..s });
        let [th4, th5, th6] = if self.mirror && !t5.singular && !wrist {
            [th4.half_turn(), th5.neg(), th6.half_turn()]
        } else {
            let (second, w) = self.wrist_angles(&r0, &b, &t5.roots[1]);
            wrist = w;
            let [th4, th6] = second.map(|d| out.angle(d));
            [th4, out.angle(t5.roots[1].dir()), th6]
        };
        out.push([a1, a2, a3, th4, th5, th6], Singularity { wrist, ..s });
    }

    /// theta4 and theta6 of R for one theta5 root (r0 = R e_x, b = R e_z), and whether the
    /// wrist is singular (axes 4 and 6 aligned: theta4 its representative value).
    fn wrist_angles(
        &self,
        r0: &Vector3<f64>,
        b: &Vector3<f64>,
        th5: &Angle,
    ) -> ([Direction; 2], bool) {
        let (c4, c5) = (&self.chain.c[4], &self.chain.c[5]);
        let c4r5 = th5.right_of(&c4.rot);
        let m5 = c4r5 * self.p6;
        let (th4, wrist) = angle_flagged(&m5, b, ATAN2_FLOOR, CLOSED_FORM_TOLERANCE);
        let th4 = th4.unwrap_or(self.free[3]);
        // Rz(theta6) = Q^T R, Q = Rz(theta4) C4 Rz(theta5) C5: its first column
        // (Q^T r0 = C5^T (C4 Rz5)^T Rz4^T r0)
        let u = c4r5.tr_mul(&th4.unturn(r0));
        let th6 = Direction {
            y: c5.rot.column(1).dot(&u),
            x: c5.rot.column(0).dot(&u),
        };
        ([th4.dir(), th6], wrist)
    }

    /// The offset wrist: W gives theta1, then per theta1 the direction of axis 6 theta5 (two
    /// roots), each root a branch. (The wrist mirror does not serve here: it moves W, which
    /// is off axis 4, and so the planar arm.) W on axis 1 (theta1 free): its representative
    /// value, or when no solution follows from it, [`Self::offset_free_theta1`].
    fn offset(&self, m: &Transform, out: &mut Found) {
        let w_m = m.rot * self.point6 + m.pos;
        let Some((t1, shoulder, free)) = self.theta1(&w_m) else {
            return;
        };
        if free {
            self.offset_theta1(m, &t1[0], shoulder, out);
            if out.is_empty() {
                self.offset_theta1(m, &self.offset_free_theta1(m), shoulder, out);
            }
            return;
        }
        for th1 in t1 {
            self.offset_theta1(m, &th1, shoulder, out);
        }
    }

    /// W on axis 1: every theta1 of an interval has solutions (theta5's equation and the
    /// planar arm both within reach), none found in closed form; the theta1 where the nearer
    /// of the two to its reach limit (relative to its range) is farthest from it, by a scan
    /// of 32 values refined by 40 golden-section steps.
    fn offset_free_theta1(&self, m: &Transform) -> Angle {
        let margin = |t: f64| self.offset_margin(m, &Angle::new(t));
        let step = std::f64::consts::TAU / 32.0;
        let t0 = self.theta0[0];
        let best = (0..32)
            .map(|i| t0 + step * i as f64)
            .max_by(|a, b| margin(*a).total_cmp(&margin(*b)))
            .unwrap_or(t0);
        let (mut a, mut b) = (best - step, best + step);
        let g = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..40 {
            let (x, y) = (b - g * (b - a), a + g * (b - a));
            if margin(x) >= margin(y) {
                b = y;
            } else {
                a = x;
            }
        }
        Angle::new((a + b) / 2.0)
    }

    /// The reach margin of theta1 (offset wrist): of theta5's equation and of the planar arm
    /// (for the better theta5 root), each relative to its range; negative out of reach.
    fn offset_margin(&self, m: &Transform, th1: &Angle) -> f64 {
        let z2 = th1.turn(&self.u2);
        let z6: Vector3<f64> = m.rot.column(2).into();
        let (w, a) = (&self.wrist, &self.arm);
        let wrist = 1.0 - (z2.dot(&z6) - w.azbz).abs() / w.rho;
        let Roots::Two(r1, r2, ..) = w.roots(
            z2.dot(&z6).clamp(w.azbz - w.rho, w.azbz + w.rho),
            CLOSED_FORM_TOLERANCE,
        ) else {
            return wrist;
        };
        let arm = [r1, r2]
            .iter()
            .map(|th5| {
                let m6 = self.chain.c[5].rot.tr_mul(&th5.unturn(&self.g));
                let th6 =
                    angle_between(&m.rot.tr_mul(&z2), &m6, ATAN2_FLOOR).unwrap_or(self.free[5]);
                let o4 = self.a4_origin_x(m, th5, &th6).0;
                let c1 = &self.chain.c[1];
                let x2 = c1.rot.tr_mul(&(th1.unturn(&o4) - c1.pos));
                1.0 - ((x2.norm_squared() - self.arm_k) / 2.0 - a.azbz).abs() / a.rho
            })
            .fold(f64::NEG_INFINITY, f64::max);
        wrist.min(arm)
    }

    /// The solutions of one theta1 of the offset wrist.
    fn offset_theta1(&self, m: &Transform, th1: &Angle, shoulder: bool, out: &mut Found) {
        let z6: Vector3<f64> = m.rot.column(2).into();
        let z2 = th1.turn(&self.u2);
        // axis 6 against axis 2: e4 . C4 Rz(theta5) C5 e_z = z2 . z6, with 1 -+ z2 . z6 from
        // |z2 -+ z6|² / 2 (exact near the wrist singularity, z6 = ±z2)
        let t5 = self.wrist.roots_unit(
            z2.dot(&z6),
            (z2 - z6).norm_squared() / 2.0,
            (z2 + z6).norm_squared() / 2.0,
            CLOSED_FORM_TOLERANCE,
        );
        let Some(t5) = roots_or(t5, self.free[4]) else {
            return;
        };
        let slot1 = out.angle(th1.dir());
        let slots5 = out.pair(&t5, Offset::Wrist);
        for (th5, slot5) in t5.roots.iter().zip(slots5) {
            self.offset_branch(m, [(th1, slot1), (th5, slot5)], &z2, shoulder, out);
        }
    }

    /// The solutions of one (theta1, theta5) branch of the offset wrist: theta6 from the
    /// direction of axis 2 seen from frame 6, then A4 and the planar arm. At the wrist
    /// singularity (axis 6 parallel to axis 2) theta6 only turns O4 about axis 6: its
    /// representative value, or when the arm does not reach O4 from there,
    /// [`Self::reaching_theta6`].
    fn offset_branch(
        &self,
        m: &Transform,
        [(th1, slot1), (th5, slot5)]: [(&Angle, Slot); 2],
        z2: &Vector3<f64>,
        shoulder: bool,
        out: &mut Found,
    ) {
        let c5 = &self.chain.c[5];
        // axis 2 seen from frame 6: Rz(theta6) n = m6
        let n = m.rot.tr_mul(z2);
        let m6 = c5.rot.tr_mul(&th5.unturn(&self.g));
        let (th6, wrist) = angle_flagged(&n, &m6, ATAN2_FLOOR, CLOSED_FORM_TOLERANCE);
        let th6 = th6.unwrap_or(self.free[5]);
        let mut found = self.offset_arm(m, th1, th5, &th6);
        if found.is_none() {
            // near the singularity theta6 (eps / |n_xy| off) may leave O4 just out of reach
            let near = self.reaching_theta6(m, th1, th5, &th6);
            let moved = (near.s * th6.c - near.c * th6.s).atan2(near.c * th6.c + near.s * th6.s);
            if n.xy().norm() * moved.abs() <= NEAR_MOVE {
                found = self.offset_arm(m, th1, th5, &near);
            }
        }
        let Some((th6, x4, (arm, t3))) = found else {
            return;
        };
        let slot6 = out.angle(th6.dir());
        // Rz(theta4) = (A3 C3)_r^T (A4)_r, its first column C3r^T Rz3^T C2r^T Rz2^T m1: theta4
        // from the direction of m1 in the plane of axes 2, 3, 4 ([`ParallelSum`])
        let m1 = self.m1(th1, &x4);
        let psi = out.angle(Direction { y: m1.y, x: m1.x });
        let slot4 = out.derive(psi, self.sum.a2 < 0.0, Offset::Sum);
        let slots3 = out.pair(&t3, Offset::Arm);
        for ((th2, _, s), slot3) in arm.into_iter().zip(slots3) {
            let singular = Singularity {
                shoulder: shoulder || s.shoulder,
                elbow: s.elbow,
                wrist,
            };
            let slot2 = out.angle(th2.dir());
            out.push([slot1, slot2, slot3, slot4, slot5, slot6], singular);
        }
    }

    /// A4 = M (C4 Rz5 C5 Rz6)^-1 and the planar arm placing its origin, if it reaches.
    fn offset_arm(
        &self,
        m: &Transform,
        th1: &Angle,
        th5: &Angle,
        th6: &Angle,
    ) -> Option<(Angle, Vector3<f64>, (ArmBranches, RootPair))> {
        let (o4, x4) = self.a4_origin_x(m, th5, th6);
        let arm = self.planar(th1, &o4)?;
        Some((*th6, x4, arm))
    }

    /// The origin and x axis of A4 = M Rz(theta6)^T K^-1 (K = C4 Rz(theta5) C5), without
    /// its products: p = K^-1 origin = -C5r^T (Rz(theta5)^T C4r^T C4p + C5p) and K_r^T e_x =
    /// C5r^T Rz(theta5)^T (C4r^T e_x), then Rz(theta6)^T and M.
    fn a4_origin_x(&self, m: &Transform, th5: &Angle, th6: &Angle) -> (Vector3<f64>, Vector3<f64>) {
        let (c4, c5) = (&self.chain.c[4].rot, &self.chain.c[5]);
        let c4x = Vector3::new(c4[(0, 0)], c4[(0, 1)], c4[(0, 2)]);
        let v =
            Matrix3x2::from_columns(&[-(th5.unturn(&self.c4_origin) + c5.pos), th5.unturn(&c4x)]);
        let w = th6.left_tr_of(&c5.rot.tr_mul(&v));
        (m.rot * w.column(0) + m.pos, m.rot * w.column(1))
    }

    /// At (or near) the offset wrist's singularity, theta6 turns O4 = M_p + M_r Rz(-theta6) p
    /// (p = K^-1 origin) on a circle about axis 6 (and barely moves the orientation): the
    /// theta6 nearest to `near` that puts O4 within the planar arm's reach (`near` itself when
    /// it does; else a root of the arm's reach boundary, an elbow double root).
    fn reaching_theta6(&self, m: &Transform, th1: &Angle, th5: &Angle, near: &Angle) -> Angle {
        let p = self
            .a4_origin_x(&Transform::identity(), th5, &Angle::new(0.0))
            .0;
        let pxy = Vector3::new(p.x, p.y, 0.0);
        // |O4 - O2|² = |d0|² + |pxy|² + 2 pxy . Rz(theta6) v, d0 the circle's centre from O2
        let d0 = m.pos + m.rot.column(2) * p.z - th1.turn(&self.chain.c[1].pos);
        let v = m.rot.tr_mul(&d0);
        // the arm reaches |O4 - O2|² = arm_k + 2 (azbz ± rho)
        let base = d0.norm_squared() + pxy.norm_squared() - self.arm_k;
        let (lo, hi) = (
            self.arm.azbz - self.arm.rho - base / 2.0,
            self.arm.azbz + self.arm.rho - base / 2.0,
        );
        let eq = DotEquation::new(&pxy, &v);
        let k = pxy.dot(&near.turn(&v)).clamp(lo, hi);
        match eq.roots(k.clamp(-eq.rho, eq.rho), eq.rho * CLOSED_FORM_TOLERANCE) {
            Roots::Two(a, b, ..) => {
                let closeness = |x: &Angle| x.c * near.c + x.s * near.s;
                if closeness(&a) >= closeness(&b) {
                    a
                } else {
                    b
                }
            }
            _ => *near,
        }
    }
}

/// Whether the spherical wrist's second solution is the mirror of the first: (theta4 + pi,
/// -theta5, theta6 + pi) gives link 6 the orientation (theta4, theta5, theta6) gives it, i.e.
/// Rz(pi) W(-t) Rz(pi) = W(t) for W(t) = C4r Rz(t) C5r and every t (the wrist centre does not
/// move). W is affine in (cos t, sin t), so t = 0, pi/2, pi prove it. It holds exactly for
/// alpha5, alpha6 = ±pi/2 and gamma6 = 0 or pi, not for other wrists, which are solved root
/// by root; [`MIRROR_TOLERANCE`] bounds the mirror's orientation error.
fn mirror_holds(c4: &Matrix3<f64>, c5: &Matrix3<f64>) -> bool {
    let half = Angle { c: -1.0, s: 0.0 };
    let w = |t: &Angle| t.right_of(c4) * c5;
    [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)].iter().all(|&(c, s)| {
        let t = Angle { c, s };
        let mirrored = half.left_of(&half.right_of(&w(&t.neg())));
        (mirrored - w(&t)).amax() <= MIRROR_TOLERANCE
    })
}

fn no_class(robot: &Robot, why: &str) -> Error {
    Error::Input(format!(
        "{}: no closed-form inverse geometric model ({why}); the closed form handles 6R chains \
         with a spherical wrist or with axes 2, 3, 4 parallel: use the numeric inverse geometric \
         model (inverse_geometry::NumericIgm)",
        robot.name()
    ))
}
