//! A motion to play back: times and the joint values of every frame 1..NJ at each sample (the
//! passive joints and the cut-joint variables of a closed robot included, so that the page only
//! composes frames).

use super::scene::{closed_pose, loop_gaps, tree_pose};
use crate::error::{Error, Result};
use crate::io::table::Table;
use crate::model::JointType;
use crate::{loop_closure, ClosedChain, Robot};
use serde_json::{json, Value};

/// At most this many samples are embedded in a page: a longer trajectory is thinned to every
/// k-th sample (the last one kept), which the page says.
pub const MAX_SAMPLES: usize = 10_000;

/// Largest gap of a loop (m, rad) accepted from a table's passive columns.
const CLOSED: f64 = 1e-6;

/// How joint columns are named in a table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum JointColumns {
    /// `q<j>` by frame number j.
    #[default]
    Frame,
    /// `q_<joint name>`.
    Joint,
}

impl JointColumns {
    /// The column of joint (frame) j's position.
    pub fn column(self, robot: &Robot, j: usize) -> String {
        match self {
            JointColumns::Frame => format!("q{j}"),
            JointColumns::Joint => format!("q_{}", robot.frame(j).name),
        }
    }
}

/// A trajectory ready to be drawn: for each sample its time and the values of frames 1..NJ.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    t: Vec<f64>,
    q: Vec<Vec<f64>>,
    /// The plotted joints (movable joints of the tree, frame numbers) and their labels.
    plotted: Vec<(usize, String)>,
    notes: Vec<String>,
}

impl Trajectory {
    /// From a table with a column `t` (s) and the joints' positions (`q<j>` or `q_<name>`,
    /// [`JointColumns`]): every movable joint of a tree; for a closed robot its actuated joints,
    /// and either all its passive joints (then each row must close the loops within 1e-6) or
    /// none (then they are solved by loop closure on the assembly branch, row after row, as
    /// `simulate` does). Other columns are ignored. Times must increase.
    pub fn from_table(robot: &Robot, table: &Table, columns: JointColumns) -> Result<Trajectory> {
        let file = &table.file;
        let t_col = table.find("t").ok_or_else(|| {
            Error::Input(format!("{file}: no column `t` (the time of each row, s)"))
        })?;
        let find = |joints: &[usize]| -> Vec<Option<usize>> {
            joints
                .iter()
                .map(|&j| table.find(&columns.column(robot, j)))
                .collect()
        };
        let required = if robot.is_tree() {
            robot.movable_joints()
        } else {
            robot.actuated_joints()
        };
        let passive = if robot.is_tree() {
            Vec::new()
        } else {
            robot.passive_joints()
        };
        let (req, pas) = (find(&required), find(&passive));
        let mut missing: Vec<String> = required
            .iter()
            .zip(&req)
            .filter(|(_, c)| c.is_none())
            .map(|(&j, _)| format!("`{}`", columns.column(robot, j)))
            .collect();
        let with_passive = pas.iter().any(Option::is_some);
        if with_passive {
            missing.extend(
                passive
                    .iter()
                    .zip(&pas)
                    .filter(|(_, c)| c.is_none())
                    .map(|(&j, _)| format!("`{}` (passive)", columns.column(robot, j))),
            );
        }
        if !missing.is_empty() {
            return Err(Error::Input(format!(
                "{file}: missing column(s) {}{}",
                missing.join(", "),
                if robot.is_tree() {
                    ""
                } else {
                    " (a closed robot needs its actuated joints, and its passive joints all or none)"
                }
            )));
        }
        let mut joints = required;
        let mut cols: Vec<usize> = req.into_iter().flatten().collect();
        if with_passive {
            joints.extend(passive);
            cols.extend(pas.into_iter().flatten());
        }
        let t: Vec<f64> = table.rows.iter().map(|r| r[t_col]).collect();
        let values: Vec<Vec<f64>> = table
            .rows
            .iter()
            .map(|r| cols.iter().map(|&c| r[c]).collect())
            .collect();
        Trajectory::build(robot, t, &joints, values, columns)
    }

    /// From samples: times `t` (s) and one row per sample over the movable joints of a tree or
    /// the actuated joints of a closed robot (frame order; the passive joints are then solved by
    /// loop closure on the assembly branch). Labels follow `columns`.
    pub fn from_samples(
        robot: &Robot,
        t: &[f64],
        rows: &[Vec<f64>],
        columns: JointColumns,
    ) -> Result<Trajectory> {
        let joints = if robot.is_tree() {
            robot.movable_joints()
        } else {
            robot.actuated_joints()
        };
        if t.len() != rows.len() {
            return Err(Error::dimension(
                "trajectory",
                t.len(),
                rows.len(),
                "one row of joint values per time",
            ));
        }
        for (r, row) in rows.iter().enumerate() {
            if row.len() != joints.len() {
                let e = Error::dimension("q", joints.len(), row.len(), format!("{joints:?}"));
                return Err(e.in_row(r + 1));
            }
        }
        Trajectory::build(robot, t.to_vec(), &joints, rows.to_vec(), columns)
    }

    /// The full rows (frames 1..NJ), checked, loops closed, thinned to [`MAX_SAMPLES`].
    fn build(
        robot: &Robot,
        t: Vec<f64>,
        joints: &[usize],
        values: Vec<Vec<f64>>,
        columns: JointColumns,
    ) -> Result<Trajectory> {
        if t.is_empty() {
            return Err(Error::Input("the trajectory has no row".into()));
        }
        for r in 0..t.len() {
            let bad = values[r].iter().chain([&t[r]]).any(|x| !x.is_finite());
            if bad {
                return Err(Error::Input("a value is not a finite number".into()).in_row(r + 1));
            }
            if r > 0 && t[r] <= t[r - 1] {
                return Err(Error::Input(format!(
                    "t = {} does not increase (the previous row has t = {})",
                    t[r],
                    t[r - 1]
                ))
                .in_row(r + 1));
            }
        }
        let q = if robot.is_tree() || joints.len() == robot.movable_joints().len() {
            given_rows(robot, joints, values)?
        } else {
            solved_rows(robot, values)?
        };
        let plotted = robot
            .movable_joints()
            .into_iter()
            .map(|j| (j, columns.column(robot, j)))
            .collect();
        let mut tr = Trajectory {
            t,
            q,
            plotted,
            notes: Vec::new(),
        };
        tr.thin();
        Ok(tr)
    }

    /// Keep every k-th sample and the last when there are more than [`MAX_SAMPLES`].
    fn thin(&mut self) {
        let n = self.t.len();
        if n <= MAX_SAMPLES {
            return;
        }
        let k = n.div_ceil(MAX_SAMPLES - 1);
        let mut keep: Vec<usize> = (0..n).step_by(k).collect();
        if keep.last() != Some(&(n - 1)) {
            keep.push(n - 1);
        }
        self.t = keep.iter().map(|&i| self.t[i]).collect();
        self.q = keep.iter().map(|&i| self.q[i].clone()).collect();
        self.notes.push(format!(
            "{n} samples thinned to {} (every {k}th and the last) for the page",
            keep.len()
        ));
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there is no sample (never, for a built trajectory).
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The times (s).
    pub fn times(&self) -> &[f64] {
        &self.t
    }

    /// The values of frames 1..NJ (index j-1; fixed frames 0) at sample `i`.
    pub fn values(&self, i: usize) -> &[f64] {
        &self.q[i]
    }

    /// What was done to the samples (thinning), for the reader.
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The trajectory as the page reads it.
    pub(crate) fn to_json(&self, robot: &Robot) -> Result<Value> {
        if self.q.first().map(Vec::len) != Some(robot.nj()) {
            return Err(Error::Input(format!(
                "the trajectory was made for another robot than `{}`",
                robot.name()
            )));
        }
        let plots: Vec<Value> = self
            .plotted
            .iter()
            .map(|(j, label)| {
                let unit = match robot.frame(*j).joint {
                    JointType::Prismatic => "m",
                    _ => "rad",
                };
                json!({ "frame": j, "label": label, "unit": unit })
            })
            .collect();
        Ok(json!({ "t": self.t, "q": self.q, "plots": plots, "notes": self.notes }))
    }
}

/// Rows over every movable tree joint (`joints`): the cut-joint variables from the placements;
/// a closed robot's loops must close.
fn given_rows(robot: &Robot, joints: &[usize], values: Vec<Vec<f64>>) -> Result<Vec<Vec<f64>>> {
    values
        .into_iter()
        .enumerate()
        .map(|(r, v)| {
            let q = tree_pose(robot, joints, &v);
            for (l, gap, angle) in loop_gaps(robot, &q) {
                if gap > CLOSED || angle > CLOSED {
                    return Err(Error::Input(format!(
                        "the passive joints' columns do not close the loop of cut joint {} \
                         (frames {} and {} are {gap:.3e} m and {angle:.3e} rad apart): leave \
                         the passive columns out to have them solved by loop closure",
                        l.cut, l.cut, l.twin
                    ))
                    .in_row(r + 1));
                }
            }
            Ok(q)
        })
        .collect()
}

/// Rows over the actuated joints of a closed robot: the passive joints and the cut-joint
/// variables by loop closure, each row reached from the previous one on the assembly branch.
fn solved_rows(robot: &Robot, values: Vec<Vec<f64>>) -> Result<Vec<Vec<f64>>> {
    let chain = ClosedChain::new(robot)?;
    let mut branch = chain.assembly_branch()?;
    values
        .iter()
        .enumerate()
        .map(|(r, q_a)| {
            let s = loop_closure(&chain, &mut branch, q_a).map_err(|e| e.in_row(r + 1))?;
            Ok(closed_pose(robot, &s))
        })
        .collect()
}
