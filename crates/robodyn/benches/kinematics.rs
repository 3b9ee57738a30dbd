//! Kinematics: the forward pass (q, q̇, q̈), the placements with every joint's Jacobian columns
//! (Pinocchio's `computeJointJacobians`), one frame Jacobian read from them, and the centre of
//! mass with its Jacobian; on the bundled RX90 URDF, a 30-link random tree, and the UR5 and
//! Panda URDFs of example-robot-data when `python3 -c "import cmeel"` finds them (installed
//! with Pinocchio).

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DMatrix;
use robodyn::algorithms::kinematics::{center_of_mass, center_of_mass_jacobian_into};
use robodyn::{
    forward_kinematics_into, frame_jacobian_into, placements_into, KinematicsData, Reference, Robot,
};
use robodyn_testing::{random_state, random_tree, rng, TreeOptions};
use std::path::PathBuf;

/// The example-robot-data URDF `name`, if Pinocchio's install has it.
fn example_robot_data(name: &str) -> Option<PathBuf> {
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import cmeel, os; print(os.path.join(os.path.dirname(os.path.dirname(\
             cmeel.__file__)), 'cmeel.prefix', 'share', 'example-robot-data', 'robots'))",
        ])
        .output()
        .ok()?;
    let dir = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    let sub = match name {
        "ur5" => "ur_description/urdf/ur5_robot.urdf",
        _ => "panda_description/urdf/panda.urdf",
    };
    let p = dir.join(sub);
    p.is_file().then_some(p)
}

/// (label, robot, the frame read: the last frame).
fn robots() -> Vec<(String, Robot)> {
    let bundled = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
    let mut v = vec![
        ("rx90".to_string(), robodyn::io::load(bundled).unwrap()),
        (
            "tree30".to_string(),
            random_tree(&mut rng(30), 30, &TreeOptions::default()),
        ),
    ];
    for name in ["ur5", "panda"] {
        match example_robot_data(name) {
            Some(p) => v.push((name.to_string(), robodyn::io::load(&p).unwrap())),
            None => eprintln!("kinematics bench: {name} URDF not found (example-robot-data)"),
        }
    }
    v
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("kinematics");
    for (label, robot) in robots() {
        let n = robot.dof();
        let [q, qd, qdd] = random_state(&mut rng(1), n);
        let frame = robot.frame_id_of(robot.nl()).unwrap();
        let mut data = KinematicsData::new(&robot);
        let mut j = DMatrix::zeros(6, n);
        let mut jcom = DMatrix::zeros(3, n);
        g.bench_function(format!("{label}/forward_kinematics"), |b| {
            b.iter(|| forward_kinematics_into(&robot, &mut data, &q, &qd, &qdd).unwrap())
        });
        g.bench_function(format!("{label}/all_jacobians"), |b| {
            b.iter(|| placements_into(&robot, &mut data, &q).unwrap())
        });
        placements_into(&robot, &mut data, &q).unwrap();
        g.bench_function(format!("{label}/frame_jacobian_read"), |b| {
            b.iter(|| frame_jacobian_into(&robot, &data, &frame, Reference::Local, &mut j).unwrap())
        });
        g.bench_function(format!("{label}/placements_and_frame_jacobian"), |b| {
            b.iter(|| {
                placements_into(&robot, &mut data, &q).unwrap();
                frame_jacobian_into(&robot, &data, &frame, Reference::Local, &mut j).unwrap()
            })
        });
        forward_kinematics_into(&robot, &mut data, &q, &qd, &qdd).unwrap();
        g.bench_function(format!("{label}/com_and_jacobian"), |b| {
            b.iter(|| {
                let g = center_of_mass(&robot, &mut data, None).unwrap();
                center_of_mass_jacobian_into(&robot, &mut data, None, &mut jcom).unwrap();
                g
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
