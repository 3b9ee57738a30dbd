//! The robot's constants in a scalar type `T`: what the recursive algorithms run on.
//!
//! `DynModel<f64>` is built once when a [`crate::Robot`] is validated; `DynModel<Expr>` is built by
//! the symbolic model generator from the same description, so the same recursion serves both.

use crate::model::{BaseMotion, Environment, JointType, RobotDescription, Wrench};
use crate::scalar::DynScalar;
use nalgebra::{Matrix3, Vector3};
use robodyn_symbolic::Expr;

/// Constant part of frame j's placement: iT_j = [pre_rot * Rz(theta), pre_pos + pre_rot * [0 0 r]].
#[derive(Clone, Debug)]
pub struct FrameConstants<T: DynScalar> {
    /// a(j).
    pub ant: usize,
    /// sigma_j.
    pub joint: JointType,
    /// Rz(gamma) Rx(alpha) ([`Self::pre_rot`]); private so that `form`, derived from it, is
    /// never stale ([`Self::set_pre_rot`]).
    pre_rot: Matrix3<T>,
    /// Rz(gamma) ([0 0 b] + Rx(alpha) [d 0 0]).
    pub pre_pos: Vector3<T>,
    /// Constant part of theta (the revolute joint variable is added to it).
    pub theta0: T,
    /// Constant part of r (the prismatic joint variable is added to it).
    pub r0: T,
    /// Sparsity of iA_j = pre_rot Rz(theta) read off `pre_rot` ([`RotationForm::of`]), set
    /// with it ([`Self::form`]).
    form: RotationForm,
}

/// Sparsity of a frame's rotation iA_j = pre_rot Rz(theta), known from its constant part. When
/// pre_rot carries z onto ±x_k (gamma and alpha multiples of pi/2, as in most KK descriptions:
/// alpha = 0 or ±pi/2 with gamma = 0 gives k = 2 or 1), row k of iA_j is (0, 0, ±1) and its
/// third column ±e_k whatever theta: a product iA_j v or jA_i v takes 5 multiplications
/// instead of 9. Numeric models only; the symbolic model's zeros vanish by themselves, so it
/// always uses `General` and its expressions do not depend on this.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RotationForm {
    /// A full 3x3 product.
    General,
    /// Row k is (0, 0, ±1).
    Axis(u8),
}

impl RotationForm {
    /// The form of pre_rot Rz(theta): `Axis(k)` when pre_rot's row k and third column are zero
    /// but for entry (k, 2) (exact zeros, see [`DynScalar::snap_zero`]).
    pub fn of<T: DynScalar>(pre_rot: &Matrix3<T>) -> RotationForm {
        if T::NAMED {
            return RotationForm::General;
        }
        (0..3)
            .find(|&k| {
                pre_rot[(k, 0)].is_zero()
                    && pre_rot[(k, 1)].is_zero()
                    && (0..3).all(|i| i == k || pre_rot[(i, 2)].is_zero())
            })
            .map_or(RotationForm::General, |k| RotationForm::Axis(k as u8))
    }
}

impl<T: DynScalar> FrameConstants<T> {
    /// Build from the six geometric parameters, already in scalar `T`. The placement of a fixed
    /// frame is constant: it is composed into `pre_rot`, `pre_pos` here (theta0 = r0 = 0), so
    /// that [`Self::transform`] returns it without a sine, a cosine or a product.
    pub fn new(ant: usize, joint: JointType, g: [T; 6]) -> Self {
        let [gamma, b, alpha, d, theta, r] = g;
        let (cg, sg) = (gamma.cos().snap_zero(), gamma.sin().snap_zero());
        let (ca, sa) = (alpha.cos().snap_zero(), alpha.sin().snap_zero());
        let z = T::zero;
        let o = T::one;
        let rz = Matrix3::new(cg.clone(), -sg.clone(), z(), sg, cg, z(), z(), z(), o());
        let rx = Matrix3::new(o(), z(), z(), z(), ca.clone(), -sa.clone(), z(), sa, ca);
        let pre_rot = &rz * rx;
        let pre_pos = &rz * Vector3::new(d, z(), b);
        let mut fc = FrameConstants {
            ant,
            joint,
            form: RotationForm::of(&pre_rot),
            pre_rot,
            pre_pos,
            theta0: theta,
            r0: r,
        };
        if joint == JointType::Fixed {
            let (rot, pos) = fc.transform_at(fc.theta0.clone(), fc.r0.clone());
            fc.set_pre_rot(rot);
            fc.pre_pos = pos;
            fc.theta0 = z();
            fc.r0 = z();
        }
        fc
    }

    /// Rz(gamma) Rx(alpha): the constant rotation before the joint's Rz(theta) (for a fixed
    /// frame, its whole constant rotation).
    pub fn pre_rot(&self) -> &Matrix3<T> {
        &self.pre_rot
    }

    /// Replace pre_rot (and its [`RotationForm`]).
    pub fn set_pre_rot(&mut self, pre_rot: Matrix3<T>) {
        self.form = RotationForm::of(&pre_rot);
        self.pre_rot = pre_rot;
    }

    /// The sparsity of this frame's rotation iA_j, found from pre_rot.
    pub fn form(&self) -> RotationForm {
        self.form
    }

    /// These constants in another scalar, each entry mapped by `f` (the form found again from
    /// the mapped pre_rot).
    pub fn map<U: DynScalar>(&self, f: impl Fn(&T) -> U) -> FrameConstants<U> {
        let pre_rot = self.pre_rot.map(|x| f(&x));
        FrameConstants {
            ant: self.ant,
            joint: self.joint,
            form: RotationForm::of(&pre_rot),
            pre_rot,
            pre_pos: self.pre_pos.map(|x| f(&x)),
            theta0: f(&self.theta0),
            r0: f(&self.r0),
        }
    }

    /// iA_j v for `m` = iA_j of this frame (a vector of R_j expressed in R_i), with the zeros
    /// of its [`RotationForm`] skipped.
    #[inline(always)]
    pub fn rot_mul(&self, m: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
        rot_mul(self.form, m, v)
    }

    /// [`inertia_to_antecedent`] through this frame (`r` = iA_j), the zeros of its
    /// [`RotationForm`] skipped (R J R^T in 25 products instead of 45 for an `Axis` form).
    #[inline]
    pub fn inertia_to_antecedent(
        &self,
        r: &Matrix3<T>,
        p: &Vector3<T>,
        j: &Matrix3<T>,
        ms: &Vector3<T>,
        mass: &T,
    ) -> (Matrix3<T>, Vector3<T>) {
        inertia_transfer(self.form, r, p, j, ms, mass)
    }

    /// jA_i v = (iA_j)^T v for `m` = iA_j of this frame (a vector of R_i expressed in R_j), with
    /// the zeros of its [`RotationForm`] skipped.
    #[inline(always)]
    pub fn rot_tr_mul(&self, m: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
        let w = [&v.x, &v.y, &v.z];
        match self.form {
            RotationForm::General => m.tr_mul(v),
            RotationForm::Axis(0) => form_tr_mul::<T, 0>(m, w),
            RotationForm::Axis(1) => form_tr_mul::<T, 1>(m, w),
            RotationForm::Axis(_) => form_tr_mul::<T, 2>(m, w),
        }
    }

    /// iA_j and iP_j for joint value q (eq 10.18 for the position), with the platform's sin and
    /// cos: the geometric models (forward kinematics, loop closure) use it.
    #[inline]
    pub fn transform(&self, q: &T) -> (Matrix3<T>, Vector3<T>) {
        match self.variables(q) {
            Some((theta, r)) => self.transform_at(theta, r),
            // composed into pre_rot, pre_pos by `new`
            None => (self.pre_rot.clone(), self.pre_pos.clone()),
        }
    }

    /// [`Self::transform`] for the dynamic recursions (Newton–Euler, composite links, articulated
    /// bodies): sin and cos from one argument reduction ([`DynScalar::sin_cos`]), within an ulp
    /// of the platform's and about 40 % cheaper, once per joint per call.
    #[inline]
    pub fn placement(&self, q: &T) -> (Matrix3<T>, Vector3<T>) {
        match self.variables(q) {
            Some((theta, r)) => {
                let (s, c) = theta.sin_cos();
                self.rotated(s, c, r)
            }
            None => (self.pre_rot.clone(), self.pre_pos.clone()),
        }
    }

    /// (theta, r) for joint value q; None for a fixed frame (its placement is constant).
    #[inline]
    fn variables(&self, q: &T) -> Option<(T, T)> {
        match self.joint {
            JointType::Revolute => Some((self.theta0.clone() + q.clone(), self.r0.clone())),
            JointType::Prismatic => Some((self.theta0.clone(), self.r0.clone() + q.clone())),
            JointType::Fixed => None,
        }
    }

    /// iA_j and iP_j for explicit theta and r.
    #[inline]
    pub fn transform_at(&self, theta: T, r: T) -> (Matrix3<T>, Vector3<T>) {
        let c = theta.cos();
        self.rotated(theta.sin(), c, r)
    }

    /// pre_rot Rz(theta), pre_pos + pre_rot [0 0 r] from s = sin(theta), c = cos(theta), column
    /// by column: with x, y, z the columns of pre_rot, pre_rot Rz(theta) = [c x + s y, c y - s x,
    /// z] (12 products, not the 27 of a general 3x3 product).
    #[inline]
    fn rotated(&self, s: T, c: T, r: T) -> (Matrix3<T>, Vector3<T>) {
        let p = &self.pre_rot;
        let col = |k: usize| Vector3::new(p[(0, k)].clone(), p[(1, k)].clone(), p[(2, k)].clone());
        let (x, y, z) = (col(0), col(1), col(2));
        let cx = &x * c.clone() + &y * s.clone();
        let cy = y * c - x * s;
        let pos = &self.pre_pos + &z * r;
        (Matrix3::from_columns(&[cx, cy, z]), pos)
    }
}

/// Inertial and drive parameters of link j in scalar `T` (about O_j, in R_j).
#[derive(Clone, Debug)]
pub struct LinkConstants<T: DynScalar> {
    /// jJ_j about O_j.
    pub inertia: Matrix3<T>,
    /// (ZZ - YY, XX - ZZ, YY - XX): the differences of principal moments the Euler moment
    /// takes in its product form (see `inverse_dynamics::euler_moment`, eq 10.8).
    pub inertia_diff: Vector3<T>,
    /// jMS_j.
    pub ms: Vector3<T>,
    /// M_j (kg).
    pub mass: T,
    /// Rotor inertia Ia_j (kg m² or kg).
    pub ia: T,
    /// Coulomb friction Fs_j (N m or N).
    pub fs: T,
    /// Viscous friction Fv_j (N m s/rad or N s/m).
    pub fv: T,
}

impl<T: DynScalar> LinkConstants<T> {
    /// From the 13 standard parameters (XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV).
    pub fn new(p: [T; super::PARAMS_PER_LINK]) -> Self {
        let [xx, xy, xz, yy, yz, zz, mx, my, mz, m, ia, fs, fv] = p;
        LinkConstants {
            inertia_diff: Vector3::new(
                zz.clone() - yy.clone(),
                xx.clone() - zz.clone(),
                yy.clone() - xx.clone(),
            ),
            inertia: Matrix3::new(xx, xy.clone(), xz.clone(), xy, yy, yz.clone(), xz, yz, zz),
            ms: Vector3::new(mx, my, mz),
            mass: m,
            ia,
            fs,
            fv,
        }
    }
}

/// Index arrays of a model's tree that the kernels walk instead of the frame structs, derived
/// once from the antecedents ([`DynModel::build`], [`DynModel::fold_fixed`]).
#[derive(Clone, Debug, Default)]
pub struct TreeIndex {
    /// lambda(j) for j = 1..NL (index 0 unused): the nearest movable proper ancestor of link j,
    /// 0 when none (the parent array of the tree of movable joints, which is the tree of A).
    pub movable_parent: Vec<usize>,
    /// Link j is movable (index 0: the base, false).
    pub movable: Vec<bool>,
    /// The movable links in depth-first preorder from the base, children by increasing number:
    /// the movable links of the subtree of any link are a contiguous range of it.
    pub preorder: Vec<usize>,
    /// `preorder[subtree[j].0..subtree[j].1]`: the movable links of link j's subtree (j and its
    /// successors); j itself first when it is movable.
    pub subtree: Vec<(usize, usize)>,
    /// Every link movable and a(j) = j - 1 (a serial chain): every entry of A is an
    /// ancestor-descendant pair, so the inertia matrix writes all of them.
    pub serial: bool,
    /// Every subtree the inertia matrix carries to an antecedent (the subtree of a link whose
    /// antecedent is not the base) has at most [`TreeIndex::SHORT`] movable links: its column
    /// wrenches are kept as records, not by component (a component loop that short does not
    /// vectorize and pays a slice per component).
    pub short: bool,
}

impl TreeIndex {
    /// The longest carried subtree of a [`TreeIndex::short`] tree: below four columns (the
    /// f64 lanes of a 256-bit vector) a component loop runs scalar.
    pub const SHORT: usize = 3;

    /// From the antecedents and joint types of frames 1..NL (`frames[j - 1]`).
    pub fn new<T: DynScalar>(frames: &[FrameConstants<T>], nl: usize) -> TreeIndex {
        let mut movable = vec![false; nl + 1];
        let mut movable_parent = vec![0; nl + 1];
        let mut children = vec![Vec::new(); nl + 1];
        for j in 1..=nl {
            let f = &frames[j - 1];
            movable[j] = f.joint.is_movable();
            let i = f.ant;
            movable_parent[j] = if i == 0 || movable[i] {
                i
            } else {
                movable_parent[i]
            };
            children[i].push(j);
        }
        let mut preorder = Vec::with_capacity(nl);
        let mut subtree = vec![(0, 0); nl + 1];
        // iterative depth-first walk: (link, children visited)
        let mut stack = vec![(0usize, 0usize)];
        while let Some((j, c)) = stack.pop() {
            if c == 0 {
                subtree[j].0 = preorder.len();
                if movable[j] {
                    preorder.push(j);
                }
            }
            if let Some(&k) = children[j].get(c) {
                stack.push((j, c + 1));
                stack.push((k, 0));
            } else {
                subtree[j].1 = preorder.len();
            }
        }
        let serial = (1..=nl).all(|j| movable[j] && frames[j - 1].ant == j - 1);
        let short = (1..=nl)
            .filter(|&j| frames[j - 1].ant != 0)
            .all(|j| subtree[j].1 - subtree[j].0 <= Self::SHORT);
        TreeIndex {
            movable_parent,
            movable,
            preorder,
            subtree,
            serial,
            short,
        }
    }
}

/// All constants of a robot in scalar `T`: the generic layer the recursions run on.
#[derive(Clone, Debug)]
pub struct DynModel<T: DynScalar> {
    /// NL, the links of the (equivalent) tree.
    pub nl: usize,
    /// Frames 1..NF at index j-1.
    pub frames: Vec<FrameConstants<T>>,
    /// Links 1..NL at index j-1.
    pub links: Vec<LinkConstants<T>>,
    /// The description's gravity, base motion and external wrenches (the default per-call
    /// inputs).
    pub env: Environment<T>,
    /// Description link number of each link, whose external wrench (in the per-call
    /// [`Environment`], indexed by description link) the link carries. Empty: link j is link j.
    /// Set by [`DynModel::fold_fixed`].
    pub link_of: Vec<usize>,
    /// Links of the description behind fixed frames whose body is folded into a movable
    /// ancestor ([`DynModel::fold_fixed`]): their external wrench is carried onto it each call.
    pub folded: Vec<FoldedLink<T>>,
    /// Index arrays of the tree (movable parents, preorder, subtrees). Derived from `frames`:
    /// rebuild it with [`TreeIndex::new`] after changing an antecedent or a joint type.
    pub index: TreeIndex,
}

/// A link rigidly attached (through fixed frames only) to a movable link of a folded model.
#[derive(Clone, Debug)]
pub struct FoldedLink<T: DynScalar> {
    /// The movable link (index in the folded model) that carries it.
    pub host: usize,
    /// Its link number in the description (the index of its wrench in an [`Environment`]).
    pub link: usize,
    /// hA_k: its orientation in the host's frame.
    pub rot: Matrix3<T>,
    /// hP_k: its origin in the host's frame.
    pub pos: Vector3<T>,
}

/// Move the inertia (J about O_k, MS, M; components in R_k) of a body rigidly attached to frame
/// R_i, with R = iA_k and p = iP_k, into R_i about O_i (parallel-axis theorem with
/// J = integral of -skew(r)^2 dm, r = p + s, m = R MS):
/// J' = R J R' + M (p'p I - p p') + 2 (p'm) I - m p' - p m',  MS' = m + M p,  M' = M.
/// Returns (J', MS'); the symmetric J' is computed on its upper triangle.
#[inline]
pub fn inertia_to_antecedent<T: DynScalar>(
    r: &Matrix3<T>,
    p: &Vector3<T>,
    j: &Matrix3<T>,
    ms: &Vector3<T>,
    mass: &T,
) -> (Matrix3<T>, Vector3<T>) {
    inertia_transfer(RotationForm::General, r, p, j, ms, mass)
}

/// R v for a rotation `m` of form `form` (its zeros skipped).
#[inline(always)]
fn rot_mul<T: DynScalar>(form: RotationForm, m: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
    let w = [&v.x, &v.y, &v.z];
    match form {
        RotationForm::General => m * v,
        RotationForm::Axis(0) => form_mul::<T, 0>(m, w),
        RotationForm::Axis(1) => form_mul::<T, 1>(m, w),
        RotationForm::Axis(_) => form_mul::<T, 2>(m, w),
    }
}

/// R v for a rotation of form `Axis(K)`, entry by entry ([`form_row`]).
#[inline(always)]
fn form_mul<T: DynScalar, const K: usize>(m: &Matrix3<T>, v: [&T; 3]) -> Vector3<T> {
    let row = |i: usize| form_row::<T, K>(m, i, v);
    Vector3::new(row(0), row(1), row(2))
}

/// R^T v for a rotation of form `Axis(K)`, entry by entry ([`form_col`]).
#[inline(always)]
fn form_tr_mul<T: DynScalar, const K: usize>(m: &Matrix3<T>, v: [&T; 3]) -> Vector3<T> {
    let col = |c: usize| form_col::<T, K>(m, c, v);
    Vector3::new(col(0), col(1), col(2))
}

/// The two row indices other than K (K < 3).
#[inline(always)]
const fn others(k: usize) -> (usize, usize) {
    match k {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// Entry i of R v for a rotation `r` whose row K is (0, 0, r_K2) and whose third column is
/// r_K2 e_K (`RotationForm::Axis(K)`); K = 3: a full rotation. K is a constant, so the zeros
/// are skipped at compile time.
#[inline(always)]
pub(crate) fn form_row<T: DynScalar, const K: usize>(r: &Matrix3<T>, i: usize, v: [&T; 3]) -> T {
    let e = |c: usize| r[(i, c)].clone() * v[c].clone();
    if K == 3 {
        e(0) + e(1) + e(2)
    } else if i == K {
        e(2)
    } else {
        e(0) + e(1)
    }
}

/// Entry c of R^T v for a rotation `r` of form `Axis(K)` (K = 3: a full rotation), as
/// [`form_row`].
#[inline(always)]
pub(crate) fn form_col<T: DynScalar, const K: usize>(r: &Matrix3<T>, c: usize, v: [&T; 3]) -> T {
    let e = |i: usize| r[(i, c)].clone() * v[i].clone();
    if K == 3 {
        e(0) + e(1) + e(2)
    } else if c == 2 {
        e(K)
    } else {
        let (a, b) = others(K);
        e(a) + e(b)
    }
}

/// [`inertia_to_antecedent`] for a rotation of form `form`: R J R^T as (R J) R^T, row b of R
/// being (0, 0, R_k2) for b = k of an `Axis(k)` form, else (R_b0, R_b1, 0).
#[inline]
fn inertia_transfer<T: DynScalar>(
    form: RotationForm,
    r: &Matrix3<T>,
    p: &Vector3<T>,
    j: &Matrix3<T>,
    ms: &Vector3<T>,
    mass: &T,
) -> (Matrix3<T>, Vector3<T>) {
    inertia_transfer_inline(form, r, p, j, ms, mass)
}

/// [`inertia_transfer`], always inlined: the passes over short subtrees of the inertia matrix
/// call it directly (a call per link there costs more than its body, measured).
#[inline(always)]
pub(crate) fn inertia_transfer_inline<T: DynScalar>(
    form: RotationForm,
    r: &Matrix3<T>,
    p: &Vector3<T>,
    j: &Matrix3<T>,
    ms: &Vector3<T>,
    mass: &T,
) -> (Matrix3<T>, Vector3<T>) {
    let m = rot_mul(form, r, ms);
    // with u = m + M p (= MS'): M p p' + m p' + p m' = p u' + m p' and
    // M p'p + 2 p'm = p'(u + m)
    let u = &m + p * mass.clone();
    let diag = p.dot(&(&u + &m));
    let rj = match form {
        RotationForm::General => r * j,
        _ => Matrix3::from_columns(&[
            rot_mul(form, r, &j.column(0).into_owned()),
            rot_mul(form, r, &j.column(1).into_owned()),
            rot_mul(form, r, &j.column(2).into_owned()),
        ]),
    };
    let t = |a: usize, b: usize, c: usize| rj[(a, c)].clone() * r[(b, c)].clone();
    let mut out = Matrix3::zeros();
    for a in 0..3 {
        for b in a..3 {
            let rjr = match form {
                RotationForm::General => t(a, b, 0) + t(a, b, 1) + t(a, b, 2),
                RotationForm::Axis(k) if b == k as usize => t(a, b, 2),
                RotationForm::Axis(_) => t(a, b, 0) + t(a, b, 1),
            };
            let mut v = rjr - p[a].clone() * u[b].clone() - m[a].clone() * p[b].clone();
            if a == b {
                v += diag.clone();
            } else {
                out[(b, a)] = v.clone();
            }
            out[(a, b)] = v;
        }
    }
    (out, u)
}

impl<T: DynScalar> DynModel<T> {
    /// Build from a description, mapping every geometric entry with `geo` and every link entry
    /// (link j, index in the 13 standard parameters or 13..19 for the wrench) with `link`.
    pub fn build(
        desc: &RobotDescription,
        mut geo: impl FnMut(&Expr) -> T,
        mut link: impl FnMut(usize, usize, &Expr) -> T,
    ) -> Self {
        let frames: Vec<_> = desc
            .frames
            .iter()
            .map(|f| FrameConstants::new(f.ant, f.joint, f.geometric().map(&mut geo)))
            .collect();
        let links = desc
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| LinkConstants::new(std::array::from_fn(|k| link(i + 1, k, &l.params[k]))))
            .collect();
        let wrenches = desc
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let mut c = |k: usize| link(i + 1, super::PARAMS_PER_LINK + k, &l.wrench[k]);
                Wrench {
                    force: Vector3::new(c(0), c(1), c(2)),
                    moment: Vector3::new(c(3), c(4), c(5)),
                }
            })
            .collect::<Vec<_>>();
        let v3 = |a: &[Expr; 3], geo: &mut dyn FnMut(&Expr) -> T| {
            Vector3::new(geo(&a[0]), geo(&a[1]), geo(&a[2]))
        };
        let gravity = v3(&desc.gravity, &mut geo);
        let base = BaseMotion {
            w0: v3(&desc.w0, &mut geo),
            wp0: v3(&desc.wp0, &mut geo),
            v0: v3(&desc.v0, &mut geo),
            vp0: v3(&desc.vp0, &mut geo),
        };
        let mut env = Environment::new(gravity, base, desc.nl);
        for (j, w) in wrenches.into_iter().enumerate() {
            env.set_wrench_by_link(j + 1, w.force, w.moment)
                .expect("one wrench per link");
        }
        DynModel {
            nl: desc.nl,
            index: TreeIndex::new(&frames, desc.nl),
            frames,
            links,
            env,
            link_of: Vec::new(),
            folded: Vec::new(),
        }
    }

    /// The description link whose external wrench link j carries (see [`Self::link_of`]).
    #[inline]
    pub fn wrench_link(&self, j: usize) -> usize {
        if self.link_of.is_empty() {
            j
        } else {
            self.link_of[j - 1]
        }
    }

    /// Frame j (1-based).
    #[inline]
    pub fn frame(&self, j: usize) -> &FrameConstants<T> {
        &self.frames[j - 1]
    }

    /// Link j (1-based).
    #[inline]
    pub fn link(&self, j: usize) -> &LinkConstants<T> {
        &self.links[j - 1]
    }
}

impl<T: DynScalar> DynModel<T> {
    /// The model of the dynamic recursions: fixed frames out. Its links are the movable tree
    /// joints 1..NL in frame order (link k is the k-th movable joint, so its tree arrays are
    /// the public joint vectors); the constant placement of the fixed frames between a movable
    /// joint and its nearest movable ancestor is composed into the joint's constants, and the
    /// body of every link behind fixed frames is added to its nearest movable ancestor's body
    /// by the exact rigid-body transfer ([`inertia_to_antecedent`]). Links rigidly attached to
    /// the base are dropped: no joint carries them. Cut-joint frames (NL+1..NF) are not part of
    /// it (the tree recursions never use them).
    ///
    /// Rotor inertia and friction of a fixed frame are ignored, as in the full model (no joint
    /// variable). External wrenches stay indexed by description link ([`Self::link_of`],
    /// [`Self::folded`]), so the per-call [`Environment`] is the description's. Generic over
    /// the scalar: the symbolic generator folds its `DynModel<Expr>` the same way.
    pub fn fold_fixed(&self) -> DynModel<T> {
        let nl = self.nl;
        // red[j]: index of movable frame j in the folded model; 0 for the base
        let mut red = vec![0; nl + 1];
        // for a fixed frame j: (h, hA_j, hP_j) with h its nearest movable ancestor (or 0)
        let mut place: Vec<Placement<T>> = vec![None; nl + 1];
        let mut frames = Vec::new();
        let mut links: Vec<LinkConstants<T>> = Vec::new();
        let mut link_of = Vec::new();
        for j in 1..=nl {
            let fr = self.frame(j);
            // the placement of the antecedent's origin and axes in its nearest movable ancestor
            let (h, pre) = match &place[fr.ant] {
                Some((h, r, p)) => (*h, Some((r, p))),
                None => (fr.ant, None),
            };
            if fr.joint.is_movable() {
                let mut c = fr.clone();
                c.ant = red[h];
                if let Some((r, p)) = pre {
                    c.pre_pos = p + r * &c.pre_pos;
                    let pre_rot = r * &c.pre_rot;
                    c.set_pre_rot(pre_rot);
                }
                frames.push(c);
                links.push(self.link(j).clone());
                link_of.push(j);
                red[j] = frames.len();
            } else {
                let (r, p) = fr.transform(&T::zero());
                place[j] = Some(match pre {
                    Some((ra, pa)) => (h, ra * &r, pa + ra * &p),
                    None => (h, r, p),
                });
            }
        }
        let mut folded = Vec::new();
        for j in 1..=nl {
            let Some((h, r, p)) = &place[j] else { continue };
            if *h == 0 {
                continue;
            }
            let l = self.link(j);
            let (jj, ms) = inertia_to_antecedent(r, p, &l.inertia, &l.ms, &l.mass);
            let host = &mut links[red[*h] - 1];
            host.inertia += jj;
            host.ms += ms;
            host.mass += l.mass.clone();
            folded.push(FoldedLink {
                host: red[*h],
                link: j,
                rot: r.clone(),
                pos: p.clone(),
            });
        }
        for l in links.iter_mut() {
            let i = &l.inertia;
            l.inertia_diff = Vector3::new(
                i[(2, 2)].clone() - i[(1, 1)].clone(),
                i[(0, 0)].clone() - i[(2, 2)].clone(),
                i[(1, 1)].clone() - i[(0, 0)].clone(),
            );
        }
        DynModel {
            nl: frames.len(),
            index: TreeIndex::new(&frames, frames.len()),
            frames,
            links,
            env: self.env.clone(),
            link_of,
            folded,
        }
    }
}

/// Placement of a fixed frame in its nearest movable ancestor h: (h, hA_j, hP_j).
type Placement<T> = Option<(usize, Matrix3<T>, Vector3<T>)>;
