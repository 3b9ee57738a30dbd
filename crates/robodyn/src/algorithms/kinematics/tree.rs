//! The tree the kinematic passes run on (Pinocchio's model): the movable joints only, link k
//! (1..N) the k-th movable joint, so that its arrays are the public joint vectors; every frame
//! of the description anchored on its nearest movable ancestor at a constant placement, and
//! the bodies of the links behind fixed frames added to that ancestor's. Built once per
//! [`KinematicsData`](super::KinematicsData) from the robot's constants.

use crate::geometry::Transform;
use crate::model::{FrameConstants, JointType, Robot, RotationForm};
use nalgebra::{Matrix3, Vector3};

/// Where a description frame is: on link `link` of the moving tree (0 the base) at the
/// constant placement `t` (`identity` when `t` is the identity: a movable joint's own frame).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Anchor {
    pub link: usize,
    pub t: Transform,
    pub identity: bool,
}

/// The moving tree of a robot: per link k = 1..N its frame constants (antecedent a moving
/// link, the fixed frames before it composed into `pre_rot`, `pre_pos`), per description frame
/// 0..NF its anchor, and per link 0..N the body of every moving description link anchored on
/// it (mass, first moment in the link's axes): links rigidly attached to the base carry no
/// joint and are not counted, as in the dynamic model.
#[derive(Clone, Debug)]
pub(crate) struct MovingTree {
    frames: Vec<FrameConstants<f64>>,
    /// Per link 0..N its antecedent (0 for the base itself): the support walks read this
    /// compact array, not the frame constants.
    pub parent: Vec<usize>,
    /// Per link 0..N whether its joint is revolute (false for the base).
    pub revolute: Vec<bool>,
    pub anchor: Vec<Anchor>,
    pub mass: Vec<f64>,
    pub ms: Vec<Vector3<f64>>,
}

impl MovingTree {
    pub fn new(robot: &Robot) -> MovingTree {
        let c = robot.coordinates();
        let anchor: Vec<Anchor> = (0..=robot.nf()).map(|j| anchor_of(robot, j)).collect();
        let frames: Vec<FrameConstants<f64>> = c
            .frames()
            .iter()
            .map(|&j| {
                let mut fc = robot.numeric().frame(j).clone();
                let a = anchor[fc.ant];
                fc.ant = a.link;
                if !a.identity {
                    fc.pre_pos = a.t.pos + a.t.rot * fc.pre_pos;
                    fc.set_pre_rot(a.t.rot * fc.pre_rot());
                }
                fc
            })
            .collect();
        let parent: Vec<usize> = std::iter::once(0)
            .chain(frames.iter().map(|fc| fc.ant))
            .collect();
        let revolute: Vec<bool> = std::iter::once(false)
            .chain(frames.iter().map(|fc| fc.joint == JointType::Revolute))
            .collect();
        let mut tree = MovingTree {
            frames,
            parent,
            revolute,
            anchor,
            mass: vec![0.0; c.len() + 1],
            ms: vec![Vector3::zeros(); c.len() + 1],
        };
        let (mut mass, mut ms) = (vec![0.0; c.len() + 1], vec![Vector3::zeros(); c.len() + 1]);
        tree.bodies(robot, |_| true, &mut mass, &mut ms);
        if let Some(base) = robot.floating_base() {
            // link 0 and the links fixed on it, about O_0 in R_0
            (mass[0], ms[0]) = (base.body.mass, base.body.ms);
        }
        (tree.mass, tree.ms) = (mass, ms);
        tree
    }

    /// Link k's frame constants (1..N).
    #[inline]
    pub fn frame(&self, k: usize) -> &FrameConstants<f64> {
        &self.frames[k - 1]
    }

    /// Number of moving links N.
    #[inline]
    pub fn n(&self) -> usize {
        self.frames.len()
    }

    /// Per moving link 0..N, the mass and first moment (in its axes) of the description links
    /// 1..NL anchored on it for which `member` holds (links on a fixed base left out).
    pub fn bodies(
        &self,
        robot: &Robot,
        member: impl Fn(usize) -> bool,
        mass: &mut [f64],
        ms: &mut [Vector3<f64>],
    ) {
        mass.fill(0.0);
        ms.fill(Vector3::zeros());
        let floating = robot.is_floating();
        for j in 1..=robot.nl() {
            let a = &self.anchor[j];
            if (a.link == 0 && !floating) || !member(j) {
                continue;
            }
            let l = robot.numeric().link(j);
            mass[a.link] += l.mass;
            ms[a.link] += l.mass * a.t.pos + a.t.rot * l.ms;
        }
    }
}

/// The anchor of description frame j: its nearest movable tree joint at or before it (0 the
/// base) and the placement through the fixed frames between them (cut joints at variable 0).
pub(crate) fn anchor_of(robot: &Robot, j: usize) -> Anchor {
    let c = robot.coordinates();
    let mut t = Transform::identity();
    let mut identity = true;
    let mut i = j;
    loop {
        if i == 0 {
            break;
        }
        if i <= robot.nl() {
            if let Some(k) = c.index_of_frame(i) {
                return Anchor {
                    link: k + 1,
                    t,
                    identity,
                };
            }
        }
        let (r, p) = robot.numeric().frame(i).transform(&0.0);
        t = Transform { rot: r, pos: p }.compose(&t);
        identity = false;
        i = robot.ant(i);
    }
    Anchor {
        link: 0,
        t,
        identity,
    }
}

/// A B for a rotation B = pre_rot Rz(theta) of form `form` (its zeros skipped: for `Axis(k)`,
/// B's third column is ±e_k and row k of its first two columns zero, 12 products instead of 27).
#[inline(always)]
pub(crate) fn mul_form(a: &Matrix3<f64>, b: &Matrix3<f64>, form: RotationForm) -> Matrix3<f64> {
    match form {
        RotationForm::General => a * b,
        RotationForm::Axis(0) => mul_axis::<0, 1, 2>(a, b),
        RotationForm::Axis(1) => mul_axis::<1, 0, 2>(a, b),
        RotationForm::Axis(_) => mul_axis::<2, 0, 1>(a, b),
    }
}

/// [`mul_form`] for `Axis(K)`, I0 and I1 the two other indices: column c < 2 of A B is
/// A_I0 B[I0, c] + A_I1 B[I1, c], the third A_K B[K, 2]. The indices are constants, so the
/// columns are fixed offsets (a closure over run-time indices was compiled as a call per
/// column, a fifth of the placement pass).
#[inline(always)]
fn mul_axis<const K: usize, const I0: usize, const I1: usize>(
    a: &Matrix3<f64>,
    b: &Matrix3<f64>,
) -> Matrix3<f64> {
    let (x, y) = (a.column(I0), a.column(I1));
    let c0 = x * b[(I0, 0)] + y * b[(I1, 0)];
    let c1 = x * b[(I0, 1)] + y * b[(I1, 1)];
    Matrix3::from_columns(&[c0, c1, a.column(K) * b[(K, 2)]])
}

/// A B for a rotation A = pre_rot Rz(theta) of form `form` (its zeros skipped: for `Axis(k)`,
/// A's row k is (0, 0, ±1), so row k of A B is ±B's row 2: 18 products instead of 27).
#[inline(always)]
pub(crate) fn form_mul(a: &Matrix3<f64>, b: &Matrix3<f64>, form: RotationForm) -> Matrix3<f64> {
    match form {
        RotationForm::General => a * b,
        RotationForm::Axis(k) => {
            let k = k as usize;
            let row = |i: usize| {
                if i == k {
                    b.row(2) * a[(k, 2)]
                } else {
                    a.row(i) * b
                }
            };
            Matrix3::from_rows(&[row(0), row(1), row(2)])
        }
    }
}

/// A v for a rotation A of form `form` (row k of A is (0, 0, ±1) for `Axis(k)`).
#[inline(always)]
pub(crate) fn form_mul_vector(
    a: &Matrix3<f64>,
    v: &Vector3<f64>,
    form: RotationForm,
) -> Vector3<f64> {
    match form {
        RotationForm::General => a * v,
        RotationForm::Axis(k) => {
            let k = k as usize;
            Vector3::from_fn(|i, _| {
                if i == k {
                    a[(k, 2)] * v.z
                } else {
                    a.row(i).transpose().dot(v)
                }
            })
        }
    }
}
