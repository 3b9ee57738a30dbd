//! Customized geometric and kinematic models (SYMORO's DGM and Jacobian): the transformation
//! iT_j between two frames and the Jacobian iJ_j of frame j expressed in frame i, written on
//! symbols so that the zeros and constants of the geometry vanish.
//!
//! Both walk the tree from the reference frame i to frame j: up from i to the deepest common
//! ancestor c of i and j (iT_a(k) = iT_k (a(k)T_k)^-1), then down from c to j (iT_k = iT_a(k)
//! a(k)T_k). A rotation about z is kept pending while the following joint axes stay parallel
//! (their constant rotation is a rotation about z, alpha = 0): the rotation of frame 3 of a chain
//! whose axes 2 and 3 are parallel is M Rz(theta2 + theta3), with C23 = C2 C3 - S2 S3 and
//! S23 = S2 C3 + C2 S3 named once (SYMORO's grouping), and M multiplied out only where an axis
//! turns. The Jacobian's column of joint k (on the path from the base to j) is, with ia_k the
//! z axis of frame k and iL_kj = iP_j - iP_k, [ia_k x iL_kj; ia_k] for a revolute joint and
//! [ia_k; 0] for a prismatic one, rows [linear; angular] (the velocity of the origin O_j and the
//! angular velocity of frame j, both expressed in frame i).

use super::{joint_symbol, pair_name};
use crate::error::{Error, Result};
use crate::model::{DynModel, FrameConstants, JointType, RobotDescription};
use crate::scalar::DynScalar;
use nalgebra::{Matrix3, Vector3};
use robodyn_symbolic::{Assignment, Expr};

/// The frames of the geometric model (iT_j) and of the Jacobian (iJ_j).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frames {
    /// Frame j: any frame 1..NL of the (equivalent) tree, fixed frames included. `None`: the
    /// terminal frame, the one link that carries no other and is moved by a joint (an error
    /// names the candidates when the robot has several).
    pub frame: Option<usize>,
    /// Reference frame i, 0..NL: the DGM gives iT_j, the Jacobian is expressed in frame i
    /// (0: the base frame, Pinocchio's `LOCAL_WORLD_ALIGNED`). `None`: frame j itself (the
    /// Jacobian jJ_j, Pinocchio's `LOCAL`; the DGM jT_j is the identity).
    pub reference: Option<usize>,
}

impl Frames {
    /// 0T_n and 0J_n of the terminal frame n.
    pub const TERMINAL: Frames = Frames {
        frame: None,
        reference: Some(0),
    };

    /// The frame numbers (i, j) for a robot: the terminal frame found, both checked.
    pub fn resolve(&self, desc: &RobotDescription) -> Result<(usize, usize)> {
        let nl = desc.nl;
        let check = |k: usize, option: &'static str, what: &str| {
            if k > nl {
                Err(Error::Setting {
                    option,
                    reason: format!(
                        "{what} {k} is not a frame of the tree ({} has frames 0..{nl}; the \
                         cut-joint frames of a closed chain are not part of the geometric model)",
                        desc.name
                    ),
                })
            } else {
                Ok(k)
            }
        };
        let j = match self.frame {
            Some(0) => {
                return Err(Error::Setting {
                    option: "codegen::Frames::frame",
                    reason: "frame 0 is the base: choose a frame 1..NL".into(),
                })
            }
            Some(j) => check(j, "codegen::Frames::frame", "frame")?,
            None => terminal_frame(desc)?,
        };
        let i = match self.reference {
            Some(i) => check(i, "codegen::Frames::reference", "reference frame")?,
            None => j,
        };
        Ok((i, j))
    }
}

impl Default for Frames {
    fn default() -> Self {
        Frames::TERMINAL
    }
}

/// The one link of the tree that carries no other frame (cut joints included) and is moved by a
/// joint, or an error naming the candidates.
fn terminal_frame(desc: &RobotDescription) -> Result<usize> {
    let nl = desc.nl;
    let mut carries = vec![false; nl + 1];
    for k in 1..=desc.nj {
        carries[desc.frame(k).ant] = true;
    }
    // a frame rigidly fixed to the base (no movable joint on its path) is not a candidate
    let mut moves = vec![false; nl + 1];
    for j in 1..=nl {
        let f = desc.frame(j);
        moves[j] = moves[f.ant] || f.joint.is_movable();
    }
    let terminal: Vec<usize> = (1..=nl).filter(|&j| !carries[j] && moves[j]).collect();
    match terminal.as_slice() {
        [j] => Ok(*j),
        _ => Err(Error::Setting {
            option: "codegen::Frames::frame",
            reason: format!(
                "{} has {} terminal links ({}): choose the frame of the model",
                desc.name,
                terminal.len(),
                terminal
                    .iter()
                    .map(|&j| match desc.frame(j).name.as_str() {
                        "" => j.to_string(),
                        name => format!("{j} `{name}`"),
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }),
    }
}

/// The names of the DGM's outputs: iT_j = [s n a P] column by column (SYMORO's names).
pub const DGM_OUTPUTS: [&str; 12] = [
    "sx", "sy", "sz", "nx", "ny", "nz", "ax", "ay", "az", "Px", "Py", "Pz",
];

/// iT_k during the walk: rotation M Rz(phi) with the rotation phi about z pending (its cosine,
/// sine and the joints it sums), and the origin P.
#[derive(Clone)]
struct Placement {
    m: Matrix3<Expr>,
    c: Expr,
    s: Expr,
    joints: Vec<(usize, bool)>,
    pos: Vector3<Expr>,
}

impl Placement {
    fn identity() -> Placement {
        Placement {
            m: Matrix3::identity(),
            c: Expr::one(),
            s: Expr::zero(),
            joints: Vec::new(),
            pos: Vector3::zeros(),
        }
    }

    /// The z axis of the frame (Rz leaves it unchanged): M's third column.
    fn axis(&self) -> Vector3<Expr> {
        self.m.column(2).into_owned()
    }

    /// iA_k v = M (Rz(phi) v).
    fn rotate(&self, v: &Vector3<Expr>) -> Vector3<Expr> {
        let u = Vector3::new(
            self.c.clone() * v.x.clone() - self.s.clone() * v.y.clone(),
            self.s.clone() * v.x.clone() + self.c.clone() * v.y.clone(),
            v.z.clone(),
        );
        &self.m * u
    }

    /// iA_k = M Rz(phi).
    fn rotation(&self) -> Matrix3<Expr> {
        let (x, y) = (self.m.column(0), self.m.column(1));
        let cx = &x * self.c.clone() + &y * self.s.clone();
        let cy = y * self.c.clone() - x * self.s.clone();
        Matrix3::from_columns(&[cx, cy, self.m.column(2).into_owned()])
    }

    /// phi += the angle of (cos, sin); joint `j` (if any; `true` when its angle is subtracted)
    /// joins the sum, whose cosine and sine are named `C<joints>`, `S<joints>` once it sums two
    /// joint angles or more of the same sign (`S23` = sin(theta2 + theta3); phi = -(theta2 +
    /// theta3) has sine -S23).
    fn turn(&mut self, cos: Expr, sin: Expr, j: Option<(usize, bool)>) {
        let c = self.c.clone() * cos.clone() - self.s.clone() * sin.clone();
        let s = self.s.clone() * cos + self.c.clone() * sin;
        self.joints.extend(j);
        let negative = self.joints.first().is_some_and(|&(_, n)| n);
        let same_sign = self.joints.iter().all(|&(_, n)| n == negative);
        if self.joints.len() >= 2 && j.is_some() && same_sign {
            let mut numbers: Vec<usize> = self.joints.iter().map(|&(k, _)| k).collect();
            numbers.sort_unstable();
            let label = joints_label(&numbers);
            self.c = c.named(|| format!("C{label}"));
            self.s = if negative {
                -(-s).named(|| format!("S{label}"))
            } else {
                s.named(|| format!("S{label}"))
            };
        } else {
            self.c = c;
            self.s = s;
        }
    }

    /// M = M Rz(phi) r with phi applied (no rotation pending), the entries named `R<i>_<x>_<r><c>`.
    fn multiply_out(&mut self, r: &Matrix3<Expr>, i: usize, x: usize) {
        let m = self.rotation() * r;
        self.m = Matrix3::from_fn(|a, b| {
            m[(a, b)]
                .clone()
                .named(|| format!("R{i}_{x}_{}{}", a + 1, b + 1))
        });
        self.c = Expr::one();
        self.s = Expr::zero();
        self.joints.clear();
    }

    fn name_position(&mut self, i: usize, x: usize) {
        self.pos =
            Vector3::from_fn(|a, _| self.pos[a].clone().named(|| format!("P{i}_{x}_{}", a + 1)));
    }

    /// iT_k = iT_a(k) a(k)T_k(q_k).
    fn down(&mut self, f: &FrameConstants<Expr>, k: usize, i: usize) {
        let (theta, r) = variables(f, k);
        let pre = f.pre_rot();
        let v = &f.pre_pos + pre.column(2) * r;
        self.pos = &self.pos + self.rotate(&v);
        self.name_position(i, k);
        if is_z_rotation(pre) {
            self.turn(pre[(0, 0)].clone(), pre[(1, 0)].clone(), None);
        } else {
            self.multiply_out(pre, i, k);
        }
        let joint = (f.joint == JointType::Revolute).then_some((k, false));
        self.turn(DynScalar::cos(&theta), DynScalar::sin(&theta), joint);
    }

    /// iT_a(k) = iT_k (a(k)T_k(q_k))^-1.
    fn up(&mut self, f: &FrameConstants<Expr>, k: usize, i: usize) {
        let (theta, r) = variables(f, k);
        let joint = (f.joint == JointType::Revolute).then_some((k, true));
        self.turn(DynScalar::cos(&theta), -DynScalar::sin(&theta), joint);
        // iP_a(k) = iP_k - iA_k Rz(theta)^T pre^T a(k)P_k = iP_k - M Rz(phi - theta) w
        let pre_t = f.pre_rot().transpose();
        let w = &pre_t * &f.pre_pos + Vector3::new(Expr::zero(), Expr::zero(), r);
        self.pos = &self.pos - self.rotate(&w);
        self.name_position(i, f.ant);
        if is_z_rotation(&pre_t) {
            self.turn(pre_t[(0, 0)].clone(), pre_t[(1, 0)].clone(), None);
        } else {
            self.multiply_out(&pre_t, i, f.ant);
        }
    }
}

/// `23`, or `2_10` when a joint number has two digits.
fn joints_label(joints: &[usize]) -> String {
    let sep = if joints.iter().all(|&j| j < 10) {
        ""
    } else {
        "_"
    };
    joints
        .iter()
        .map(|j| j.to_string())
        .collect::<Vec<_>>()
        .join(sep)
}

/// True when `r` is a rotation about z (its third row and column are e_z): the axes before and
/// after it are parallel.
fn is_z_rotation(r: &Matrix3<Expr>) -> bool {
    r[(2, 2)].is_one()
        && [(0, 2), (1, 2), (2, 0), (2, 1)]
            .iter()
            .all(|&e| r[e].is_zero())
}

/// (theta, r) of frame k: the constant parts plus the joint variable q<k>.
fn variables(f: &FrameConstants<Expr>, k: usize) -> (Expr, Expr) {
    let q = || Expr::symbol(joint_symbol("q", k));
    match f.joint {
        JointType::Revolute => (f.theta0.clone() + q(), f.r0.clone()),
        JointType::Prismatic => (f.theta0.clone(), f.r0.clone() + q()),
        JointType::Fixed => (f.theta0.clone(), f.r0.clone()),
    }
}

/// Frames from the base to k: [0, ..., a(k), k] (k = 0: [0]).
fn path_from_base(model: &DynModel<Expr>, k: usize) -> Vec<usize> {
    let mut p = vec![k];
    let mut x = k;
    while x != 0 {
        x = model.frame(x).ant;
        p.push(x);
    }
    p.reverse();
    p
}

/// The walk from i to j: iT_x for x = i, a(i), ..., 0 (up, every ancestor of i, with `to_base`;
/// else up to the common ancestor c only) and for x on the path from c down to j. Returned as
/// (frame, placement) pairs.
fn walk(model: &DynModel<Expr>, i: usize, j: usize, to_base: bool) -> Vec<(usize, Placement)> {
    let (pi, pj) = (path_from_base(model, i), path_from_base(model, j));
    let common = pi.iter().zip(&pj).take_while(|(a, b)| a == b).count();
    let c = pj[common - 1];
    let mut out = Vec::new();
    let mut t = Placement::identity();
    out.push((i, t.clone()));
    let mut at_c = (i == c).then(|| t.clone());
    let mut x = i;
    while x != 0 && (to_base || x != c) {
        t.up(model.frame(x), x, i);
        x = model.frame(x).ant;
        out.push((x, t.clone()));
        if x == c {
            at_c = Some(t.clone());
        }
    }
    let mut t = at_c.expect("the common ancestor is on the way up from i");
    for &k in &pj[common..] {
        t.down(model.frame(k), k, i);
        out.push((k, t.clone()));
    }
    out
}

/// The outputs of the DGM iT_j ([`DGM_OUTPUTS`]).
pub(super) fn dgm(model: &DynModel<Expr>, i: usize, j: usize) -> Vec<Assignment> {
    let placements = walk(model, i, j, false);
    let (_, t) = placements.last().expect("the walk has a start");
    let r = t.rotation();
    let values = (0..3)
        .flat_map(|c| (0..3).map(move |a| (a, c)))
        .map(|e| r[e].clone())
        .chain(t.pos.iter().cloned());
    DGM_OUTPUTS
        .iter()
        .zip(values)
        .map(|(name, expr)| Assignment {
            name: name.to_string(),
            expr,
        })
        .collect()
}

/// The outputs of the Jacobian iJ_j: 6 rows [linear; angular] by one column per movable joint
/// in `joints` (frame order), row by row, named `J<row><joint>`; a joint that does not move
/// frame j has a zero column.
pub(super) fn jacobian(
    model: &DynModel<Expr>,
    i: usize,
    j: usize,
    joints: &[usize],
) -> Vec<Assignment> {
    let placements = walk(model, i, j, true);
    let at = |x: usize| {
        placements
            .iter()
            .rev()
            .find(|(f, _)| *f == x)
            .map(|(_, t)| t)
            .expect("every frame on the path to j is visited")
    };
    let on_path = path_from_base(model, j);
    let pj = at(j).pos.clone();
    let zero = || Vector3::from_element(Expr::zero());
    let columns: Vec<[Vector3<Expr>; 2]> = joints
        .iter()
        .map(|&k| {
            if !on_path.contains(&k) {
                return [zero(), zero()];
            }
            let t = at(k);
            let a = t.axis();
            match model.frame(k).joint {
                JointType::Revolute => [a.cross(&(&pj - &t.pos)), a],
                _ => [a, zero()],
            }
        })
        .collect();
    let mut out = Vec::with_capacity(6 * joints.len());
    for row in 0..6 {
        for (col, &k) in columns.iter().zip(joints) {
            out.push(Assignment {
                name: pair_name("J", row + 1, k),
                expr: col[row / 3][row % 3].clone(),
            });
        }
    }
    out
}

/// The header lines of a geometric or kinematic model.
pub(super) fn describe(
    desc: &RobotDescription,
    kind: super::ModelKind,
    i: usize,
    j: usize,
    numeric: bool,
) -> Vec<String> {
    let frame = |k: usize| match desc.frames.get(k.wrapping_sub(1)).map(|f| f.name.as_str()) {
        Some(name) if !name.is_empty() => format!("frame {k} ({name})"),
        _ if k == 0 => "frame 0 (base)".to_string(),
        _ => format!("frame {k}"),
    };
    let expressed = match i {
        0 => " (the base frame: LOCAL_WORLD_ALIGNED)".to_string(),
        _ if i == j => " (its own frame: LOCAL)".to_string(),
        _ => String::new(),
    };
    let what = match kind {
        super::ModelKind::Dgm(_) => format!(
            "direct geometric model {i}T{j}: {} in {}, outputs [s n a P] column by column \
             (sx sy sz nx ny nz ax ay az Px Py Pz)",
            frame(j),
            frame(i)
        ),
        _ => format!(
            "Jacobian {i}J{j} of {} expressed in {}{expressed}: rows [linear; angular] (the \
             velocity of its origin, its angular velocity), one column per movable joint, \
             outputs row by row (J<row><joint>)",
            frame(j),
            frame(i)
        ),
    };
    vec![
        format!("{} -- {what}", desc.name),
        "Generated by robodyn (robodyn generate); do not edit.".to_string(),
        format!(
            "Options: {}",
            if numeric {
                "numeric values substituted"
            } else {
                "geometric symbols kept"
            }
        ),
    ]
}
