//! `robodyn view` in a real browser: Debian's Chromium, headless, driven by playwright-core
//! (`tests/browser/view_check.mjs`, `npm ci` there; no browser download). For the page of every
//! bundled robot (robots/*.toml, *.urdf, *.par): it loads with no console error and no network
//! request, it draws (the screenshot is not blank and shows the red x and blue z axes), moving a
//! slider changes the picture, and the frames it draws agree with robodyn's own forward
//! kinematics (`robodyn::geometry::frame_transforms_with_cuts`) to 1e-9 on random joint values; closed
//! robots are drawn assembled (R_k on its twin R_{k+B}) at their assembly and at random actuated
//! values solved by `robodyn::loop_closure`; trajectories (a tree's, a closed robot's with and
//! without its passive columns, `simulate`'s output) play. Talos (example-robot-data) with its
//! STL meshes loads too.
//!
//! Optional check `browser` (node.js, Chromium, `npm ci` in tests/browser): skipped visibly
//! without them, required by `ROBODYN_REQUIRE=browser` (CI).

mod common;

use common::{robot, run, tmp};
use robodyn::geometry::frame_transforms_with_cuts;
use robodyn::{loop_closure, ClosedChain, Robot};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Frames drawn vs computed: largest difference of the 4x4 entries (origins in m).
const TOL: f64 = 1e-9;

/// The directory of the browser scripts.
fn browser_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/browser")
}

/// Chromium and the installed scripts, or None after a visible skip of the optional check.
fn browser() -> Option<PathBuf> {
    let what = "the page of `robodyn view` in a browser not checked";
    if !crate::harness::tool(
        "browser",
        "node",
        &["--version"],
        &format!("node.js: {what}"),
    ) {
        return None;
    }
    let names = [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
    ];
    let chromium = std::env::var_os("ROBODYN_CHROMIUM")
        .map(PathBuf::from)
        .or_else(|| {
            let path = std::env::var_os("PATH").unwrap_or_default();
            std::env::split_paths(&path)
                .flat_map(|d| names.iter().map(move |n| d.join(n)))
                .find(|p| p.is_file())
        });
    let Some(chromium) = chromium else {
        crate::harness::skip(
            "browser",
            &format!("chromium not found (Debian: apt-get install chromium): {what}"),
        );
        return None;
    };
    if !browser_dir().join("node_modules/playwright-core").is_dir() {
        crate::harness::skip(
            "browser",
            &format!(
                "playwright-core not installed (run `npm ci` in {}): {what}",
                browser_dir().display()
            ),
        );
        return None;
    }
    Some(chromium)
}

/// Deterministic uniform numbers in [lo, hi) (splitmix64).
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        lo + (hi - lo) * ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// 0T_j (j = 1..NF) as 4x4 row-major, from robodyn.
fn expected(robot: &Robot, q_frames: &[f64]) -> Vec<[f64; 16]> {
    let movable: Vec<f64> = robot
        .coordinates()
        .frames()
        .iter()
        .map(|&j| q_frames[j - 1])
        .collect();
    let cuts: Vec<f64> = (robot.nl() + 1..=robot.nj())
        .map(|j| q_frames.get(j - 1).copied().unwrap_or(0.0))
        .collect();
    frame_transforms_with_cuts(robot, &movable, &cuts)
        .expect("a finite state")
        .iter()
        .map(|t| {
            let m = t.matrix();
            std::array::from_fn(|k| m[(k / 4, k % 4)])
        })
        .collect()
}

/// Largest entry difference between drawn and computed frames.
fn worst(drawn: &Value, want: &[[f64; 16]]) -> f64 {
    let drawn = drawn.as_array().expect("a list of frames");
    assert_eq!(drawn.len(), want.len(), "number of frames drawn");
    drawn
        .iter()
        .zip(want)
        .flat_map(|(d, w)| (0..16).map(move |k| (d[k].as_f64().unwrap() - w[k]).abs()))
        .fold(0.0, f64::max)
}

/// Values of frames 1..NJ of a closed robot at q_a (default: its assembly) by loop closure.
fn closed_values(robot: &Robot, q_a: Option<&[f64]>) -> Vec<f64> {
    let chain = ClosedChain::new(robot).unwrap();
    let mut branch = chain.assembly_branch().unwrap();
    let qa = q_a.map_or_else(|| branch.q_a().to_vec(), <[f64]>::to_vec);
    let s = loop_closure(&chain, &mut branch, &qa).unwrap();
    let mut q = vec![0.0; robot.nj()];
    for (&j, &x) in robot.coordinates().frames().iter().zip(s.q_tree.iter()) {
        q[j - 1] = x;
    }
    q[robot.nl()..].copy_from_slice(s.q_c.as_slice());
    q
}

/// The movable-joint vector scattered into frame values 1..NJ.
fn frames_of(robot: &Robot, q: &[f64]) -> Vec<f64> {
    let mut v = vec![0.0; robot.nj()];
    for (&j, &x) in robot.coordinates().frames().iter().zip(q) {
        v[j - 1] = x;
    }
    v
}

/// What one page must show, and how it is checked.
struct Case {
    name: String,
    robot: Robot,
    /// Frame values of the initial pose, when known (checked to TOL).
    initial: Option<Vec<f64>>,
    /// Random movable-joint vectors set through the page (trees).
    joints: Vec<Vec<f64>>,
    slider: bool,
    /// A trajectory's rows: the values of frames 1..NJ the page must draw at each sample (the
    /// tree frames 1..NL are compared where the page stops playing).
    trajectory: Option<Vec<Vec<f64>>>,
}

fn make_page(dir: &Path, name: &str, args: &[&str]) -> PathBuf {
    let html = dir.join(format!("{name}.html"));
    let mut full: Vec<&str> = vec!["view"];
    full.extend(args);
    let out = html.to_str().unwrap().to_string();
    full.extend(["--output", &out]);
    run(&full);
    html
}

fn bundled_cases(dir: &Path, rng: &mut Rng) -> (Vec<Case>, Vec<PathBuf>) {
    let mut files: Vec<PathBuf> = std::fs::read_dir(robot(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("toml" | "urdf" | "par")
            )
        })
        .collect();
    files.sort();
    let (mut cases, mut pages) = (Vec::new(), Vec::new());
    for f in files {
        let file = f.file_name().unwrap().to_string_lossy().into_owned();
        let r = robodyn::io::load(&f).unwrap();
        // a floating robot is drawn with its base frame R_0 at the origin: its frames are
        // those of the same robot on a fixed base
        let r = if r.is_floating() {
            let mut d = r.description().clone();
            d.floating_base = None;
            robodyn::Robot::new(d).unwrap()
        } else {
            r
        };
        pages.push(make_page(dir, &file, &[f.to_str().unwrap()]));
        let closes = !r.is_tree()
            && ClosedChain::new(&r)
                .and_then(|c| c.assembly_branch())
                .is_ok();
        let (initial, joints) = if r.is_tree() {
            let joints = (0..4)
                .map(|_| (0..r.dof()).map(|_| rng.uniform(-2.0, 2.0)).collect())
                .collect();
            (Some(vec![0.0; r.nj()]), joints)
        } else if closes {
            (Some(closed_values(&r, None)), Vec::new())
        } else {
            (None, Vec::new())
        };
        cases.push(Case {
            name: file.clone(),
            slider: r.is_tree() && r.dof() > 0,
            robot: r,
            initial,
            joints,
            trajectory: None,
        });
        // closed robots at random actuated values near their assembly, by `--q`
        let r = &cases.last().unwrap().robot;
        if closes {
            let chain = ClosedChain::new(r).unwrap();
            let qa: Vec<f64> = chain
                .assembly_branch()
                .unwrap()
                .q_a()
                .iter()
                .map(|x| x + rng.uniform(-0.15, 0.15))
                .collect();
            let list: Vec<String> = qa.iter().map(|x| format!("{x:?}")).collect();
            let name = format!("{file} --q");
            pages.push(make_page(
                dir,
                &name.replace(' ', "_"),
                &[f.to_str().unwrap(), "--q", &list.join(",")],
            ));
            cases.push(Case {
                name,
                robot: r.clone(),
                initial: Some(closed_values(r, Some(&qa))),
                joints: Vec::new(),
                slider: false,
                trajectory: None,
            });
        }
    }
    (cases, pages)
}

/// Trajectories: the RX-90 (a tree), the SR400 with only its actuated columns (passive joints
/// solved by robodyn) and `simulate`'s output of the SR400 (passive columns used).
fn trajectory_cases(dir: &Path) -> (Vec<Case>, Vec<PathBuf>) {
    let mut csv = String::from("t,q1,q2,q3,q4,q5,q6\n");
    for k in 0..200 {
        let t = k as f64 * 0.01;
        let v: Vec<String> = (1..=6)
            .map(|j| format!("{}", 0.8 * (t * (1.0 + 0.3 * j as f64)).sin()))
            .collect();
        csv += &format!("{t},{}\n", v.join(","));
    }
    let rx = tmp("view", "rx90_traj.csv");
    std::fs::write(&rx, csv).unwrap();
    let mut csv = String::from("t,q1,q2,q4,q5,q6,q7\n");
    for k in 0..100 {
        let t = k as f64 * 0.02;
        let s = (3.0 * t).sin();
        csv += &format!(
            "{t},{},{},{},0,{},{}\n",
            0.4 * s,
            0.2 * s,
            0.5 * s,
            s,
            std::f64::consts::FRAC_PI_2 + 0.2 * s
        );
    }
    let sr = tmp("view", "sr400_actuated.csv");
    std::fs::write(&sr, csv).unwrap();
    let sim = tmp("view", "sr400_sim.csv");
    run(&[
        "simulate",
        &robot("sr400.toml"),
        "--duration",
        "0.3",
        "--dt",
        "0.002",
        "--output",
        sim.to_str().unwrap(),
    ]);
    let mut cases = Vec::new();
    let mut pages = Vec::new();
    for (name, file, csv) in [
        ("rx90 trajectory", "rx90.toml", &rx),
        ("sr400 actuated trajectory", "sr400.toml", &sr),
        ("sr400 simulate trajectory", "sr400.toml", &sim),
    ] {
        let args = [
            robot(file),
            "--trajectory".into(),
            csv.display().to_string(),
        ];
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        pages.push(make_page(dir, &name.replace(' ', "_"), &args));
        let r = robodyn::io::load(robot(file)).unwrap();
        cases.push(Case {
            name: name.into(),
            trajectory: Some(trajectory_rows(&r, csv)),
            robot: r,
            initial: None,
            joints: Vec::new(),
            slider: false,
        });
    }
    (cases, pages)
}

/// The values of frames 1..NJ at each row of a trajectory file: its columns `q<j>`, or for a
/// closed robot given by its actuated joints alone, loop closure row after row.
fn trajectory_rows(r: &Robot, csv: &Path) -> Vec<Vec<f64>> {
    let (head, rows) = common::csv(&std::fs::read_to_string(csv).unwrap());
    let col = |j: usize| head.iter().position(|h| *h == format!("q{j}"));
    let movable = r.coordinates().frames();
    if movable.iter().all(|&j| col(j).is_some()) {
        return rows
            .iter()
            .map(|row| {
                let q: Vec<f64> = movable.iter().map(|&j| row[col(j).unwrap()]).collect();
                frames_of(r, &q)
            })
            .collect();
    }
    let chain = ClosedChain::new(r).unwrap();
    let mut branch = chain.assembly_branch().unwrap();
    rows.iter()
        .map(|row| {
            let qa: Vec<f64> = chain
                .coordinates()
                .frames()
                .iter()
                .map(|&j| row[col(j).unwrap()])
                .collect();
            let s = loop_closure(&chain, &mut branch, &qa).unwrap();
            frames_of(r, s.q_tree.as_slice())
        })
        .collect()
}

/// example-robot-data's robots folder (installed with Pinocchio), or None after a visible skip.
fn example_robot_data() -> Option<PathBuf> {
    let python = std::env::var("ROBODYN_PYTHON").unwrap_or_else(|_| "python3".into());
    let out = Command::new(python)
        .args([
            "-c",
            "import cmeel, os; print(os.path.join(os.path.dirname(os.path.dirname(cmeel.__file__)), \
             'cmeel.prefix', 'share', 'example-robot-data', 'robots'))",
        ])
        .output();
    let found = out
        .ok()
        .filter(|o| o.status.success())
        .map(|o| PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()))
        .filter(|p| p.is_dir());
    if found.is_none() {
        crate::harness::skip(
            "pinocchio",
            "example-robot-data not found (pip install pin example-robot-data): Talos' page with \
             its STL meshes not checked in the browser",
        );
    }
    found
}

/// Talos (example-robot-data) with its 48 STL meshes, at q = 0 and a random q.
fn talos_case(dir: &Path, rng: &mut Rng) -> Option<(Case, PathBuf)> {
    let urdf = example_robot_data()?.join("talos_data/robots/talos_full_v2.urdf");
    let r = robodyn::io::load(&urdf).unwrap();
    let page = make_page(dir, "talos", &[urdf.to_str().unwrap()]);
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.contains(r#""shape":"stl""#),
        "Talos' meshes are not in its page"
    );
    let q = (0..r.dof()).map(|_| rng.uniform(-1.0, 1.0)).collect();
    let case = Case {
        name: "talos_full_v2.urdf".into(),
        initial: Some(vec![0.0; r.nj()]),
        joints: vec![q],
        slider: true,
        trajectory: None,
        robot: r,
    };
    Some((case, page))
}

/// Run the browser on the pages; the report per page.
fn drive(chromium: &Path, cases: &[Case], pages: &[PathBuf]) -> Vec<Value> {
    let specs: Vec<Value> = cases
        .iter()
        .zip(pages)
        .map(|(c, html)| {
            let mut s = json!({ "name": c.name, "html": html, "joints": c.joints,
                                "trajectory": c.trajectory.is_some() });
            if c.slider {
                s["slider"] = json!({ "start": vec![0.0; c.robot.dof()] });
            }
            s
        })
        .collect();
    let job = tmp("view", "job.json");
    let report = tmp("view", "report.json");
    std::fs::write(
        &job,
        json!({ "chromium": chromium, "pages": specs }).to_string(),
    )
    .unwrap();
    let out = Command::new("node")
        .arg(browser_dir().join("view_check.mjs"))
        .args([&job, &report])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "node view_check.mjs: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let r: Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    r["pages"].as_array().unwrap().clone()
}

/// The checks of one page's report.
fn check(c: &Case, r: &Value) {
    let name = &c.name;
    assert_eq!(r["errors"], json!([]), "{name}: errors in the page");
    assert_eq!(
        r["requests"],
        json!([]),
        "{name}: the page asked the network"
    );
    let s = &r["stats"];
    let non_white = s["nonWhite"].as_f64().unwrap();
    assert!(non_white > 0.01, "{name}: blank picture ({non_white})");
    for axis in ["red", "blue"] {
        let n = s[axis].as_u64().unwrap();
        assert!(
            n > 40,
            "{name}: {n} {axis} pixels: the frames are not visible"
        );
    }
    let mut largest: f64 = 0.0;
    if let Some(q) = &c.initial {
        let e = worst(&r["transforms"], &expected(&c.robot, q));
        assert!(
            e < TOL,
            "{name}: drawn frames differ from robodyn's by {e:e}"
        );
        largest = largest.max(e);
    }
    for (q, drawn) in c
        .joints
        .iter()
        .zip(r["joint_transforms"].as_array().unwrap())
    {
        let e = worst(drawn, &expected(&c.robot, &frames_of(&c.robot, q)));
        assert!(
            e < TOL,
            "{name}: at q = {q:?} the drawn frames differ by {e:e}"
        );
        largest = largest.max(e);
    }
    assert_eq!(
        r["joint_transforms"].as_array().unwrap().len(),
        c.joints.len()
    );
    if !c.robot.is_tree() {
        closed_drawn(c, &r["transforms"]);
    }
    if c.slider {
        let changed = r["slider"]["changed"].as_f64().unwrap();
        assert!(
            changed > 0.005,
            "{name}: moving a slider changed {changed} of the picture"
        );
        let first = r["slider"]["joints"][0].as_f64().unwrap();
        assert!(first != 0.0, "{name}: the slider did not move joint 1");
    }
    if let Some(rows) = &c.trajectory {
        let t = &r["trajectory"];
        // the frames drawn where playing stopped: those of that row
        let k = t["sample"].as_u64().unwrap() as usize;
        let want = expected(&c.robot, &rows[k]);
        let nl = c.robot.nl();
        let drawn = json!(t["transforms"].as_array().unwrap()[..nl]);
        let e = worst(&drawn, &want[..nl]);
        assert!(
            e < TOL,
            "{name}: at sample {k} the drawn frames differ by {e:e}"
        );
        largest = largest.max(e);
        if !c.robot.is_tree() {
            closed_drawn(c, &t["transforms"]);
        }
        let (t0, t1) = (t["t0"].as_f64().unwrap(), t["t1"].as_f64().unwrap());
        assert!(t["playing"] == json!(true), "{name}: not playing");
        assert!(t1 > t0, "{name}: time did not advance ({t0} -> {t1})");
        let changed = t["changed"].as_f64().unwrap();
        assert!(
            changed > 0.002,
            "{name}: playing changed {changed} of the picture"
        );
    }
    // (shown with --nocapture)
    println!(
        "{name}: {} pose(s) compared, largest difference {largest:.1e}; picture {:.1} % drawn, \
         {} red and {} blue pixels; slider changed {}; trajectory [t0, t1, changed] {}",
        usize::from(c.initial.is_some()) + c.joints.len() + usize::from(c.trajectory.is_some()),
        100.0 * non_white,
        s["red"],
        s["blue"],
        r["slider"]["changed"],
        json!([
            &r["trajectory"]["t0"],
            &r["trajectory"]["t1"],
            &r["trajectory"]["changed"]
        ])
    );
}

/// A closed robot's loops drawn closed: R_k on its twin R_{k+B}.
fn closed_drawn(c: &Case, drawn: &Value) {
    for l in &c.robot.structure().loops {
        let (k, t) = (&drawn[l.cut - 1], &drawn[l.twin - 1]);
        let gap = (0..16)
            .map(|i| (k[i].as_f64().unwrap() - t[i].as_f64().unwrap()).abs())
            .fold(0.0, f64::max);
        if c.initial.is_some() || c.trajectory.is_some() {
            assert!(
                gap < TOL,
                "{}: loop of cut joint {} drawn open ({gap:e})",
                c.name,
                l.cut
            );
        }
    }
}

#[test]
fn every_bundled_robot_and_trajectory_in_a_browser() {
    let Some(chromium) = browser() else { return };
    let dir = tmp("view", "pages");
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = Rng(20261126);
    let (mut cases, mut pages) = bundled_cases(&dir, &mut rng);
    let (c, p) = trajectory_cases(&dir);
    cases.extend(c);
    pages.extend(p);
    if let Some((c, p)) = talos_case(&dir, &mut rng) {
        cases.push(c);
        pages.push(p);
    }
    let reports = drive(&chromium, &cases, &pages);
    assert_eq!(reports.len(), cases.len());
    for (c, r) in cases.iter().zip(&reports) {
        check(c, r);
    }
}

/// `robodyn ARGS` in `dir` with `env`, expected to fail: its standard error.
fn fails(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .current_dir(dir)
        .envs(env.iter().copied())
        .output()
        .unwrap();
    assert!(!out.status.success(), "robodyn {args:?} succeeded");
    assert!(out.stdout.is_empty(), "robodyn {args:?} printed something");
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn the_page_is_written_where_asked_and_nothing_else() {
    let dir = tmp("view_out", "d");
    std::fs::create_dir_all(&dir).unwrap();
    let sr400 = robot("sr400.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(["view", &sr400])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(out.status.success());
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        ["sr400.html"],
        "default output, no temporary file left"
    );
    let page = run(&["view", &sr400, "--output", "-"]);
    assert_eq!(
        page,
        std::fs::read_to_string(dir.join("sr400.html")).unwrap()
    );
    assert!(page.starts_with("<!DOCTYPE html>") && page.contains(r#"<script type="importmap">"#));
}

#[test]
fn errors_say_what_is_wrong() {
    let dir = tmp("view_err", "d");
    std::fs::create_dir_all(&dir).unwrap();
    let rx90 = robot("rx90.toml");
    let e = fails(&dir, &["view", &rx90, "--q", "0.1,0.2"], &[]);
    assert!(
        e.contains("q has 2 entries") || e.contains("expected 6"),
        "{e}"
    );
    let e = fails(
        &dir,
        &["view", &rx90, "--png", "a.png", "--size", "12x"],
        &[],
    );
    assert!(e.contains("WIDTHxHEIGHT"), "{e}");
    let e = fails(
        &dir,
        &["view", &rx90, "--png", "a.png"],
        &[("ROBODYN_CHROMIUM", "/no/chrome")],
    );
    assert!(
        e.contains("ROBODYN_CHROMIUM=/no/chrome: no such program"),
        "{e}"
    );
    let e = fails(
        &dir,
        &["view", &rx90, "--png", "a.png"],
        &[("PATH", "/nonexistent")],
    );
    assert!(
        e.contains("apt-get install chromium") && e.contains("--output"),
        "{e}"
    );
    let csv = dir.join("t.csv");
    std::fs::write(&csv, "t,q1,q2\n0,0,0\n").unwrap();
    let e = fails(
        &dir,
        &["view", &rx90, "--trajectory", csv.to_str().unwrap()],
        &[],
    );
    assert!(e.contains("t.csv") && e.contains("`q3`"), "{e}");
    // nothing written on failure
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "only t.csv");
}
