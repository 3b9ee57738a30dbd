//! Growth of the numerical base-parameter method with the robot's size.
//!
//! ```text
//!  cargo run --release -p robodyn --example base_parameters_scale -- N [write FILE.toml]
//! ```
//!
//! Builds a random tree of N links (`robodyn_testing::random_tree`, seed 13) and runs the
//! numerical method with the selection of `robodyn base-params --method numeric` (rotor
//! inertias on the actuated joints, friction), printing the count, the size of W and the time.
//! With `write FILE.toml` it writes the tree instead, to time the CLI on it (with
//! `/usr/bin/time -v` for the peak memory). Time and memory are measured here and in the
//! criterion bench `base_parameters`, never in tests.

use robodyn::algorithms::base_parameters::{numeric_base_parameters, NumericOptions, TreeSampler};
use robodyn::algorithms::regressor::{Friction, ParameterSelection, RotorMode};
use robodyn_testing::{random_tree, rng, TreeOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(100);
    let robot = random_tree(&mut rng(13), n, &TreeOptions::default());
    if args.get(2).map(String::as_str) == Some("write") {
        let path = std::path::Path::new(args.get(3).expect("write FILE.toml"));
        robodyn::io::save_description(robot.description(), path).expect("write the tree");
        return;
    }
    let opt = NumericOptions {
        selection: ParameterSelection::new(&robot, RotorMode::Actuated, Friction::Actuated),
        samples: None,
        seed: 1,
    };
    let t = std::time::Instant::now();
    match numeric_base_parameters(&robot, &mut TreeSampler, &opt) {
        Ok(nb) => println!(
            "{n} links: {} base parameters of {} columns, W {} x {}, {:.2} s",
            nb.count(),
            nb.columns.len(),
            nb.rows,
            nb.columns.len(),
            t.elapsed().as_secs_f64()
        ),
        Err(e) => println!(
            "{n} links: error after {:.2} s: {e}",
            t.elapsed().as_secs_f64()
        ),
    }
}
