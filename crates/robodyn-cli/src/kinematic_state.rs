//! The state the kinematic commands (`fk`, `jacobian`, `com`) share: the robot and one state
//! from `--q/--qd/--qdd` (a closed chain's actuated joints, completed on the assembly branch),
//! and the frames named by `--frame`.

use crate::common::{parse_list, start_branch, warn_conditioning, CliResult, RobotArgs};
use nalgebra::DMatrix;
use robodyn::{closed_state, forward_kinematics_into, ClosedChain, FrameId, KinematicsData, Robot};

/// `--q`, `--qd`, `--qdd` and `--guess` of the kinematic commands.
#[derive(clap::Args, Debug)]
pub struct StateArgs {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Joint positions, comma separated (movable joints in frame order; closed chains: the
    /// actuated joints; default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// Joint velocities (default zeros).
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
    /// The state's q: the movable joints (closed chains: the actuated joints given).
    pub q: Vec<f64>,
    /// The chain and its G at the state (closed chains).
    pub closed: Option<(ClosedChain, DMatrix<f64>)>,
}

impl StateArgs {
    /// Load the robot and compute the kinematics at the state.
    pub fn evaluate(&self) -> CliResult<Evaluated> {
        let robot = self.robot.load()?;
        let chain = (!robot.is_tree())
            .then(|| ClosedChain::new(&robot))
            .transpose()?;
        let n = match &chain {
            Some(c) => c.dof(),
            None => robot.dof(),
        };
        let list = |name: &str, s: &Option<String>| -> CliResult<Vec<f64>> {
            match s {
                Some(s) => parse_list(name, s),
                None => Ok(vec![0.0; n]),
            }
        };
        let (q, qd, qdd) = (
            list("q", &self.q)?,
            list("qd", &self.qd)?,
            list("qdd", &self.qdd)?,
        );
        let mut data = KinematicsData::new(&robot);
        let closed = match chain {
            None => {
                forward_kinematics_into(&robot, &mut data, &q, &qd, &qdd)?;
                None
            }
            Some(c) => {
                let mut branch = start_branch(&c, &q, self.guess.as_deref())?;
                let s = closed_state(&c, &mut branch, &q, &qd, &qdd)?;
                // near a singular configuration the results are sensitive to their inputs
                warn_conditioning(&c, None, &s.conditioning);
                let tree = [&s.q, &s.qd, &s.qdd].map(|v| v.as_slice());
                forward_kinematics_into(&robot, &mut data, tree[0], tree[1], tree[2])?;
                Some((c, s.g))
            }
        };
        Ok(Evaluated {
            robot,
            data,
            q,
            closed,
        })
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
