//! Loop closure (§10.3.1, eqs 10.27–10.30, 10.42): closure solutions against Example 10.1, W
//! against central finite differences of the solved q_p, Ψ against the second derivative of the
//! solved q_p along random smooth paths q_a(t), and the errors (unreachable, singular Wp).

mod common;

use common::{cases, robot, slider_crank, ROBOTS};
use rand::Rng;
use robodyn::{closed_state, loop_closure, ClosedChain, Error, Robot};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_6, PI};

/// Independent closure equations kept per loop (by rank), for each bundled closed robot.
const ROWS_PER_LOOP: &[(&str, &[usize])] = &[
    ("sr400.toml", &[2]),
    ("fourbar.toml", &[2]),
    ("fivebar.toml", &[2]),
    ("spatial_loop.toml", &[5]),
    ("twoloops.toml", &[2, 2]),
];

/// A random reachable q_a near the reference and its q_p (by the branch tracker from the
/// reference).
fn random_config(
    cc: &ClosedChain,
    rng: &mut impl Rng,
    qa0: &[f64],
    qp0: &[f64],
    range: f64,
) -> (Vec<f64>, Vec<f64>) {
    let qa: Vec<f64> = qa0
        .iter()
        .map(|x| x + rng.random_range(-range..range))
        .collect();
    let mut b = cc.branch_from(qa0, qp0).unwrap();
    let s = loop_closure(cc, &mut b, &qa).unwrap();
    (qa, s.q_p.iter().copied().collect())
}

/// Loop closure at q_a from a guess of q_p (a branch started there).
fn solve(
    cc: &ClosedChain,
    qa: &[f64],
    guess: &[f64],
) -> robodyn::Result<robodyn::algorithms::closed_chain::ClosureSolution> {
    let mut b = cc.branch_from(qa, guess)?;
    loop_closure(cc, &mut b, qa)
}

/// Joint values of every tree joint and cut joint (frames 1..NJ) of a closure solution.
#[test]
fn sr400_example_10_1() {
    let r = robot("sr400.toml");
    let lc = ClosedChain::new(&r).unwrap();
    assert_eq!(lc.coordinates().frames(), &[1, 2, 4, 5, 6, 7]);
    assert_eq!(lc.passive_coordinates().frames(), &[3, 8]);
    let mut rng = robodyn_testing::rng(1);
    let mut worst: f64 = 0.0;
    for _ in 0..50 {
        let qa: Vec<f64> = (0..6).map(|_| rng.random_range(-1.5..1.5)).collect();
        let (t2, t7) = (qa[1], qa[5]);
        let guess = [
            t7 + FRAC_PI_2 - t2 + rng.random_range(-0.3..0.3),
            t2 - t7 + rng.random_range(-0.3..0.3),
        ];
        let s = solve(&lc, &qa, &guess).unwrap();
        let d3 = s.q_tree[2] - (t7 + FRAC_PI_2 - t2);
        let d8 = s.q_tree[7] - (t2 - t7);
        worst = worst.max(d3.abs()).max(d8.abs());
        assert!(d3.abs() < 1e-10, "theta3 off by {d3}");
        assert!(d8.abs() < 1e-10, "theta8 off by {d8}");
        // the closed frames coincide as frames: 0T_9(q9) = 0T_10
        let t = robodyn::geometry::frame_transforms_with_cuts(
            &r,
            s.q_tree.as_slice(),
            s.q_c.as_slice(),
        )
        .unwrap();
        assert!((t[8].rot - t[9].rot).amax() < 1e-10);
        assert!((t[8].pos - t[9].pos).amax() < 1e-10);
    }
    println!("SR400 closure vs Example 10.1: max error {worst:.2e}");
}

#[test]
fn bundled_robots_close_at_reference_with_rank_chosen_rows() {
    for ((name, qa0, qp0, _), (rows_name, rows)) in ROBOTS.iter().zip(ROWS_PER_LOOP) {
        assert_eq!(name, rows_name);
        let r = robot(name);
        let lc = ClosedChain::new(&r).unwrap();
        let kept: Vec<usize> = lc.loops().iter().map(|l| l.rows.len()).collect();
        assert_eq!(&kept, rows, "{name}: independent equations per loop");
        // the reference is regular (Wp well conditioned: a branch starts there)
        let s = solve(&lc, qa0, qp0).unwrap();
        assert!(s.residual < 1e-12, "{name}: residual {}", s.residual);
        for (a, b) in s.q_p.iter().zip(qp0.iter()) {
            assert!((a - b).abs() < 1e-10, "{name}: q_p {:?}", s.q_p);
        }
        // the cut frame and its twin coincide as frames (with the cut variable)
        let t = robodyn::geometry::frame_transforms_with_cuts(
            &r,
            s.q_tree.as_slice(),
            s.q_c.as_slice(),
        )
        .unwrap();
        for l in lc.loops() {
            let (k, tw) = (l.topology.cut, l.topology.twin);
            assert!((t[k - 1].rot - t[tw - 1].rot).amax() < 1e-10, "{name}");
            assert!((t[k - 1].pos - t[tw - 1].pos).amax() < 1e-10, "{name}");
        }
        assert!(!s.conditioning.warning, "{name}: {:?}", s.conditioning);
    }
}

#[test]
fn random_solutions_close_the_loops_as_frames() {
    let mut rng = robodyn_testing::rng(2);
    for (name, r, qa0, qp0, range) in cases() {
        let lc = ClosedChain::new(&r).unwrap();
        for _ in 0..10 {
            let (qa, qp) = random_config(&lc, &mut rng, qa0, qp0, range);
            // perturbed guess converges back to the same solution
            let g: Vec<f64> = qp
                .iter()
                .map(|x| x + rng.random_range(-0.05..0.05))
                .collect();
            let s = solve(&lc, &qa, &g).unwrap();
            for (a, b) in s.q_p.iter().zip(&qp) {
                assert!((a - b).abs() < 1e-9, "{name}");
            }
            let t = robodyn::geometry::frame_transforms_with_cuts(
                &r,
                s.q_tree.as_slice(),
                s.q_c.as_slice(),
            )
            .unwrap();
            for l in lc.loops() {
                let (k, tw) = (l.topology.cut, l.topology.twin);
                assert!((t[k - 1].rot - t[tw - 1].rot).amax() < 1e-10, "{name}");
                assert!((t[k - 1].pos - t[tw - 1].pos).amax() < 1e-10, "{name}");
            }
        }
    }
}

#[test]
fn w_matches_finite_differences_of_the_closure_solution() {
    let mut rng = robodyn_testing::rng(3);
    for (name, r, qa0, qp0, range) in cases() {
        let lc = ClosedChain::new(&r).unwrap().with_tolerance(1e-14);
        let mut worst: f64 = 0.0;
        for _ in 0..5 {
            let (qa, qp) = random_config(&lc, &mut rng, qa0, qp0, range);
            let b = lc.branch_from(&qa, &qp).unwrap();
            let c = loop_closure(&lc, &mut b.clone(), &qa).unwrap();
            let h = 1e-5;
            for col in 0..qa.len() {
                let mut qp_ = qa.clone();
                qp_[col] += h;
                let mut qm = qa.clone();
                qm[col] -= h;
                let sp = loop_closure(&lc, &mut b.clone(), &qp_).unwrap();
                let sm = loop_closure(&lc, &mut b.clone(), &qm).unwrap();
                for row in 0..qp.len() {
                    let fd = (sp.q_p[row] - sm.q_p[row]) / (2.0 * h);
                    let e = (fd - c.w[(row, col)]).abs() / c.w[(row, col)].abs().max(1.0);
                    worst = worst.max(e);
                    assert!(
                        e < 1e-6,
                        "{name}: W[{row},{col}] = {} vs {fd}",
                        c.w[(row, col)]
                    );
                }
            }
        }
        println!("{name}: W vs central differences, max relative error {worst:.2e}");
    }
}

#[test]
fn psi_matches_second_derivative_along_smooth_paths() {
    let mut rng = robodyn_testing::rng(4);
    for (name, r, qa0, qp0, range) in cases() {
        let lc = ClosedChain::new(&r).unwrap().with_tolerance(1e-14);
        let mut worst: f64 = 0.0;
        for _ in 0..5 {
            let (c0, qp) = random_config(&lc, &mut rng, qa0, qp0, range * 0.5);
            let n = c0.len();
            // q_a(t) = c0 + A sin(om t + ph) - A sin(ph): a smooth path through c0 at t = 0
            let amp: Vec<f64> = (0..n).map(|_| rng.random_range(-0.2..0.2)).collect();
            let om: Vec<f64> = (0..n).map(|_| rng.random_range(0.5..3.0)).collect();
            let ph: Vec<f64> = (0..n).map(|_| rng.random_range(-3.0..3.0)).collect();
            let qa_at = |t: f64| -> Vec<f64> {
                (0..n)
                    .map(|i| c0[i] + amp[i] * ((om[i] * t + ph[i]).sin() - ph[i].sin()))
                    .collect()
            };
            let qd: Vec<f64> = (0..n).map(|i| amp[i] * om[i] * ph[i].cos()).collect();
            let qdd: Vec<f64> = (0..n)
                .map(|i| -amp[i] * om[i] * om[i] * ph[i].sin())
                .collect();
            let b = lc.branch_from(&c0, &qp).unwrap();
            let st = closed_state(&lc, &mut b.clone(), &c0, &qd, &qdd).unwrap();
            let mut solve = |t: f64| -> Vec<f64> {
                let s = loop_closure(&lc, &mut b.clone(), &qa_at(t)).unwrap();
                s.q_p.iter().copied().collect()
            };
            let second = |h: f64, solve: &mut dyn FnMut(f64) -> Vec<f64>| -> Vec<f64> {
                let (a, b, c) = (solve(-h), solve(0.0), solve(h));
                (0..a.len())
                    .map(|k| (a[k] - 2.0 * b[k] + c[k]) / (h * h))
                    .collect()
            };
            // Richardson extrapolation of the central second difference: O(h^4)
            let (d1, d2) = (second(2e-3, &mut solve), second(1e-3, &mut solve));
            for (k, &j) in lc.passive_coordinates().frames().iter().enumerate() {
                let fd = (4.0 * d2[k] - d1[k]) / 3.0;
                let an = st.qdd[j - 1];
                let e = (fd - an).abs() / an.abs().max(1.0);
                worst = worst.max(e);
                assert!(e < 1e-5, "{name}: qdd_{j} = {an} (10.42) vs {fd}");
            }
        }
        println!("{name}: W qdd_a - Wp^-1 Psi vs second differences, max rel. error {worst:.2e}");
    }
}

#[test]
fn unreachable_configuration_names_the_loop() {
    let r = robot("fivebar.toml");
    let lc = ClosedChain::new(&r).unwrap();
    // proximal tips 0.447 m apart, distal links reach 0.4 m together
    let e = lc.branch_from(&[0.0, -FRAC_PI_2], &[0.0, 0.0]).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, Error::LoopNotClosed { .. }), "{msg}");
    assert!(
        msg.contains("loop 1 (cut joint 5 between links 2 and 4)") && msg.contains("q_a = "),
        "{msg}"
    );
    // from the assembly, the tracker cannot reach it: a typed error, the tracker unchanged
    let mut b = lc.assembly_branch().unwrap();
    let before = b.clone();
    let e = loop_closure(&lc, &mut b, &[0.0, -FRAC_PI_2]).unwrap_err();
    assert!(matches!(e, Error::BranchLost { .. }), "{e}");
    assert_eq!(b, before);
}

#[test]
fn singular_wp_is_an_error_naming_the_loop() {
    let r = robot("fivebar.toml");
    let cc = ClosedChain::new(&r).unwrap();
    // distal links aligned (a parallel singularity): q = [pi/6, -pi/2, -pi/6, pi/2] is closed
    let q = [FRAC_PI_6, -FRAC_PI_2, -FRAC_PI_6, FRAC_PI_2];
    let e = cc.branch_from(&[q[0], q[2]], &[q[1], q[3]]).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, Error::Singular { rcond, limit, .. } if rcond < limit),
        "{msg}"
    );
    assert!(
        msg.contains("Wp") && msg.contains("loop 1 (cut joint 5"),
        "{msg}"
    );
}

#[test]
fn wrong_number_of_actuators_is_reported() {
    let mut d = robot("fourbar.toml").into_description();
    d.frame_mut(2).actuated = true;
    let r = Robot::new(d).unwrap();
    let e = ClosedChain::new(&r).unwrap_err().to_string();
    assert!(
        e.contains("2 independent closure equations") && e.contains("passive"),
        "{e}"
    );
}

#[test]
fn grashof_cranks_turn_fully() {
    // the four-bar and both loops of the Watt six-bar are Grashof with the driving link
    // shortest: continuation over a full crank turn never meets a singular Wp
    for name in ["fourbar.toml", "twoloops.toml"] {
        let r = robot(name);
        let cc = ClosedChain::new(&r).unwrap();
        let mut b = cc.assembly_branch().unwrap();
        let mut qp = Vec::new();
        for s in 1..=72 {
            let qa = [s as f64 * 2.0 * PI / 72.0];
            let sol = loop_closure(&cc, &mut b, &qa).unwrap();
            assert!(!sol.conditioning.warning, "{name}: {:?}", sol.conditioning);
            qp = sol.q_p.iter().copied().collect();
        }
        // back to the start after one turn, up to 2 pi on passive joints that turn fully
        for x in &qp {
            let m = x.rem_euclid(2.0 * PI);
            assert!(
                m.min(2.0 * PI - m) < 1e-9,
                "{name}: q_p after a turn {qp:?}"
            );
        }
    }
}

#[test]
fn prismatic_cut_slider_crank_closed_form() {
    // slider position x_B = a cos(phi) + sqrt(L^2 - a^2 sin^2(phi)), phi = pi/2 + q1; the cut
    // variable is the slide of R_4 along z_4 = x_0 to the twin at the origin: q_c = -x_B
    let r = slider_crank();
    let lc = ClosedChain::new(&r).unwrap();
    assert_eq!(lc.loops()[0].rows.len(), 2);
    let mut rng = robodyn_testing::rng(5);
    let mut b = lc.branch_from(&[0.0], &[0.0, 0.0]).unwrap();
    let mut worst: f64 = 0.0;
    for s in 1..=36 {
        let q1 = s as f64 * 2.0 * PI / 36.0;
        let sol = loop_closure(&lc, &mut b, &[q1]).unwrap();
        let qp: Vec<f64> = sol.q_p.iter().copied().collect();
        let phi = FRAC_PI_2 + q1;
        let xb = 0.1 * phi.cos() + (0.09 - 0.01 * phi.sin().powi(2)).sqrt();
        worst = worst.max((sol.q_c[0] + xb).abs());
        assert!(
            (sol.q_c[0] + xb).abs() < 1e-12,
            "q_c {} vs {}",
            sol.q_c[0],
            -xb
        );
        // from a perturbed guess too
        let g: Vec<f64> = qp.iter().map(|x| x + rng.random_range(-0.1..0.1)).collect();
        let again = solve(&lc, &[q1], &g).unwrap();
        assert!((again.q_c[0] + xb).abs() < 1e-12);
    }
    println!("slider-crank: cut slide vs closed form, max error {worst:.2e}");
}
