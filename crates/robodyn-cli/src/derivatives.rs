//! `idm --derivatives` and `ddm --derivatives`: the three derivative matrices at one state
//! (a tree's over its movable joints, a closed chain's over its actuated joints on the
//! assembly branch) in the table format of `--format`.

use crate::common::{
    conditioning_json, format_number, parse_list, warn_conditioning, write_text, CliResult,
    TableFormat, TableOutput,
};
use robodyn::nalgebra::DMatrix;
use robodyn::{ClosedChain, Conditioning};

/// The one state of `--q`, `--qd` and the third list (default zeros), over `n` joints.
pub fn state(n: usize, lists: [(&str, &Option<String>); 3]) -> CliResult<[Vec<f64>; 3]> {
    let list = |(name, s): (&str, &Option<String>)| match s {
        Some(s) => parse_list(name, s),
        None => Ok(vec![0.0; n]),
    };
    Ok([list(lists[0])?, list(lists[1])?, list(lists[2])?])
}

/// What one derivatives command writes.
pub struct Table<'a> {
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
pub fn write(t: &Table, out: &TableOutput) -> CliResult {
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
