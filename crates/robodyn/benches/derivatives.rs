//! The analytical derivatives of the inverse model (`inverse_dynamics_derivatives_into`:
//! dGamma/dq, dGamma/dqd and A) against the forward-mode route they replace: the generic
//! Newton–Euler recursion `rnea` run on hyper-dual numbers (`HyperDual64`, the route of
//! tests/derivatives.rs), one coordinate seeded per run, 2N runs for dGamma/dq and dGamma/dqd
//! (A not included in that route: it favours the hyper-dual side). Same robots, same states, in
//! one run: the bundled RX90, and the UR5, Panda and Talos (full, 44 joints) URDFs of
//! example-robot-data when `python3 -c "import cmeel"` finds them (installed with Pinocchio).
//!
//! `cargo bench -p robodyn --bench derivatives`; the criterion is a ratio >= 5
//! (hyper-dual time / analytical time) on UR5, Panda and Talos.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DMatrix;
use num_dual::HyperDual64;
use robodyn::algorithms::energy::convert_model;
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::{
    inverse_dynamics_derivatives_into, Data, DerivativesData, DynModel, IdmDerivatives, Robot,
};
use robodyn_testing::{random_state, rng};
use std::path::{Path, PathBuf};

/// example-robot-data's `robots` folder, if Pinocchio's install has it.
fn example_robot_data() -> Option<PathBuf> {
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import cmeel, os; print(os.path.join(os.path.dirname(os.path.dirname(\
             cmeel.__file__)), 'cmeel.prefix', 'share', 'example-robot-data', 'robots'))",
        ])
        .output()
        .ok()?;
    let dir = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    dir.is_dir().then_some(dir)
}

/// The robots: RX90 (bundled), then UR5, Panda, Talos when found.
fn robots() -> Vec<(String, Robot)> {
    let bundled = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
    let mut v = vec![("rx90".to_string(), robodyn::io::load(bundled).unwrap())];
    let files = [
        ("ur5", "ur_description/urdf/ur5_robot.urdf"),
        ("panda", "panda_description/urdf/panda.urdf"),
        ("talos", "talos_data/robots/talos_full_v2.urdf"),
    ];
    match example_robot_data() {
        Some(dir) => {
            for (name, sub) in files {
                let p: &Path = &dir.join(sub);
                match p.is_file() {
                    true => v.push((name.to_string(), robodyn::io::load(p).unwrap())),
                    false => eprintln!("derivatives bench: {} not found", p.display()),
                }
            }
        }
        None => eprintln!("derivatives bench: example-robot-data not found (UR5, Panda, Talos)"),
    }
    v
}

/// The hyper-dual route's buffers: the model on hyper-dual numbers and the lifted state.
struct HyperDual {
    model: DynModel<HyperDual64>,
    data: Data<HyperDual64>,
    state: [Vec<HyperDual64>; 3],
    tau: Vec<HyperDual64>,
    out: [DMatrix<f64>; 2],
}

impl HyperDual {
    fn new(robot: &Robot, q: &[f64], qd: &[f64], qdd: &[f64]) -> Self {
        let model: DynModel<HyperDual64> = convert_model(robot.dynamic());
        let data = Data::from_model(&model);
        let lift = |x: &[f64]| x.iter().map(|&v| HyperDual64::from_re(v)).collect();
        let n = robot.dof();
        HyperDual {
            model,
            data,
            state: [lift(q), lift(qd), lift(qdd)],
            tau: vec![HyperDual64::from_re(0.0); n],
            out: [DMatrix::zeros(n, n), DMatrix::zeros(n, n)],
        }
    }

    /// dGamma/dq (d = 0) and dGamma/dqd (d = 1): eps1 seeded on one coordinate per run.
    fn derivatives(&mut self) {
        let n = self.tau.len();
        for d in 0..2 {
            for k in 0..n {
                self.state[d][k].eps1 = 1.0;
                let [q, qd, qdd] = &self.state;
                rnea(&self.model, &mut self.data, q, qd, qdd, &mut self.tau);
                self.state[d][k].eps1 = 0.0;
                for (j, t) in self.tau.iter().enumerate() {
                    self.out[d][(j, k)] = t.eps1;
                }
            }
        }
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("derivatives");
    for (label, robot) in robots() {
        let n = robot.dof();
        let [q, qd, qdd] = random_state(&mut rng(28), n);
        let mut data = DerivativesData::new(&robot);
        let mut out = IdmDerivatives::new(&robot);
        let env = robot.environment();
        let mut hd = HyperDual::new(&robot, &q, &qd, &qdd);
        // the two routes agree before they are timed
        inverse_dynamics_derivatives_into(&robot, &mut data, env, &q, &qd, &qdd, &mut out).unwrap();
        hd.derivatives();
        let gap = (&out.dtau_dq - &hd.out[0])
            .amax()
            .max((&out.dtau_dqd - &hd.out[1]).amax());
        assert!(
            gap <= 1e-9 * out.dtau_dq.amax().max(1.0),
            "{label}: routes differ by {gap:e}"
        );
        g.bench_function(format!("{label}/analytical"), |b| {
            b.iter(|| {
                inverse_dynamics_derivatives_into(&robot, &mut data, env, &q, &qd, &qdd, &mut out)
                    .unwrap()
            })
        });
        g.bench_function(format!("{label}/hyper_dual"), |b| {
            b.iter(|| hd.derivatives())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
