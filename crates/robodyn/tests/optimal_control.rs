//! The multiple-shooting solver of `examples/optimal_control` (its `shooting.rs`, shared by
//! `#[path]`) on a small problem: the bundled RX90 (6 joints), K = 10 intervals of 0.1 s, from
//! rest at q = 0 to rest at a goal, minimum effort beyond gravity compensation. Checked by
//! routes the solver does not use:
//! - the returned torques Gamma_c + g(q) re-simulated WITH gravity by the articulated-body
//!   method pass through every node and reach the goal (1e-6);
//! - the first-order optimality residual of the analytical solution measured with
//!   finite-difference sensitivities (1e-6);
//! - feasible perturbations of the solution (a random control direction, then the terminal
//!   state restored by Newton steps on single shooting) cost more, on both sides;
//! - the same code with finite-difference sensitivities converges to the same torques.

#[path = "../examples/optimal_control/shooting.rs"]
#[allow(dead_code)]
mod shooting;

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use robodyn::Robot;
use robodyn_testing::rng;
use shooting::{
    initial_guess, kkt_solve, linearize, resimulate, solve, stationarity, terminal_map, Integrator,
    Options, Problem, Sensitivities,
};

fn rx90() -> Robot {
    robodyn::io::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/rx90.toml"
    ))
    .unwrap()
}

fn problem(robot: &Robot) -> Problem {
    let n = robot.dof();
    Problem {
        x_start: vec![0.0; 2 * n],
        q_goal: vec![0.5, -0.4, 0.6, 0.3, -0.5, 0.4],
        horizon: 1.0,
        intervals: 10,
        substeps: 2,
        weights: vec![1.0; n],
    }
}

fn solved(robot: &Robot, p: &Problem, how: Sensitivities) -> shooting::Solution {
    let (x, u) = initial_guess(robot, p).unwrap();
    solve(robot, p, &Options::new(how), x, u).unwrap()
}

/// `u` made feasible again: single shooting from x_start, then minimum-norm Newton corrections
/// of the controls, M dU = x_goal - x_K, until the terminal gap is below 1e-12.
fn restore_terminal(robot: &Robot, p: &Problem, mut u: Vec<DVector<f64>>) -> Vec<DVector<f64>> {
    let n = robot.dof();
    let mut integ = Integrator::new(robot, p);
    let h = DMatrix::<f64>::identity(n * u.len(), n * u.len());
    for _ in 0..20 {
        let mut x = vec![DVector::from_column_slice(&p.x_start)];
        for uk in &u {
            let next = integ.step(x.last().unwrap(), uk).unwrap();
            x.push(next);
        }
        let lin = linearize(&mut integ, p, &x, &u, Some(Sensitivities::Analytical)).unwrap();
        if lin.d_end.amax() < 1e-12 {
            return u;
        }
        let m = terminal_map(&lin, n);
        let zero = DVector::zeros(n * u.len());
        let (du, _) = kkt_solve(&m, &h, &zero, &lin.d_end).unwrap();
        for (k, uk) in u.iter_mut().enumerate() {
            *uk += du.rows(k * n, n);
        }
    }
    panic!("the perturbed controls could not be made feasible again");
}

#[test]
fn shooting_solution_is_feasible_by_an_independent_simulation() {
    let robot = rx90();
    let p = problem(&robot);
    let s = solved(&robot, &p, Sensitivities::Analytical);
    assert!(s.max_defect <= 1e-8, "defects {:e}", s.max_defect);
    assert!(s.iterations < 100);
    let nodes = resimulate(&robot, &p, &s.u, p.substeps).unwrap();
    for (k, (a, b)) in nodes.iter().zip(&s.x).enumerate() {
        let gap = (a - b).amax();
        assert!(gap <= 1e-6, "node {k}: re-simulated state off by {gap:e}");
    }
    let miss = (nodes.last().unwrap() - p.x_goal()).amax();
    assert!(miss <= 1e-6, "goal missed by {miss:e}");
}

#[test]
fn shooting_solution_is_optimal() {
    let robot = rx90();
    let p = problem(&robot);
    let s = solved(&robot, &p, Sensitivities::Analytical);
    // first order, with sensitivities of another route
    let r = stationarity(&robot, &p, &s.x, &s.u, Sensitivities::CentralDifferences).unwrap();
    assert!(r <= 1e-6, "optimality residual (finite differences) {r:e}");
    // feasible neighbours cost more, on both sides of each direction
    let mut g = rng(7);
    let scale = s.u.iter().map(|v| v.amax()).fold(0.0, f64::max);
    for _ in 0..4 {
        let dir: Vec<DVector<f64>> =
            s.u.iter()
                .map(|v| DVector::from_fn(v.len(), |_, _| g.random_range(-1.0..1.0)))
                .collect();
        for sign in [1.0, -1.0] {
            let u: Vec<DVector<f64>> =
                s.u.iter()
                    .zip(&dir)
                    .map(|(a, d)| a + sign * 0.01 * scale * d)
                    .collect();
            let feasible = restore_terminal(&robot, &p, u);
            let (c, c0) = (p.cost(&feasible), s.cost);
            assert!(c > c0, "a feasible neighbour costs {c} <= optimum {c0}");
        }
    }
}

#[test]
fn shooting_with_finite_differences_reaches_the_same_torques() {
    let robot = rx90();
    let p = problem(&robot);
    let a = solved(&robot, &p, Sensitivities::Analytical);
    let f = solved(&robot, &p, Sensitivities::CentralDifferences);
    assert!(f.max_defect <= 1e-8);
    let scale = a.u.iter().map(|v| v.amax()).fold(0.0, f64::max);
    let gap =
        a.u.iter()
            .zip(&f.u)
            .map(|(x, y)| (x - y).amax())
            .fold(0.0, f64::max);
    assert!(
        gap <= 1e-5 * scale,
        "torques differ by {gap:e} (scale {scale})"
    );
    assert!((a.cost - f.cost).abs() <= 1e-8 * a.cost);
}
