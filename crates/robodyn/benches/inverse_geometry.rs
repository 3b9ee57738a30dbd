//! The closed-form inverse geometric model (every solution of one target) on the RX-90 (a
//! spherical wrist), on a UR-like chain (axes 2, 3, 4 parallel) and, when example-robot-data is
//! installed (`pip install example-robot-data`), on its UR5 URDF (limits, offsets, a tool
//! frame), against the direct geometric model that made the targets.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use robodyn::algorithms::inverse_geometry::ClosedFormIgm;
use robodyn::geometry::frame_transforms;
use robodyn::Robot;
use std::hint::black_box;

fn robot(file: &str) -> Robot {
    let robots = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots");
    robodyn::io::load(format!("{robots}/{file}")).unwrap()
}

/// A UR5-like chain in KK parameters (axes 2, 3, 4 parallel, axes 5, 6 meeting).
fn ur_like() -> Robot {
    let toml = r#"
name = "UR-like"
nl = 6
nj = 6
[[frame]]
j = 1
ant = 0
r = 0.089
[[frame]]
j = 2
ant = 1
alpha = "pi/2"
[[frame]]
j = 3
ant = 2
d = -0.425
[[frame]]
j = 4
ant = 3
d = -0.392
r = 0.109
[[frame]]
j = 5
ant = 4
alpha = "pi/2"
r = 0.095
[[frame]]
j = 6
ant = 5
alpha = "-pi/2"
r = 0.082
"#;
    let links: String = (1..=6)
        .map(|j| {
            format!(
                "[[link]]\nj = {j}\nXX = 0.01\nXY = 0\nXZ = 0\nYY = 0.01\nYZ = 0\nZZ = 0.01\n\
                 MX = 0\nMY = 0\nMZ = 0\nM = 1\n"
            )
        })
        .collect();
    robodyn::io::toml_format::parse_robot(&format!("{toml}{links}"), None).unwrap()
}

/// example-robot-data's UR5 URDF, found through Python's `cmeel` (as the tests find it), if
/// installed.
fn ur5_urdf() -> Option<Robot> {
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import cmeel, os; print(os.path.join(os.path.dirname(os.path.dirname(cmeel.__file__)), \
             'cmeel.prefix', 'share', 'example-robot-data', 'robots', 'ur_description', 'urdf', \
             'ur5_robot.urdf'))",
        ])
        .output()
        .ok()?;
    let path = String::from_utf8_lossy(&out.stdout).trim().to_string();
    robodyn::io::load(path).ok()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("inverse_geometry");
    let mut robots = vec![("rx90", robot("rx90.toml")), ("ur_like", ur_like())];
    robots.extend(ur5_urdf().map(|r| ("ur5", r)));
    for (name, r) in robots {
        let ik = ClosedFormIgm::new(&r).unwrap();
        let q = [0.3, -0.7, 0.9, 0.4, -0.8, 1.1];
        let target = frame_transforms(&r, &q).unwrap()[ik.frame() - 1].matrix();
        assert_eq!(ik.solve(&target).unwrap().len(), 8, "{name}");
        g.bench_with_input(BenchmarkId::new("closed_form_all", name), &(), |b, _| {
            b.iter(|| ik.solve(black_box(&target)).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("direct_geometric", name), &(), |b, _| {
            b.iter(|| frame_transforms(&r, black_box(&q)).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
