//! `robodyn::view` without a browser (the page in a browser: crates/robodyn-cli/tests/cli_view.rs):
//! the scene carries the geometry the page composes (checked by composing it here with
//! nalgebra's rotations, independently of `geometry`), closed robots are exported closed (cut
//! frames on their twins, prismatic cut joints too), trajectories are read and checked (columns,
//! times, passive columns that do not close a loop, thinning), URDF visuals are found and placed
//! (package://, relative, missing, other formats, the size cap), and `save` never replaces what
//! is not a regular file.
#[path = "common/frames.rs"]
mod frames;

mod common;

use common::{robot, slider_crank};
use nalgebra::{Isometry3, Rotation3, Translation3, Vector3};
use robodyn::io::table::Table;
use robodyn::view::{
    page, save, urdf_visuals, JointColumns, MeshOptions, Pose, Trajectory, ViewOptions, MAX_SAMPLES,
};
use robodyn::{loop_closure, ClosedChain, Error, Robot};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The scene JSON embedded in a page.
fn scene(html: &str) -> Value {
    let start = html.find(r#"id="robodyn-scene">"#).unwrap() + r#"id="robodyn-scene">"#.len();
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end]).unwrap()
}

fn page_of(robot: &Robot, options: &ViewOptions) -> (Value, Vec<String>) {
    let p = page(robot, options).unwrap();
    (scene(&p.html), p.warnings)
}

/// 0T_j from the exported numbers, as the product of the six elementary transformations of the
/// notation (nalgebra's rotations about the unit axes), q added to theta or r.
fn compose(scene: &Value, q: &[f64]) -> Vec<Isometry3<f64>> {
    let mut t: Vec<Isometry3<f64>> = vec![Isometry3::identity()];
    for f in scene["frames"].as_array().unwrap() {
        let v: Vec<f64> = (0..6).map(|k| f["values"][k].as_f64().unwrap()).collect();
        let j = f["j"].as_u64().unwrap() as usize;
        let sigma = f["sigma"].as_u64().unwrap();
        let qj = if j <= q.len() { q[j - 1] } else { 0.0 };
        let (theta, r) = match sigma {
            0 => (v[4] + qj, v[5]),
            1 => (v[4], v[5] + qj),
            _ => (v[4], v[5]),
        };
        let rz = |a: f64| {
            Isometry3::from_parts(
                Translation3::identity(),
                Rotation3::from_axis_angle(&Vector3::z_axis(), a).into(),
            )
        };
        let rx = |a: f64| {
            Isometry3::from_parts(
                Translation3::identity(),
                Rotation3::from_axis_angle(&Vector3::x_axis(), a).into(),
            )
        };
        let tz = |d: f64| Isometry3::translation(0.0, 0.0, d);
        let tx = |d: f64| Isometry3::translation(d, 0.0, 0.0);
        let local = rz(v[0]) * tz(v[1]) * rx(v[2]) * tx(v[3]) * rz(theta) * tz(r);
        let ant = f["ant"].as_u64().unwrap() as usize;
        t.push(t[ant] * local);
    }
    t.remove(0);
    t
}

fn pose_q(scene: &Value) -> Vec<f64> {
    scene["pose"]["q"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Largest distance between the origins of two lists of frames, and of their axes.
fn gap(a: &[Isometry3<f64>], b: &[robodyn::geometry::Transform]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let m = x.to_homogeneous();
            let n = y.matrix();
            (m - n).abs().max()
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_scene_carries_the_geometry_of_every_bundled_robot() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for f in files {
        let r = robodyn::io::load(&f).unwrap();
        let (s, warnings) = page_of(&r, &ViewOptions::default());
        assert!(warnings.is_empty(), "{}: {warnings:?}", f.display());
        assert_eq!(s["frames"].as_array().unwrap().len(), r.nf());
        let q = pose_q(&s);
        let drawn = compose(&s, &q);
        // a floating robot is drawn with its base frame R_0 at the origin: its frames are
        // those of the same robot on a fixed base
        let fixed = if r.is_floating() {
            let mut d = r.description().clone();
            d.floating_base = None;
            robodyn::Robot::new(d).unwrap()
        } else {
            r.clone()
        };
        let e = gap(&drawn, &frames::per_frame(&fixed, &q));
        assert!(
            e < 1e-12,
            "{}: the exported geometry differs by {e:e}",
            f.display()
        );
        // closed robots arrive closed: each cut frame on its twin
        for l in &r.structure().loops {
            let d = (drawn[l.cut - 1].to_homogeneous() - drawn[l.twin - 1].to_homogeneous())
                .abs()
                .max();
            assert!(
                d < 1e-9,
                "{}: loop of cut joint {} open by {d:e}",
                f.display(),
                l.cut
            );
        }
    }
}

#[test]
fn a_prismatic_cut_joint_is_exported_closed() {
    let r = slider_crank();
    for pose in [Pose::Default, Pose::Actuated(vec![0.7])] {
        let (s, warnings) = page_of(
            &r,
            &ViewOptions {
                pose,
                ..Default::default()
            },
        );
        assert!(warnings.is_empty());
        let drawn = compose(&s, &pose_q(&s));
        let l = &r.structure().loops[0];
        let d = (drawn[l.cut - 1].to_homogeneous() - drawn[l.twin - 1].to_homogeneous())
            .abs()
            .max();
        assert!(d < 1e-9, "slider-crank drawn open by {d:e}");
    }
}

#[test]
fn poses_are_checked() {
    let rx90 = robot("rx90.toml");
    let e = page(
        &rx90,
        &ViewOptions {
            pose: Pose::Tree(vec![0.1; 5]),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            Error::Dimension {
                expected: 6,
                got: 5,
                ..
            }
        ),
        "{e}"
    );
    let tr = Trajectory::from_samples(&rx90, &[0.0], &[vec![0.0; 6]], JointColumns::Frame).unwrap();
    let both = ViewOptions {
        pose: Pose::Tree(vec![0.0; 6]),
        trajectory: Some(tr),
        ..Default::default()
    };
    let e = page(&rx90, &both).unwrap_err();
    assert!(e.to_string().contains("give one or the other"), "{e}");
    let e = page(
        &rx90,
        &ViewOptions {
            pose: Pose::Actuated(vec![0.0; 6]),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("no closed loop"), "{e}");
    // a closed robot drawn as given: its loop is open, and the page says so
    let sr = robot("sr400.toml");
    let p = page(
        &sr,
        &ViewOptions {
            pose: Pose::Tree(vec![0.0; 8]),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(p.warnings.len(), 1, "{:?}", p.warnings);
    assert!(
        p.warnings[0].contains("cut joint 9 is open"),
        "{:?}",
        p.warnings
    );
}

#[test]
fn a_closed_robot_whose_loops_cannot_close_is_drawn_open_with_a_warning() {
    // the four-bar with its coupler joint declared actuated: 2 actuated joints for 1 degree of
    // freedom, no closed-chain model; the viewer still draws it, and says why it is open
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/fourbar.toml"),
    )
    .unwrap()
    .replacen(
        "j = 2\nant = 1\nsigma = 0\nmu = 0",
        "j = 2\nant = 1\nsigma = 0\nmu = 1",
        1,
    );
    assert!(text.contains("j = 2\nant = 1\nsigma = 0\nmu = 1"));
    let r = robodyn::io::toml_format::parse_robot(&text, None).unwrap();
    let (s, warnings) = page_of(&r, &ViewOptions::default());
    assert!(
        warnings[0].starts_with("loop closure failed"),
        "{warnings:?}"
    );
    assert!(s["pose"]["note"]
        .as_str()
        .unwrap()
        .contains("loops as they fall"));
}

fn table(headers: &[&str], rows: Vec<Vec<f64>>) -> Table {
    Table {
        headers: headers.iter().map(|s| s.to_string()).collect(),
        rows,
        file: "traj.csv".into(),
    }
}

#[test]
fn tree_trajectories_are_read_by_frame_or_by_joint_name() {
    let r = robot("rx90.urdf");
    let rows: Vec<Vec<f64>> = (0..5)
        .map(|k| {
            (0..7)
                .map(|c| {
                    if c == 0 {
                        k as f64 * 0.1
                    } else {
                        0.1 * (k * c) as f64
                    }
                })
                .collect()
        })
        .collect();
    let by_frame = table(&["t", "q1", "q2", "q3", "q4", "q5", "q6"], rows.clone());
    let tr = Trajectory::from_table(&r, &by_frame, JointColumns::Frame).unwrap();
    assert_eq!(tr.len(), 5);
    assert_eq!(tr.values(3), &rows[3][1..]);
    let names: Vec<String> = std::iter::once("t".to_string())
        .chain(r.coordinates().names().iter().map(|n| format!("q_{n}")))
        .collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let by_name = table(&names, rows.clone());
    let tn = Trajectory::from_table(&r, &by_name, JointColumns::Joint).unwrap();
    assert_eq!(tn.values(4), tr.values(4));
    // a missing column, times that do not increase
    let e = Trajectory::from_table(
        &r,
        &table(&["t", "q1", "q2"], vec![vec![0.0; 3]]),
        JointColumns::Frame,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("`q3`") && e.contains("`q6`"), "{e}");
    let mut back = rows.clone();
    back[2][0] = 0.05;
    let e = Trajectory::from_table(
        &r,
        &table(
            by_frame
                .headers
                .iter()
                .map(String::as_str)
                .collect::<Vec<_>>()
                .as_slice(),
            back,
        ),
        JointColumns::Frame,
    )
    .unwrap_err();
    assert!(matches!(e, Error::Row { row: 3, .. }), "{e}");
}

#[test]
fn closed_trajectories_close_their_loops() {
    let r = robot("sr400.toml");
    let chain = ClosedChain::new(&r).unwrap();
    let mut branch = chain.assembly_branch().unwrap();
    let start = branch.q_a().to_vec();
    let (mut t, mut qa, mut full) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..20 {
        let a: Vec<f64> = start.iter().map(|x| x + 0.02 * k as f64).collect();
        let s = loop_closure(&chain, &mut branch, &a).unwrap();
        t.push(k as f64 * 0.01);
        full.push(s.q_tree.as_slice().to_vec());
        qa.push(a);
    }
    // actuated joints only: solved by loop closure, the loops closed at every sample
    let tr = Trajectory::from_samples(&r, &t, &qa, JointColumns::Frame).unwrap();
    for i in 0..tr.len() {
        let f = frames::per_frame(&r, tr.values(i));
        assert!((f[8].pos - f[9].pos).norm() < 1e-9 && (f[8].rot - f[9].rot).abs().max() < 1e-9);
    }
    // with the passive columns (q3, q8): used as given, and checked
    let headers = ["t", "q1", "q2", "q3", "q4", "q5", "q6", "q7", "q8"];
    let rows: Vec<Vec<f64>> = t
        .iter()
        .zip(&full)
        .map(|(t, q)| std::iter::once(*t).chain(q.iter().copied()).collect())
        .collect();
    let given =
        Trajectory::from_table(&r, &table(&headers, rows.clone()), JointColumns::Frame).unwrap();
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(given.values(i)[2], row[3]); // q3 as given
        let d = given
            .values(i)
            .iter()
            .zip(tr.values(i))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-9, "sample {i}: {d:e}");
    }
    // a passive column that does not close the loop is an error naming the row
    let mut bad = rows.clone();
    bad[7][3] += 0.01;
    let e = Trajectory::from_table(&r, &table(&headers, bad), JointColumns::Frame).unwrap_err();
    assert!(matches!(e, Error::Row { row: 8, .. }), "{e}");
    assert!(
        e.to_string()
            .contains("do not close the loop of cut joint 9"),
        "{e}"
    );
    // passive columns all or none
    let some: Vec<&str> = headers[..8].to_vec();
    let rows7: Vec<Vec<f64>> = rows.iter().map(|r| r[..8].to_vec()).collect();
    let e = Trajectory::from_table(&r, &table(&some, rows7), JointColumns::Frame).unwrap_err();
    assert!(e.to_string().contains("`q8` (passive)"), "{e}");
}

#[test]
fn long_trajectories_are_thinned_keeping_the_last_sample() {
    let r = robot("scara.toml");
    let n = 25_001;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let rows: Vec<Vec<f64>> = t.iter().map(|&x| vec![x, -x, 0.1 * x, 2.0 * x]).collect();
    let tr = Trajectory::from_samples(&r, &t, &rows, JointColumns::Frame).unwrap();
    assert!(
        tr.len() <= MAX_SAMPLES && tr.len() > MAX_SAMPLES / 2,
        "{}",
        tr.len()
    );
    assert_eq!(tr.times()[0], 0.0);
    assert_eq!(*tr.times().last().unwrap(), t[n - 1]);
    assert_eq!(tr.notes().len(), 1);
    let (s, _) = page_of(
        &r,
        &ViewOptions {
            trajectory: Some(tr),
            ..Default::default()
        },
    );
    assert_eq!(
        s["trajectory"]["t"].as_array().unwrap().len(),
        s["trajectory"]["q"].as_array().unwrap().len()
    );
}

/// A binary STL of one triangle.
fn stl() -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend(1u32.to_le_bytes());
    for x in [
        0.0f32, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0,
    ] {
        b.extend(x.to_le_bytes());
    }
    b.extend([0, 0]);
    b
}

/// A URDF in `dir/pkg/urdf/r.urdf` with meshes found and not found.
fn urdf_with_visuals(dir: &Path) -> PathBuf {
    let pkg = dir.join("pkg");
    std::fs::create_dir_all(pkg.join("urdf")).unwrap();
    std::fs::create_dir_all(pkg.join("meshes")).unwrap();
    std::fs::write(pkg.join("meshes/a.stl"), stl()).unwrap();
    std::fs::write(pkg.join("urdf/rel.STL"), stl()).unwrap();
    std::fs::write(pkg.join("meshes/big.stl"), vec![0u8; 5000]).unwrap();
    std::fs::write(pkg.join("meshes/c.dae"), "<COLLADA/>").unwrap();
    let urdf = pkg.join("urdf/r.urdf");
    let inertial =
        r#"<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"/></inertial>"#;
    std::fs::write(
        &urdf,
        format!(
            r#"<robot name="r">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base"><visual><geometry><box size="0.1 0.2 0.3"/></geometry><material name="red"/></visual></link>
  <link name="l1">{inertial}
    <visual><origin xyz="0.1 0 0"/><geometry><mesh filename="package://pkg/meshes/a.stl" scale="2 2 2"/></geometry></visual>
    <visual><geometry><mesh filename="rel.STL"/></geometry></visual>
    <visual><geometry><mesh filename="package://pkg/meshes/missing.stl"/></geometry></visual>
    <visual><geometry><mesh filename="package://pkg/meshes/c.dae"/></geometry></visual>
    <visual><geometry><mesh filename="package://pkg/meshes/big.stl"/></geometry></visual>
    <visual><geometry><cylinder radius="x" length="1"/></geometry></visual>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 1" rpy="0 1.5707963267948966 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#
        ),
    )
    .unwrap();
    urdf
}

#[test]
fn urdf_visuals_are_found_placed_and_capped() {
    let dir = std::env::temp_dir().join(format!("robodyn_view_visuals_{}", std::process::id()));
    let urdf = urdf_with_visuals(&dir);
    let r = robodyn::io::load(&urdf).unwrap();
    let options = MeshOptions {
        search_paths: Vec::new(),
        max_bytes: 1000,
    };
    let v = urdf_visuals(&r, &urdf, &options).unwrap();
    assert_eq!(v.len(), 3, "{:?}", v.notes()); // the box, a.stl, rel.STL
    assert_eq!(v.meshes(), (2, 2 * stl().len()));
    let notes = v.notes().join("\n");
    for what in [
        "missing.stl` not found",
        "only STL meshes",
        "size cap",
        "radius",
    ] {
        assert!(notes.contains(what), "{what}: {notes}");
    }
    let (s, _) = page_of(
        &r,
        &ViewOptions {
            visuals: Some(v),
            ..Default::default()
        },
    );
    let items = s["visuals"]["items"].as_array().unwrap();
    assert_eq!(items[0]["frame"], 0);
    assert_eq!(items[0]["color"], serde_json::json!([1.0, 0.0, 0.0, 1.0]));
    assert_eq!(items[1]["scale"], serde_json::json!([2.0, 2.0, 2.0]));
    // a.stl's origin, placed in R_1 and composed with 0T_1: the URDF's placement of the visual,
    // joint origin (0, 0, 1) turned by pitch pi/2 (x_link = -z_0), then 0.1 along x_link
    let t1 = frames::per_frame(&r, &[0.0])[0].matrix();
    let o: Vec<f64> = (0..16)
        .map(|k| items[1]["origin"][k].as_f64().unwrap())
        .collect();
    let o = nalgebra::Matrix4::from_row_slice(&o);
    let world = t1 * o;
    let want = Vector3::new(0.0, 0.0, 0.9);
    let got = Vector3::new(world[(0, 3)], world[(1, 3)], world[(2, 3)]);
    assert!((got - want).norm() < 1e-12, "{got} vs {want}");
    let x_link = Vector3::new(world[(0, 0)], world[(1, 0)], world[(2, 0)]);
    assert!(
        (x_link - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-12,
        "{x_link}"
    );
    // without the cap the big file is embedded too (it is no STL but the page's loader judges)
    let all = urdf_visuals(&r, &urdf, &MeshOptions::default()).unwrap();
    assert_eq!(all.meshes().0, 3);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn save_replaces_regular_files_and_writes_other_paths_in_place() {
    let dir = std::env::temp_dir().join(format!("robodyn_view_save_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a.html");
    std::fs::write(&file, "old").unwrap();
    save(&file, b"new").unwrap();
    assert_eq!(std::fs::read(&file).unwrap(), b"new");
    #[cfg(unix)]
    {
        let link = dir.join("link.html");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        save(&link, b"via link").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&file).unwrap(), b"via link");
        // a device is written, never replaced
        save(Path::new("/dev/null"), b"x").unwrap();
        assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
    }
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), if cfg!(unix) { 2 } else { 1 }, "{left:?}");
    // a directory that does not exist: an error naming the file, nothing left behind
    let e = save(&dir.join("no/such.html"), b"x").unwrap_err();
    assert!(e.to_string().contains("no/such.html"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
