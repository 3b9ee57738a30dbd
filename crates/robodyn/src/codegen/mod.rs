//! Customized symbolic models (§10.2, Table 10.3): the numeric recursions run on [`Expr`] while a
//! [`program`](robodyn_symbolic::program) recorder is active, so that zeros, ones and constant
//! trigonometric values vanish, every named intermediate (`WI12`, `VP32`, `E13`...) becomes one
//! assignment, and the result is a straight-line [`Program`] with operation counts and emitters
//! (text, LaTeX, Rust, C, Python, Julia).
//!
//! Models: the inverse dynamic model Gamma = f(q, qd, qdd) of the (equivalent) tree (eqs
//! 10.3–10.12), the inertia matrix A(q), the vector H(q, qd), the direct dynamic model of trees
//! (A qdd = Gamma - H solved by A = L' D L written out along the parent array) and the closed-chain models
//! Gamma_cl = G^T Gamma_tr (10.40) and W = d q_p / d q_a (10.30), with a constant G where the
//! loops have one and the loop-closure Jacobian written out otherwise (`closed.rs`).
//!
//! Joint arrays of the generated code hold the movable joints in frame order (the library's
//! joint vectors); the tree models run on the folded model (`DynModel::fold_fixed`), names keep
//! the frame numbers (`q<j>`, `GAM<j>`, `W<c><j>`).

mod closed;
mod derivatives;
mod floating;
mod geometric;
mod linear;
mod parallel_links;

pub use closed::constant_g;
use closed::{closed_form, closed_torques, closed_w, ClosedForm};
pub use derivatives::BLOCKS as DERIVATIVE_BLOCKS;
pub use floating::{BASE_ACCELERATION, BASE_QUATERNION, BASE_VELOCITY, BASE_WRENCH};
pub use geometric::{Frames, DGM_OUTPUTS};
pub use parallel_links::parallel_links;

use crate::algorithms::inertia_matrix::composite_inertia_matrix;
use crate::algorithms::inverse_dynamics::{
    backward_recursion_sharing, forward_recursion_sharing, rnea, SharedOrientation,
};
use crate::algorithms::regressor::ZeroParameters;
use crate::data::Data;
use crate::error::{Error, Item, Result};
use crate::model::{DynModel, FloatingBase, RobotDescription, STANDARD_PARAMETERS};
use crate::scalar::DynScalar as _;
use nalgebra::DMatrix;
use robodyn_symbolic::program::{name_value, record};
use robodyn_symbolic::{cmp_expr, Assignment, Expr, InputGroup, Program};
use std::collections::{BTreeSet, HashMap};

/// Which model to generate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelKind {
    /// Direct geometric model iT_j (SYMORO's DGM): the 12 entries of [s n a P] column by
    /// column ([`DGM_OUTPUTS`]) from the positions of the movable joints.
    Dgm(Frames),
    /// Jacobian iJ_j of frame j expressed in frame i: the velocity of the origin O_j and the
    /// angular velocity of frame j, rows [linear; angular], one column per movable joint, from
    /// the positions (`J<row><joint>`, row by row).
    Jacobian(Frames),
    /// Inverse dynamic model of the (equivalent) tree: Gamma(q, qd, qdd).
    Idm,
    /// Derivatives of the inverse dynamic model of the (equivalent) tree: dGamma/dq,
    /// dGamma/dqd and A = dGamma/dqdd, each N x N column-major, one after the other (3 N^2
    /// outputs, [`DERIVATIVE_BLOCKS`]): the customized IDM differentiated in forward mode,
    /// structural zeros never computed. Coulomb friction's derivative is 0 (where qd != 0).
    IdmDerivatives,
    /// Inertia matrix A(q) (lower triangle).
    Inertia,
    /// Vector H(q, qd) = Gamma(q, qd, 0) (centrifugal, Coriolis, gravity, friction, wrenches).
    H,
    /// Direct dynamic model of a tree: qdd = A^-1 (Gamma - H).
    Ddm,
    /// Closed chain: Gamma_cl = G^T Gamma_tr (10.40): with G constant when the loops make it so
    /// (parallelograms), else Gamma_cl = Gamma_a + Wa^T lambda, Wp^T lambda = -Gamma_p (10.36–10.37)
    /// with the loop-closure Jacobian written out.
    Closed,
    /// Closed chain: W = d q_p / d q_a = -Wp^-1 Wa (10.30) at a closed configuration.
    W,
}

impl ModelKind {
    /// Short name (`dgm`, `jacobian`, `idm`, `idm_derivatives`, `inertia`, `h`, `ddm`,
    /// `closed`, `w`): the default function name's suffix.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Dgm(_) => "dgm",
            ModelKind::Jacobian(_) => "jacobian",
            ModelKind::Idm => "idm",
            ModelKind::IdmDerivatives => "idm_derivatives",
            ModelKind::Inertia => "inertia",
            ModelKind::H => "h",
            ModelKind::Ddm => "ddm",
            ModelKind::Closed => "closed",
            ModelKind::W => "w",
        }
    }
}

/// One grouped base parameter: `name` (e.g. `XXR2`) takes the place of the standard parameter
/// `replaces` (e.g. `XX2`); `expr` is its value over the standard parameters and the geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupedParameter {
    /// The standard parameter it replaces (`XX2`).
    pub replaces: String,
    /// Its name in the generated model (`XXR2`).
    pub name: String,
    /// Its value over the standard parameters and the geometry.
    pub expr: Expr,
}

/// A set of base parameters (§10.3): grouped parameters, and the standard parameters set to
/// zero (no effect, or grouped into others). Standard parameters in neither list stay.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BaseParameters {
    /// The grouped parameters, each replacing one standard parameter.
    pub grouped: Vec<GroupedParameter>,
    /// Names of the standard parameters set to zero.
    pub zero: BTreeSet<String>,
}

/// Options of the generator.
#[derive(Clone, Debug)]
pub struct GenOptions {
    /// The model to generate.
    pub model: ModelKind,
    /// Substitute the robot's numeric values for every symbol (geometry and parameters).
    pub numeric: bool,
    /// Symmetric links (Table 10.3, simplified case): XY = XZ = YZ = MX = MY = 0 for every link.
    pub symmetric: bool,
    /// Keep Coulomb and viscous friction (FS, FV).
    pub friction: bool,
    /// Keep rotor inertias (IA).
    pub rotor: bool,
    /// Base parameters instead of standard ones.
    pub base: Option<BaseParameters>,
    /// A constant G (NL rows, one column per actuated joint) for [`ModelKind::Closed`] and
    /// [`ModelKind::W`]; when `None`, [`constant_g`] looks for one and the general form (G
    /// depending on q) is generated when there is none.
    pub g: Option<DMatrix<Expr>>,
    /// Function name in generated code (default `<robot>_<model>`).
    pub name: Option<String>,
    /// Run the program optimisations (common subexpressions, dead code).
    pub optimize: bool,
    /// What a parameter written as a literal `0` means: with [`ZeroParameters::Absent`]
    /// (SYMORO's `.par`, [`ZeroParameters::for_path`]) it does not exist and is dropped from the
    /// model, as the regressor and base parameters drop it; the default
    /// [`ZeroParameters::Value`] keeps it as a symbol (whose value is 0).
    pub zeros: ZeroParameters,
}

impl Default for GenOptions {
    fn default() -> Self {
        GenOptions {
            model: ModelKind::Idm,
            numeric: false,
            symmetric: false,
            friction: true,
            rotor: true,
            base: None,
            g: None,
            name: None,
            optimize: true,
            zeros: ZeroParameters::Value,
        }
    }
}

/// Names of the joint variables: `q<j>`, velocities `QP<j>`, accelerations `QDP<j>`, torques
/// `GAM<j>` (SYMORO's names).
pub fn joint_symbol(kind: &str, j: usize) -> String {
    format!("{kind}{j}")
}

fn ident(s: &str) -> String {
    let mut out: String = s
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, 'r');
    }
    out.to_lowercase()
}

/// The symbolic model: DynModel<Expr> with the options applied.
/// The symbolic model and, for a floating base, link 0's 13 standard parameters (as the
/// options make them: symbols, numbers, zeros).
fn symbolic_model(desc: &RobotDescription, opt: &GenOptions) -> Result<SymbolicModel> {
    let env = |s: &str| desc.symbols.get(s).copied();
    // symbols replaced by their values, exact constants (pi/2) kept exact
    let numeric = |e: &Expr, item: &dyn Fn() -> Item| -> Result<Expr> {
        let v = e.substitute(&|s| env(s).map(Expr::num));
        if v.symbols().is_empty() {
            return Ok(v);
        }
        e.eval(&env).map(Expr::num).map_err(|err| {
            Error::invalid(
                item(),
                format!("`{e}` has no numeric value (a numeric model needs every symbol's value): {err}"),
            )
        })
    };
    let base_map: HashMap<&str, &GroupedParameter> = opt
        .base
        .iter()
        .flat_map(|b| b.grouped.iter().map(|g| (g.replaces.as_str(), g)))
        .collect();
    // Check the geometry first so that errors are values.
    let mut errors = Vec::new();
    let mut geo = |e: &Expr| -> Expr {
        if opt.numeric {
            numeric(e, &|| Item::Robot).unwrap_or_else(|err| {
                errors.push(err);
                Expr::zero()
            })
        } else {
            e.clone()
        }
    };
    let mut link_errors = Vec::new();
    let mut link = |j: usize, k: usize, e: &Expr| -> Expr {
        if k >= 13 {
            // external wrench as given in the description
            return if opt.numeric {
                numeric(e, &|| Item::Link(j, None)).unwrap_or_else(|err| {
                    link_errors.push(err);
                    Expr::zero()
                })
            } else {
                e.clone()
            };
        }
        let pname = STANDARD_PARAMETERS[k];
        let full = format!("{pname}{j}");
        let grouped = base_map.get(full.as_str());
        let symmetric_zero = match grouped {
            // a grouped parameter vanishes when its expression does on symmetric links
            Some(g) => opt.symmetric && g.expr.substitute(&symmetric_zeros).expand().is_zero(),
            None => opt.symmetric && matches!(pname, "XY" | "XZ" | "YZ" | "MX" | "MY"),
        };
        let zero = symmetric_zero
            || (opt.zeros == ZeroParameters::Absent && e.is_zero())
            || (!opt.friction && matches!(pname, "FS" | "FV"))
            || (!opt.rotor && pname == "IA")
            || opt.base.as_ref().is_some_and(|b| b.zero.contains(&full));
        if zero {
            return Expr::zero();
        }
        let standard = |name: &str| -> Option<Expr> {
            // value of standard parameter NAME<j> from the description
            let (p, idx) = split_param(name)?;
            let kk = STANDARD_PARAMETERS.iter().position(|&x| x == p)?;
            desc.links
                .get(idx.checked_sub(1)?)
                .map(|l| l.params[kk].clone())
        };
        if let Some(g) = grouped {
            if opt.numeric {
                let ex = g.expr.substitute(&standard);
                return numeric(&ex, &|| Item::Link(j, Some(g.name.clone()))).unwrap_or_else(
                    |err| {
                        link_errors.push(err);
                        Expr::zero()
                    },
                );
            }
            return Expr::symbol(g.name.clone());
        }
        if opt.numeric {
            numeric(e, &|| Item::Link(j, Some(pname.into()))).unwrap_or_else(|err| {
                link_errors.push(err);
                Expr::zero()
            })
        } else {
            Expr::symbol(full)
        }
    };
    let model = DynModel::build(desc, &mut geo, &mut link);
    let link0 = desc
        .floating_base
        .as_ref()
        .map(|l| std::array::from_fn(|k| link(0, k, &l.params[k])));
    if let Some(e) = errors.into_iter().chain(link_errors).next() {
        return Err(e);
    }
    Ok((model, link0))
}

/// A symbolic model and its floating base's link 0 parameters.
type SymbolicModel = (
    DynModel<Expr>,
    Option<[Expr; crate::model::PARAMS_PER_LINK]>,
);

/// Symmetric links (Table 10.3, simplified case): XY, XZ, YZ, MX, MY of every link are zero.
fn symmetric_zeros(name: &str) -> Option<Expr> {
    let (p, _) = split_param(name)?;
    matches!(p, "XY" | "XZ" | "YZ" | "MX" | "MY").then(Expr::zero)
}

/// `XX12` -> ("XX", 12).
fn split_param(name: &str) -> Option<(&str, usize)> {
    let i = name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    Some((&name[..i], name[i..].parse().ok()?))
}

/// The inertia matrix A(q) of a model's tree arrays (NL x NL), by the composite-link method
/// (`algorithms::inertia_matrix`, generic over the scalar), rotor inertias on the diagonal.
/// Entries of two links neither of which is an ancestor of the other are structurally zero
/// (`Expr::zero()`, never computed).
pub fn inertia_matrix_expr(model: &DynModel<Expr>, q: &[Expr]) -> DMatrix<Expr> {
    let n = model.nl;
    let mut ws = Data::from_model(model);
    let mut a = DMatrix::from_element(n, n, Expr::zero());
    composite_inertia_matrix(model, &mut ws, q, &mut a);
    a
}

pub(crate) fn pair_name(prefix: &str, i: usize, j: usize) -> String {
    if i < 10 && j < 10 {
        format!("{prefix}{i}{j}")
    } else {
        format!("{prefix}{i}_{j}")
    }
}

/// Generate a customized model of a robot description.
///
/// # Example
///
/// The customized inverse dynamic model of the RX-90, printed as C and checked against the
/// numeric Newton–Euler model at one state (inputs `q<j>`, `QP<j>`, `QDP<j>`):
///
/// ```
/// use robodyn::codegen::{generate, joint_symbol, GenOptions, ModelKind};
/// use robodyn_symbolic::{emit, Lang};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.toml");
/// let desc = robodyn::io::load_description(path)?;
/// let opt = GenOptions { model: ModelKind::Idm, numeric: true, ..GenOptions::default() };
/// let program = generate(&desc, &opt)?;
/// let ops = program.count();
/// println!("{} multiplications, {} additions", ops.mul, ops.add);
/// let c_source = emit(&program, Lang::C); // also Rust, Python, Julia, MATLAB, text, LaTeX
/// assert!(c_source.contains("double"));
///
/// let (q, qd, qdd) = ([0.1, 0.2, 0.3, 0.4, 0.5, 0.6], [0.3; 6], [-0.2; 6]);
/// let input = |s: &str| {
///     (1..=6).find_map(|j| {
///         [("q", &q), ("QP", &qd), ("QDP", &qdd)]
///             .iter()
///             .find(|(kind, _)| s == joint_symbol(kind, j))
///             .map(|(_, v)| v[j - 1])
///     })
/// };
/// let generated = program.evaluate(&input).expect("every input has a value");
/// let robot = robodyn::Robot::new(desc)?;
/// let newton_euler = robodyn::inverse_dynamics(&robot, &q, &qd, &qdd)?;
/// for j in 0..6 {
///     assert!((generated[j] - newton_euler[j]).abs() < 1e-9);
/// }
/// # Ok(())
/// # }
/// ```
pub fn generate(desc: &RobotDescription, opt: &GenOptions) -> Result<Program> {
    generate_with_progress(desc, opt, &mut |_| {})
}

/// [`generate`], calling `progress` with what it is doing as each stage starts (building the
/// symbolic model, recording the recursions, each optimisation pass): a long generation (a
/// humanoid's direct model takes seconds) can show it.
pub fn generate_with_progress(
    desc: &RobotDescription,
    opt: &GenOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<Program> {
    crate::model::validate_structure(desc)?;
    floating::check(desc, opt)?;
    let geometric = matches!(
        opt.model,
        ModelKind::Dgm(_) | ModelKind::Jacobian(_) | ModelKind::W
    );
    if !geometric && (opt.friction || opt.rotor) {
        desc.require_no_motor_drive_parameters("code generation with rotor inertia or friction")?;
    }
    progress("building the symbolic model");
    let (model, link0) = symbolic_model(desc, opt)?;
    // a floating base's body: link 0 with the links fixed on it (before the folding drops them)
    let base = link0.map(|p| FloatingBase::new(p, &model));
    let nl = desc.nl;
    let joints = desc.movable_joints();
    let closed = matches!(opt.model, ModelKind::Closed | ModelKind::W);
    // geometric and kinematic models: the frames resolved and checked first (errors as values)
    let kinematic = match opt.model {
        ModelKind::Dgm(f) | ModelKind::Jacobian(f) => Some(f.resolve(desc)?),
        _ => None,
    };
    // Tree models run on the model of the dynamic recursions (`Robot::dynamic`): fixed frames
    // folded into their movable ancestor, so link k is the movable joint joints[k - 1] and the
    // tree arrays are the joint vectors of the library. Closed models need the cut-joint frames
    // and keep every frame (q of a fixed frame is never read).
    // The geometric models keep every frame too: frame j may be a fixed frame (a tool).
    let model = if closed || kinematic.is_some() {
        model
    } else {
        model.fold_fixed()
    };
    // the numeric robot of the closed models (loop closure, constant G, parallel links)
    let robot = closed.then(|| crate::Robot::new(desc.clone()));
    let form = match &robot {
        Some(robot) => closed_form(desc, opt, robot.as_ref())?,
        None => ClosedForm::Tree,
    };
    // Closed chains: links kept parallel by the loops take their orientation from their partner.
    let shared: Vec<Option<SharedOrientation<Expr>>> = if opt.model == ModelKind::Closed {
        robot
            .as_ref()
            .and_then(|r| r.as_ref().ok())
            .and_then(|r| parallel_links(r).ok())
            .unwrap_or_else(|| vec![None; nl])
            .into_iter()
            .map(|s| {
                s.map(|s| SharedOrientation {
                    link: s.link,
                    rot: s.rot.map(Expr::num),
                })
            })
            .collect()
    } else {
        Vec::new()
    };
    progress(&format!(
        "recording the {} model ({} links, {} movable joints)",
        opt.model.name(),
        nl,
        joints.len()
    ));
    let (outputs, assignments) = record(&reserved_names(desc, opt), || match &base {
        Some(base) => {
            let (q, qd, qdd) = joint_symbols(&model);
            Ok(floating::record_idm(&model, base, &q, &qd, &qdd))
        }
        None => record_model(desc, &model, opt, &form, &shared),
    });
    let mut outputs = outputs?;
    let mut assignments = assignments;
    if opt.model == ModelKind::IdmDerivatives {
        let frames: Vec<usize> = (1..=model.nl).map(|k| model.wrench_link(k)).collect();
        progress("differentiating the inverse dynamic model (forward mode)");
        let a_low = outputs.split_off(frames.len());
        (assignments, outputs) =
            derivatives::derivative_program(assignments, outputs, a_low, &frames);
    }
    let mut description = describe(desc, opt, kinematic);
    if base.is_some() {
        description.extend(floating::describe());
    }
    if closed {
        description.extend(form.describe(nl));
    } else if desc.nj > desc.nl {
        description.push(
            "Closed robot: this is the model of the equivalent tree (loops cut); \
             the closed-chain model gives Gamma_cl"
                .into(),
        );
    }
    let mut prog = Program {
        name: opt
            .name
            .clone()
            .unwrap_or_else(|| format!("{}_{}", ident(&desc.name), opt.model.name())),
        description,
        inputs: if base.is_some() {
            floating::inputs(&joints)
        } else {
            joint_inputs(&joints, opt.model)
        },
        assignments,
        outputs,
    };
    if opt.optimize {
        let n = prog.assignments.len();
        prog.optimize_with_progress(&mut |pass| {
            progress(&format!("optimizing {n} assignments: {pass}"))
        });
    } else {
        prog.remove_dead();
    }
    add_parameter_inputs(&mut prog);
    Ok(prog)
}

/// Names intermediates may not take: the joint variables, the robot's symbols, the standard
/// and grouped parameters.
fn reserved_names(desc: &RobotDescription, opt: &GenOptions) -> Vec<String> {
    let nl = desc.nl;
    let mut reserved: Vec<String> = Vec::new();
    // GAM<j> are inputs of the direct model only; elsewhere they name the tree torques
    let kinds: &[&str] = if opt.model == ModelKind::Ddm {
        &["q", "QP", "QDP", "GAM"]
    } else {
        &["q", "QP", "QDP"]
    };
    for k in kinds {
        reserved.extend((1..=nl).map(|j| joint_symbol(k, j)));
    }
    reserved.extend(desc.symbols.keys().cloned());
    for l in 1..=nl {
        for p in STANDARD_PARAMETERS {
            reserved.push(format!("{p}{l}"));
        }
    }
    if let Some(b) = &opt.base {
        reserved.extend(b.grouped.iter().map(|g| g.name.clone()));
    }
    if desc.floating_base.is_some() {
        reserved.extend(floating::reserved_names());
    }
    reserved
}

/// The joint-variable input arrays of a model: the movable joints in frame order (the
/// library's joint vectors, [`crate::Robot::coordinates`]); entry k of `q` is `q<j>` with
/// j = joints[k], the frame number.
fn joint_inputs(joints: &[usize], model: ModelKind) -> Vec<InputGroup> {
    let group = |name: &str, kind: &str, doc: &str| InputGroup {
        name: name.into(),
        doc: format!("{doc}, movable joints in frame order: {kind}<frame number>"),
        symbols: joints
            .iter()
            .map(|&j| Some(joint_symbol(kind, j)))
            .collect(),
        by_name: false,
    };
    let mut inputs = vec![group("q", "q", "joint positions")];
    match model {
        ModelKind::Idm | ModelKind::IdmDerivatives | ModelKind::Closed => {
            inputs.push(group("qd", "QP", "joint velocities"));
            inputs.push(group("qdd", "QDP", "joint accelerations"));
        }
        ModelKind::H => inputs.push(group("qd", "QP", "joint velocities")),
        ModelKind::Inertia | ModelKind::W | ModelKind::Dgm(_) | ModelKind::Jacobian(_) => {}
        ModelKind::Ddm => {
            inputs.push(group("qd", "QP", "joint velocities"));
            inputs.push(group("gam", "GAM", "joint torques"));
        }
    }
    inputs
}

/// The joint symbols `q<j>`, `QP<j>`, `QDP<j>` of a model's tree arrays (j the frame number).
fn joint_symbols(model: &DynModel<Expr>) -> (Vec<Expr>, Vec<Expr>, Vec<Expr>) {
    let sym = |kind: &str| -> Vec<Expr> {
        (1..=model.nl)
            .map(|k| Expr::symbol(joint_symbol(kind, model.wrench_link(k))))
            .collect()
    };
    (sym("q"), sym("QP"), sym("QDP"))
}

/// Run the model's recursions on symbols (inside a recording): its outputs. For the tree models
/// `model` is folded (link k is the k-th movable joint); for the closed ones it has every frame
/// (tree arrays indexed by frame number). Either way `wrench_link` gives the frame number.
fn record_model(
    desc: &RobotDescription,
    model: &DynModel<Expr>,
    opt: &GenOptions,
    form: &ClosedForm,
    shared: &[Option<SharedOrientation<Expr>>],
) -> Result<Vec<Assignment>> {
    let nl = model.nl;
    // frame number of tree-array entry k
    let frame = |k: usize| model.wrench_link(k + 1);
    let (q, qd, qdd) = joint_symbols(model);
    let outputs = |prefix: &str, tau: &[Expr]| -> Vec<Assignment> {
        (0..nl)
            .filter(|&k| model.frame(k + 1).joint.is_movable())
            .map(|k| Assignment {
                name: joint_symbol(prefix, frame(k)),
                expr: tau[k].clone(),
            })
            .collect()
    };
    let mut ws = Data::from_model(model);
    let mut tau = vec![Expr::zero(); nl];
    match opt.model {
        ModelKind::Dgm(f) => {
            let (i, j) = f.resolve(desc)?;
            Ok(geometric::dgm(model, i, j))
        }
        ModelKind::Jacobian(f) => {
            let (i, j) = f.resolve(desc)?;
            Ok(geometric::jacobian(model, i, j, &desc.movable_joints()))
        }
        ModelKind::Idm | ModelKind::Closed => {
            forward_recursion_sharing(model, &mut ws, &q, &qd, &qdd, shared);
            // the closed model only needs G^T Gamma_tr: moments of shared links move too
            backward_recursion_sharing(model, &mut ws, &qd, &qdd, &mut tau, shared);
            if opt.model == ModelKind::Idm {
                Ok(outputs("GAM", &tau))
            } else {
                let gam: Vec<Expr> = (1..=nl).map(|j| tau[j - 1].clone().named_gam(j)).collect();
                closed_torques(model, form, &q, &gam)
            }
        }
        ModelKind::W => closed_w(model, form, &q),
        ModelKind::IdmDerivatives => {
            // Gamma, then the lower triangle of A (split and differentiated by
            // `derivatives::derivative_program`)
            rnea(model, &mut ws, &q, &qd, &qdd, &mut tau);
            let mut out = outputs("GAM", &tau);
            out.extend(lower_triangle(model, &q));
            Ok(out)
        }
        ModelKind::H => {
            let zero = vec![Expr::zero(); nl];
            rnea(model, &mut ws, &q, &qd, &zero, &mut tau);
            Ok(outputs("H", &tau))
        }
        ModelKind::Inertia => Ok(lower_triangle(model, &q)),
        ModelKind::Ddm => {
            let zero = vec![Expr::zero(); nl];
            rnea(model, &mut ws, &q, &qd, &zero, &mut tau);
            // right-hand side Gamma - H
            let rhs: Vec<Expr> = (0..nl)
                .map(|k| {
                    let j = frame(k);
                    let h = tau[k].clone().named(|| joint_symbol("H", j));
                    (Expr::symbol(joint_symbol("GAM", j)) - h).named(|| format!("BB{j}"))
                })
                .collect();
            let mut a = inertia_matrix_expr(model, &q);
            for i in 0..nl {
                for j in 0..=i {
                    let v = a[(i, j)]
                        .clone()
                        .named(|| pair_name("A", frame(i), frame(j)));
                    a[(j, i)] = v.clone();
                    a[(i, j)] = v;
                }
            }
            let parent: Vec<usize> = (1..=nl).map(|k| model.frame(k).ant).collect();
            let labels: Vec<usize> = (0..nl).map(frame).collect();
            Ok(outputs(
                "QDP",
                &linear::ltdl_solve(a, rhs, &parent, &labels),
            ))
        }
    }
}

/// The lower triangle of the inertia matrix A(q) of a folded model (every link a movable
/// joint), row by row: outputs `A<i><j>`.
fn lower_triangle(model: &DynModel<Expr>, q: &[Expr]) -> Vec<Assignment> {
    let frame = |k: usize| model.wrench_link(k + 1);
    let a = inertia_matrix_expr(model, q);
    let mut out = Vec::new();
    for i in 0..model.nl {
        for j in 0..=i {
            out.push(Assignment {
                name: pair_name("A", frame(i), frame(j)),
                expr: a[(i, j)].clone(),
            });
        }
    }
    out
}

/// The parameter input `p`: every symbol that is neither an input nor an intermediate, passed
/// by name (a struct, a mapping); none when there is none (`--numeric`: every value is in the
/// code, and the functions take no `p`).
fn add_parameter_inputs(prog: &mut Program) {
    let known: BTreeSet<String> = prog
        .input_symbols()
        .into_iter()
        .chain(prog.assignments.iter().map(|a| a.name.clone()))
        .collect();
    let mut params: Vec<Expr> = prog
        .assignments
        .iter()
        .chain(&prog.outputs)
        .flat_map(|a| a.expr.symbols())
        .collect::<BTreeSet<String>>()
        .into_iter()
        .filter(|s| !known.contains(s))
        .map(Expr::symbol)
        .collect();
    if params.is_empty() {
        return;
    }
    params.sort_by(cmp_expr);
    prog.inputs.push(InputGroup {
        name: "p".into(),
        doc: "parameters (geometry, inertial, drive, gravity)".into(),
        symbols: params
            .iter()
            .map(|e| e.as_symbol().map(str::to_string))
            .collect(),
        by_name: true,
    });
}

/// The values of a program's parameters `p`, by name in the order of its header, from the
/// robot description it was generated from (with the same options): the file's symbol values,
/// the standard parameters (`XX3`: link 3's entry; `XX0`: a floating base's link 0) and the
/// grouped base parameters of `opt.base` (`XXR2`: its grouping expression over the standard
/// parameters and the geometry).
/// `None` for a parameter without a numeric value (a symbol the file leaves free). Empty for a
/// program without parameters (`--numeric`).
pub fn parameter_values(
    desc: &RobotDescription,
    opt: &GenOptions,
    prog: &Program,
) -> Vec<(String, Option<f64>)> {
    let symbol = |s: &str| desc.symbols.get(s).copied();
    let standard = |s: &str| -> Option<Expr> {
        let (p, j) = split_param(s)?;
        let k = STANDARD_PARAMETERS.iter().position(|&x| x == p)?;
        // link 0: a floating base's body
        let link = match j {
            0 => desc.floating_base.as_ref()?,
            j => desc.links.get(j - 1)?,
        };
        Some(link.params[k].clone())
    };
    let value = |name: &str| -> Option<f64> {
        if let Some(v) = symbol(name) {
            return Some(v);
        }
        let grouped = opt
            .base
            .iter()
            .flat_map(|b| &b.grouped)
            .find(|g| g.name == name);
        let e = match grouped {
            Some(g) => g.expr.substitute(&standard),
            None => standard(name)?,
        };
        e.eval(&symbol).ok()
    };
    prog.inputs
        .iter()
        .filter(|g| g.by_name)
        .flat_map(|g| g.symbols.iter().flatten())
        .map(|s| (s.clone(), value(s)))
        .collect()
}

/// Helper so that the closed-chain model names the tree torques GAM<j>.
trait NamedGam {
    fn named_gam(self, j: usize) -> Expr;
}
impl NamedGam for Expr {
    fn named_gam(self, j: usize) -> Expr {
        name_value(self, || format!("GAM{j}"))
    }
}

fn describe(
    desc: &RobotDescription,
    opt: &GenOptions,
    kinematic: Option<(usize, usize)>,
) -> Vec<String> {
    if let Some((i, j)) = kinematic {
        return geometric::describe(desc, opt.model, i, j, opt.numeric);
    }
    let model = match opt.model {
        ModelKind::Dgm(_) | ModelKind::Jacobian(_) => "geometric model",
        ModelKind::Idm => "customized inverse dynamic model Gamma = f(q, qd, qdd) (Newton-Euler, eqs 10.3-10.12)",
        ModelKind::IdmDerivatives => "derivatives of the customized inverse dynamic model: out = [dGamma/dq, dGamma/dqd, A = dGamma/dqdd], each N x N column-major (forward-mode differentiation of the Newton-Euler model; Coulomb friction's derivative is 0 where qd != 0)",
        ModelKind::Inertia => "inertia matrix A(q), lower triangle (Newton-Euler columns)",
        ModelKind::H => "vector H(q, qd) = Gamma(q, qd, 0)",
        ModelKind::Ddm => "direct dynamic model qdd = A^-1 (Gamma - H), A = L' D L along the parent array written out",
        ModelKind::Closed => "closed-chain inverse dynamic model Gamma_cl = G^T Gamma_tr (eq 10.40), inputs are the tree state",
        ModelKind::W => "closed-chain kinematic constraint W = d q_p / d q_a = -Wp^-1 Wa (eq 10.30), inputs are the tree positions",
    };
    let mut v = vec![
        format!("{} -- {model}", desc.name),
        "Generated by robodyn (robodyn generate); do not edit.".to_string(),
    ];
    let mut o = Vec::new();
    o.push(if opt.base.is_some() {
        "base parameters"
    } else {
        "standard parameters"
    });
    if opt.numeric {
        o.push("numeric values substituted");
    }
    if opt.symmetric {
        o.push("symmetric links (XY = XZ = YZ = MX = MY = 0)");
    }
    if !opt.friction {
        o.push("no friction");
    }
    if !opt.rotor {
        o.push("no rotor inertia");
    }
    v.push(format!("Options: {}", o.join(", ")));
    v
}

impl BaseParameters {
    /// The base parameters found by the symbolic method (§10.2.4, §10.3.4–10.3.6) for the drive
    /// parameters the generator keeps: rotor inertias (`rotor`) and friction (`friction`) of the
    /// actuated joints. Drive parameters outside that selection, grouped parameters and
    /// parameters with no effect are set to zero. Fails when the symbolic method is incomplete
    /// for the robot (closed loops other than parallelograms): use a grouping file then.
    pub fn symbolic(
        desc: &RobotDescription,
        rotor: bool,
        friction: bool,
    ) -> Result<BaseParameters> {
        Self::symbolic_with_zeros(desc, rotor, friction, ZeroParameters::Value)
    }

    /// [`BaseParameters::symbolic`], with parameters written as a literal 0 read as `zeros`
    /// says ([`ZeroParameters::Absent`] for SYMORO's `.par`: they do not exist, so they are
    /// neither base parameters nor in any grouping).
    pub fn symbolic_with_zeros(
        desc: &RobotDescription,
        rotor: bool,
        friction: bool,
        zeros: ZeroParameters,
    ) -> Result<BaseParameters> {
        use crate::algorithms::base_parameters::symbolic::symbolic_base_parameters;
        use crate::algorithms::regressor::{
            parameter_name, Friction, ParameterSelection, RotorMode,
        };
        let mode = if rotor {
            RotorMode::Actuated
        } else {
            RotorMode::None
        };
        let friction = if friction {
            Friction::Actuated
        } else {
            Friction::None
        };
        let sel = ParameterSelection::from_description(desc, mode, friction)
            .with_zero_parameters(desc, zeros);
        let sb = symbolic_base_parameters(desc, &sel)?;
        if !sb.unhandled_loops.is_empty() {
            return Err(Error::Setting {
                option: "codegen::GenOptions::base",
                reason: format!(
                    "the symbolic grouping rules do not cover the loops cut at joints {:?} (not \
                     parallelograms): compute the base parameters with the numerical method and \
                     give them as the model's base parameters",
                    sb.unhandled_loops
                ),
            });
        }
        let selected: BTreeSet<usize> = sel.columns().into_iter().collect();
        let mut out = BaseParameters::default();
        for idx in 0..STANDARD_PARAMETERS.len() * desc.nl {
            if !selected.contains(&idx) || sb.grouped.contains(&idx) || sb.no_effect.contains(&idx)
            {
                out.zero.insert(parameter_name(idx));
            }
        }
        for (r, &idx) in sb.base.iter().enumerate() {
            if sb.is_regrouped(r) {
                let std = parameter_name(idx);
                let (p, j) = split_param(&std).expect("standard parameter names end in digits");
                out.grouped.push(GroupedParameter {
                    replaces: std.clone(),
                    name: format!("{p}R{j}"),
                    expr: sb.equations[r].clone(),
                });
            }
        }
        Ok(out)
    }

    /// Read a grouping list: one `NAME = expr` per line, where NAME is a standard parameter
    /// with `R` before the link number (`XXR2` replaces `XX2`, `MR3` replaces `M3`) and expr is
    /// its value over standard parameters and geometry; `zero: XX1 XY1 ...` lines list the
    /// parameters set to zero; `#` starts a comment. `file` names the source in errors.
    pub fn parse(text: &str, file: &str) -> Result<BaseParameters> {
        let mut out = BaseParameters::default();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let err = |reason: String| {
                Error::Input(format!("{file}:{}: {reason} in `{}`", i + 1, raw.trim()))
            };
            if let Some(rest) = line.strip_prefix("zero:") {
                for name in rest.split_whitespace() {
                    if split_param(name)
                        .filter(|(p, _)| STANDARD_PARAMETERS.contains(p))
                        .is_none()
                    {
                        return Err(err(format!("`{name}` is not a standard parameter")));
                    }
                    out.zero.insert(name.to_string());
                }
                continue;
            }
            let (name, expr) = line
                .split_once('=')
                .ok_or_else(|| err("expected `NAME = expression` or `zero: ...`".into()))?;
            let name = name.trim();
            let replaces = split_param(name)
                .and_then(|(p, j)| {
                    let p = p.strip_suffix('R')?;
                    STANDARD_PARAMETERS.contains(&p).then(|| format!("{p}{j}"))
                })
                .ok_or_else(|| {
                    err(format!(
                        "`{name}` is not a grouped parameter name (standard name with R \
                         before the link number, e.g. XXR2)"
                    ))
                })?;
            let expr = Expr::parse(expr.trim()).map_err(|e| err(e.to_string()))?;
            out.grouped.push(GroupedParameter {
                replaces,
                name: name.to_string(),
                expr,
            });
        }
        Ok(out)
    }
}
