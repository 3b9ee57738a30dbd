//! A serial chain in canonical form: T(theta) = C0 Rz(theta_1) C1 Rz(theta_2) ... Rz(theta_n) Cn,
//! the constant transforms C_k gathering the fixed frames and the constant parts of the joints'
//! placements (KK: iT_j = Trans(pre_pos) Rot(Rz(gamma) Rx(alpha)) Rz(theta) Trans(0, 0, r)).

use crate::error::{Error, Item, Result};
use crate::geometry::{local_transform, Transform};
use crate::model::{JointType, Robot};
use nalgebra::{Matrix3, Vector3};

/// The revolute chain from the base to one frame, its joints' constants and limits.
#[derive(Clone, Debug)]
pub(crate) struct Chain {
    /// C_0 .. C_n.
    pub c: Vec<Transform>,
    /// theta = q + theta0 per joint.
    pub theta0: Vec<f64>,
    /// Index of each chain joint in the robot's movable-joint vector.
    pub coord: Vec<usize>,
    /// Lower and upper position limits (-inf, +inf when absent).
    pub limits: Vec<(f64, f64)>,
    /// A length scale of the chain (sum of the constant offsets, at least 1e-3 m).
    pub scale: f64,
}

/// The frames from the base (excluded) to `frame` (included).
pub(crate) fn path(robot: &Robot, frame: usize) -> Vec<usize> {
    let mut p = Vec::new();
    let mut k = frame;
    while k != 0 {
        p.push(k);
        k = robot.ant(k);
    }
    p.reverse();
    p
}

/// Check that `frame` is a frame of the robot's tree (1..=NL, or a fixed frame beyond NJ).
pub(crate) fn check_frame(robot: &Robot, frame: usize) -> Result<()> {
    let in_tree = (1..=robot.nl()).contains(&frame) || (robot.nj() < frame && frame <= robot.nf());
    if in_tree {
        Ok(())
    } else {
        let fixed = if robot.nf() > robot.nj() {
            format!(" and the fixed frames {}..{}", robot.nj() + 1, robot.nf())
        } else {
            String::new()
        };
        let what = if frame == 0 {
            "the base frame does not move: it is no placement target".to_string()
        } else {
            "no such frame for a placement target".to_string()
        };
        Err(Error::invalid(
            Item::Frame(frame, None),
            format!("{what}: the link frames 1..{}{fixed} are", robot.nl()),
        ))
    }
}

/// The default terminal frame: the frame farthest from the base (most frames on its path)
/// whose path holds every movable joint; an error when there is none or several tie (a tree:
/// name the frame).
pub(crate) fn terminal_frame(robot: &Robot) -> Result<usize> {
    let movable = robot.coordinates().frames();
    let mut best: Vec<(usize, usize)> = Vec::new();
    for j in (1..=robot.nl()).chain(robot.nj() + 1..=robot.nf()) {
        let p = path(robot, j);
        if movable.iter().all(|m| p.contains(m)) {
            best.push((p.len(), j));
        }
    }
    best.sort_unstable();
    match best.as_slice() {
        [.., (l1, _), (l2, j)] if l1 < l2 => Ok(*j),
        [(_, j)] => Ok(*j),
        _ => Err(Error::Input(format!(
            "{}: no single frame ends a chain through every movable joint: name the frame \
             whose placement is the target",
            robot.name()
        ))),
    }
}

impl Chain {
    /// The chain from the base to `frame`: every joint on the path revolute, the movable joints
    /// that are not on the path ignored.
    pub fn new(robot: &Robot, frame: usize) -> Result<Chain> {
        super::refuse_floating(robot, "the closed-form inverse geometric model")?;
        check_frame(robot, frame)?;
        let mut chain = Chain {
            c: Vec::new(),
            theta0: Vec::new(),
            coord: Vec::new(),
            limits: Vec::new(),
            scale: 0.0,
        };
        let mut acc = Transform::identity();
        for j in path(robot, frame) {
            let fc = robot.numeric().frame(j);
            match fc.joint {
                JointType::Fixed => acc = acc.compose(&local_transform(robot, j, 0.0)),
                JointType::Prismatic => {
                    return Err(Error::invalid(
                        Item::Frame(j, Some("sigma".into())),
                        "a prismatic joint on the path: the closed-form inverse geometric model \
                         handles revolute chains only (use the numeric inverse geometric model)",
                    ))
                }
                JointType::Revolute => {
                    let pre = Transform {
                        rot: *fc.pre_rot(),
                        pos: fc.pre_pos,
                    };
                    chain.c.push(acc.compose(&pre));
                    acc = Transform {
                        rot: Matrix3::identity(),
                        pos: Vector3::new(0.0, 0.0, fc.r0),
                    };
                    chain.theta0.push(wrap(fc.theta0));
                    chain
                        .coord
                        .push(robot.coordinates().index_of_frame(j).ok_or_else(|| {
                            Error::Input(format!("frame {j} is not a movable joint"))
                        })?);
                    let lim = robot.description().limits.get(&j);
                    chain.limits.push((
                        lim.and_then(|l| l.q_min).unwrap_or(f64::NEG_INFINITY),
                        lim.and_then(|l| l.q_max).unwrap_or(f64::INFINITY),
                    ));
                }
            }
        }
        chain.c.push(acc);
        chain.scale = chain.c.iter().map(|c| c.pos.norm()).sum::<f64>().max(1e-3);
        Ok(chain)
    }

    /// Whether every joint's limits hold the whole turn [-pi, pi] (no limits, or wider ones:
    /// a UR arm's ±2 pi): a joint value wrapped to (-pi, pi] then lies within them as it is,
    /// and [`Self::joint_value`] is the wrap alone.
    pub fn wraps_within_limits(&self) -> bool {
        use std::f64::consts::PI;
        self.limits.iter().all(|&(lo, hi)| lo <= -PI && hi >= PI)
    }

    /// Number of joints.
    pub fn n(&self) -> usize {
        self.theta0.len()
    }

    /// The joint value of angle `theta` of joint k, wrapped to (-pi, pi] and then moved by a
    /// turn into the joint's limits when a turn does; whether it lies within them.
    #[inline]
    pub fn joint_value(&self, k: usize, theta: f64) -> (f64, bool) {
        use std::f64::consts::TAU;
        let q = wrap_near(theta - self.theta0[k]);
        let (lo, hi) = self.limits[k];
        let inside = |x: f64| lo <= x && x <= hi;
        if inside(q) {
            return (q, true);
        }
        for shifted in [q + TAU, q - TAU] {
            if inside(shifted) {
                return (shifted, true);
            }
        }
        (q, false)
    }
}

/// x wrapped to (-pi, pi], for x = theta - theta0 with theta0 in (-pi, pi] and theta from
/// atan2 and acos sums (within a turn and a half): one conditional turn, [`wrap`] only beyond.
#[inline]
pub(crate) fn wrap_near(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let q = if x > PI {
        x - TAU
    } else if x <= -PI {
        x + TAU
    } else {
        x
    };
    if -PI < q && q <= PI {
        q
    } else {
        wrap(q)
    }
}

/// x wrapped to (-pi, pi] (x itself when it is not finite).
#[cold]
fn wrap(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    if !x.is_finite() {
        return x;
    }
    let mut q = x.rem_euclid(TAU);
    if q > PI {
        q -= TAU;
    }
    q
}
