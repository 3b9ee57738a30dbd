//! robodyn side of the side-by-side benchmark against Pinocchio (`benches/peers/run.py`; not run
//! by CI). Every call into robodyn is in this file.
//!
//! ```text
//! cargo run --release --example peer_timing -- URDF STATES RESULTS [--samples N] [--target-us T]
//! ```
//!
//! Loads the URDF with robodyn's loader, zeroes the rotor inertias and friction (Pinocchio's
//! algorithms have neither), reads the states written by `run.py` (joints named as in the URDF,
//! in Pinocchio's order), writes every algorithm's result on every state to RESULTS in that order
//! (the agreement check) and prints `time <algorithm> <median ns per call>` lines: a sample times
//! loops over all states, repeated so that it lasts about T microseconds; the median over the
//! samples is printed (the same protocol as `pinocchio_peer.cpp`).
//!
//! With `--floating`, the URDF's root link becomes a free-flyer base (Pinocchio's
//! `JointModelFreeFlyer` root): the states then hold q (nq = 7 + N), v, a, tau (nv = 6 + N), the
//! first name of the states file is Pinocchio's root joint, and only the dynamics (rnea, crba,
//! aba, composite) are written and timed.
//!
//! `peer_timing --batch URDF N` times `inverse_dynamics_batch` on N random states with a rayon
//! pool of 1 and of 2 threads, 15 pairs run back to back, and prints the median ratio.

use nalgebra::DMatrix;
use robodyn::algorithms::derivatives::{
    direct_dynamics_derivatives_into, inverse_dynamics_derivatives_into, DdmDerivatives,
    DerivativesData, IdmDerivatives,
};
use robodyn::algorithms::kinematics::center_of_mass_jacobian_from_q_into;
use robodyn::model::param;
use robodyn::{
    direct_dynamics_into, frame_jacobian_from_q_into, frame_jacobian_into, inertia_matrix_into,
    inverse_dynamics_into, joint_jacobians_into, Data, Environment, FrameId, KinematicsData,
    Method, Reference, Robot,
};
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::Path;

#[path = "../benches/peers/median.rs"]
mod median;
use median::time;

type Error = Box<dyn std::error::Error>;

/// One state over robodyn's movable joints (its joint vectors).
struct State {
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    tau: Vec<f64>,
}

/// The robot with rotor inertia and friction set to zero (a free-flyer base if `floating`).
fn load_robot(path: &Path, floating: bool) -> Result<Robot, Error> {
    let options = match floating {
        true => robodyn::io::LoadOptions::floating(),
        false => robodyn::io::LoadOptions::default(),
    };
    let robot = robodyn::io::load_with_options(path, &Default::default(), &options)?;
    let mut k = robot.standard_parameters();
    for link in k.chunks_mut(13) {
        link[param::IA] = 0.0;
        link[param::FS] = 0.0;
        link[param::FV] = 0.0;
    }
    Ok(robot.with_standard_parameters(&k)?)
}

/// Entry in robodyn's joint vectors of each joint named in the states file.
fn joint_indices(robot: &Robot, names: &[&str]) -> Result<Vec<usize>, Error> {
    let c = robot.coordinates();
    names
        .iter()
        .map(|n| {
            c.index_of(n).ok_or_else(|| {
                format!("joint {n} is not a movable joint of the robodyn model").into()
            })
        })
        .collect()
}

/// The frame of each joint named in the states file (Pinocchio's joint frames), in its order.
fn joint_frames(robot: &Robot, path: &Path) -> Result<Vec<FrameId>, Error> {
    let text = std::fs::read_to_string(path)?;
    let header = text.lines().next().ok_or("empty states file")?;
    let frames = header.split_whitespace().skip(1).map(|n| robot.frame_id(n));
    Ok(frames.collect::<robodyn::Result<_>>()?)
}

/// Where each entry of the states file's q and v vectors goes in robodyn's q (nq) and v (nv):
/// the base entries (floating: 7 and 6, in the same convention) first, then the joints by name.
struct Layout {
    q: Vec<usize>,
    v: Vec<usize>,
}

impl Layout {
    fn new(robot: &Robot, names: &[&str]) -> Result<Layout, Error> {
        let joints = if robot.is_floating() {
            // Pinocchio's first joint is the free flyer (`root_joint`): robodyn's base
            let root = names.first().ok_or("no joint in the states file")?;
            if robot.coordinates().index_of(root).is_some() {
                return Err(format!("{root} is a movable joint, not the free-flyer root").into());
            }
            &names[1..]
        } else {
            names
        };
        let idx = joint_indices(robot, joints)?;
        if idx.len() != robot.dof() {
            let n = idx.len();
            return Err(format!("{n} joints in the states, robodyn has {}", robot.dof()).into());
        }
        let (bq, bv) = (robot.nq() - robot.dof(), robot.nv() - robot.dof());
        let map = |b: usize| (0..b).chain(idx.iter().map(|i| b + i)).collect();
        Ok(Layout {
            q: map(bq),
            v: map(bv),
        })
    }
}

/// States file: a line `names <joint>...`, then one line per state: q (nq), v, a, tau (nv each).
fn read_states(robot: &Robot, path: &Path) -> Result<(Layout, Vec<State>), Error> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines();
    let header = lines.next().ok_or("empty states file")?;
    let names: Vec<&str> = header.split_whitespace().skip(1).collect();
    let layout = Layout::new(robot, &names)?;
    let (nq, nv) = (robot.nq(), robot.nv());
    let mut states = Vec::new();
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let x: Vec<f64> = line
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()?;
        if x.len() != nq + 3 * nv {
            let want = nq + 3 * nv;
            return Err(format!("state line with {} numbers, {want} expected", x.len()).into());
        }
        let scatter = |from: usize, map: &[usize]| {
            let mut v = vec![0.0; map.len()];
            for (k, &i) in map.iter().enumerate() {
                v[i] = x[from + k];
            }
            v
        };
        states.push(State {
            q: scatter(0, &layout.q),
            qd: scatter(nq, &layout.v),
            qdd: scatter(nq + nv, &layout.v),
            tau: scatter(nq + 2 * nv, &layout.v),
        });
    }
    Ok((layout, states))
}

/// `--batch URDF N`: batch inverse dynamics of N random states on 1 and 2 threads.
fn batch(path: &Path, rows: usize) -> Result<(), Error> {
    use rand::Rng;
    let robot = load_robot(path, false)?;
    let n = robot.dof();
    let mut r = robodyn_testing::rng(1);
    let mut v = |s: f64| {
        (0..rows * n)
            .map(|_| r.random_range(-s..s))
            .collect::<Vec<f64>>()
    };
    let (q, qd, qdd) = (v(3.0), v(2.0), v(5.0));
    let mut tau = vec![0.0; rows * n];
    let env = robot.environment();
    let pools = [1, 2].map(|t| rayon::ThreadPoolBuilder::new().num_threads(t).build());
    let [one, two] = pools;
    let (one, two) = (one?, two?);
    let mut run = |pool: &rayon::ThreadPool| -> Result<f64, Error> {
        let t = std::time::Instant::now();
        pool.install(|| {
            robodyn::inverse_dynamics_batch(&robot, env, black_box(&q), &qd, &qdd, &mut tau)
        })?;
        black_box(&tau);
        Ok(t.elapsed().as_secs_f64() * 1e3)
    };
    // pairs run back to back (order swapped every other pair): the VM's speed changes within
    // seconds, so each pair's ratio is compared, not medians taken at different times
    let (mut t1, mut t2, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..15 {
        let (a, b) = if k % 2 == 0 {
            let a = run(&one)?;
            (a, run(&two)?)
        } else {
            let b = run(&two)?;
            (run(&one)?, b)
        };
        t1.push(a);
        t2.push(b);
        ratio.push(a / b);
    }
    for v in [&mut t1, &mut t2, &mut ratio] {
        v.sort_by(f64::total_cmp);
    }
    println!("batch idm {rows} states, 1 thread: median {:.2} ms", t1[7]);
    println!("batch idm {rows} states, 2 threads: median {:.2} ms", t2[7]);
    println!(
        "speedup 2 threads / 1 thread: {:.2} (median of 15 back-to-back pairs; range {:.2}-{:.2})",
        ratio[7], ratio[0], ratio[14]
    );
    Ok(())
}

/// The options after URDF STATES RESULTS.
struct Options {
    samples: usize,
    target_us: f64,
    /// The frame of the kinematics' comparison: the last joint's child link (its frame is the
    /// joint's frame in a URDF, Pinocchio's joint frame); default the last joint's own frame.
    tip: Option<String>,
    floating: bool,
}

impl Options {
    fn parse(args: &[String]) -> Result<Options, Error> {
        let mut o = Options {
            samples: 21,
            target_us: 400.0,
            tip: None,
            floating: false,
        };
        let mut it = args.iter();
        while let Some(k) = it.next() {
            if k == "--floating" {
                o.floating = true;
                continue;
            }
            let v = it.next().ok_or_else(|| format!("{k} needs a value"))?;
            match k.as_str() {
                "--samples" => o.samples = v.parse()?,
                "--target-us" => o.target_us = v.parse()?,
                "--tip" => o.tip = Some(v.clone()),
                _ => return Err(format!("unknown option {k}").into()),
            }
        }
        Ok(o)
    }
}

/// The dynamics' buffers: the per-call data, A and an nv vector.
struct Dynamics {
    data: Data,
    a: DMatrix<f64>,
    out: Vec<f64>,
}

impl Dynamics {
    fn new(robot: &Robot) -> Dynamics {
        let nv = robot.nv();
        Dynamics {
            data: Data::new(robot),
            a: DMatrix::zeros(nv, nv),
            out: vec![0.0; nv],
        }
    }
}

/// The kinematics' and derivatives' buffers (fixed base only) and the frames they are read at.
struct Kinematics {
    kin: KinematicsData,
    jac: DMatrix<f64>,
    jcom: DMatrix<f64>,
    dd: DerivativesData,
    di: IdmDerivatives,
    da: DdmDerivatives,
    frames: Vec<FrameId>,
    tip: FrameId,
}

impl Kinematics {
    fn new(robot: &Robot, states: &Path, tip: Option<&str>) -> Result<Kinematics, Error> {
        let n = robot.dof();
        let frames = joint_frames(robot, states)?;
        let tip = match tip {
            Some(name) => robot.frame_id(name)?,
            None => *frames.last().ok_or("no joint")?,
        };
        Ok(Kinematics {
            kin: KinematicsData::new(robot),
            jac: DMatrix::zeros(6, n),
            jcom: DMatrix::zeros(3, n),
            dd: DerivativesData::new(robot),
            di: IdmDerivatives::new(robot),
            da: DdmDerivatives::new(robot),
            frames,
            tip,
        })
    }
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() == 4 && args[1] == "--batch" {
        return batch(Path::new(&args[2]), args[3].parse()?);
    }
    if args.len() < 4 {
        return Err(
            "usage: peer_timing URDF STATES RESULTS [--samples N] [--target-us T] [--tip FRAME] \
             [--floating]"
                .into(),
        );
    }
    let o = Options::parse(&args[4..])?;
    let robot = load_robot(Path::new(&args[1]), o.floating)?;
    let (layout, states) = read_states(&robot, Path::new(&args[2]))?;
    let env = robot.environment().clone();
    let mut dy = Dynamics::new(&robot);
    let mut kin = if o.floating {
        None
    } else {
        Some(Kinematics::new(
            &robot,
            Path::new(&args[2]),
            o.tip.as_deref(),
        )?)
    };
    let mut text = String::new();
    for s in &states {
        write_dynamics(&robot, &env, &mut dy, s, &layout.v, &mut text)?;
        if let Some(k) = &mut kin {
            write_kinematics(&robot, &env, k, s, &layout.v, &mut text)?;
        }
    }
    std::fs::write(&args[3], text)?;
    time_dynamics(&robot, &env, &mut dy, &states, &o);
    if let Some(k) = &mut kin {
        time_kinematics(&robot, &env, k, &states, &o);
    }
    Ok(())
}

/// `tag`, then the nv vector in the states' order.
fn put(text: &mut String, tag: &str, v: &[f64], idx: &[usize]) {
    text.push_str(tag);
    for &i in idx {
        write!(text, " {:e}", v[i]).unwrap();
    }
    text.push('\n');
}

/// The results of rnea, crba (full A), aba and the composite direct model at one state.
fn write_dynamics(
    robot: &Robot,
    env: &Environment,
    dy: &mut Dynamics,
    s: &State,
    idx: &[usize],
    text: &mut String,
) -> Result<(), Error> {
    let (cmp, aba) = (Method::Composite, Method::ArticulatedBody);
    let (data, out) = (&mut dy.data, &mut dy.out);
    inverse_dynamics_into(robot, data, env, &s.q, &s.qd, &s.qdd, out)?;
    put(text, "rnea", out, idx);
    inertia_matrix_into(robot, data, &s.q, &mut dy.a)?;
    put_squares(text, "crba", &[&dy.a], idx);
    direct_dynamics_into(robot, data, env, &s.q, &s.qd, &s.tau, aba, out)?;
    put(text, "aba", out, idx);
    direct_dynamics_into(robot, data, env, &s.q, &s.qd, &s.tau, cmp, out)?;
    put(text, "composite", out, idx);
    Ok(())
}

/// The results of the frame Jacobian, the centre of mass's Jacobian and the derivatives at one
/// state (fixed base).
fn write_kinematics(
    robot: &Robot,
    env: &Environment,
    k: &mut Kinematics,
    s: &State,
    idx: &[usize],
    text: &mut String,
) -> Result<(), Error> {
    let tip = &k.tip;
    frame_jacobian_from_q_into(robot, &mut k.kin, &s.q, tip, Reference::Local, &mut k.jac)?;
    put_matrix(text, "jac", &k.jac, idx, &[]);
    // G and its Jacobian from q in one pass pair (Pinocchio's jacobianCenterOfMass gives
    // both); G checked against center_of_mass after a full forward pass
    let g = center_of_mass_jacobian_from_q_into(robot, &mut k.kin, &s.q, None, &mut k.jcom)?;
    let g_fk =
        robodyn::algorithms::kinematics::center_of_mass(robot, &mut kin_motion(robot, s)?, None)?;
    if (g - g_fk.position).amax() > 1e-12 {
        let p = g_fk.position;
        return Err(format!("G from q {g} differs from center_of_mass {p}").into());
    }
    put_matrix(text, "com", &k.jcom, idx, g.as_slice());
    let (dd, di, da) = (&mut k.dd, &mut k.di, &mut k.da);
    inverse_dynamics_derivatives_into(robot, dd, env, &s.q, &s.qd, &s.qdd, di)?;
    put_squares(text, "drnea", &[&di.dtau_dq, &di.dtau_dqd], idx);
    direct_dynamics_derivatives_into(robot, dd, env, &s.q, &s.qd, &s.tau, da)?;
    put_squares(text, "daba", &[&da.dqdd_dq, &da.dqdd_dqd], idx);
    Ok(())
}

/// Times rnea, crba (full A), aba and the composite direct model.
fn time_dynamics(robot: &Robot, env: &Environment, dy: &mut Dynamics, st: &[State], o: &Options) {
    let (samples, target_us) = (o.samples, o.target_us);
    let (cmp, aba) = (Method::Composite, Method::ArticulatedBody);
    let Dynamics { data, a, out } = dy;
    time("rnea", st, samples, target_us, |s| {
        let q = black_box(&s.q);
        inverse_dynamics_into(robot, data, env, q, &s.qd, &s.qdd, out).unwrap();
        black_box(&out);
    });
    time("crba_full", st, samples, target_us, |s| {
        inertia_matrix_into(robot, data, black_box(&s.q), a).unwrap();
        black_box(&a);
    });
    time("aba", st, samples, target_us, |s| {
        let q = black_box(&s.q);
        direct_dynamics_into(robot, data, env, q, &s.qd, &s.tau, aba, out).unwrap();
        black_box(&out);
    });
    time("composite", st, samples, target_us, |s| {
        let q = black_box(&s.q);
        direct_dynamics_into(robot, data, env, q, &s.qd, &s.tau, cmp, out).unwrap();
        black_box(&out);
    });
}

/// Times the Jacobians, the centre of mass's Jacobian and the derivatives (fixed base).
fn time_kinematics(
    robot: &Robot,
    env: &Environment,
    k: &mut Kinematics,
    st: &[State],
    o: &Options,
) {
    let (samples, target_us) = (o.samples, o.target_us);
    let Kinematics {
        kin,
        jac,
        jcom,
        dd,
        di,
        da,
        frames,
        tip,
    } = k;
    time("joint_jacobians", st, samples, target_us, |s| {
        joint_jacobians_into(robot, kin, black_box(&s.q)).unwrap();
        black_box(&kin);
    });
    time("all_frame_jacobians", st, samples, target_us, |s| {
        joint_jacobians_into(robot, kin, black_box(&s.q)).unwrap();
        for f in frames.iter() {
            frame_jacobian_into(robot, kin, f, Reference::World, jac).unwrap();
            black_box(&jac);
        }
    });
    time("frame_jacobian", st, samples, target_us, |s| {
        let q = black_box(&s.q);
        frame_jacobian_from_q_into(robot, kin, q, tip, Reference::Local, jac).unwrap();
        black_box(&jac);
    });
    time("com_jacobian", st, samples, target_us, |s| {
        let q = black_box(&s.q);
        let g = center_of_mass_jacobian_from_q_into(robot, kin, q, None, jcom).unwrap();
        black_box((&jcom, g));
    });
    time("rnea_derivatives", st, samples, target_us, |s| {
        let q = black_box(&s.q);
        inverse_dynamics_derivatives_into(robot, dd, env, q, &s.qd, &s.qdd, di).unwrap();
        black_box(&di);
    });
    time("aba_derivatives", st, samples, target_us, |s| {
        let q = black_box(&s.q);
        direct_dynamics_derivatives_into(robot, dd, env, q, &s.qd, &s.tau, da).unwrap();
        black_box(&da);
    });
}

/// `tag`, then each N x N matrix row by row, rows and columns in the states' order.
fn put_squares(text: &mut String, tag: &str, ms: &[&DMatrix<f64>], idx: &[usize]) {
    text.push_str(tag);
    for m in ms {
        for &r in idx {
            for &c in idx {
                write!(text, " {:e}", m[(r, c)]).unwrap();
            }
        }
    }
    text.push('\n');
}

/// The kinematics at a state with velocities (the centre of mass's position is read there).
fn kin_motion(robot: &Robot, s: &State) -> Result<KinematicsData, Error> {
    let mut k = KinematicsData::new(robot);
    robodyn::forward_kinematics_into(robot, &mut k, &s.q, &s.qd, &s.qdd)?;
    Ok(k)
}

/// `tag`, the leading values, then the matrix row by row with its columns in the states' order.
fn put_matrix(text: &mut String, tag: &str, m: &DMatrix<f64>, idx: &[usize], lead: &[f64]) {
    text.push_str(tag);
    for x in lead {
        write!(text, " {x:e}").unwrap();
    }
    for r in 0..m.nrows() {
        for &c in idx {
            write!(text, " {:e}", m[(r, c)]).unwrap();
        }
    }
    text.push('\n');
}
