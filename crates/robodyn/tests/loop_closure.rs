//! Loop closure (§10.3.1): closure solutions, W against finite differences, Ψ against the second
//! derivative of the solved q_p along smooth paths, error reporting.

use robodyn::algorithms::loop_closure::LoopClosure;
use robodyn::Robot;
use std::path::PathBuf;

fn robot(name: &str) -> Robot {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(name);
    robodyn::io::load(&p).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn sr400_example_10_1() {
    let r = robot("sr400.toml");
    let lc = LoopClosure::new(&r).unwrap();
    assert_eq!(lc.actuated_joints(), &[1, 2, 4, 5, 6, 7]);
    assert_eq!(lc.passive_joints(), &[3, 8]);
    // a planar parallelogram keeps 2 equations once the cut variable is eliminated
    assert_eq!(lc.loops()[0].rows.len(), 2);
    let mut ws = lc.workspace();
    let mut rng = robodyn::testing::rng(1);
    use rand::Rng;
    for _ in 0..50 {
        let qa: Vec<f64> = (0..6).map(|_| rng.random_range(-1.5..1.5)).collect();
        let (t2, t7) = (qa[1], qa[5]);
        // guess near the book's solution (+-0.3 rad)
        let guess = [
            t7 + std::f64::consts::FRAC_PI_2 - t2 + rng.random_range(-0.3..0.3),
            t2 - t7 + rng.random_range(-0.3..0.3),
        ];
        let s = lc.solve(&mut ws, &qa, Some(&guess)).unwrap();
        let d3 = s.q_tr[2] - (t7 + std::f64::consts::FRAC_PI_2 - t2);
        let d8 = s.q_tr[7] - (t2 - t7);
        assert!(d3.abs() < 1e-10, "theta3 off by {d3}");
        assert!(d8.abs() < 1e-10, "theta8 off by {d8}");
        println!("{:?} {}", s.q_c, s.iterations);
    }
}
