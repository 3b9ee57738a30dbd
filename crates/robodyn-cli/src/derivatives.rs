//! `idm --derivatives` and `ddm --derivatives`: the three derivative matrices at one state
//! (a tree's over its movable joints, a closed chain's over its actuated joints on the
//! assembly branch) in the table format of `--format`.

use crate::common::{
    conditioning_json, format_number, parse_list, start_branch, warn_conditioning, write_text,
    CliResult, TableFormat, TableOutput,
};
use crate::rows::EvaluationArgs;
use robodyn::nalgebra::{DMatrix, DVector};
use robodyn::{Branch, ClosedChain, ClosedDerivativesData, Conditioning, Environment, Robot};

/// What a model's derivatives are at one state: the model's value and its three matrices.
pub type Derivatives = (DVector<f64>, [DMatrix<f64>; 3]);

/// The names of a derivatives command's table: the three inputs (the state's `--q`, `--qd` and
/// third list), the model's value and the three matrices.
pub struct Names {
    pub inputs: [&'static str; 3],
    pub value: &'static str,
    pub matrices: [&'static str; 3],
}

/// The closed-chain model's derivatives at one state (on the tracked branch) and the
/// conditioning there.
pub type ClosedModel<'f> = dyn FnMut(
        &ClosedChain,
        &mut ClosedDerivativesData,
        &mut Branch,
        &Environment,
        [&[f64]; 3],
    ) -> robodyn::Result<(Derivatives, Conditioning)>
    + 'f;

/// Evaluate and write a model's derivatives at the one state of the three lists: `tree` for a
/// tree, `closed` for a closed chain (its branch started at `--guess` or the assembly).
pub fn run(
    robot: &Robot,
    eval: &EvaluationArgs,
    lists: [&Option<String>; 3],
    names: &Names,
    tree: impl FnOnce(&Robot, [&[f64]; 3]) -> robodyn::Result<Derivatives>,
    closed: &mut ClosedModel,
) -> CliResult {
    let lists = [0, 1, 2].map(|k| (names.inputs[k], lists[k]));
    let chain = (!robot.is_tree())
        .then(|| ClosedChain::new(robot))
        .transpose()?;
    let n = chain.as_ref().map_or(robot.dof(), |c| c.dof());
    let x = state(n, lists)?;
    let xs = [x[0].as_slice(), x[1].as_slice(), x[2].as_slice()];
    let (((value, m), conditioning), joints) = match &chain {
        Some(chain) => {
            let mut branch = start_branch(chain, xs[0], eval.guess.as_deref())?;
            let mut data = ClosedDerivativesData::new(chain);
            let env = robot.environment();
            let d = closed(chain, &mut data, &mut branch, env, xs)?;
            ((d.0, Some(d.1)), chain.coordinates().frames().to_vec())
        }
        None => (
            (tree(robot, xs)?, None),
            robot.coordinates().frames().to_vec(),
        ),
    };
    let table = Table {
        joints: &joints,
        vectors: [
            (names.inputs[0], xs[0]),
            (names.inputs[1], xs[1]),
            (names.inputs[2], xs[2]),
            (names.value, value.as_slice()),
        ],
        matrices: [
            (names.matrices[0], &m[0]),
            (names.matrices[1], &m[1]),
            (names.matrices[2], &m[2]),
        ],
        closed: chain.as_ref().zip(conditioning),
    };
    write(&table, &eval.out)
}

/// The one state of `--q`, `--qd` and the third list (default zeros), over `n` joints.
fn state(n: usize, lists: [(&str, &Option<String>); 3]) -> CliResult<[Vec<f64>; 3]> {
    let list = |(name, s): (&str, &Option<String>)| match s {
        Some(s) => parse_list(name, s),
        None => Ok(vec![0.0; n]),
    };
    Ok([list(lists[0])?, list(lists[1])?, list(lists[2])?])
}

/// What one derivatives command writes.
struct Table<'a> {
    /// The joints of the rows and columns (frame numbers).
    pub joints: &'a [usize],
    /// The state's vectors and the model's value, by name (`q`, `qd`, `qdd`, `tau`).
    pub vectors: [(&'a str, &'a [f64]); 4],
    /// The three matrices, by name; row j is the derivative of the model's value j.
    pub matrices: [(&'a str, &'a DMatrix<f64>); 3],
    /// A closed chain's conditioning at the state (and its chain, for the warning).
    pub closed: Option<(&'a ClosedChain, Conditioning)>,
}

/// Write `t`: csv columns matrix, joint, then one per joint (one row per matrix row); json an
/// object with `joints`, the vectors, the matrices as lists of rows and, for a closed chain,
/// `rcond_wp` (`rcond_a_cl`) and `singularity_warning`.
fn write(t: &Table, out: &TableOutput) -> CliResult {
    if let Some((chain, c)) = &t.closed {
        warn_conditioning(chain, None, c);
    }
    let text = match out.format {
        TableFormat::Csv => {
            let mut s = String::from("matrix,joint");
            for j in t.joints {
                s += &format!(",{j}");
            }
            s.push('\n');
            for (name, m) in t.matrices {
                for (i, j) in t.joints.iter().enumerate() {
                    s += &format!("{name},{j}");
                    for x in m.row(i).iter() {
                        s += &format!(",{}", format_number(*x));
                    }
                    s.push('\n');
                }
            }
            s
        }
        TableFormat::Json => {
            let mut o = serde_json::Map::new();
            o.insert("joints".into(), serde_json::json!(t.joints));
            for (name, v) in t.vectors {
                o.insert(name.into(), serde_json::json!(v));
            }
            for (name, m) in t.matrices {
                let rows: Vec<Vec<f64>> = (0..m.nrows())
                    .map(|i| m.row(i).iter().copied().collect())
                    .collect();
                o.insert(name.into(), serde_json::json!(rows));
            }
            if let Some((_, c)) = &t.closed {
                o.extend(conditioning_json(c));
            }
            serde_json::to_string_pretty(&serde_json::Value::Object(o))? + "\n"
        }
    };
    write_text(out.output.as_deref(), &text)
}
