//! Random robots for robodyn's tests and benchmarks (fixed seeds give reproducible robots).
//!
//! One generator shared by the integration tests, the benches and the property tests of every
//! algorithm. The library's own random samples (base parameters, customized models) come from
//! `robodyn`'s internal `sampling` module, never from here.

#![deny(missing_docs)]

use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::Rng;
use robodyn::model::{JointType, LinkDesc, RobotDescription};
use robodyn::{Expr, Robot};

/// Options of the random tree generator.
#[derive(Clone, Debug)]
pub struct TreeOptions {
    /// Probability of a prismatic joint.
    pub p_prismatic: f64,
    /// Probability of a fixed frame (sigma = 2).
    pub p_fixed: f64,
    /// Probability that the antecedent is the previous link (a serial chain when 1).
    pub p_serial: f64,
    /// Use nonzero gamma and b.
    pub general_frames: bool,
    /// Random Coulomb/viscous friction and rotor inertia.
    pub friction: bool,
    /// Random external wrenches.
    pub wrenches: bool,
    /// Gravity in R_0 (random direction when None).
    pub gravity: Option<[f64; 3]>,
}

impl Default for TreeOptions {
    fn default() -> Self {
        TreeOptions {
            p_prismatic: 0.25,
            p_fixed: 0.1,
            p_serial: 0.6,
            general_frames: true,
            friction: true,
            wrenches: true,
            gravity: Some([0.0, 0.0, -9.81]),
        }
    }
}

/// Physically consistent random inertial parameters about O_j: mass, centre of mass c, a random
/// positive definite inertia about the centre of mass, then J_O = J_G + m (c'c I - c c').
pub fn random_inertial<R: Rng>(rng: &mut R) -> [f64; 10] {
    let m = rng.random_range(0.5..5.0);
    let c = Vector3::new(
        rng.random_range(-0.3..0.3),
        rng.random_range(-0.3..0.3),
        rng.random_range(-0.3..0.3),
    );
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let rot = Rotation3::new(axis);
    let pr = Vector3::new(
        rng.random_range(0.01..0.3),
        rng.random_range(0.01..0.3),
        rng.random_range(0.01..0.3),
    );
    let jg = rot.matrix() * Matrix3::from_diagonal(&pr) * rot.matrix().transpose();
    robodyn::model::inertial_parameters(m, &c, &jg)
}

/// A random tree of `n` links with random geometry and parameters.
pub fn random_tree_description<R: Rng>(
    rng: &mut R,
    n: usize,
    opt: &TreeOptions,
) -> RobotDescription {
    let mut d = RobotDescription::new(format!("random tree ({n} links)"), n, n);
    let angle = |rng: &mut R| -> Expr {
        // mix exact multiples of pi/2 with general angles
        if rng.random_bool(0.4) {
            Expr::num(rng.random_range(-3.0..3.0))
        } else {
            Expr::parse(["0", "pi/2", "-pi/2", "pi"][rng.random_range(0..4)]).unwrap()
        }
    };
    for j in 1..=n {
        let ant = if j == 1 || rng.random_bool(opt.p_serial) {
            j - 1
        } else {
            rng.random_range(0..j)
        };
        let u: f64 = rng.random();
        let joint = if u < opt.p_fixed {
            JointType::Fixed
        } else if u < opt.p_fixed + opt.p_prismatic {
            JointType::Prismatic
        } else {
            JointType::Revolute
        };
        let alpha = angle(rng);
        let theta = if rng.random_bool(0.5) {
            angle(rng)
        } else {
            Expr::zero()
        };
        let (gamma, b) = if opt.general_frames && rng.random_bool(0.5) {
            (angle(rng), Expr::num(rng.random_range(-0.5..0.5)))
        } else {
            (Expr::zero(), Expr::zero())
        };
        let f = d.frame_mut(j);
        f.ant = ant;
        f.joint = joint;
        f.actuated = joint.is_movable();
        f.gamma = gamma;
        f.b = b;
        f.alpha = alpha;
        f.d = Expr::num(rng.random_range(-0.5..0.5));
        f.theta = theta;
        f.r = Expr::num(rng.random_range(-0.5..0.5));
        let mut l = LinkDesc::zero(format!("link{j}"));
        for (k, v) in random_inertial(rng).iter().enumerate() {
            l.params[k] = Expr::num(*v);
        }
        if opt.friction && joint.is_movable() {
            l.params[10] = Expr::num(rng.random_range(0.0..0.5));
            l.params[11] = Expr::num(rng.random_range(0.0..2.0));
            l.params[12] = Expr::num(rng.random_range(0.0..2.0));
        }
        if opt.wrenches && rng.random_bool(0.3) {
            for w in l.wrench.iter_mut() {
                *w = Expr::num(rng.random_range(-5.0..5.0));
            }
        }
        d.links[j - 1] = l;
    }
    let g = opt.gravity.unwrap_or_else(|| {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize()
            * 9.81;
        [v.x, v.y, v.z]
    });
    d.gravity = g.map(Expr::num);
    d
}

/// A validated random tree.
pub fn random_tree<R: Rng>(rng: &mut R, n: usize, opt: &TreeOptions) -> Robot {
    Robot::new(random_tree_description(rng, n, opt)).expect("random trees are valid")
}

/// A validated random tree with a floating base: link 0 with random physical inertial
/// parameters ([`random_inertial`]).
pub fn random_floating_tree<R: Rng>(rng: &mut R, n: usize, opt: &TreeOptions) -> Robot {
    let mut d = random_tree_description(rng, n, opt);
    let mut base = LinkDesc::zero("base");
    for (k, v) in random_inertial(rng).iter().enumerate() {
        base.params[k] = Expr::num(*v);
    }
    d.floating_base = Some(base);
    Robot::new(d).expect("random floating trees are valid")
}

/// A random state (q, v, a) of a floating robot with `n` joints: q = [p, unit quaternion
/// (x, y, z, w), joints] (nq = 7 + n), v and a over nv = 6 + n.
pub fn random_floating_state<R: Rng>(rng: &mut R, n: usize) -> [Vec<f64>; 3] {
    let [qj, vj, aj] = random_state(rng, n + 6);
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let quat = nalgebra::UnitQuaternion::new(axis * rng.random_range(0.0..3.0));
    let mut q = qj[..3].to_vec();
    q.extend([quat.i, quat.j, quat.k, quat.w]);
    q.extend_from_slice(&qj[6..]);
    [q, vj, aj]
}

/// A random state (q, qd, qdd) for `n` joints.
pub fn random_state<R: Rng>(rng: &mut R, n: usize) -> [Vec<f64>; 3] {
    let mut v = |s: f64| {
        (0..n)
            .map(|_| rng.random_range(-s..s))
            .collect::<Vec<f64>>()
    };
    [v(3.0), v(2.0), v(5.0)]
}

/// The deterministic RNG used by tests and benches.
pub fn rng(seed: u64) -> rand_chacha::ChaCha8Rng {
    use rand::SeedableRng;
    rand_chacha::ChaCha8Rng::seed_from_u64(seed)
}
