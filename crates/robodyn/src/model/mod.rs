//! What a robot IS: the description (frames, links, symbols), its validated topology, its
//! numeric constants, the coordinate map of its joint vectors and its default per-call inputs.
//! Immutable once built; per-evaluation buffers live in [`crate::data`].

mod constants;
mod coordinates;
mod description;
mod drives;
mod environment;
mod floating;
pub mod inertial;
mod structure;

pub(crate) use constants::{form_row, inertia_transfer_inline};
pub use constants::{
    inertia_to_antecedent, DynModel, FoldedLink, FrameConstants, LinkConstants, RotationForm,
    TreeIndex,
};
pub use coordinates::Coordinates;
pub use description::{
    inertial_parameters, param, FrameDesc, JointLimits, JointType, LinkDesc, RobotDescription,
    RotorMode, Tool, Transmission, GEOMETRIC_PARAMETERS, PARAMS_PER_LINK, STANDARD_PARAMETERS,
    WRENCH_COMPONENTS,
};
pub use drives::MotorDrives;
pub use environment::{BaseMotion, Environment, Wrench};
pub use floating::{
    require_fixed_base, BaseKind, FloatingBase, BASE_CONFIGURATION_NAMES, BASE_VELOCITY_NAMES,
    QUATERNION_TOLERANCE,
};
pub use structure::{path_from_base, ClosedLoop, Structure, StructureType};

use crate::error::{Error, Item, Result};
use robodyn_symbolic::Expr;

/// A validated tree robot (the equivalent tree of a closed chain): description, topology,
/// numeric model (every symbol has a value) and the coordinate map of its joint vectors (the
/// movable joints, in frame order).
#[derive(Clone, Debug)]
pub struct Robot {
    desc: RobotDescription,
    structure: Structure,
    numeric: DynModel<f64>,
    /// `numeric` with the fixed frames folded out ([`DynModel::fold_fixed`]).
    dynamic: DynModel<f64>,
    coords: Coordinates,
    /// The floating base (link 0's body), when the base floats.
    floating: Option<FloatingBase>,
    /// The motors of the description's transmission, when it has one (their IA, FS, FV are
    /// zero in `numeric` and `dynamic`: the checked functions add them through R).
    drives: Option<MotorDrives>,
}

/// Check counts and antecedents and derive the topology. Needs no numeric values, so it also
/// serves purely symbolic descriptions.
pub fn validate_structure(desc: &RobotDescription) -> Result<Structure> {
    let (nl, nj) = (desc.nl, desc.nj);
    check_counts(desc)?;
    let mut ant = vec![0; desc.nf() + 1];
    for (idx, f) in desc.frames.iter().enumerate() {
        let j = idx + 1;
        check_antecedent(f, j, nl, nj)?;
        check_joint_kind(f, j, nl, nj)?;
        ant[j] = f.ant;
    }
    check_assembly(desc)?;
    let b = nj - nl;
    for k in nl + 1..=nj {
        if ant[k] == structure::carrying_link(&ant, nl, k + b) {
            return Err(Error::invalid(
                Item::Frame(k, Some("ant".into())),
                format!(
                    "cut joint {k} and its twin frame {} are on the same link {}: not a loop",
                    k + b,
                    ant[k]
                ),
            ));
        }
    }
    check_tools(desc)?;
    Ok(Structure::new(ant, nl, nj))
}

/// NL > 0, NJ >= NL, NF = 2 NJ - NL frames and NL links.
fn check_counts(desc: &RobotDescription) -> Result<()> {
    let (nl, nj) = (desc.nl, desc.nj);
    if nl == 0 {
        return Err(Error::invalid(
            Item::Robot,
            "the robot has no link (NL = 0)",
        ));
    }
    if nj < nl {
        return Err(Error::invalid(
            Item::Robot,
            format!("NJ = {nj} is smaller than NL = {nl}: a robot has at least one joint per link"),
        ));
    }
    let nf = desc.nf();
    if desc.frames.len() != nf {
        return Err(Error::invalid(
            Item::Robot,
            format!(
                "{} frames given, NF = 2 NJ - NL = {nf} expected",
                desc.frames.len()
            ),
        ));
    }
    if desc.links.len() != nl {
        return Err(Error::invalid(
            Item::Robot,
            format!("{} links given, NL = {nl} expected", desc.links.len()),
        ));
    }
    Ok(())
}

/// The antecedent of frame `j`: a link frame's is an earlier frame, a cut joint's a link, a twin
/// frame's a link or an earlier twin frame.
fn check_antecedent(f: &FrameDesc, j: usize, nl: usize, nj: usize) -> Result<()> {
    let item = || Item::Frame(j, Some("ant".into()));
    if j <= nl {
        if f.ant >= j {
            return Err(Error::invalid(
                item(),
                format!(
                    "antecedent a({j}) = {} must be smaller than {j} (frames are numbered \
                     from the base; a(j) >= j makes a cycle or a forward reference)",
                    f.ant
                ),
            ));
        }
    } else if j <= nj && f.ant > nl {
        return Err(Error::invalid(
            item(),
            format!(
                "antecedent a({j}) = {} of a cut-joint frame must be a link (0..{nl})",
                f.ant
            ),
        ));
    } else if j > nj && f.ant > nl && (f.ant <= nj || f.ant >= j) {
        // A twin frame may sit on an earlier twin frame (OpenSYMORO's TwoLoops: frame 12 on
        // frame 11): the chain of fixed frames then ends on a link. A cut joint's frame
        // moves with its own variable, so nothing may be fixed on it.
        return Err(Error::invalid(
            item(),
            format!(
                "antecedent a({j}) = {} of a twin frame must be a link (0..{nl}) or an \
                 earlier twin frame ({}..{})",
                f.ant,
                nj + 1,
                j - 1
            ),
        ));
    }
    Ok(())
}

/// The joint of frame `j`: a cut joint is movable and passive, a twin frame fixed, a fixed link
/// frame not actuated.
fn check_joint_kind(f: &FrameDesc, j: usize, nl: usize, nj: usize) -> Result<()> {
    if j > nl && j <= nj {
        if f.joint == JointType::Fixed {
            return Err(Error::invalid(
                Item::Frame(j, Some("sigma".into())),
                "a cut joint must be revolute or prismatic (sigma 0 or 1)",
            ));
        }
        if f.actuated {
            return Err(Error::invalid(
                Item::Frame(j, Some("mu".into())),
                "a cut joint must be passive (mu = 0)",
            ));
        }
    }
    if j > nj && f.joint != JointType::Fixed {
        return Err(Error::invalid(
            Item::Frame(j, Some("sigma".into())),
            format!(
                "frame {j} is the twin of cut joint {} and must be fixed (sigma = 2)",
                j - (nj - nl)
            ),
        ));
    }
    if j <= nl && f.joint == JointType::Fixed && f.actuated {
        return Err(Error::invalid(
            Item::Frame(j, Some("mu".into())),
            "a fixed frame (sigma = 2) cannot be actuated",
        ));
    }
    Ok(())
}

/// The assembly configuration, when given: NL finite values.
fn check_assembly(desc: &RobotDescription) -> Result<()> {
    let Some(a) = &desc.assembly else {
        return Ok(());
    };
    if a.len() != desc.nl {
        return Err(Error::invalid(
            Item::Base("assembly".into()),
            format!("{} joint values given, NL = {} expected", a.len(), desc.nl),
        ));
    }
    if let Some(k) = a.iter().position(|x| !x.is_finite()) {
        return Err(Error::invalid(
            Item::Base("assembly".into()),
            format!("q{} = {} is not a finite number", k + 1, a[k]),
        ));
    }
    Ok(())
}

/// The item of tool `name` in errors (the TOML reader records its line under it).
pub(crate) fn tool_item(name: &str) -> Item {
    Item::Base(format!("tool `{name}`"))
}

/// Each `[[tool]]` is fixed on the base, a link frame or a twin frame, with finite numbers and
/// a name no other tool has.
fn check_tools(desc: &RobotDescription) -> Result<()> {
    let (nl, nj, nf) = (desc.nl, desc.nj, desc.nf());
    for (k, t) in desc.tools.iter().enumerate() {
        let err = |reason: String| Err(Error::invalid(tool_item(&t.name), reason));
        if t.name.is_empty() {
            return err("a tool needs a name".into());
        }
        if desc.tools[..k].iter().any(|o| o.name == t.name) {
            return err(format!("two tools are named `{}`", t.name));
        }
        if t.frame > nf {
            return err(format!(
                "frame {} does not exist (frames 0..{nf}, 0 the base)",
                t.frame
            ));
        }
        if t.frame > nl && t.frame <= nj {
            return err(format!(
                "frame {} is a cut joint's frame, which moves with the loop's cut variable: fix \
                 the tool on its twin frame {} or on a link",
                t.frame,
                t.frame + nj - nl
            ));
        }
        if let Some(x) = t.xyz.iter().chain(&t.rpy).find(|x| !x.is_finite()) {
            return err(format!("{x} is not a finite number"));
        }
    }
    Ok(())
}

/// The drives of the description's transmission ([`MotorDrives::new`]); a floating base with a
/// transmission is refused (not supported yet).
fn robot_drives(
    desc: &RobotDescription,
    movable: &[usize],
    value: &impl Fn(&Expr) -> f64,
) -> Result<Option<MotorDrives>> {
    if desc.transmission.is_some() && desc.floating_base.is_some() {
        return Err(Error::invalid(
            Item::Base("transmission".into()),
            "a motor-joint transmission on a floating-base robot is not supported yet",
        ));
    }
    let k: Vec<f64> = desc
        .links
        .iter()
        .flat_map(|l| l.params.iter().map(value))
        .collect();
    MotorDrives::new(desc, &k, movable)
}

/// Link 0 of a floating base: every parameter and wrench component has a finite value, mass
/// non-negative. Returns its 13 standard parameters.
fn check_link0(
    l: &LinkDesc,
    eval: &impl Fn(&Expr, Item) -> Result<f64>,
) -> Result<[f64; PARAMS_PER_LINK]> {
    let mut p = [0.0; PARAMS_PER_LINK];
    for (k, e) in l.params.iter().enumerate() {
        let item = || Item::Link(0, Some(STANDARD_PARAMETERS[k].into()));
        p[k] = eval(e, item())?;
        if k == param::M && p[k] < 0.0 {
            return Err(Error::physical(item(), format!("M = {} is negative", p[k])));
        }
    }
    for (k, e) in l.wrench.iter().enumerate() {
        if eval(e, Item::Link(0, Some(WRENCH_COMPONENTS[k].into())))? != 0.0 {
            return Err(Error::invalid(
                Item::Link(0, Some(WRENCH_COMPONENTS[k].into())),
                "an external wrench on the floating base (link 0) is not supported yet: put it \
                 on a link fixed to the base",
            ));
        }
    }
    Ok(p)
}

impl Robot {
    /// Validate a description and build its numeric model. Every symbol must have a value, every
    /// value must be finite, masses, rotor inertias and friction coefficients non-negative.
    pub fn new(desc: RobotDescription) -> Result<Robot> {
        let structure = validate_structure(&desc)?;
        for (name, v) in &desc.symbols {
            if !v.is_finite() {
                return Err(Error::invalid(
                    Item::Symbol(name.clone()),
                    format!("value {v} is not a finite number"),
                ));
            }
        }
        let env = |s: &str| desc.symbols.get(s).copied();
        let eval = |e: &Expr, item: Item| -> Result<f64> {
            e.eval(&env).map_err(|err| {
                Error::invalid(
                    item,
                    match err {
                        robodyn_symbolic::EvalError::UnknownSymbol(s) => format!(
                            "symbol `{s}` in `{e}` has no numeric value (give `{s}` a value \
                             in the description's symbols)"
                        ),
                        other => other.to_string(),
                    },
                )
            })
        };
        // Evaluate everything first so that the first error is reported with its item.
        for (idx, f) in desc.frames.iter().enumerate() {
            for (k, e) in f.geometric().iter().enumerate() {
                eval(
                    e,
                    Item::Frame(idx + 1, Some(GEOMETRIC_PARAMETERS[k].into())),
                )?;
            }
        }
        for (idx, l) in desc.links.iter().enumerate() {
            for (k, e) in l.params.iter().enumerate() {
                let v = eval(e, Item::Link(idx + 1, Some(STANDARD_PARAMETERS[k].into())))?;
                if matches!(k, param::M | param::IA | param::FS | param::FV) && v < 0.0 {
                    return Err(Error::physical(
                        Item::Link(idx + 1, Some(STANDARD_PARAMETERS[k].into())),
                        format!("{} = {v} is negative", STANDARD_PARAMETERS[k]),
                    ));
                }
            }
            for (k, e) in l.wrench.iter().enumerate() {
                eval(e, Item::Link(idx + 1, Some(WRENCH_COMPONENTS[k].into())))?;
            }
        }
        let link0 = match &desc.floating_base {
            Some(l) => Some(check_link0(l, &eval)?),
            None => None,
        };
        if desc.floating_base.is_some() && desc.mobile_base {
            return Err(Error::invalid(
                Item::Base("is_mobile".into()),
                "a base cannot be both mobile (its motion imposed) and floating (its motion \
                 resulting from the dynamics)",
            ));
        }
        for (name, v) in [
            ("G", &desc.gravity),
            ("W0", &desc.w0),
            ("WP0", &desc.wp0),
            ("V0", &desc.v0),
            ("VP0", &desc.vp0),
        ] {
            for (k, e) in v.iter().enumerate() {
                eval(e, Item::Base(format!("{name}[{}]", k + 1)))?;
            }
        }
        let value = |e: &Expr| e.eval(&env).expect("checked above");
        let mut numeric = DynModel::build(&desc, value, |_, _, e| value(e));
        let movable = desc.movable_joints();
        let drives = robot_drives(&desc, &movable, &value)?;
        if drives.is_some() {
            // the transmission's IA, FS, FV are the motors': the drives add them through R
            for &j in &desc.transmission.as_ref().expect("drives").joints {
                let l = &mut numeric.links[j - 1];
                (l.ia, l.fs, l.fv) = (0.0, 0.0, 0.0);
            }
        }
        let names = movable
            .iter()
            .map(|&j| desc.frame(j).name.clone())
            .collect();
        let mut coords = Coordinates::new(movable, names, desc.nl);
        coords.floating = link0.is_some();
        let dynamic = numeric.fold_fixed();
        let floating = link0.map(|p| FloatingBase::new(p, &numeric));
        Ok(Robot {
            desc,
            structure,
            numeric,
            dynamic,
            coords,
            floating,
            drives,
        })
    }

    /// The motors of the robot's motor–joint transmission ([`Transmission`]), when it has one:
    /// the inverse and direct models, A(q), H(q, qd), the energies and the simulation add their
    /// reflected inertia and friction; joint torques are joint-side (tau = R' tau_motor).
    #[inline]
    pub fn motor_drives(&self) -> Option<&MotorDrives> {
        self.drives.as_ref()
    }

    /// Error when the robot has a transmission whose motors have a nonzero IA, FS or FV: the
    /// refusal of the functions that do not apply transmissions yet (`what` names the
    /// function), never a wrong number. Motors without inertia and friction change nothing.
    pub fn require_no_motor_drives(&self, what: &str) -> Result<()> {
        if self.drives.as_ref().is_some_and(|d| !d.is_inert()) {
            return Err(Error::invalid(
                Item::Base("transmission".into()),
                format!(
                    "{what} does not apply motor-joint transmissions yet (it would read the \
                     motors' IA, FS, FV as joint-side values)"
                ),
            ));
        }
        Ok(())
    }

    /// What moves the base: fixed, mobile (imposed motion) or floating.
    pub fn base_kind(&self) -> BaseKind {
        if self.floating.is_some() {
            BaseKind::Floating
        } else if self.desc.mobile_base {
            BaseKind::Mobile
        } else {
            BaseKind::Fixed
        }
    }

    /// True when the base floats ([`BaseKind::Floating`]).
    #[inline]
    pub fn is_floating(&self) -> bool {
        self.floating.is_some()
    }

    /// The floating base's body (link 0 and the links fixed on it), when the base floats.
    #[inline]
    pub fn floating_base(&self) -> Option<&FloatingBase> {
        self.floating.as_ref()
    }

    /// Error unless the base is fixed or mobile: the refusal of the functions that do not
    /// support floating bases yet (`what` names the function), never a wrong number.
    pub fn require_fixed_base(&self, what: &str) -> Result<()> {
        require_fixed_base(&self.desc, what)
    }

    /// nq, the entries of a configuration: N for a fixed or mobile base, 7 + N for a floating
    /// one (base position, quaternion x y z w, joints).
    #[inline]
    pub fn nq(&self) -> usize {
        self.dof() + if self.is_floating() { 7 } else { 0 }
    }

    /// nv, the entries of a velocity, acceleration or generalized-force vector: N for a fixed
    /// or mobile base, 6 + N for a floating one (base linear and angular velocity in R_0,
    /// joints).
    #[inline]
    pub fn nv(&self) -> usize {
        self.dof() + if self.is_floating() { 6 } else { 0 }
    }

    /// Names of the nq configuration entries ([`BASE_CONFIGURATION_NAMES`] first for a
    /// floating base, then the joint names).
    pub fn configuration_names(&self) -> Vec<String> {
        self.names_after_base(&BASE_CONFIGURATION_NAMES)
    }

    /// Names of the nv velocity entries ([`BASE_VELOCITY_NAMES`] first for a floating base,
    /// then the joint names).
    pub fn velocity_names(&self) -> Vec<String> {
        self.names_after_base(&BASE_VELOCITY_NAMES)
    }

    /// `base` (for a floating base only), then the joint names.
    fn names_after_base(&self, base: &[&str]) -> Vec<String> {
        let base = if self.is_floating() { base } else { &[] };
        base.iter()
            .map(|s| s.to_string())
            .chain(self.coords.names().iter().cloned())
            .collect()
    }

    /// The coordinate map of joint vectors: the movable joints (fixed frames carry no
    /// variable), in frame order. `q`, `qd`, `qdd`, `tau` of the tree functions have
    /// `coordinates().len()` entries.
    #[inline]
    pub fn coordinates(&self) -> &Coordinates {
        &self.coords
    }

    /// N, the number of entries of a joint vector (movable joints).
    #[inline]
    pub fn dof(&self) -> usize {
        self.coords.len()
    }

    /// The description's gravity, base motion and external wrenches: the default per-call
    /// inputs (clone it to change them for a call).
    #[inline]
    pub fn environment(&self) -> &Environment<f64> {
        &self.numeric.env
    }

    /// Joint values (movable joints, frame order) of the description's `assembly`, if any.
    pub fn assembly(&self) -> Option<Vec<f64>> {
        let a = self.desc.assembly.as_ref()?;
        Some(self.coords.frames().iter().map(|&j| a[j - 1]).collect())
    }

    /// The validated description.
    pub fn description(&self) -> &RobotDescription {
        &self.desc
    }

    /// The description (consumes the robot).
    pub fn into_description(self) -> RobotDescription {
        self.desc
    }

    /// The topology: antecedents, children, main branches, loops.
    pub fn structure(&self) -> &Structure {
        &self.structure
    }

    /// The numeric model of the tree: every frame 1..NF, tree arrays of NL entries (joint j at
    /// index j-1). Geometry, loop closure, the regressor and the closed chains run on it.
    #[inline]
    pub fn numeric(&self) -> &DynModel<f64> {
        &self.numeric
    }

    /// The numeric model of the dynamic recursions (Newton–Euler, composite links, L'DL,
    /// articulated bodies): the movable joints only, fixed frames folded into their movable
    /// ancestor ([`DynModel::fold_fixed`]). Its tree arrays are the public joint vectors
    /// (link k is `coordinates().frame(k - 1)`); the per-call [`Environment`] is the same.
    #[inline]
    pub fn dynamic(&self) -> &DynModel<f64> {
        &self.dynamic
    }

    /// The robot's name.
    pub fn name(&self) -> &str {
        &self.desc.name
    }

    /// NL: links of the equivalent tree (joint variables 1..NL).
    #[inline]
    pub fn nl(&self) -> usize {
        self.desc.nl
    }

    /// NJ: joints (tree joints and cut joints).
    pub fn nj(&self) -> usize {
        self.desc.nj
    }

    /// NF = 2 NJ - NL: frames.
    pub fn nf(&self) -> usize {
        self.desc.nf()
    }

    /// B = NJ - NL, the number of closed loops.
    pub fn n_loops(&self) -> usize {
        self.desc.nj - self.desc.nl
    }

    /// True when the robot has no closed loop (NJ = NL).
    pub fn is_tree(&self) -> bool {
        self.desc.nj == self.desc.nl
    }

    /// a(j).
    #[inline]
    pub fn ant(&self, j: usize) -> usize {
        self.structure.ant[j]
    }

    /// Frame j's description (1-based).
    pub fn frame(&self, j: usize) -> &FrameDesc {
        self.desc.frame(j)
    }

    /// Link j's description (1-based).
    pub fn link(&self, j: usize) -> &LinkDesc {
        self.desc.link(j)
    }

    /// Tree joints 1..NL that are movable (not fixed).
    pub fn movable_joints(&self) -> Vec<usize> {
        self.desc.movable_joints()
    }

    /// Actuated tree joints (mu = 1), in increasing order: q_a.
    pub fn actuated_joints(&self) -> Vec<usize> {
        self.desc.actuated_joints()
    }

    /// Passive movable tree joints (mu = 0): q_p.
    pub fn passive_joints(&self) -> Vec<usize> {
        self.desc.passive_joints()
    }

    /// The value of an expression over the robot's symbols (e.g. a geometric parameter).
    pub fn value(&self, e: &Expr) -> Result<f64> {
        e.eval(&|s| self.desc.symbols.get(s).copied())
            .map_err(|err| Error::Input(err.to_string()))
    }

    /// Numeric standard parameters, 13 per link (XX..FV), link 1 first.
    pub fn standard_parameters(&self) -> Vec<f64> {
        self.desc
            .links
            .iter()
            .flat_map(|l| {
                l.params.iter().map(|e| {
                    e.eval(&|s| self.desc.symbols.get(s).copied())
                        .expect("validated")
                })
            })
            .collect()
    }

    /// The same robot with the given numeric standard parameters (13 per link, link 1 first).
    pub fn with_standard_parameters(&self, k: &[f64]) -> Result<Robot> {
        crate::error::check_vector(
            "standard parameters",
            k,
            PARAMS_PER_LINK * self.nl(),
            || "13 per link: XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV".into(),
        )?;
        let mut desc = self.desc.clone();
        for (j, l) in desc.links.iter_mut().enumerate() {
            for (p, e) in l.params.iter_mut().enumerate() {
                *e = Expr::num(k[PARAMS_PER_LINK * j + p]);
            }
        }
        Robot::new(desc)
    }
}
