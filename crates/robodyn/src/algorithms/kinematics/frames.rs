//! Named frames: every frame of the description (by name or number), every link (by its name:
//! link j is on frame j) and every tool (`[[tool]]`, the body frames of URDF links), resolved
//! once into a [`FrameId`].

use crate::error::{Error, Result};
use crate::geometry::Transform;
use crate::model::{Robot, Tool};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// A frame of a robot, resolved once by name ([`Robot::frame_id`]) or number
/// ([`Robot::frame_id_of`]): the description frame it is fixed on (0 the base, 1..NF) and its
/// constant placement in that frame. Cheap to copy; the kinematic functions check that it
/// belongs to a robot of the same size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameId {
    frame: usize,
    offset: Transform,
    /// `offset` is the identity (the frame is its parent frame): no product to read it.
    identity: bool,
    nf: usize,
}

impl FrameId {
    /// The description frame (0 the base, 1..NF) this frame is fixed on.
    pub fn parent(&self) -> usize {
        self.frame
    }

    /// The constant placement of this frame in its parent frame ([`FrameId::parent`]).
    pub fn offset(&self) -> &Transform {
        &self.offset
    }

    /// Whether the offset is the identity (the frame is its parent frame).
    pub(crate) fn is_identity(&self) -> bool {
        self.identity
    }

    /// The frame translated to the point `p` (m, in this frame's coordinates), same
    /// orientation: the Jacobian of a point on a frame is the Jacobian of this frame.
    pub fn at_point(&self, p: Vector3<f64>) -> FrameId {
        self.with_offset(&Transform {
            rot: nalgebra::Matrix3::identity(),
            pos: p,
        })
    }

    /// The frame placed at `t` in this frame (a frame fixed on this one).
    pub fn with_offset(&self, t: &Transform) -> FrameId {
        let offset = self.offset.compose(t);
        FrameId {
            frame: self.frame,
            identity: offset == Transform::identity(),
            offset,
            nf: self.nf,
        }
    }

    /// Error unless the frame was resolved on a robot of `robot`'s size.
    pub(crate) fn check(&self, robot: &Robot) -> Result<()> {
        if self.nf != robot.nf() || self.frame > robot.nf() {
            return Err(Error::Input(format!(
                "the frame id (on frame {} of a robot with {} frames) was resolved on another \
                 robot than `{}` ({} frames)",
                self.frame,
                self.nf,
                robot.name(),
                robot.nf()
            )));
        }
        Ok(())
    }
}

/// The placement of a tool in its frame: Trans(xyz) Rz(yaw) Ry(pitch) Rx(roll) (URDF's
/// `<origin xyz rpy>`).
pub fn tool_transform(tool: &Tool) -> Transform {
    let [r, p, y] = tool.rpy;
    Transform {
        rot: *Rotation3::from_euler_angles(r, p, y).matrix(),
        pos: Vector3::from(tool.xyz),
    }
}

/// Roll, pitch, yaw (rad) of a rotation matrix in URDF's convention (`rot` = Rz(yaw) Ry(pitch)
/// Rx(roll), pitch in [-pi/2, pi/2]): [`tool_transform`] reads them back to `rot` within a few
/// ulps, at the gimbal lock (pitch = ±pi/2, the body frame of a URDF link whose axis is x) too:
/// yaw and pitch from the first column, then roll from what they leave, so that an error in yaw
/// where it is ill-defined is taken up by roll.
pub fn rpy(rot: &Matrix3<f64>) -> [f64; 3] {
    let (r00, r10, r20) = (rot[(0, 0)], rot[(1, 0)], rot[(2, 0)]);
    let yaw = if r00 == 0.0 && r10 == 0.0 {
        0.0
    } else {
        r10.atan2(r00)
    };
    let pitch = (-r20).atan2(r00.hypot(r10));
    let rest = Rotation3::from_euler_angles(0.0, pitch, yaw)
        .matrix()
        .tr_mul(rot);
    let roll = rest[(2, 1)].atan2(rest[(2, 2)]);
    [roll, pitch, yaw]
}

impl Robot {
    /// The frame named `name`: a tool (`[[tool]]`, or the body frame of a URDF link), else a
    /// link (link j is on frame j), else a frame of the description (a URDF joint's name,
    /// `j<j>` by default), else a frame number (`"0"` the base, `"1"`..NF). Names are resolved
    /// in this order, so a URDF link named like a joint is the link.
    ///
    /// Errors: [`Error::Input`] for an unknown name (with the nearest names the robot has) or
    /// a cut joint's frame (it moves with the loop's cut variable, which is not a coordinate).
    ///
    /// # Example
    ///
    /// ```
    /// # fn main() -> robodyn::Result<()> {
    /// let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
    /// let rx90 = robodyn::io::load(urdf)?;
    /// let elbow = rx90.frame_id("elbow")?; // a joint's frame
    /// assert_eq!(elbow.parent(), 3);
    /// let err = rx90.frame_id("elbw").unwrap_err().to_string();
    /// assert!(err.contains("elbow"), "{err}"); // the near names
    /// # Ok(())
    /// # }
    /// ```
    pub fn frame_id(&self, name: &str) -> Result<FrameId> {
        let d = self.description();
        if let Some(t) = d.tools.iter().find(|t| t.name == name) {
            return Ok(self.frame_at(t.frame, tool_transform(t)));
        }
        let j = d
            .links
            .iter()
            .position(|l| l.name == name)
            .or_else(|| d.frames.iter().position(|f| f.name == name))
            .map(|i| i + 1)
            .or_else(|| name.parse::<usize>().ok());
        match j {
            Some(j) => self.frame_id_of(j),
            None => Err(Error::Input(format!(
                "no frame of `{}` is named `{name}`{}",
                self.name(),
                near_names(self, name)
            ))),
        }
    }

    /// Frame number `j` of the description (0 the base, 1..NF).
    ///
    /// Errors: [`Error::Input`] for a number above NF or a cut joint's frame (NL+1..NJ).
    pub fn frame_id_of(&self, j: usize) -> Result<FrameId> {
        let (nl, nj, nf) = (self.nl(), self.nj(), self.nf());
        if j > nf {
            return Err(Error::Input(format!(
                "frame {j} does not exist: `{}` has frames 0..{nf} (0 the base)",
                self.name()
            )));
        }
        if j > nl && j <= nj {
            return Err(Error::Input(format!(
                "frame {j} is the frame of cut joint {j}, which moves with the loop's cut \
                 variable (not a coordinate): use its twin frame {} or a link frame",
                j + nj - nl
            )));
        }
        Ok(self.frame_at(j, Transform::identity()))
    }

    fn frame_at(&self, frame: usize, offset: Transform) -> FrameId {
        FrameId {
            frame,
            identity: offset == Transform::identity(),
            offset,
            nf: self.nf(),
        }
    }

    /// Every name [`Robot::frame_id`] resolves (tools, links, frames), each once.
    pub fn frame_names(&self) -> Vec<&str> {
        let d = self.description();
        let mut out: Vec<&str> = Vec::new();
        let names = d.tools.iter().map(|t| t.name.as_str());
        let names = names.chain(d.links.iter().map(|l| l.name.as_str()));
        let (nl, nj) = (self.nl(), self.nj());
        let frames = d.frames.iter().enumerate();
        let names = names.chain(
            frames
                .filter(|(i, _)| *i < nl || *i >= nj)
                .map(|(_, f)| f.name.as_str()),
        );
        for n in names {
            if !out.contains(&n) {
                out.push(n);
            }
        }
        out
    }
}

/// "; near names: `a`, `b`" for the up to five names closest to `name` by edit distance (or
/// sharing it as a part), empty when none is close.
fn near_names(robot: &Robot, name: &str) -> String {
    let lower = name.to_lowercase();
    let mut scored: Vec<(usize, &str)> = robot
        .frame_names()
        .into_iter()
        .filter_map(|n| {
            let l = n.to_lowercase();
            let d = edit_distance(&lower, &l);
            let close = d <= 2 + lower.len() / 4 || (lower.len() >= 3 && l.contains(&lower));
            close.then_some((d, n))
        })
        .collect();
    scored.sort();
    if scored.is_empty() {
        return String::new();
    }
    let list: Vec<String> = scored
        .iter()
        .take(5)
        .map(|(_, n)| format!("`{n}`"))
        .collect();
    format!("; near names: {}", list.join(", "))
}

/// Levenshtein distance over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (k, cb) in b.iter().enumerate() {
            let cur = row[k + 1];
            row[k + 1] = (prev + usize::from(ca != *cb)).min(row[k] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}
