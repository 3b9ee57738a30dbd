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
    inverse_dynamics_into, joint_jacobians_into, Data, FrameId, KinematicsData, Method, Reference,
    Robot,
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

/// The robot with rotor inertia and friction set to zero.
fn load_robot(path: &Path) -> Result<Robot, Error> {
    let robot = robodyn::io::load(path)?;
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

/// States file: a line `names <joint>...`, then one line per state: q, v, a, tau (nv each).
fn read_states(robot: &Robot, path: &Path) -> Result<(Vec<usize>, Vec<State>), Error> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines();
    let header = lines.next().ok_or("empty states file")?;
    let names: Vec<&str> = header.split_whitespace().skip(1).collect();
    let idx = joint_indices(robot, &names)?;
    let nv = idx.len();
    if nv != robot.dof() {
        return Err(format!("{nv} joints in the states, robodyn has {}", robot.dof()).into());
    }
    let mut states = Vec::new();
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let x: Vec<f64> = line
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()?;
        if x.len() != 4 * nv {
            return Err(format!("state line with {} numbers, {} expected", x.len(), 4 * nv).into());
        }
        let scatter = |part: usize| {
            let mut v = vec![0.0; nv];
            for (k, &i) in idx.iter().enumerate() {
                v[i] = x[part * nv + k];
            }
            v
        };
        states.push(State {
            q: scatter(0),
            qd: scatter(1),
            qdd: scatter(2),
            tau: scatter(3),
        });
    }
    Ok((idx, states))
}

/// `--batch URDF N`: batch inverse dynamics of N random states on 1 and 2 threads.
fn batch(path: &Path, rows: usize) -> Result<(), Error> {
    use rand::Rng;
    let robot = load_robot(path)?;
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

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() == 4 && args[1] == "--batch" {
        return batch(Path::new(&args[2]), args[3].parse()?);
    }
    if args.len() < 4 {
        return Err("usage: peer_timing URDF STATES RESULTS [--samples N] [--target-us T]".into());
    }
    let (mut samples, mut target_us) = (21usize, 400.0);
    // the frame of the kinematics' comparison: the last joint's child link (its frame is the
    // joint's frame in a URDF, Pinocchio's joint frame); default the last joint's own frame
    let mut tip_name: Option<String> = None;
    for kv in args[4..].chunks(2) {
        match (kv[0].as_str(), kv.get(1)) {
            ("--samples", Some(v)) => samples = v.parse()?,
            ("--target-us", Some(v)) => target_us = v.parse()?,
            ("--tip", Some(v)) => tip_name = Some(v.clone()),
            _ => return Err(format!("unknown option {}", kv[0]).into()),
        }
    }
    let robot = load_robot(Path::new(&args[1]))?;
    let (idx, states) = read_states(&robot, Path::new(&args[2]))?;
    let n = robot.dof();
    let env = robot.environment().clone();
    let mut data = Data::new(&robot);
    let mut a = DMatrix::zeros(n, n);
    let mut out = vec![0.0; n];
    let (cmp, aba) = (Method::Composite, Method::ArticulatedBody);
    let frames = joint_frames(&robot, Path::new(&args[2]))?;
    let tip = match &tip_name {
        Some(name) => robot.frame_id(name)?,
        None => *frames.last().ok_or("no joint")?,
    };
    let mut kin = KinematicsData::new(&robot);
    let (mut jac, mut jcom) = (DMatrix::zeros(6, n), DMatrix::zeros(3, n));
    let mut dd = DerivativesData::new(&robot);
    let (mut di, mut da) = (IdmDerivatives::new(&robot), DdmDerivatives::new(&robot));

    let mut text = String::new();
    let put = |text: &mut String, tag: &str, v: &[f64]| {
        text.push_str(tag);
        for &i in &idx {
            write!(text, " {:e}", v[i]).unwrap();
        }
        text.push('\n');
    };
    for s in &states {
        inverse_dynamics_into(&robot, &mut data, &env, &s.q, &s.qd, &s.qdd, &mut out)?;
        put(&mut text, "rnea", &out);
        inertia_matrix_into(&robot, &mut data, &s.q, &mut a)?;
        text.push_str("crba");
        for &r in &idx {
            for &c in &idx {
                write!(text, " {:e}", a[(r, c)])?;
            }
        }
        text.push('\n');
        direct_dynamics_into(&robot, &mut data, &env, &s.q, &s.qd, &s.tau, aba, &mut out)?;
        put(&mut text, "aba", &out);
        direct_dynamics_into(&robot, &mut data, &env, &s.q, &s.qd, &s.tau, cmp, &mut out)?;
        put(&mut text, "composite", &out);
        frame_jacobian_from_q_into(&robot, &mut kin, &s.q, &tip, Reference::Local, &mut jac)?;
        put_matrix(&mut text, "jac", &jac, &idx, &[]);
        // G and its Jacobian from q in one pass pair (Pinocchio's jacobianCenterOfMass gives
        // both); G checked against center_of_mass after a full forward pass
        let g = center_of_mass_jacobian_from_q_into(&robot, &mut kin, &s.q, None, &mut jcom)?;
        let g_fk = robodyn::algorithms::kinematics::center_of_mass(
            &robot,
            &mut kin_motion(&robot, s)?,
            None,
        )?;
        if (g - g_fk.position).amax() > 1e-12 {
            return Err(
                format!("G from q {g} differs from center_of_mass {}", g_fk.position).into(),
            );
        }
        put_matrix(&mut text, "com", &jcom, &idx, g.as_slice());
        inverse_dynamics_derivatives_into(&robot, &mut dd, &env, &s.q, &s.qd, &s.qdd, &mut di)?;
        put_squares(&mut text, "drnea", &[&di.dtau_dq, &di.dtau_dqd], &idx);
        direct_dynamics_derivatives_into(&robot, &mut dd, &env, &s.q, &s.qd, &s.tau, &mut da)?;
        put_squares(&mut text, "daba", &[&da.dqdd_dq, &da.dqdd_dqd], &idx);
    }
    std::fs::write(&args[3], text)?;

    time("rnea", &states, samples, target_us, |s| {
        inverse_dynamics_into(
            &robot,
            &mut data,
            &env,
            black_box(&s.q),
            &s.qd,
            &s.qdd,
            &mut out,
        )
        .unwrap();
        black_box(&out);
    });
    time("crba_full", &states, samples, target_us, |s| {
        inertia_matrix_into(&robot, &mut data, black_box(&s.q), &mut a).unwrap();
        black_box(&a);
    });
    time("aba", &states, samples, target_us, |s| {
        let q = black_box(&s.q);
        direct_dynamics_into(&robot, &mut data, &env, q, &s.qd, &s.tau, aba, &mut out).unwrap();
        black_box(&out);
    });
    time("composite", &states, samples, target_us, |s| {
        let q = black_box(&s.q);
        direct_dynamics_into(&robot, &mut data, &env, q, &s.qd, &s.tau, cmp, &mut out).unwrap();
        black_box(&out);
    });
    time("joint_jacobians", &states, samples, target_us, |s| {
        joint_jacobians_into(&robot, &mut kin, black_box(&s.q)).unwrap();
        black_box(&kin);
    });
    time("all_frame_jacobians", &states, samples, target_us, |s| {
        joint_jacobians_into(&robot, &mut kin, black_box(&s.q)).unwrap();
        for f in &frames {
            frame_jacobian_into(&robot, &kin, f, Reference::World, &mut jac).unwrap();
            black_box(&jac);
        }
    });
    time("frame_jacobian", &states, samples, target_us, |s| {
        let q = black_box(&s.q);
        frame_jacobian_from_q_into(&robot, &mut kin, q, &tip, Reference::Local, &mut jac).unwrap();
        black_box(&jac);
    });
    time("com_jacobian", &states, samples, target_us, |s| {
        let q = black_box(&s.q);
        let g = center_of_mass_jacobian_from_q_into(&robot, &mut kin, q, None, &mut jcom).unwrap();
        black_box((&jcom, g));
    });
    time("rnea_derivatives", &states, samples, target_us, |s| {
        let q = black_box(&s.q);
        inverse_dynamics_derivatives_into(&robot, &mut dd, &env, q, &s.qd, &s.qdd, &mut di)
            .unwrap();
        black_box(&di);
    });
    time("aba_derivatives", &states, samples, target_us, |s| {
        let q = black_box(&s.q);
        direct_dynamics_derivatives_into(&robot, &mut dd, &env, q, &s.qd, &s.tau, &mut da).unwrap();
        black_box(&da);
    });
    Ok(())
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
