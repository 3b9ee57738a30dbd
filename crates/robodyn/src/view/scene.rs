//! The scene the page draws, as JSON: the Khalil–Kleinfinger geometry of every frame (numbers
//! and the expressions as written), the structure, the pose (joint values of frames 1..NJ, loops
//! closed by the library), the trajectory and the visuals.

use super::{Pose, ViewOptions};
use crate::algorithms::closed_chain::ClosureSolution;
use crate::error::{Error, Result};
use crate::geometry::{frame_transforms_per_frame, Transform};
use crate::model::{param, ClosedLoop, JointType, Robot, GEOMETRIC_PARAMETERS};
use crate::{loop_closure, ClosedChain};
use serde_json::{json, Value};

/// The joint values of a pose: one per frame 1..NJ (tree joints, then cut joints; fixed
/// frames 0), and how they were obtained.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct PoseValues {
    pub q: Vec<f64>,
    pub note: String,
    /// Why the loops are not closed by loop closure, if they are not.
    pub warning: Option<String>,
}

/// The scene of `robot` with `options`, as the page reads it, and the warnings for the reader
/// (loops not closed at the pose).
pub(crate) fn scene(robot: &Robot, options: &ViewOptions) -> Result<(Value, Vec<String>)> {
    if options.trajectory.is_some() && options.pose != Pose::Default {
        return Err(Error::Input(
            "joint values and a trajectory were both given: the page starts at the trajectory's \
             first sample; give one or the other"
                .into(),
        ));
    }
    let pose = pose_values(robot, &options.pose)?;
    let mut warnings: Vec<String> = pose.warning.iter().cloned().collect();
    for (l, gap, angle) in loop_gaps(robot, &pose.q) {
        if gap > 1e-6 || angle > 1e-6 {
            warnings.push(format!(
                "the loop of cut joint {} is open at the pose shown: frames {} and {} are \
                 {gap:.3e} m and {angle:.3e} rad apart",
                l.cut, l.cut, l.twin
            ));
        }
    }
    let g = robot.environment().gravity;
    let mut s = json!({
        "robot": robot.name(),
        "nl": robot.nl(),
        "nj": robot.nj(),
        "nf": robot.nf(),
        "gravity": [g.x, g.y, g.z],
        "frames": frames(robot)?,
        "coordinates": robot.coordinates().frames(),
        "actuated": robot.actuated_joints(),
        "closed": !robot.is_tree(),
        "loops": loops(robot, &pose.q),
        "pose": { "q": pose.q, "note": pose.note },
        "notes": robot.description().notes,
    });
    if let Some(t) = &options.trajectory {
        s["trajectory"] = t.to_json(robot)?;
    }
    if let Some(v) = &options.visuals {
        s["visuals"] = v.to_json();
    }
    if let Some(p) = options.picture {
        s["picture"] = json!({ "width": p.width, "height": p.height });
    }
    Ok((s, warnings))
}

/// Every frame: number, name, antecedent, sigma, mu, kind (tree, fixed, cut, twin), the link it
/// carries, the six parameters (numbers, and as written) and the position limits.
fn frames(robot: &Robot) -> Result<Vec<Value>> {
    let (nl, nj) = (robot.nl(), robot.nj());
    (1..=robot.nf())
        .map(|j| {
            let f = robot.frame(j);
            let kind = match (j, f.joint) {
                (j, _) if j > nj => "twin",
                (j, _) if j > nl => "cut",
                (_, JointType::Fixed) => "fixed",
                _ => "tree",
            };
            let mut values = [0.0; 6];
            for (v, e) in values.iter_mut().zip(f.geometric()) {
                *v = robot.value(e)?;
            }
            let text: Vec<String> = f
                .geometric()
                .iter()
                .map(|e| e.decimal().to_string())
                .collect();
            let limits = robot
                .description()
                .limits
                .get(&j)
                .and_then(|l| Some([l.q_min?, l.q_max?]));
            Ok(json!({
                "com": (j <= nl).then(|| centre_of_mass(robot, j)).flatten(),
                "j": j,
                "name": f.name,
                "ant": f.ant,
                "sigma": f.joint.sigma(),
                "mu": u8::from(f.actuated),
                "kind": kind,
                "link": (j <= nl).then(|| robot.link(j).name.clone()),
                "params": GEOMETRIC_PARAMETERS,
                "values": values,
                "text": text,
                "limits": limits,
            }))
        })
        .collect()
}

/// The centre of mass of link j in R_j (MS / M), when its mass is positive.
fn centre_of_mass(robot: &Robot, j: usize) -> Option<[f64; 3]> {
    let k = &robot.link(j).params;
    let v = |p: usize| robot.value(&k[p]).ok();
    let m = v(param::M)?;
    (m > 0.0).then_some([v(param::MX)? / m, v(param::MY)? / m, v(param::MZ)? / m])
}

/// The joint values of frames 1..NJ for a pose.
pub(crate) fn pose_values(robot: &Robot, pose: &Pose) -> Result<PoseValues> {
    let coords = robot.coordinates();
    match pose {
        Pose::Default if robot.is_tree() => Ok(PoseValues {
            q: vec![0.0; robot.nj()],
            note: "q = 0".into(),
            warning: None,
        }),
        Pose::Default => Ok(match assembled(robot, None) {
            Ok(p) => p,
            // a viewer shows a robot whose loops do not close too (that is what it is for):
            // the values of the file, loops open, and why
            Err(e) => {
                let mut q = robot
                    .description()
                    .assembly
                    .clone()
                    .unwrap_or_else(|| vec![0.0; robot.nl()]);
                q.resize(robot.nj(), 0.0);
                with_cut_variables(robot, &mut q);
                let why = format!("loop closure failed: {e}");
                PoseValues {
                    q,
                    note: format!(
                        "{why}; shown at the file's assembly values (else q = 0), the loops as \
                         they fall"
                    ),
                    warning: Some(why),
                }
            }
        }),
        Pose::Tree(values) => {
            coords.check("q", values, "movable joints")?;
            Ok(PoseValues {
                q: tree_pose(robot, coords.frames(), values),
                note: "given joint values".into(),
                warning: None,
            })
        }
        Pose::Actuated(q_a) => {
            if robot.is_tree() {
                return Err(Error::Input(format!(
                    "robot `{}` has no closed loop: give the values of its movable joints",
                    robot.name()
                )));
            }
            assembled(robot, Some(q_a))
        }
    }
}

/// The closed pose at `q_a` (default: the assembly's) on the assembly branch.
fn assembled(robot: &Robot, q_a: Option<&[f64]>) -> Result<PoseValues> {
    let chain = ClosedChain::new(robot)?;
    let mut branch = chain.assembly_branch()?;
    let target = q_a.map_or_else(|| branch.q_a().to_vec(), <[f64]>::to_vec);
    let s = loop_closure(&chain, &mut branch, &target)?;
    let q = closed_pose(robot, &s);
    let from = if q_a.is_some() {
        "given actuated values"
    } else if robot.description().assembly.is_some() {
        "the assembly of the robot file"
    } else {
        "q = 0"
    };
    Ok(PoseValues {
        q,
        note: format!(
            "{from}; passive joints by loop closure on the assembly branch (residual {:.1e})",
            s.residual
        ),
        warning: None,
    })
}

/// The values of frames 1..NJ of a closed configuration found by loop closure.
pub(crate) fn closed_pose(robot: &Robot, s: &ClosureSolution) -> Vec<f64> {
    let mut q = vec![0.0; robot.nj()];
    for (&j, &x) in robot.coordinates().frames().iter().zip(s.q_tree.iter()) {
        q[j - 1] = x;
    }
    q[robot.nl()..].copy_from_slice(s.q_c.as_slice());
    q
}

/// The values of frames 1..NJ with `values` on the tree joints `joints` (others 0) and the
/// cut-joint variables from the placements ([`with_cut_variables`]).
pub(crate) fn tree_pose(robot: &Robot, joints: &[usize], values: &[f64]) -> Vec<f64> {
    let mut q = vec![0.0; robot.nj()];
    for (&j, &x) in joints.iter().zip(values) {
        q[j - 1] = x;
    }
    with_cut_variables(robot, &mut q);
    q
}

/// Set the cut-joint variables (entries NL..NJ of `q`) from the placements of the tree: the
/// angle about z_k from x_k to x_{k+B} (revolute cut) or the slide along z_k (prismatic), the
/// values that make R_k coincide with its twin when the loop is closed.
pub(crate) fn with_cut_variables(robot: &Robot, q: &mut [f64]) {
    let (nl, nj) = (robot.nl(), robot.nj());
    q[nl..nj].iter_mut().for_each(|x| *x = 0.0);
    let t = frame_transforms_per_frame(robot, q);
    for k in nl + 1..=nj {
        let (tk, tt) = (&t[k - 1], &t[k + nj - nl - 1]);
        let rel = tk.rot.transpose();
        q[k - 1] = match robot.frame(k).joint {
            JointType::Prismatic => (rel * (tt.pos - tk.pos)).z,
            _ => {
                let x = rel * tt.rot.column(0);
                x.y.atan2(x.x)
            }
        };
    }
}

/// The gap of each loop at `q` (frames 1..NJ): the distance of the origins of R_k and
/// R_{k+B} (m) and the angle of their relative rotation (rad), both 0 when the loop is closed.
pub(crate) fn loop_gaps<'r>(robot: &'r Robot, q: &[f64]) -> Vec<(&'r ClosedLoop, f64, f64)> {
    let t: Vec<Transform> = frame_transforms_per_frame(robot, q);
    robot
        .structure()
        .loops
        .iter()
        .map(|l| {
            let (tk, tt) = (&t[l.cut - 1], &t[l.twin - 1]);
            let rel = tk.rot.transpose() * tt.rot;
            let cos = ((rel.trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
            (l, (tt.pos - tk.pos).norm(), cos.acos())
        })
        .collect()
}

/// Each loop: cut joint, twin frame, links, and its gap at `q` ([`loop_gaps`]).
fn loops(robot: &Robot, q: &[f64]) -> Vec<Value> {
    loop_gaps(robot, q)
        .into_iter()
        .map(|(l, gap, angle)| {
            json!({
                "cut": l.cut,
                "twin": l.twin,
                "link_i": l.link_i,
                "link_j": l.link_j,
                "gap": gap,
                "angle": angle,
            })
        })
        .collect()
}
