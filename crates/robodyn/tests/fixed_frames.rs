//! Fixed frames out of the dynamic recursions: on random trees with many fixed frames (chains
//! of them, fixed frames on the base, fixed leaves), every checked tree function (run on the
//! folded model) equals the kernel on the full frame list to 1e-12 relative, under random base
//! motion, gravity and external wrenches on every link (those of folded links included); and
//! the fold keeps the frame list, names and geometry.
#[path = "common/frames.rs"]
mod frames;

#[path = "common/folding.rs"]
mod folding;

use rand::Rng;
use robodyn_testing::{random_tree, rng, TreeOptions};

#[test]
fn folded_model_equals_full_frame_list_on_random_trees() {
    let mut r = rng(18);
    let mut folded_links = 0;
    for case in 0..60 {
        let opt = TreeOptions {
            p_fixed: [0.2, 0.4, 0.6][case % 3],
            p_serial: 0.5,
            ..TreeOptions::default()
        };
        let n = 2 + case % 11;
        let robot = random_tree(&mut r, n, &opt);
        if robot.dof() == 0 {
            continue;
        }
        folded_links += robot.dynamic().folded.len();
        assert_eq!(robot.dynamic().nl, robot.dof());
        let env = folding::random_environment(&robot, &mut r);
        folding::check_fold(&format!("case {case}"), &robot, &env, &mut r);
        folding::check_fold(
            &format!("case {case}, own environment"),
            &robot,
            robot.environment(),
            &mut r,
        );
    }
    // the trees did exercise the fold
    assert!(folded_links > 40, "only {folded_links} folded links");
}

/// The folded frame of every movable joint is its placement in its nearest movable ancestor:
/// 0T_h^-1 0T_j from the geometric model (full frame list) at random q.
#[test]
fn folded_placements_compose_the_fixed_frames() {
    let mut r = rng(7);
    let opt = TreeOptions {
        p_fixed: 0.5,
        ..TreeOptions::default()
    };
    for _ in 0..20 {
        let robot = random_tree(&mut r, 9, &opt);
        let q: Vec<f64> = (0..robot.nl()).map(|_| r.random_range(-3.0..3.0)).collect();
        let t0 = frames::per_frame(&robot, &q);
        let dynamic = robot.dynamic();
        let c = robot.coordinates();
        for k in 1..=dynamic.nl {
            let j = c.frame(k - 1);
            let fr = dynamic.frame(k);
            let (rot, pos) = fr.transform(&q[j - 1]);
            let want = match fr.ant {
                0 => t0[j - 1],
                h => t0[c.frame(h - 1) - 1].inverse().compose(&t0[j - 1]),
            };
            assert!((rot - want.rot).amax() < 1e-12, "frame {j}");
            assert!((pos - want.pos).amax() < 1e-12, "frame {j}");
        }
    }
}
