//! `robodyn generate ROBOT`: customized symbolic models (Table 10.3) as SYMORO-style text, LaTeX
//! or code (Rust, C, Python, Julia, MATLAB/Octave), with operation counts in the header.

use crate::common::{choices, CliResult};
use robodyn::algorithms::regressor::ZeroParameters;
use robodyn::codegen::{generate_with_progress, BaseParameters, Frames, GenOptions, ModelKind};
use robodyn::model::RobotDescription;
use robodyn_symbolic::{check_function_name, emit, Lang};
use std::path::PathBuf;

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum Model {
    /// Inverse dynamic model Gamma(q, qd, qdd) of the (equivalent) tree.
    Idm,
    /// Derivatives of the inverse dynamic model: dGamma/dq, dGamma/dqd and A = dGamma/dqdd,
    /// each N x N column-major, one after the other (3 N^2 outputs).
    IdmDerivatives,
    /// Inertia matrix A(q).
    Inertia,
    /// Vector H(q, qd).
    H,
    /// Direct dynamic model of a tree.
    Ddm,
    /// Closed chain: Gamma_cl = G^T Gamma_tr (10.40), inputs the closed tree state.
    Closed,
    /// Closed chain: W = d q_p / d q_a (10.30), inputs the closed tree positions.
    W,
    /// Direct geometric model iT_j (see --frame, --reference), inputs the joint positions.
    Dgm,
    /// Jacobian iJ_j of frame j expressed in frame i, rows [linear; angular] (see --frame,
    /// --reference), inputs the joint positions.
    Jacobian,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum Params {
    /// The 13 standard parameters of every link as symbols.
    Standard,
    /// Base parameters as symbols (the symbolic method's grouping, or --base-file).
    Base,
}

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Robot file (.toml, .par or .urdf); symbols need no values unless --numeric or closed.
    pub robot: PathBuf,
    /// Give or override a symbol value, e.g. `--set d3=0.6` (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Make a URDF's root link the floating base (a free-flyer root, Pinocchio's
    /// `JointModelFreeFlyer`; a .toml or .par file says it itself: `base = "floating"`,
    /// `is_floating = 1`). A floating robot's generated model is `--model idm` only: inputs q
    /// (nq = 7 + N: base position, quaternion x y z w, joints), qd and qdd (nv = 6 + N: the base
    /// twist in the base frame and its derivative, joints); outputs the base wrench (force,
    /// moment about O_0, in the base frame) then the joint torques.
    #[arg(long)]
    pub floating: bool,
    /// The model to generate.
    #[arg(long, value_enum, default_value = "idm")]
    pub model: Model,
    /// Frame j of --model dgm and jacobian: a number 1..NL or a name as the robot file gives
    /// it (URDF link or joint, frame name); default the terminal link's frame.
    #[arg(long, value_name = "J|NAME")]
    pub frame: Option<String>,
    /// Reference frame i of --model dgm and jacobian: the DGM is iT_j, the Jacobian is
    /// expressed in frame i; 0 the base (world axes at O_j, the default), `local` frame j itself.
    #[arg(long, value_name = "I|local", value_parser = reference)]
    pub reference: Option<Reference>,
    /// Which inertial parameters are the model's symbols.
    #[arg(long, value_enum, default_value = "standard")]
    pub params: Params,
    /// Grouping list for --params base: lines `XXR2 = XX2 - YY2 + ...` and `zero: XX1 XY1 ...`
    /// (default: the grouping of the symbolic method, as `robodyn base-params` prints it).
    #[arg(long, value_name = "FILE")]
    pub base_file: Option<PathBuf>,
    /// Symmetric links: XY = XZ = YZ = MX = MY = 0 (Table 10.3, simplified case).
    #[arg(long)]
    pub symmetric: bool,
    /// Drop Coulomb and viscous friction.
    #[arg(long)]
    pub no_friction: bool,
    /// Drop rotor inertias.
    #[arg(long)]
    pub no_rotor: bool,
    /// Substitute the robot's numeric values for all symbols.
    #[arg(long)]
    pub numeric: bool,
    /// Output language (operation counts in the header of every one). The code takes its
    /// parameters by name (a struct in Rust and C, keywords in Python, a named tuple in Julia,
    /// a struct in MATLAB) unless --numeric; a MATLAB function file is named after --output's
    /// file stem.
    #[arg(long, default_value = "text", value_parser = choices(&Lang::ALL, Lang::name, Lang::describe))]
    pub lang: Lang,
    /// Function name in the generated code (an identifier of the language that is not one of its
    /// reserved words; default `<robot>_<model>`).
    #[arg(long)]
    pub name: Option<String>,
    /// Output file (default or `-`: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
}

/// `--reference`: a frame number, or `local` (frame j itself).
#[derive(Clone, Copy, Debug)]
pub struct Reference(Option<usize>);

fn reference(s: &str) -> Result<Reference, String> {
    if s == "local" {
        return Ok(Reference(None));
    }
    s.parse()
        .map(|i| Reference(Some(i)))
        .map_err(|_| format!("`{s}`: expected a frame number (0: the base) or `local`"))
}

/// The frames of --model dgm and jacobian; --frame and --reference belong to those models only.
fn frames(a: &Args, desc: &RobotDescription) -> CliResult<Frames> {
    let mut f = Frames::TERMINAL;
    f.frame = a
        .frame
        .as_deref()
        .map(|s| frame_number(desc, s))
        .transpose()?;
    if let Some(Reference(i)) = a.reference {
        f.reference = i;
    }
    Ok(f)
}

/// `--frame`: a frame number, else a name resolved as `Robot::frame_id` does (a URDF link,
/// then a frame or joint name); a `[[tool]]` is a frame fixed on another one, which the
/// generated models do not place: its frame is named in the error.
fn frame_number(desc: &RobotDescription, s: &str) -> CliResult<usize> {
    if let Ok(j) = s.parse::<usize>() {
        return Ok(j);
    }
    if let Some(t) = desc.tools.iter().find(|t| t.name == s) {
        return Err(format!(
            "--frame {s}: a [[tool]] (an offset on frame {}), not a frame of the description:              generate frame {} and compose the tool's constant placement",
            t.frame, t.frame
        )
        .into());
    }
    let j = desc
        .links
        .iter()
        .position(|l| l.name == s)
        .or_else(|| desc.frames.iter().position(|f| f.name == s));
    match j {
        Some(i) => Ok(i + 1),
        None => {
            let names: Vec<&str> = desc.links.iter().map(|l| l.name.as_str()).collect();
            Err(format!(
                "--frame {s}: no frame, link or joint of `{}` has this name (links: {})",
                desc.name,
                names.join(", ")
            )
            .into())
        }
    }
}

pub fn run(a: Args) -> CliResult {
    if !matches!(a.model, Model::Dgm | Model::Jacobian)
        && (a.frame.is_some() || a.reference.is_some())
    {
        return Err("--frame and --reference choose the frames of --model dgm and jacobian".into());
    }
    let rargs = crate::common::RobotArgs {
        robot: a.robot.clone(),
        set: a.set.clone(),
        floating: a.floating,
    };
    let (desc, _) = rargs.description()?;
    // a literal 0 in a SYMORO .par: the parameter does not exist (as in base-params, regressor)
    let zeros = ZeroParameters::for_path(&a.robot);
    let base = match a.params {
        Params::Standard => None,
        Params::Base => match &a.base_file {
            Some(path) => {
                let mut text = String::new();
                let file =
                    std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
                // a grouping list is a few kB: an endless file (`/dev/zero`) is refused
                std::io::Read::read_to_string(&mut std::io::Read::take(file, 1 << 24), &mut text)
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                if text.len() >= 1 << 24 {
                    return Err(format!(
                        "{}: longer than 16 MiB: not a grouping list",
                        path.display()
                    )
                    .into());
                }
                Some(BaseParameters::parse(&text, &path.display().to_string())?)
            }
            // the grouping of the symbolic method (Table 10.2 for the SR400)
            None => Some(BaseParameters::symbolic_with_zeros(
                &desc,
                !a.no_rotor,
                !a.no_friction,
                zeros,
            )?),
        },
    };
    let opt = GenOptions {
        model: match a.model {
            Model::Idm => ModelKind::Idm,
            Model::IdmDerivatives => ModelKind::IdmDerivatives,
            Model::Inertia => ModelKind::Inertia,
            Model::H => ModelKind::H,
            Model::Ddm => ModelKind::Ddm,
            Model::Closed => ModelKind::Closed,
            Model::W => ModelKind::W,
            Model::Dgm => ModelKind::Dgm(frames(&a, &desc)?),
            Model::Jacobian => ModelKind::Jacobian(frames(&a, &desc)?),
        },
        numeric: a.numeric,
        symmetric: a.symmetric,
        friction: !a.no_friction,
        rotor: !a.no_rotor,
        base,
        g: None,
        name: function_name(&a)?,
        optimize: true,
        zeros,
    };
    let n = desc.movable_joints().len();
    // movable joints on the longest path from the base: the L'DL of the direct model walks the
    // ancestors of each joint, so it costs about n d^2 (a serial chain: cubic)
    let mut depth = vec![0usize; desc.nl + 1];
    for j in 1..=desc.nl {
        let f = desc.frame(j);
        depth[j] = depth[f.ant] + usize::from(f.joint.is_movable());
    }
    let d = depth.iter().copied().max().unwrap_or(0);
    if matches!(a.model, Model::Ddm) && d > DDM_DEPTH_NOTE {
        eprintln!(
            "robodyn: note: the symbolic direct dynamic model writes out the L'DL factorization \
             of A(q) along chains of up to {d} movable joints, whose cost grows as the cube of \
             that depth (seconds beyond ~{DDM_DEPTH_NOTE}, about 20 s for 100); `--model \
             inertia` and `--model h` with a numeric solve, or the numeric `robodyn \
             ddm`/`simulate`, stay linear"
        );
    }
    let what = format!(
        "generating {} of {} ({n} joints)",
        format!("{:?}", a.model).to_lowercase(),
        desc.name
    );
    let spinner = working(what.clone());
    let prog = generate_with_progress(&desc, &opt, &mut |stage| {
        spinner.set_message(format!("{what}: {stage}"))
    });
    spinner.finish_and_clear();
    let prog = prog?;
    let text = emit(&prog, a.lang);
    crate::common::write_text(a.output.as_deref(), &text)?;
    let c = prog.count();
    eprintln!(
        "{}: {} multiplications, {} additions",
        prog.name, c.mul, c.add
    );
    Ok(())
}

/// Beyond this many movable joints on one path from the base, `--model ddm` says that it may
/// take long.
const DDM_DEPTH_NOTE: usize = 60;

/// A spinner with the elapsed time on a terminal's standard error, so a long generation says
/// what it does (nothing when standard error is not a terminal).
fn working(what: String) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new_spinner();
    if let Ok(style) = indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
        bar.set_style(style);
    }
    bar.set_message(what);
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// The function name: `--name`, or for MATLAB, which calls a function file by its file name, the
/// stem of `--output` (`sr400_idm.m` -> `sr400_idm`). Checked for the language: an identifier
/// that is no reserved word and no name the generated code uses itself.
fn function_name(a: &Args) -> Result<Option<String>, String> {
    let language = a.lang;
    let checked = |name: &str, what: &str| {
        check_function_name(name, language).map_err(|e| format!("{what}: {e}"))
    };
    if let Some(n) = &a.name {
        checked(n, &format!("--name {n}"))?;
    }
    if a.lang != Lang::Matlab {
        return Ok(a.name.clone());
    }
    let Some(stem) = a.output.as_ref().and_then(|p| p.file_stem()) else {
        return Ok(a.name.clone());
    };
    let stem = stem.to_string_lossy();
    let output = a
        .output
        .as_ref()
        .map_or(String::new(), |p| p.display().to_string());
    checked(
        &stem,
        &format!("--output {output}: a MATLAB function file is named after its function"),
    )?;
    match &a.name {
        Some(n) if n != stem.as_ref() => Err(format!(
            "--name {n} differs from the file name {stem}.m: MATLAB calls a function file by its \
             file name"
        )),
        _ => Ok(Some(stem.into_owned())),
    }
}
