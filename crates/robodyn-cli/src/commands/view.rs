//! `robodyn view ROBOT [--q ..] [--trajectory traj.csv] [--output robot.html] [--png shot.png]`:
//! a 3D view of the robot's frames, links and joints in one self-contained HTML page
//! (`robodyn::view`; docs/view.md), and a PNG picture of it by a headless Chromium.

use crate::common::{parse_list, CliResult, Names, NamesArg, RobotArgs};
use robodyn::io::table::Table;
use robodyn::io::Format;
use robodyn::view::{
    page, urdf_visuals, JointColumns, MeshOptions, Picture, Pose, Trajectory, ViewOptions,
};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Joint values, comma separated: the movable joints of a tree (frame order), or the
    /// actuated joints of a closed robot (its passive joints by loop closure on the assembly
    /// branch). Default: q = 0 for a tree, the robot's `assembly` for a closed robot.
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// A trajectory to play back: a CSV file with a column `t` (s) and the joints' positions
    /// (`q<j>`, or `q_<name>` with `--names joint`), such as the output of `simulate`; a closed
    /// robot needs its actuated joints, and its passive joints all or none (then solved by loop
    /// closure).
    #[arg(long)]
    pub trajectory: Option<PathBuf>,
    #[command(flatten)]
    pub names: NamesArg,
    /// The HTML page to write (`-`: standard output). Default: the robot file's name with
    /// `.html`, in the current directory (none when only `--png` is asked for).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// Also write a PNG picture of the 3D view (fixed camera, no panels), rendered by a
    /// headless Chromium or Google Chrome (`ROBODYN_CHROMIUM` names the program; else
    /// `chromium`, `chromium-browser`, `google-chrome` on the PATH).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Size of the PNG picture in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1200x900")]
    pub size: String,
    /// URDF meshes: a directory searched for `package://NAME/...` (repeatable; the entries of
    /// ROS_PACKAGE_PATH and the directories above the URDF are searched too).
    #[arg(long = "package-path", value_name = "DIR")]
    pub package_path: Vec<PathBuf>,
    /// URDF meshes: at most this many MB of STL files embedded in the page (0: none; the other
    /// links are drawn as the sketch).
    #[arg(long, default_value = "32", value_name = "MB")]
    pub mesh_limit: f64,
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    let pose = match &a.q {
        None => Pose::Default,
        Some(s) if robot.is_tree() => Pose::Tree(parse_list("q", s)?),
        Some(s) => Pose::Actuated(parse_list("q", s)?),
    };
    let trajectory = match &a.trajectory {
        None => None,
        Some(p) => {
            // `-`: standard input
            let table = if robodyn::io::is_stdio(p) {
                Table::from_reader(std::io::stdin().lock(), "<stdin>")?
            } else {
                Table::read(p)?
            };
            let columns = match a.names.names {
                Names::Frame => JointColumns::Frame,
                Names::Joint => JointColumns::Joint,
            };
            let tr = Trajectory::from_table(&robot, &table, columns)?;
            for n in tr.notes() {
                eprintln!("robodyn: view: {n}");
            }
            Some(tr)
        }
    };
    let visuals = visuals(&a, &robot)?;
    let mut options = ViewOptions {
        pose,
        trajectory,
        visuals,
        picture: None,
    };
    let html_path = match (&a.output, &a.png) {
        (Some(p), _) => Some(p.clone()),
        (None, Some(_)) => None,
        (None, None) => Some(default_output(&a.robot.robot)),
    };
    if let Some(path) = &html_path {
        let p = page(&robot, &options)?;
        for w in &p.warnings {
            eprintln!("robodyn: warning: {w}");
        }
        if robodyn::io::is_stdio(path) {
            crate::common::print_out(&p.html)?;
        } else {
            p.save(path)?;
            eprintln!(
                "robodyn: wrote {} ({:.1} MB): open it in a web browser (it needs no network)",
                path.display(),
                p.html.len() as f64 / 1e6
            );
        }
    }
    if let Some(png) = &a.png {
        let (width, height) = parse_size(&a.size)?;
        options.picture = Some(Picture { width, height });
        let p = page(&robot, &options)?;
        if html_path.is_none() {
            for w in &p.warnings {
                eprintln!("robodyn: warning: {w}");
            }
        }
        screenshot(&p.html, png, width, height)?;
        eprintln!("robodyn: wrote {} ({width}x{height})", png.display());
    }
    Ok(())
}

/// The meshes of a URDF robot (none for the other formats or with `--mesh-limit 0`).
fn visuals(a: &Args, robot: &robodyn::Robot) -> CliResult<Option<robodyn::view::Visuals>> {
    let path = &a.robot.robot;
    let is_urdf =
        !robodyn::io::is_stdio(path) && matches!(Format::from_path(path), Ok(Format::Urdf));
    if !is_urdf || a.mesh_limit <= 0.0 {
        return Ok(None);
    }
    if !a.mesh_limit.is_finite() {
        return Err(format!("--mesh-limit {}: a number of MB expected", a.mesh_limit).into());
    }
    let mut search = a.package_path.clone();
    if let Some(ros) = std::env::var_os("ROS_PACKAGE_PATH") {
        search.extend(std::env::split_paths(&ros));
    }
    let options = MeshOptions {
        search_paths: search,
        max_bytes: (a.mesh_limit * 1e6) as usize,
    };
    let v = urdf_visuals(robot, path, &options)?;
    for n in v.notes() {
        eprintln!("robodyn: view: {n}");
    }
    let (n, bytes) = v.meshes();
    eprintln!(
        "robodyn: view: {} visual(s) of the URDF embedded ({n} STL mesh(es), {:.1} MB)",
        v.len(),
        bytes as f64 / 1e6
    );
    Ok(Some(v))
}

/// `ROBOT.html` in the current directory.
fn default_output(robot: &Path) -> PathBuf {
    let stem = robot
        .file_stem()
        .filter(|_| !robodyn::io::is_stdio(robot))
        .map_or_else(|| "robot".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from(format!("{stem}.html"))
}

fn parse_size(s: &str) -> CliResult<(u32, u32)> {
    let bad = || format!("--size {s}: WIDTHxHEIGHT in pixels expected (e.g. 1200x900)");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if !(16..=8192).contains(&w) || !(16..=8192).contains(&h) {
        return Err(format!("--size {s}: each side must be 16 to 8192 pixels").into());
    }
    Ok((w, h))
}

/// The Chromium-based browser to render with: `ROBODYN_CHROMIUM`, else the first of the usual
/// names on the PATH.
fn browser() -> CliResult<PathBuf> {
    if let Some(p) = std::env::var_os("ROBODYN_CHROMIUM") {
        let p = PathBuf::from(p);
        return if p.is_file() {
            Ok(p)
        } else {
            Err(format!("ROBODYN_CHROMIUM={}: no such program", p.display()).into())
        };
    }
    let names = [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
    ];
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .flat_map(|d| names.iter().map(move |n| d.join(n)))
        .find(|p| p.is_file())
        .ok_or_else(|| {
            "--png renders the page in a headless Chromium, and none was found (chromium, \
             chromium-browser, google-chrome on the PATH; or set \
             ROBODYN_CHROMIUM=/path/to/chrome). Install one (Debian/Ubuntu: `apt-get install chromium`), or write the page with \
             --output robot.html and take the picture from a browser"
                .into()
        })
}

/// Render `html` in a headless Chromium at `width` x `height` and write the picture to `png`
/// (the browser writes into a temporary directory; `robodyn::view::save` replaces `png`). The
/// page is robodyn's own and loads nothing, so the browser runs without its sandbox (which
/// refuses to start as root) and with software WebGL.
fn screenshot(html: &str, png: &Path, width: u32, height: u32) -> CliResult {
    let program = browser()?;
    let dir = std::env::temp_dir().join(format!(
        "robodyn-view-{}-{}",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos())
    ));
    std::fs::create_dir_all(dir.join("profile")).map_err(|e| format!("{}: {e}", dir.display()))?;
    let result = (|| -> CliResult {
        let page = dir.join("page.html");
        std::fs::write(&page, html).map_err(|e| format!("{}: {e}", page.display()))?;
        let tmp = dir.join("shot.png");
        let mut child = Command::new(&program)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--enable-unsafe-swiftshader",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--disable-extensions",
                "--no-first-run",
                "--no-default-browser-check",
                "--hide-scrollbars",
                "--force-device-scale-factor=1",
                "--virtual-time-budget=20000",
            ])
            .arg(format!("--user-data-dir={}", dir.join("profile").display()))
            .arg(format!("--window-size={width},{height}"))
            .arg(format!("--screenshot={}", tmp.display()))
            .arg(format!("file://{}", page.display()))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("{}: {e}", program.display()))?;
        let start = Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait()? {
                break s;
            }
            if start.elapsed() > Duration::from_secs(180) {
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!("{}: no picture after 180 s", program.display()).into());
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        let mut err = String::new();
        if let Some(mut e) = child.stderr.take() {
            let _ = std::io::Read::read_to_string(&mut e, &mut err);
        }
        let written = std::fs::metadata(&tmp).is_ok_and(|m| m.len() > 0);
        if !status.success() || !written {
            let tail: Vec<&str> = err.lines().rev().take(5).collect();
            return Err(format!(
                "{} could not take the picture ({status}): {}",
                program.display(),
                tail.into_iter().rev().collect::<Vec<_>>().join(" | ")
            )
            .into());
        }
        let bytes = std::fs::read(&tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
        Ok(robodyn::view::save(png, &bytes)?)
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}
