//! The states the kinematic commands (`fk`, `jacobian`, `com`) share: the robot and one state
//! from `--q/--qd/--qdd`, or every state of an `--input` table (columns as `idm` reads them);
//! a closed chain's actuated joints completed on the assembly branch (a table's rows one after
//! the other on the branch tracker); a floating robot's states with the base first (nq, nv
//! entries; a table's base columns as `simulate` writes them); and the frames named by
//! `--frame`.

use crate::common::{
    format_number, parse_list, start_branch, warn_conditioning, CliResult, NamesArg, RobotArgs,
};
use crate::states::{base_columns3, Chunk, StateInput, StateRequest};
use nalgebra::DMatrix;
use robodyn::{
    closed_state, forward_kinematics_into, Branch, ClosedChain, FrameId, KinematicsData, Robot,
};
use std::path::{Path, PathBuf};

/// `--input`, `--q`, `--qd`, `--qdd` and `--guess` of the kinematic commands.
#[derive(clap::Args, Debug)]
pub struct StateArgs {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// CSV of states with columns q<j> (required), qd<j>, qdd<j> (optional: zeros) for the
    /// movable joints (closed chains: the actuated joints), as `idm` reads them (a floating
    /// base's columns base_x .. base_qw, base_vx .. base_wz, base_ax .. base_dwz first, as
    /// `simulate` writes them); the output is a CSV table with the state's row number (and the
    /// table's other columns) on every line.
    #[arg(long, conflicts_with_all = ["q", "qd", "qdd"])]
    pub input: Option<PathBuf>,
    #[command(flatten)]
    pub names: NamesArg,
    /// Joint positions, comma separated (movable joints in frame order; closed chains: the
    /// actuated joints; a floating base: nq = 7 + N values, x,y,z,qx,qy,qz,qw of the base in
    /// the world first; default zeros, the base at the world origin).
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// Joint velocities (a floating base: nv = 6 + N values, the base's linear and angular
    /// velocity in its own frame first; default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub qd: Option<String>,
    /// Joint accelerations (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub qdd: Option<String>,
    /// Closed chains: start the assembly branch at --q with this guess of q_p (passive tree
    /// joints in order) instead of the robot's `assembly`.
    #[arg(long, allow_hyphen_values = true)]
    pub guess: Option<String>,
}

/// A robot at one state: the tree's joint vectors (a closed chain's completed on its branch),
/// the kinematics computed, and for a closed chain G (tree joints x actuated joints), which
/// maps a tree Jacobian to the actuated coordinates (J_a = J_tr G).
pub struct Evaluated {
    pub robot: Robot,
    pub data: KinematicsData,
    /// The state's q: the movable joints (closed chains: the actuated joints given; a floating
    /// robot's base pose first).
    pub q: Vec<f64>,
    /// The chain and its G at the state (closed chains).
    pub closed: Option<(ClosedChain, DMatrix<f64>)>,
}

impl StateArgs {
    /// The robot and, when it has loops, its closed chain.
    fn load(&self) -> CliResult<(Robot, Option<ClosedChain>)> {
        let robot = self.robot.load()?;
        let chain = (!robot.is_tree())
            .then(|| ClosedChain::new(&robot))
            .transpose()?;
        Ok((robot, chain))
    }

    /// Load the robot and compute the kinematics at the state of `--q/--qd/--qdd`.
    pub fn evaluate(&self) -> CliResult<Evaluated> {
        let (robot, chain) = self.load()?;
        let n = match &chain {
            Some(c) => c.dof(),
            None => robot.dof(),
        };
        let list = |name: &str, s: &Option<String>, base: &[f64]| -> CliResult<Vec<f64>> {
            match s {
                Some(s) => parse_list(name, s),
                None => Ok([base, &vec![0.0; n]].concat()),
            }
        };
        // a floating base defaults to the world origin, unit quaternion (0, 0, 0, 1), at rest
        let (bq, bv): (&[f64], &[f64]) = if robot.is_floating() {
            (&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], &[0.0; 6])
        } else {
            (&[], &[])
        };
        let x = [
            list("q", &self.q, bq)?,
            list("qd", &self.qd, bv)?,
            list("qdd", &self.qdd, bv)?,
        ];
        let mut e = Evaluated::new(robot, chain);
        let mut branch = None;
        e.at(
            &mut branch,
            self.guess.as_deref(),
            [&x[0], &x[1], &x[2]],
            None,
        )?;
        Ok(e)
    }

    /// Every state of the `--input` table `input`: `setup` once on the robot, then
    /// `each(&setup's value, row, carried values, the kinematics at the row)` per row (1-based;
    /// a closed chain's rows continued on the branch tracker). Returns the carried columns'
    /// names (the table's other columns, written in front of each output line).
    pub fn each_state<T>(
        &self,
        input: &Path,
        setup: impl FnOnce(&Robot, &[String]) -> CliResult<T>,
        mut each: impl FnMut(&mut T, usize, &[f64], &mut Evaluated) -> CliResult,
    ) -> CliResult<T> {
        let (robot, chain) = self.load()?;
        let (coords, what) = match &chain {
            Some(c) => (c.coordinates().clone(), "actuated joints (closed chain)"),
            None => (robot.coordinates().clone(), "movable joints"),
        };
        let mut states = StateInput::open(&StateRequest {
            input: Some(input),
            prefixes: ["q", "qd", "qdd"],
            lists: [None; 3],
            coords: &coords,
            tree: robot.coordinates(),
            names: self.names,
            what,
            carry: &[],
            base: base_columns3(&robot, ["q", "qd", "qdd"]),
        })?;
        let carried = states.carried_headers().to_vec();
        let mut value = setup(&robot, &carried)?;
        // entries of q, qd, qdd (a floating base's nq, nv)
        let n = [robot.nq(), robot.nv(), robot.nv()].map(|b| b - robot.dof() + coords.len());
        let nc = carried.len();
        let mut e = Evaluated::new(robot, chain);
        let (mut chunk, mut branch) = (Chunk::default(), None);
        let per_state = n.iter().sum::<usize>() + nc;
        while states.next_chunk(crate::common::chunk_states(per_state), &mut chunk)? {
            for s in 0..chunk.count {
                let row = chunk.first + s;
                let x = std::array::from_fn(|i| &chunk.x[i][s * n[i]..(s + 1) * n[i]]);
                e.at(&mut branch, self.guess.as_deref(), x, Some(row))?;
                each(&mut value, row, chunk.carried(s, nc), &mut e)?;
            }
        }
        Ok(value)
    }
}

impl Evaluated {
    fn new(robot: Robot, chain: Option<ClosedChain>) -> Evaluated {
        Evaluated {
            data: KinematicsData::new(&robot),
            robot,
            q: Vec::new(),
            closed: chain.map(|c| (c, DMatrix::zeros(0, 0))),
        }
    }

    /// The kinematics at state `x` (q, q̇, q̈; a closed chain's actuated joints completed on
    /// `branch`, started from `guess` or the assembly at the first state); `row` names a
    /// table's row in errors and warnings.
    fn at(
        &mut self,
        branch: &mut Option<Branch>,
        guess: Option<&str>,
        x: [&[f64]; 3],
        row: Option<usize>,
    ) -> CliResult {
        let in_row = |e: robodyn::Error| match row {
            Some(r) => e.in_row(r),
            None => e,
        };
        self.q = x[0].to_vec();
        match &mut self.closed {
            None => forward_kinematics_into(&self.robot, &mut self.data, x[0], x[1], x[2])
                .map_err(in_row)?,
            Some((c, g)) => {
                let b = match branch {
                    Some(b) => b,
                    None => branch.insert(start_branch(c, x[0], guess)?),
                };
                let s = closed_state(c, b, x[0], x[1], x[2]).map_err(in_row)?;
                // near a singular configuration the results are sensitive to their inputs
                warn_conditioning(c, row, &s.conditioning);
                let tree = [&s.q, &s.qd, &s.qdd].map(|v| v.as_slice());
                forward_kinematics_into(&self.robot, &mut self.data, tree[0], tree[1], tree[2])
                    .map_err(in_row)?;
                *g = s.g;
            }
        }
        Ok(())
    }
}

/// The names of the columns of a state table's Jacobians: the movable joints (closed chains:
/// the actuated ones; a floating robot's base velocity entries first).
pub fn joint_names(robot: &Robot) -> CliResult<Vec<String>> {
    Ok(if robot.is_tree() {
        robot.velocity_names()
    } else {
        ClosedChain::new(robot)?.coordinates().names().to_vec()
    })
}

/// A CSV table built line by line: the carried columns, `row`, then the command's.
pub struct CsvTable {
    pub text: String,
}

impl CsvTable {
    /// The header line: `carried`, `row`, `columns`.
    pub fn new(carried: &[String], columns: &[&str]) -> CsvTable {
        let mut h: Vec<String> = carried.iter().map(|c| csv_field(c)).collect();
        h.push("row".into());
        h.extend(columns.iter().map(|c| csv_field(c)));
        CsvTable {
            text: h.join(",") + "\n",
        }
    }

    /// One line: the carried values, the row number, the labels, the values.
    pub fn line(&mut self, carried: &[f64], row: usize, labels: &[&str], values: &[f64]) {
        let mut f: Vec<String> = carried.iter().map(|x| format_number(*x)).collect();
        f.push(row.to_string());
        f.extend(labels.iter().map(|l| csv_field(l)));
        f.extend(values.iter().map(|x| format_number(*x)));
        self.text += &(f.join(",") + "\n");
    }
}

/// A CSV field, quoted when it holds a comma or a quote.
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// `--format json` is the single state's: a table is CSV.
pub fn table_format(format: crate::common::TableFormat) -> CliResult {
    match format {
        crate::common::TableFormat::Csv => Ok(()),
        _ => Err(
            "--input writes a CSV table: drop --format json (or give one state with --q)".into(),
        ),
    }
}

/// The frames named on the command line (every frame name of the robot when none).
pub fn frames(robot: &Robot, names: &[String]) -> CliResult<Vec<(String, FrameId)>> {
    let names: Vec<String> = if names.is_empty() {
        robot.frame_names().into_iter().map(String::from).collect()
    } else {
        names.to_vec()
    };
    names
        .into_iter()
        .map(|n| Ok((n.clone(), robot.frame_id(&n)?)))
        .collect()
}

/// The rows of a matrix as vectors (tables and JSON).
pub fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| m.row(i).iter().copied().collect())
        .collect()
}
