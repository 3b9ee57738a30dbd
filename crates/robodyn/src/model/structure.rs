//! Topology derived from the antecedent array: children, main branches, closed loops.

use serde::Serialize;

/// A closed loop of the mechanism, cut at joint `cut` (chapter 10, §10.3.1).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ClosedLoop {
    /// Cut joint k (NL < k <= NJ); frame R_k is on link `link_i`.
    pub cut: usize,
    /// Frame k + B, fixed on link `link_j`, coincident with R_k when the loop is closed.
    pub twin: usize,
    /// i = a(k).
    pub link_i: usize,
    /// j: the link carrying frame k + B, a(k + B) or, when the twin sits on other twin frames
    /// (OpenSYMORO's TwoLoops: frame 12 on frame 11), the link that chain of fixed frames ends on.
    pub link_j: usize,
    /// Root of the loop: the nearest common ancestor of i and j (0 = base).
    pub root: usize,
    /// Links from the root (excluded) to i, in order from the root.
    pub branch_i: Vec<usize>,
    /// Links from the root (excluded) to j, in order from the root.
    pub branch_j: Vec<usize>,
}

impl ClosedLoop {
    /// Tree joints of the loop (both branches).
    pub fn tree_joints(&self) -> impl Iterator<Item = usize> + '_ {
        self.branch_i.iter().chain(self.branch_j.iter()).copied()
    }
}

/// Kind of structure, as reported by `info`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StructureType {
    /// One chain, no branching.
    Serial,
    /// A tree with branches, no loop.
    Tree,
    /// At least one closed loop.
    Closed,
}

impl std::fmt::Display for StructureType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            StructureType::Serial => "serial",
            StructureType::Tree => "tree",
            StructureType::Closed => "closed chain",
        })
    }
}

/// Topology of the equivalent tree and its loops.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Structure {
    /// a(j) for frames 1..NF at index j; `ant[0]` is unused (0).
    pub ant: Vec<usize>,
    /// `children[i]`: links k <= NL with a(k) = i, for i = 0..NL.
    pub children: Vec<Vec<usize>>,
    /// Main branches: paths (link numbers from the base) to each terminal link.
    pub main_branches: Vec<Vec<usize>>,
    /// The closed loops (one per cut joint).
    pub loops: Vec<ClosedLoop>,
    /// Serial, tree or closed.
    pub kind: StructureType,
}

impl Structure {
    /// Build from the antecedents (already validated: a(j) < j for j <= NL, a(j) <= NL for the cut
    /// joints, a(j) a link or an earlier twin frame for the twin frames).
    pub fn new(ant: Vec<usize>, nl: usize, nj: usize) -> Structure {
        let mut children = vec![Vec::new(); nl + 1];
        for j in 1..=nl {
            children[ant[j]].push(j);
        }
        let mut main_branches = Vec::new();
        for j in 1..=nl {
            if children[j].is_empty() {
                main_branches.push(path_from_base(&ant, j));
            }
        }
        let b = nj - nl;
        let loops = (nl + 1..=nj)
            .map(|k| {
                let (i, j) = (ant[k], carrying_link(&ant, nl, k + b));
                let pi = path_from_base(&ant, i);
                let pj = path_from_base(&ant, j);
                let common = pi.iter().zip(&pj).take_while(|(a, b)| a == b).count();
                let root = if common == 0 { 0 } else { pi[common - 1] };
                ClosedLoop {
                    cut: k,
                    twin: k + b,
                    link_i: i,
                    link_j: j,
                    root,
                    branch_i: pi[common..].to_vec(),
                    branch_j: pj[common..].to_vec(),
                }
            })
            .collect::<Vec<_>>();
        let kind = if !loops.is_empty() {
            StructureType::Closed
        } else if children.iter().all(|c| c.len() <= 1) {
            StructureType::Serial
        } else {
            StructureType::Tree
        };
        Structure {
            ant,
            children,
            main_branches,
            loops,
            kind,
        }
    }

    /// True when link `anc` is link `j` or one of its ancestors (0 = base is everyone's).
    pub fn is_ancestor(&self, anc: usize, mut j: usize) -> bool {
        loop {
            if j == anc {
                return true;
            }
            if j == 0 {
                return false;
            }
            j = self.ant[j];
        }
    }
}

/// The link (0 = base) frame `f` is fixed on: a(f), followed down while it is a frame beyond NL
/// (a twin frame on another twin frame). `ant` must be validated (a(f) < f beyond NJ).
pub fn carrying_link(ant: &[usize], nl: usize, f: usize) -> usize {
    let mut a = ant[f];
    while a > nl {
        a = ant[a];
    }
    a
}

/// Links from the base (excluded) to j (included).
pub fn path_from_base(ant: &[usize], j: usize) -> Vec<usize> {
    let mut p = Vec::new();
    let mut k = j;
    while k != 0 {
        p.push(k);
        k = ant[k];
    }
    p.reverse();
    p
}
