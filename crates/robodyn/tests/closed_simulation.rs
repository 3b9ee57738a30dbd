//! Simulation of closed-chain robots in the actuated coordinates through the simulation module
//! (`simulation::ClosedChainDynamics`, adaptive Dormand–Prince 5(4)): energy conservation, loop
//! closure along the trajectory checked on the frame placements (independent of the closure
//! solver's own residual), energy dissipation by viscous friction against the integrated
//! friction power, and idm(ddm(tau)) = tau through the API the CLI uses.
#[path = "common/frames.rs"]
mod frames;

use rand::Rng;
use robodyn::simulation::{
    simulate, ClosedChainDynamics, Dynamics, Integrator, Recorder, SimOptions, TorqueInput,
};
use robodyn::{
    closed_direct_dynamics, closed_inverse_dynamics, closed_state, loop_closure, ClosedChain,
};
use robodyn::{Expr, Robot};
use std::path::PathBuf;

fn load(name: &str) -> Robot {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(name);
    robodyn::io::load(&p).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The robot with gravity `g` (None: as in the file), Coulomb friction removed and viscous
/// friction scaled by `fv_scale` (0: conservative).
fn variant(name: &str, g: Option<[f64; 3]>, fv_scale: f64) -> Robot {
    let mut d = load(name).into_description();
    if let Some(g) = g {
        d.gravity = g.map(Expr::num);
    }
    for l in d.links.iter_mut() {
        // params: ... 11 = FS, 12 = FV
        l.params[11] = Expr::zero();
        l.params[12] = l.params[12].clone() * Expr::num(fv_scale);
    }
    Robot::new(d).unwrap()
}

fn dopri(rtol: f64, atol: f64) -> Integrator {
    Integrator::Dopri5 {
        rtol,
        atol,
        h0: None,
        h_max: None,
    }
}

/// The simulated system of a closed robot on its assembly branch.
fn system(r: &Robot) -> ClosedChainDynamics {
    let cc = ClosedChain::new(r).unwrap();
    let b = cc.assembly_branch().unwrap();
    ClosedChainDynamics::new(cc, b)
}

fn run(r: &Robot, q0: &[f64], qd0: &[f64], duration: f64, output_dt: f64) -> Recorder {
    let mut sys = system(r);
    let n = sys.dof();
    let mut rec = Recorder::default();
    let opts = SimOptions {
        duration,
        integrator: dopri(1e-11, 1e-12),
        output_dt,
        max_steps: Some(2_000_000),
    };
    simulate(
        &mut sys,
        &TorqueInput::Constant(vec![0.0; n]),
        q0,
        qd0,
        &opts,
        &mut rec,
        &mut |_| {},
    )
    .unwrap();
    rec
}

fn col(rec: &Recorder, name: &str) -> usize {
    rec.headers
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", rec.headers))
}

/// q_tr of an output row: actuated q<j> and passive q<j> (extra) columns.
fn tree_q(r: &Robot, rec: &Recorder, row: &[f64]) -> Vec<f64> {
    let mut q = vec![0.0; r.nl()];
    for j in 1..=r.nl() {
        if let Some(c) = rec.headers.iter().position(|h| *h == format!("q{j}")) {
            q[j - 1] = row[c];
        }
    }
    q
}

/// Largest distance between the origins of a cut frame and its twin (the origin of a revolute
/// or prismatic cut frame does not depend on its own variable... for a prismatic cut it moves
/// along z_k, so only the part normal to z_k is used), from `geometry::frame_transforms`.
fn placement_gap(r: &Robot, q: &[f64]) -> f64 {
    let t = frames::per_frame(r, q);
    r.structure()
        .loops
        .iter()
        .map(|l| {
            let (a, b) = (&t[l.cut - 1], &t[l.twin - 1]);
            let d = b.pos - a.pos;
            let z = a.rot.column(2);
            (d - z * z.dot(&d)).norm()
        })
        .fold(0.0, f64::max)
}

#[test]
fn conservative_simulation_conserves_energy_and_keeps_the_loops_closed() {
    // 10 s, no friction, no torque. The five-bar is mounted upside down (gravity +y0) so that it
    // swings about a regular equilibrium instead of falling into its parallel singularity (with
    // the file's gravity -y0 it reaches a configuration where Wp is singular, which stops the
    // run with an error); the SR400 moves without gravity (a free drift that keeps the
    // parallelogram away from its flat configurations for 10 s).
    // The SR400 starts at q7 = pi/2: its file's assembly (q_a = 0) is a singular configuration
    // of the parallelogram (Wp singular), used only to pick the assembly branch.
    for (name, g, q0, qd0) in [
        (
            "fivebar.toml",
            Some([0.0, 9.81, 0.0]),
            vec![0.0, 0.0],
            vec![1.0, -0.5],
        ),
        (
            "sr400.toml",
            Some([0.0, 0.0, 0.0]),
            vec![0.0, 0.0, 0.0, 0.0, 0.0, std::f64::consts::FRAC_PI_2],
            vec![0.1, 0.05, -0.1, 0.2, 0.3, -0.05],
        ),
        ("fourbar.toml", None, vec![0.0], vec![2.0]),
    ] {
        let r = variant(name, g, 0.0);
        let rec = run(&r, &q0, &qd0, 10.0, 0.05);
        assert_eq!(rec.rows.len(), 201);
        let (ce, cr) = (col(&rec, "energy"), col(&rec, "closure_residual"));
        let e0 = rec.rows[0][ce];
        let scale = e0.abs().max(1e-3);
        let (mut drift, mut residual, mut gap, mut moved): (f64, f64, f64, f64) =
            (0.0, 0.0, 0.0, 0.0);
        for row in &rec.rows {
            drift = drift.max((row[ce] - e0).abs() / scale);
            residual = residual.max(row[cr]);
            gap = gap.max(placement_gap(&r, &tree_q(&r, &rec, row)));
            moved = moved.max((row[1] - rec.rows[0][1]).abs());
        }
        println!(
            "{name}: 10 s conservative: relative energy drift {drift:.2e}, closure residual \
             {residual:.1e}, cut/twin origin gap {gap:.1e}, joint {} moved {moved:.2} ",
            &rec.headers[1]
        );
        assert!(moved > 0.1, "{name}: the robot should move");
        assert!(drift < 1e-6, "{name}: relative energy drift {drift}");
        assert!(residual < 1e-9, "{name}: closure residual {residual}");
        assert!(gap < 1e-9, "{name}: cut and twin frames apart by {gap}");
    }
}

#[test]
fn viscous_friction_dissipates_the_integrated_friction_power() {
    // dE/dt = -sum_j Fv_j qd_j^2 over all tree joints (actuated and passive, qd_tr = G qd_a,
    // 10.29) when no torque acts: E decreases monotonically and E(0) - E(T) equals the
    // integral of the friction power (trapezoid rule on 1 ms rows).
    for (name, g, qd0) in [
        ("fourbar.toml", None, vec![3.0]),
        ("fivebar.toml", Some([0.0, 9.81, 0.0]), vec![1.0, -0.5]),
    ] {
        let r = variant(name, g, 1.0);
        let cc = ClosedChain::new(&r).unwrap();
        let n = cc.dof();
        let mut b = cc.assembly_branch().unwrap();
        let q0 = b.q_a().to_vec();
        let rec = run(&r, &q0, &qd0, 2.0, 1e-3);
        let ce = col(&rec, "energy");
        let fv: Vec<f64> = (1..=r.nl()).map(|j| r.numeric().link(j).fv).collect();
        assert!(fv.iter().any(|&f| f > 0.0));
        let mut power = Vec::new();
        for row in &rec.rows {
            let qa: Vec<f64> = row[1..1 + n].to_vec();
            let qda: Vec<f64> = row[1 + n..1 + 2 * n].to_vec();
            let s = closed_state(&cc, &mut b, &qa, &qda, &vec![0.0; n])
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            power.push(s.qd.iter().zip(&fv).map(|(v, f)| f * v * v).sum::<f64>());
        }
        let e0 = rec.rows[0][ce];
        let mut dissipated = 0.0;
        let mut worst: f64 = 0.0;
        for k in 1..rec.rows.len() {
            let (ep, e) = (rec.rows[k - 1][ce], rec.rows[k][ce]);
            assert!(
                e <= ep + 1e-10 * e0.abs().max(1.0),
                "{name}: E rose at row {k}"
            );
            let dt = rec.rows[k][0] - rec.rows[k - 1][0];
            dissipated += 0.5 * dt * (power[k - 1] + power[k]);
            worst = worst.max(((e0 - e) - dissipated).abs());
        }
        let lost = e0 - rec.rows.last().unwrap()[ce];
        let rel = worst / lost;
        println!(
            "{name}: viscous friction: energy lost {lost:.4} J, |lost - integrated power| \
             <= {:.2e} relative",
            rel
        );
        assert!(
            lost > 1e-2 * e0.abs().max(0.1),
            "{name}: friction should dissipate"
        );
        assert!(rel < 1e-4, "{name}: energy balance off by {rel}");
    }
}

#[test]
fn sr400_as_in_its_file_dissipates_its_friction_power() {
    // The SR400 as bundled (viscous and Coulomb friction on every joint, rotor inertia, gravity),
    // released from its assembly with no torque, falls into a singular configuration after
    // about 0.7 s and loses most of its energy on the way. That loss must be friction's:
    // dE/dt = -sum_j (Fv_j qd_j^2 + Fs_j qd_j tanh(qd_j / v)) over all tree joints (actuated
    // and passive, qd_tr = G qd_a, 10.29) with Coulomb friction smoothed as the CLI simulates it
    // (Fs tanh(qd / v), v = 0.01 rad/s). The friction power is computed here from the tree
    // velocities the closure gives, independently of the direct model that drives the motion.
    let r = load("sr400.toml");
    let v = 0.01;
    let cc = ClosedChain::new(&r).unwrap();
    let n = cc.dof();
    let mut b = cc.assembly_branch().unwrap();
    let q0 = b.q_a().to_vec();
    let mut sys = ClosedChainDynamics::new(cc.clone(), b.clone()).with_coulomb_smoothing(Some(v));
    let mut rec = Recorder::default();
    let opts = SimOptions {
        duration: 0.6,
        integrator: dopri(1e-11, 1e-12),
        output_dt: 1e-4,
        max_steps: Some(2_000_000),
    };
    simulate(
        &mut sys,
        &TorqueInput::Constant(vec![0.0; n]),
        &q0,
        &vec![0.0; n],
        &opts,
        &mut rec,
        &mut |_| {},
    )
    .unwrap();
    let ce = col(&rec, "energy");
    let links: Vec<_> = (1..=r.nl()).map(|j| r.numeric().link(j)).collect();
    assert!(links.iter().any(|l| l.fs > 0.0) && links.iter().any(|l| l.fv > 0.0));
    let mut power = Vec::new();
    for row in &rec.rows {
        let qa: Vec<f64> = row[1..1 + n].to_vec();
        let qda: Vec<f64> = row[1 + n..1 + 2 * n].to_vec();
        let s = closed_state(&cc, &mut b, &qa, &qda, &vec![0.0; n]).unwrap();
        power.push(
            s.qd.iter()
                .zip(&links)
                .map(|(w, l)| l.fv * w * w + l.fs * w * (w / v).tanh())
                .sum::<f64>(),
        );
    }
    let e0 = rec.rows[0][ce];
    let (mut dissipated, mut worst) = (0.0, 0.0f64);
    for k in 1..rec.rows.len() {
        let dt = rec.rows[k][0] - rec.rows[k - 1][0];
        // trapezoid rule on 0.1 ms rows (measured agreement 1e-8 relative)
        dissipated += 0.5 * dt * (power[k - 1] + power[k]);
        worst = worst.max(((e0 - rec.rows[k][ce]) - dissipated).abs());
    }
    let lost = e0 - rec.rows.last().unwrap()[ce];
    println!(
        "sr400: E(0) = {e0:.4} J, lost {lost:.4} J in 0.6 s, |lost - integrated friction power| \
         <= {:.2e} relative",
        worst / lost
    );
    assert!(
        lost > 1.0,
        "sr400: friction should dissipate (lost {lost} J)"
    );
    assert!(
        worst / lost < 1e-6,
        "sr400: energy balance off by {}",
        worst / lost
    );
}

#[test]
fn idm_of_ddm_is_tau_for_all_bundled_closed_robots() {
    // The CLI's route: one branch tracker from the reference assembly, rows continued from the
    // previous row, ddm, then idm at the same state.
    let mut rng = robodyn_testing::rng(41);
    for name in [
        "sr400.toml",
        "fourbar.toml",
        "fivebar.toml",
        "spatial_loop.toml",
        "twoloops.toml",
    ] {
        let r = load(name);
        assert!(!r.is_tree());
        let cc = ClosedChain::new(&r).unwrap();
        let n = cc.dof();
        let mut b = cc.assembly_branch().unwrap();
        let qa0 = b.q_a().to_vec();
        let mut worst: f64 = 0.0;
        for _ in 0..20 {
            let qa: Vec<f64> = qa0
                .iter()
                .map(|x| x + rng.random_range(-0.2..0.2))
                .collect();
            let qd: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let tau: Vec<f64> = (0..n).map(|_| rng.random_range(-20.0..20.0)).collect();
            let d = closed_direct_dynamics(&cc, &mut b, &qa, &qd, &tau)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let qdd: Vec<f64> = d.qdd_a.iter().copied().collect();
            let i = closed_inverse_dynamics(&cc, &mut b, &qa, &qd, &qdd).unwrap();
            let scale = tau.iter().fold(1.0_f64, |a, b| a.max(b.abs()));
            for (k, t) in tau.iter().enumerate() {
                let e = (i.gamma_cl[k] - t).abs() / scale;
                worst = worst.max(e);
                assert!(e < 1e-9, "{name}: tau{k} {} vs {t}", i.gamma_cl[k]);
            }
            assert!(placement_gap(&r, i.state.q.as_slice()) < 1e-10);
        }
        println!("{name}: idm(ddm(tau)) vs tau: max relative error {worst:.2e}");
    }
}

#[test]
fn reference_start_is_the_assembly_branch() {
    // The SR400 file's assembly q3 = pi/2 selects the parallelogram branch; starting from it the
    // closure satisfies Example 10.1: theta3 = theta7 + pi/2 - theta2, theta8 = theta2 - theta7.
    let r = load("sr400.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let qa = [0.1, 0.3, 0.2, -0.4, 0.5, 0.6];
    let s = loop_closure(&cc, &mut cc.assembly_branch().unwrap(), &qa).unwrap();
    let q_tr = s.q_tree.as_slice();
    let (t2, t7) = (q_tr[1], q_tr[6]);
    let wrap = |x: f64| {
        (x + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
    };
    assert!(wrap(q_tr[2] - (t7 + std::f64::consts::FRAC_PI_2 - t2)).abs() < 1e-9);
    assert!(wrap(q_tr[7] - (t2 - t7)).abs() < 1e-9);
    // the simulator's first evaluation starts there too
    let mut sys = system(&r);
    let mut out = vec![0.0; sys.extra_columns().len()];
    sys.extra_values(&qa, &[0.0; 6], &mut out).unwrap();
    for (k, &j) in cc.passive_coordinates().frames().iter().enumerate() {
        assert!(wrap(out[1 + k] - q_tr[j - 1]).abs() < 1e-9, "q{j}");
    }
}

#[test]
fn falling_into_a_singularity_is_a_clear_error() {
    // The five-bar under the file's gravity (-y0) falls until its distal links align (a parallel
    // singularity, Wp singular): the run stops with an error value that says so, and the rows
    // written before it are closed loops.
    let r = load("fivebar.toml");
    let mut sys = system(&r);
    let mut rec = Recorder::default();
    let opts = SimOptions {
        duration: 2.0,
        integrator: dopri(1e-9, 1e-11),
        output_dt: 0.01,
        max_steps: Some(200_000),
    };
    let e = simulate(
        &mut sys,
        &TorqueInput::Constant(vec![0.0; 2]),
        &[0.1, -0.1],
        &[0.0, 0.0],
        &opts,
        &mut rec,
        &mut |_| {},
    )
    .unwrap_err();
    let m = e.to_string();
    println!("{m}");
    assert!(matches!(e, robodyn::Error::Numerical(_)), "{m}");
    assert!(m.contains("simulation stopped at t = "), "{m}");
    assert!(m.contains("singular configuration"), "{m}");
    assert!(rec.rows.len() > 10);
    let (cr, gap) = (
        col(&rec, "closure_residual"),
        rec.rows
            .iter()
            .map(|row| placement_gap(&r, &tree_q(&r, &rec, row)))
            .fold(0.0, f64::max),
    );
    assert!(rec.rows.iter().all(|row| row[cr] < 1e-9) && gap < 1e-9);
}
