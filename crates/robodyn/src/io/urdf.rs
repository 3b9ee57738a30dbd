//! URDF import for tree robots.
//!
//! XML is parsed with `roxmltree` rather than `urdf-rs`: roxmltree keeps the byte range of every
//! node, so each error names the line of the offending `<joint>`/`<link>`, and it does not reject
//! the extension tags real URDFs carry (`<gazebo>`, `<transmission>`, ...).
//!
//! Conversion (exact, derived from first principles; frames as in §10.1 of the chapter, iT_j by
//! gamma, b, alpha, d, theta, r, its position iP_j by eq 10.18):
//! - joints are numbered depth-first from the root link (children in file order), so a(j) < j;
//!   frame j keeps the URDF joint's name, link j the child link's name;
//! - frame R_j is placed at the joint origin with z_j along the axis (minimal rotation S_j taking
//!   z to the axis); the URDF child link frame is then R_j(q) C_j with the constant C_j = S_j^-1,
//!   because a rotation (translation) about (along) the axis in the joint frame is the rotation
//!   (translation) about (along) z_j in R_j, with the same q; each link whose C_j is not the
//!   identity becomes a named frame (a [`Tool`]) with the link's name fixed on R_j with
//!   orientation C_j, and the root link one on R_0, so that every URDF link frame can be named
//!   (`Robot::frame_id`);
//! - the placement of R_j in R_i (i = a(j)) is T = C_i O_j S_j (O_j = joint origin xyz/rpy), and
//!   T is decomposed into Rz(gamma) Tz(b) Rx(alpha) Tx(d) Rz(theta) Tz(r) via the common normal of
//!   z_i and z_j ([`decompose`]); parallel or coincident axes take the normal through R_j's
//!   origin (r = 0);
//! - `fixed` joints become sigma = 2 frames, `revolute`/`continuous` sigma = 0, `prismatic`
//!   sigma = 1; a root joint of type `floating` (from a massless world link) makes the root link
//!   a floating base; `planar` joints are refused;
//! - `<inertial>` (COM frame xyz/rpy, mass, inertia about the COM) becomes the standard
//!   parameters about O_j in R_j: c = C_j xyz, R = C_j Rot(rpy), J_O = R J_G R^T + m (c'c I - c c'),
//!   MS = m c; `<dynamics damping friction>` give FV and FS;
//! - `mimic` joints are imported as independent joints and flagged in the notes;
//! - the root link is the fixed base (link 0), or the floating base with its `<inertial>`
//!   ([`parse_description_with`]); gravity is [0, 0, -9.81].

use crate::error::{Error, Item, Location, Result};
use crate::io::source::LineIndex;
use crate::io::{SourceMap, Warning};
use crate::model::{param, FrameDesc, JointLimits, JointType, LinkDesc, RobotDescription, Tool};
use nalgebra::{Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use robodyn_symbolic::Expr;
use std::collections::HashMap;

type Iso = nalgebra::Isometry3<f64>;

/// Below this |z_i x z_j| the axes are taken as parallel (the error is then below 1e-12 rad).
pub const PARALLEL: f64 = 1e-12;

/// Whether z_i and z_j are nearly but not exactly parallel (1e-12 < |z_i x z_j| < 1e-2): the
/// common normal is then far away (b, r ~ distance / angle) and the six parameters lose
/// precision (~1e-16 |b|), so the placement is split in two with a fixed frame rotated by
/// Rx(pi/2).
pub fn needs_auxiliary_frame(t: &Iso) -> bool {
    let u = t.rotation * Vector3::z();
    let c = Vector3::z().cross(&u).norm();
    c > PARALLEL && c < 1e-2
}

/// The six parameters (gamma, b, alpha, d, theta, r) of a frame placed at `t` in its
/// antecedent frame: t = Rz(gamma) Tz(b) Rx(alpha) Tx(d) Rz(theta) Tz(r).
///
/// The x axis of the intermediate frame is the common normal n of z_i (through the origin) and
/// z_j = u (through p): n = e3 x u / |e3 x u|, with its sign chosen so that |gamma| <= pi/2.
/// Its feet are t e3 and t e3 + d n, with t e3 + d n + r u = p. For parallel axes
/// (|e3 x u| <= [`PARALLEL`]) the normal through p is used (r = 0); for coincident axes n = x_i.
/// Nearly parallel axes make b and r huge and inexact: [`parse_description`] avoids them by
/// inserting an auxiliary fixed frame (see [`needs_auxiliary_frame`]).
pub fn decompose(t: &Iso) -> [f64; 6] {
    let rot = t.rotation.to_rotation_matrix();
    let r = rot.matrix();
    let p = t.translation.vector;
    let e3 = Vector3::z();
    let u = r.column(2).into_owned();
    let xf = r.column(0).into_owned();
    let cross = e3.cross(&u);
    let (n, b, d, rr);
    if cross.norm() > PARALLEL {
        let mut nn = cross / cross.norm();
        if nn.x < 0.0 || (nn.x == 0.0 && nn.y < 0.0) {
            nn = -nn;
        }
        n = nn;
        d = n.dot(&p);
        let c = e3.dot(&u);
        let q = p - d * n;
        let (qa, qb) = (e3.dot(&q), u.dot(&q));
        let den = cross.norm_squared(); // = 1 - c^2, without cancellation
                                        // t e3 + r u = q: dot with e3 gives t + r c = qa, with u gives t c + r = qb
        let r_ = (qb - c * qa) / den;
        // b from r (not from its own formula) keeps t e3 + d n + r u = p consistent: the
        // residual is then dr sin(alpha), not dr, for an error dr ~ eps / sin^2 in r
        b = e3.dot(&(p - d * n - r_ * u));
        rr = r_;
    } else {
        let w = Vector3::new(p.x, p.y, 0.0);
        if w.norm() > 1e-12 {
            let mut nn = w / w.norm();
            if nn.x < 0.0 || (nn.x == 0.0 && nn.y < 0.0) {
                nn = -nn;
            }
            n = nn;
            d = n.dot(&w);
        } else {
            n = Vector3::x();
            d = 0.0;
        }
        b = p.z;
        rr = 0.0;
    }
    let gamma = n.y.atan2(n.x);
    let alpha = e3.cross(&u).dot(&n).atan2(e3.dot(&u));
    let theta = n.cross(&xf).dot(&u).atan2(n.dot(&xf));
    [gamma, b, alpha, d, theta, rr]
}

/// A number as an expression: exact multiples of pi/4 for angles within 1e-12 (a hand turned
/// by 45 degrees, as the Panda's), exact 0 for lengths below 1e-15.
fn num_expr(x: f64, angle: bool) -> Expr {
    if angle {
        let k = (x / std::f64::consts::FRAC_PI_4).round();
        if (x - k * std::f64::consts::FRAC_PI_4).abs() < 1e-12 && k.abs() <= 8.0 {
            let k = k as i64;
            return if k == 0 {
                Expr::zero()
            } else {
                Expr::int(k) * Expr::pi() / Expr::int(4)
            };
        }
    } else if x.abs() < 1e-15 {
        return Expr::zero();
    }
    Expr::num(x)
}

struct Ctx<'a> {
    file: Option<&'a str>,
    lines: LineIndex,
}

impl Ctx<'_> {
    fn line(&self, node: roxmltree::Node) -> usize {
        self.lines.line(node.range().start)
    }
    fn err(&self, node: roxmltree::Node, reason: impl Into<String>) -> Error {
        Error::parse(self.file, self.line(node), reason)
    }
    fn numbers<const N: usize>(
        &self,
        node: roxmltree::Node,
        attr: &str,
        default: [f64; N],
        what: &str,
    ) -> Result<[f64; N]> {
        let Some(s) = node.attribute(attr) else {
            return Ok(default);
        };
        let v: Vec<&str> = s.split_whitespace().collect();
        if v.len() != N {
            return Err(self.err(
                node,
                format!(
                    "{what}: {attr}=\"{s}\" has {} numbers, {N} expected",
                    v.len()
                ),
            ));
        }
        let mut out = [0.0; N];
        for (k, t) in v.iter().enumerate() {
            out[k] = self.number(node, t, &format!("{what}: {attr}"))?;
        }
        Ok(out)
    }
    fn number(&self, node: roxmltree::Node, t: &str, what: &str) -> Result<f64> {
        let x: f64 = t
            .trim()
            .parse()
            .map_err(|_| self.err(node, format!("{what}: `{t}` is not a number")))?;
        if !x.is_finite() {
            return Err(self.err(node, format!("{what}: {x} is not a finite number")));
        }
        Ok(x)
    }
    fn attr<'n>(&self, node: roxmltree::Node<'n, 'n>, a: &str, what: &str) -> Result<&'n str> {
        node.attribute(a)
            .ok_or_else(|| self.err(node, format!("{what}: missing attribute `{a}`")))
    }
}

fn child<'a>(n: roxmltree::Node<'a, 'a>, tag: &str) -> Option<roxmltree::Node<'a, 'a>> {
    n.children().find(|c| c.is_element() && c.has_tag_name(tag))
}

fn origin(ctx: &Ctx, n: roxmltree::Node, what: &str) -> Result<Iso> {
    Ok(match child(n, "origin") {
        None => Iso::identity(),
        Some(o) => {
            let xyz = ctx.numbers(o, "xyz", [0.0; 3], what)?;
            let rpy = ctx.numbers(o, "rpy", [0.0; 3], what)?;
            Iso::from_parts(
                Translation3::new(xyz[0], xyz[1], xyz[2]),
                UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
            )
        }
    })
}

struct UJoint<'a> {
    name: String,
    node: roxmltree::Node<'a, 'a>,
    joint: JointType,
    parent: usize,
    child: usize,
    origin: Iso,
    axis: Vector3<f64>,
    mimic: Option<UMimic<'a>>,
    damping: f64,
    friction: f64,
    limits: Option<JointLimits>,
}

/// `<mimic joint multiplier offset>`: q = multiplier * q_joint + offset.
struct UMimic<'a> {
    joint: String,
    node: roxmltree::Node<'a, 'a>,
    multiplier: f64,
    offset: f64,
}

struct ULink<'a> {
    name: String,
    node: roxmltree::Node<'a, 'a>,
    /// (COM frame in the link frame, mass, inertia about the COM in the COM frame, mass node)
    inertial: Option<(Iso, f64, Matrix3<f64>, roxmltree::Node<'a, 'a>)>,
}

/// The minimal rotation taking z to the unit vector `a`: the half-way quaternion
/// (1 + z.a, z x a) normalised, which stays accurate for small angles (an `acos` would lose
/// half the digits); for a in the lower half-space, a half turn about x first.
fn axis_rotation(a: &Vector3<f64>) -> UnitQuaternion<f64> {
    let half_way = |from: Vector3<f64>| {
        let v = from.cross(a);
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(1.0 + from.dot(a), v.x, v.y, v.z))
    };
    if a.z >= 0.0 {
        half_way(Vector3::z())
    } else {
        half_way(-Vector3::z())
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    }
}

/// Parse a URDF tree robot. `file` names the source in error messages. The root link is a
/// fixed base, or link 0 of a floating base when the file's root joint is of type `floating`.
pub fn parse_description(text: &str, file: Option<&str>) -> Result<(RobotDescription, SourceMap)> {
    parse_description_with(text, file, false)
}

/// [`parse_description`] with the root link made a floating base (link 0, with its
/// `<inertial>`) when `floating` is true (Pinocchio's `buildModelFromUrdf(path,
/// JointModelFreeFlyer())`); a root joint of type `floating` in the file does the same.
pub fn parse_description_with(
    text: &str,
    file: Option<&str>,
    floating: bool,
) -> Result<(RobotDescription, SourceMap)> {
    let doc = roxmltree::Document::parse(text).map_err(|e| Error::Parse {
        location: Location {
            file: file.map(str::to_string),
            line: Some(e.pos().row as usize),
            column: Some(e.pos().col as usize),
        },
        reason: format!("invalid XML: {e}"),
    })?;
    let ctx = Ctx {
        file,
        lines: LineIndex::new(text),
    };
    let robot = doc.root_element();
    if !robot.has_tag_name("robot") {
        return Err(ctx.err(
            robot,
            format!(
                "the root element is <{}>, <robot> expected",
                robot.tag_name().name()
            ),
        ));
    }
    let robot_name = robot.attribute("name").unwrap_or("robot").to_string();
    let (links, link_index) = read_links(&ctx, robot)?;
    let mut free = Vec::new();
    let joints = read_joints(&ctx, robot, &links, &link_index, &mut free)?;
    let world = free_joint_parent(&ctx, &links, &joints, &free)?;
    let (root, order) = tree_order(&ctx, robot, &links, &joints, world)?;
    let (mut desc, mut map) = build(&ctx, robot_name, &links, &joints, root, &order)?;
    if floating || world.is_some() {
        make_floating(&mut desc, &mut map, &ctx, &links[root]);
    } else if let Some(w) = legged_warning(&ctx, &links, root) {
        map.warn(w);
    }
    Ok((desc, map))
}

/// The root link becomes link 0 of a floating base, with its `<inertial>` about O_0 in R_0
/// (the root link's frame).
fn make_floating(desc: &mut RobotDescription, map: &mut SourceMap, ctx: &Ctx, root: &ULink) {
    let mut l = LinkDesc::zero(root.name.clone());
    map.set_link(0, None, ctx.line(root.node));
    if let Some((com, m, jg, mass_node)) = &root.inertial {
        map.set_link(0, Some("M"), ctx.line(*mass_node));
        let vals = inertial_about_origin(&UnitQuaternion::identity(), com, *m, jg);
        for (k, v) in vals.iter().enumerate() {
            l.params[k] = num_expr(*v, false);
        }
    }
    desc.floating_base = Some(l);
    desc.notes[0] = format!(
        "imported from URDF; root link `{}` is the floating base (link 0, frame 0)",
        root.name
    );
}

/// A root joint of type `floating` (`free`: its parent and child links, its node): at most
/// one, from a massless root link (the world) to the floating base, at the identity placement.
/// Returns the world link, which the tree then leaves out.
fn free_joint_parent(
    ctx: &Ctx,
    links: &[ULink],
    joints: &[UJoint],
    free: &[(usize, usize, roxmltree::Node)],
) -> Result<Option<usize>> {
    let Some(&(parent, _, node)) = free.first() else {
        return Ok(None);
    };
    let name = |n: roxmltree::Node| n.attribute("name").unwrap_or("").to_string();
    if free.len() > 1 {
        return Err(ctx.err(
            free[1].2,
            format!(
                "joint `{}`: type `floating` a second time (after `{}`): robodyn models one \
                 floating base, the root link's",
                name(free[1].2),
                name(node)
            ),
        ));
    }
    let what = format!("joint `{}`: type `floating`", name(node));
    let has_parent = joints.iter().any(|j| j.child == parent);
    let has_children = joints.iter().any(|j| j.parent == parent);
    let massive = links[parent].inertial.as_ref().is_some_and(|i| i.1 != 0.0);
    if has_parent || has_children || massive {
        return Err(ctx.err(
            node,
            format!(
                "{what} is accepted as the root joint only: its parent link `{}` must be the \
                 massless world link, with no other joint (its child is the floating base)",
                links[parent].name
            ),
        ));
    }
    let o = origin(ctx, node, &what)?;
    if o.translation.vector.norm() != 0.0 || o.rotation.angle() != 0.0 {
        return Err(ctx.err(
            node,
            format!("{what}: its <origin> must be the identity (the base pose is in q)"),
        ));
    }
    Ok(Some(parent))
}

/// A warning when the links look like the feet of a legged robot (two or more links named
/// `*foot*`, `*feet*`, `*sole*` or `*ankle*` as a word: `lf_foot`, `LEFT_FOOT`, `l_sole`,
/// `ankle1_1`; not `base_footprint`): such a robot has a floating base, which robodyn does not
/// model yet, and the root link is taken as a fixed base.
fn legged_warning(ctx: &Ctx, links: &[ULink], root: usize) -> Option<Warning> {
    let feet: Vec<&str> = links
        .iter()
        .map(|l| l.name.as_str())
        .filter(|n| {
            n.split(|c: char| !c.is_ascii_alphabetic()).any(|w| {
                ["foot", "feet", "sole", "ankle"]
                    .iter()
                    .any(|f| w.eq_ignore_ascii_case(f))
            })
        })
        .collect();
    if feet.len() < 2 {
        return None;
    }
    let shown: Vec<String> = feet.iter().take(4).map(|n| format!("`{n}`")).collect();
    let more = if feet.len() > shown.len() {
        ", ..."
    } else {
        ""
    };
    let mut w = Warning::new(
        Item::Robot,
        format!(
            "links {}{more} look like the feet of a legged robot, whose base floats: robodyn \
             loads the root link `{}` as a fixed base (frame 0; its inertia plays no role), so \
             the models are those of the robot with its base held fixed; load it with a \
             floating base to model the free robot",
            shown.join(", "),
            links[root].name
        ),
    );
    w.location.line = Some(ctx.line(links[root].node));
    Some(w)
}

/// The `<link>`s, each defined once, with their inertials.
fn read_links<'a>(
    ctx: &Ctx,
    robot: roxmltree::Node<'a, 'a>,
) -> Result<(Vec<ULink<'a>>, HashMap<String, usize>)> {
    let mut links: Vec<ULink> = Vec::new();
    let mut link_index: HashMap<String, usize> = HashMap::new();
    for n in robot
        .children()
        .filter(|c| c.is_element() && c.has_tag_name("link"))
    {
        let name = ctx.attr(n, "name", "<link>")?.to_string();
        if let Some(&prev) = link_index.get(&name) {
            return Err(ctx.err(
                n,
                format!(
                    "link `{name}` is defined twice (first on line {})",
                    ctx.line(links[prev].node)
                ),
            ));
        }
        let what = format!("link `{name}`, <inertial>");
        let inertial = match child(n, "inertial") {
            None => None,
            Some(i) => {
                let com = origin(ctx, i, &what)?;
                let mass_node = child(i, "mass")
                    .ok_or_else(|| ctx.err(i, format!("{what}: missing <mass>")))?;
                let m = ctx.number(
                    mass_node,
                    ctx.attr(mass_node, "value", &what)?,
                    &format!("{what}: mass"),
                )?;
                let inode = child(i, "inertia")
                    .ok_or_else(|| ctx.err(i, format!("{what}: missing <inertia>")))?;
                let mut v = [0.0; 6];
                for (k, a) in ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]
                    .iter()
                    .enumerate()
                {
                    v[k] = match inode.attribute(*a) {
                        Some(s) => ctx.number(inode, s, &format!("{what}: {a}"))?,
                        None => 0.0,
                    };
                }
                let jg = Matrix3::new(v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5]);
                Some((com, m, jg, mass_node))
            }
        };
        link_index.insert(name.clone(), links.len());
        links.push(ULink {
            name,
            node: n,
            inertial,
        });
    }

    Ok((links, link_index))
}

/// The `<joint>`s: type, parent and child links, origin, axis, mimic, dynamics.
fn read_joints<'a>(
    ctx: &Ctx,
    robot: roxmltree::Node<'a, 'a>,
    links: &[ULink<'a>],
    link_index: &HashMap<String, usize>,
    free: &mut Vec<(usize, usize, roxmltree::Node<'a, 'a>)>,
) -> Result<Vec<UJoint<'a>>> {
    let mut joints: Vec<UJoint> = Vec::new();
    let mut joint_names: HashMap<String, usize> = HashMap::new();
    for n in robot
        .children()
        .filter(|c| c.is_element() && c.has_tag_name("joint"))
    {
        let name = ctx.attr(n, "name", "<joint>")?.to_string();
        let what = format!("joint `{name}`");
        if let Some(&prev) = joint_names.get(&name) {
            return Err(ctx.err(
                n,
                format!(
                    "{what} is defined twice (first on line {})",
                    ctx.line(joints[prev].node)
                ),
            ));
        }
        let kind = ctx.attr(n, "type", &what)?;
        let joint = match kind {
            "revolute" | "continuous" => JointType::Revolute,
            "prismatic" => JointType::Prismatic,
            "fixed" => JointType::Fixed,
            "floating" => JointType::Fixed,
            "planar" => {
                return Err(ctx.err(n, format!("{what}: type `{kind}` has several degrees of freedom; robodyn imports revolute, continuous, prismatic, fixed and (as the root joint) floating joints only (model a planar joint as two prismatic and one revolute joint)")))
            }
            other => return Err(ctx.err(n, format!("{what}: unknown joint type `{other}`"))),
        };
        let link_of = |tag: &str| -> Result<usize> {
            let e = child(n, tag).ok_or_else(|| ctx.err(n, format!("{what}: missing <{tag}>")))?;
            let l = ctx.attr(e, "link", &format!("{what}, <{tag}>"))?;
            link_index
                .get(l)
                .copied()
                .ok_or_else(|| ctx.err(e, format!("{what}: {tag} link `{l}` is not defined")))
        };
        let parent = link_of("parent")?;
        let childl = link_of("child")?;
        if parent == childl {
            return Err(ctx.err(
                n,
                format!(
                    "{what}: parent and child are the same link `{}` (a cycle)",
                    links[parent].name
                ),
            ));
        }
        if kind == "floating" {
            free.push((parent, childl, n));
            continue;
        }
        let axis = joint_axis(ctx, n, &what, joint)?;
        let mimic = joint_mimic(ctx, n, &what)?;
        let (damping, friction) = joint_dynamics(ctx, n, &what)?;
        let limits = joint_limits(ctx, n, &what, joint, kind != "continuous")?;
        joint_names.insert(name.clone(), joints.len());
        joints.push(UJoint {
            limits,
            origin: origin(ctx, n, &what)?,
            name,
            node: n,
            joint,
            parent,
            child: childl,
            axis,
            mimic,
            damping,
            friction,
        });
    }

    Ok(joints)
}

/// The unit axis of joint `n` (x when absent, as URDF says; a fixed joint's zero axis is z).
fn joint_axis(ctx: &Ctx, n: roxmltree::Node, what: &str, joint: JointType) -> Result<Vector3<f64>> {
    Ok(match child(n, "axis") {
        None => Vector3::x(),
        Some(a) => {
            let v = ctx.numbers(a, "xyz", [1.0, 0.0, 0.0], &format!("{what}, <axis>"))?;
            let v = Vector3::new(v[0], v[1], v[2]);
            if v.norm() < 1e-12 && joint.is_movable() {
                return Err(ctx.err(a, format!("{what}: the axis is the zero vector")));
            }
            if v.norm() < 1e-12 {
                Vector3::z()
            } else {
                v / v.norm()
            }
        }
    })
}

/// The `<mimic>` of joint `n`, if any.
fn joint_mimic<'a>(
    ctx: &Ctx,
    n: roxmltree::Node<'a, 'a>,
    what: &str,
) -> Result<Option<UMimic<'a>>> {
    Ok(match child(n, "mimic") {
        None => None,
        Some(m) => {
            let w = format!("{what}, <mimic>");
            let number = |a: &str, default: f64| -> Result<f64> {
                m.attribute(a)
                    .map_or(Ok(default), |t| ctx.number(m, t, &format!("{w}: {a}")))
            };
            Some(UMimic {
                joint: ctx.attr(m, "joint", &w)?.to_string(),
                node: m,
                multiplier: number("multiplier", 1.0)?,
                offset: number("offset", 0.0)?,
            })
        }
    })
}

/// The `<dynamics damping friction>` of joint `n`: (viscous, Coulomb) friction, 0 when absent.
fn joint_dynamics(ctx: &Ctx, n: roxmltree::Node, what: &str) -> Result<(f64, f64)> {
    let (mut damping, mut friction) = (0.0, 0.0);
    if let Some(dn) = child(n, "dynamics") {
        if let Some(s) = dn.attribute("damping") {
            damping = ctx.number(dn, s, &format!("{what}, damping"))?;
        }
        if let Some(s) = dn.attribute("friction") {
            friction = ctx.number(dn, s, &format!("{what}, friction"))?;
        }
    }
    Ok((damping, friction))
}

/// The `<limit lower upper velocity effort>` of joint `n`: position limits of revolute and
/// prismatic joints (`positional`: not continuous) when lower < upper; speed and effort when
/// positive (URDF writes 0 for "not given").
fn joint_limits(
    ctx: &Ctx,
    n: roxmltree::Node,
    what: &str,
    joint: JointType,
    positional: bool,
) -> Result<Option<JointLimits>> {
    Ok(match child(n, "limit") {
        Some(ln) if joint != JointType::Fixed => {
            let w = format!("{what}, <limit>");
            let get = |a: &str| -> Result<Option<f64>> {
                ln.attribute(a)
                    .map(|t| ctx.number(ln, t, &format!("{w}: {a}")))
                    .transpose()
            };
            let (lo, hi) = (get("lower")?, get("upper")?);
            let (q_min, q_max) = match (lo, hi) {
                (Some(a), Some(b)) if positional && a < b => (Some(a), Some(b)),
                (None, Some(b)) if positional && b > 0.0 => (Some(0.0), Some(b)),
                (Some(a), None) if positional && a < 0.0 => (Some(a), Some(0.0)),
                _ => (None, None),
            };
            let positive = |v: Option<f64>| v.filter(|&x| x > 0.0);
            let l = JointLimits {
                q_min,
                q_max,
                qd: positive(get("velocity")?),
                qdd: None,
                tau: positive(get("effort")?),
            };
            (l != JointLimits::default()).then_some(l)
        }
        _ => None,
    })
}

/// The standard inertial parameters about O_j in R_j (XX XY XZ YY YZ ZZ MX MY MZ M) of a URDF
/// `<inertial>`: centre of mass `com` in the URDF link frame, whose orientation in R_j is `c_j`,
/// mass `m`, inertia `jg` about the centre of mass in the `com` frame (Huygens-Steiner).
fn inertial_about_origin(
    c_j: &UnitQuaternion<f64>,
    com: &Iso,
    m: f64,
    jg: &Matrix3<f64>,
) -> [f64; 10] {
    let cj = c_j.to_rotation_matrix();
    let c = cj * com.translation.vector;
    let rot: Rotation3<f64> = cj * com.rotation.to_rotation_matrix();
    crate::model::inertial_parameters(m, &c, &(rot.matrix() * jg * rot.matrix().transpose()))
}

/// The warning for a `<mimic>` of joint `name` (frame `frame`) naming a joint the file does not
/// define: the model does not change (mimic joints are imported as independent joints), but the
/// file is wrong (example-robot-data's alex_psyonic_hands.urdf has such references, and
/// Pinocchio loads it).
fn unknown_mimic(ctx: &Ctx, name: &str, m: &UMimic, frame: usize) -> Warning {
    let mut w = Warning::new(
        Item::Frame(frame, None),
        format!(
            "joint `{name}`, <mimic>: joint `{}` is not defined (the joint is imported as an \
             independent joint)",
            m.joint
        ),
    );
    w.location.line = Some(ctx.line(m.node));
    w
}

/// The root link and the joints in depth-first order from it (children in file order), after
/// checking that the joints form one tree: each link at most one parent joint, exactly one root,
/// every joint reachable.
fn tree_order(
    ctx: &Ctx,
    robot: roxmltree::Node,
    links: &[ULink],
    joints: &[UJoint],
    world: Option<usize>,
) -> Result<(usize, Vec<usize>)> {
    // tree check: each link at most one parent joint, exactly one root, everything reachable
    let mut parent_joint: Vec<Option<usize>> = vec![None; links.len()];
    for (k, jt) in joints.iter().enumerate() {
        if let Some(prev) = parent_joint[jt.child] {
            return Err(ctx.err(
                jt.node,
                format!(
                    "link `{}` has two parents: joint `{}` (line {}) makes it a child of `{}` and joint `{}` a child of `{}`; a URDF must be a tree (close loops in a .toml or .par file)",
                    links[jt.child].name,
                    joints[prev].name,
                    ctx.line(joints[prev].node),
                    links[joints[prev].parent].name,
                    jt.name,
                    links[jt.parent].name
                ),
            ));
        }
        parent_joint[jt.child] = Some(k);
    }
    let roots: Vec<usize> = (0..links.len())
        .filter(|&l| parent_joint[l].is_none() && Some(l) != world)
        .collect();
    if links.is_empty() {
        return Err(ctx.err(robot, "the robot has no <link>"));
    }
    let root = match roots.as_slice() {
        [r] => *r,
        [] => {
            return Err(ctx.err(
                robot,
                format!(
                    "every link has a parent joint: the joints {} form a cycle and there is no \
                     root link",
                    joints
                        .iter()
                        .map(|j| format!("`{}` (line {})", j.name, ctx.line(j.node)))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        many => {
            return Err(ctx.err(
                links[many[1]].node,
                format!(
                    "several root links (links without a parent joint): {}; a URDF tree has one root",
                    many.iter().map(|&l| format!("`{}` (line {})", links[l].name, ctx.line(links[l].node))).collect::<Vec<_>>().join(", ")
                ),
            ));
        }
    };
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); links.len()];
    for (k, jt) in joints.iter().enumerate() {
        children[jt.parent].push(k);
    }
    // depth-first numbering: order[j-1] = joint index
    let mut order = Vec::with_capacity(joints.len());
    let mut stack: Vec<usize> = children[root].iter().rev().copied().collect();
    while let Some(k) = stack.pop() {
        order.push(k);
        stack.extend(children[joints[k].child].iter().rev().copied());
    }
    if order.len() != joints.len() {
        let mut reached = vec![false; joints.len()];
        for &k in &order {
            reached[k] = true;
        }
        let lost: Vec<&UJoint> = joints
            .iter()
            .enumerate()
            .filter(|(k, _)| !reached[*k])
            .map(|(_, j)| j)
            .collect();
        return Err(ctx.err(
            lost[0].node,
            format!(
                "the joints {} form a cycle not connected to the root link `{}`",
                lost.iter()
                    .map(|j| format!("`{}`", j.name))
                    .collect::<Vec<_>>()
                    .join(", "),
                links[root].name
            ),
        ));
    }
    if order.is_empty() {
        return Err(ctx.err(robot, "the robot has no joint (NL = 0)"));
    }

    Ok((root, order))
}

/// The description: frame j carries link j (auxiliary fixed frames carry massless links).
/// The body frame of URDF link `name` as a named frame fixed on frame `j` with orientation
/// `c` (C_j, a rotation: the link frame and R_j share their origin).
fn link_frame(name: &str, j: usize, c: &UnitQuaternion<f64>) -> Tool {
    Tool {
        name: name.to_string(),
        frame: j,
        xyz: [0.0; 3],
        rpy: crate::algorithms::kinematics::rpy(c.to_rotation_matrix().matrix()),
    }
}

fn build(
    ctx: &Ctx,
    robot_name: String,
    links: &[ULink],
    joints: &[UJoint],
    root: usize,
    order: &[usize],
) -> Result<(RobotDescription, SourceMap)> {
    let mut frames: Vec<FrameDesc> = Vec::with_capacity(order.len());
    let mut dlinks: Vec<LinkDesc> = Vec::with_capacity(order.len());
    let mut notes = Vec::new();
    let mut limits = Vec::new();
    let mut map = SourceMap::default();
    map.file = ctx.file.map(str::to_string);
    let mut number_of_link: Vec<usize> = vec![0; links.len()]; // URDF link -> our link number
                                                               // c_of[j]: orientation of the URDF link frame in R_j (index 0: the base)
    let mut c_of: Vec<UnitQuaternion<f64>> = vec![UnitQuaternion::identity()];
    // the root link is the base frame R_0
    let mut tools = vec![link_frame(
        &links[root].name,
        0,
        &UnitQuaternion::identity(),
    )];
    let frame_of = |name: String, ant: usize, joint: JointType, t: &Iso| {
        let p = decompose(t);
        let mut f = FrameDesc::new(name, ant, joint, joint.is_movable());
        for (kk, e) in f.geometric_mut().into_iter().enumerate() {
            *e = num_expr(p[kk], kk % 2 == 0);
        }
        f
    };
    let joint_set: std::collections::HashSet<&str> =
        joints.iter().map(|j| j.name.as_str()).collect();
    for &k in order {
        let jt = &joints[k];
        let mut i = number_of_link[jt.parent];
        let s = if jt.joint.is_movable() {
            axis_rotation(&jt.axis)
        } else {
            UnitQuaternion::identity()
        };
        let mut t = Iso::from_parts(Translation3::identity(), c_of[i])
            * jt.origin
            * Iso::from_parts(Translation3::identity(), s);
        if needs_auxiliary_frame(&t) {
            let aux = Iso::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
            );
            frames.push(frame_of(
                format!("{}_aux", jt.name),
                i,
                JointType::Fixed,
                &aux,
            ));
            dlinks.push(LinkDesc::zero(format!("{}_aux", jt.name)));
            c_of.push(UnitQuaternion::identity());
            let a = frames.len();
            map.set_frame(a, None, ctx.line(jt.node));
            map.set_link(a, None, ctx.line(jt.node));
            notes.push(format!(
                "frame {a} ({}_aux) is an auxiliary fixed frame: the axis of joint {} is nearly \
                 parallel to its antecedent's",
                jt.name, jt.name
            ));
            t = aux.inverse() * t;
            i = a;
        }
        frames.push(frame_of(jt.name.clone(), i, jt.joint, &t));
        let j = frames.len();
        if let Some(l) = &jt.limits {
            limits.push((j, l.clone()));
        }
        c_of.push(s.inverse());
        if s.angle() != 0.0 {
            // the URDF link frame differs from R_j: a named frame fixed on R_j keeps it
            tools.push(link_frame(&links[jt.child].name, j, &s.inverse()));
        }
        number_of_link[jt.child] = j;
        map.set_frame(j, None, ctx.line(jt.node));
        if let Some(m) = &jt.mimic {
            // a mimic of an unknown joint does not change the model (mimic joints are imported
            // as independent joints), but the file is wrong: example-robot-data's
            // alex_psyonic_hands.urdf has such references, and Pinocchio loads it
            if !joint_set.contains(m.joint.as_str()) {
                map.warn(unknown_mimic(ctx, &jt.name, m, frames.len()));
            }
            notes.push(format!(
                "joint {} mimics {} (q = {:?} * q_{} + {:?}); imported as an independent joint",
                jt.name, m.joint, m.multiplier, m.joint, m.offset
            ));
        }

        let ul = &links[jt.child];
        let mut ld = LinkDesc::zero(ul.name.clone());
        map.set_link(j, None, ctx.line(ul.node));
        if let Some((com, m, jg, mass_node)) = &ul.inertial {
            map.set_link(j, Some("M"), ctx.line(*mass_node));
            let vals = inertial_about_origin(&c_of[j], com, *m, jg);
            for (kk, v) in vals.iter().enumerate() {
                ld.params[kk] = num_expr(*v, false);
            }
        }
        ld.params[param::FV] = num_expr(jt.damping, false);
        ld.params[param::FS] = num_expr(jt.friction, false);
        dlinks.push(ld);
    }
    let nl = frames.len();
    let mut desc = RobotDescription::new(robot_name, nl, nl);
    desc.frames = frames;
    desc.links = dlinks;
    desc.notes = notes;
    desc.limits = limits.into_iter().collect();
    desc.tools = tools;
    desc.gravity = [Expr::zero(), Expr::zero(), Expr::num(-9.81)];
    desc.notes.insert(
        0,
        format!(
            "imported from URDF; root link `{}` is the fixed base (frame 0)",
            links[root].name
        ),
    );
    Ok((desc, map))
}
