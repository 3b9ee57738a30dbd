//! The coordinate map of public joint vectors (Pinocchio's `idx_q`): entry k of a joint vector
//! is the variable of frame `frame(k)`, named `name(k)`.

use crate::error::{check_vector, Result};

/// Which joints a public joint vector holds, in frame order: the movable joints of a tree
/// ([`crate::Robot::coordinates`]) or the actuated / passive joints of a closed chain
/// ([`crate::ClosedChain::coordinates`]).
///
/// # Example
///
/// ```
/// # fn main() -> robodyn::Result<()> {
/// let robots = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots");
/// let rx90 = robodyn::io::load(format!("{robots}/rx90.urdf"))?;
/// let c = rx90.coordinates();
/// let elbow = c.index_of("elbow").expect("a joint of the URDF");
/// assert_eq!((elbow, c.frame(elbow), c.name(elbow)), (2, 3, "elbow"));
///
/// // A closed chain's vectors hold its actuated joints; the passive ones have their own map.
/// let sr400 = robodyn::io::load(format!("{robots}/sr400.toml"))?;
/// let chain = robodyn::ClosedChain::new(&sr400)?;
/// assert_eq!(chain.coordinates().frames(), &[1, 2, 4, 5, 6, 7]);
/// assert_eq!(chain.passive_coordinates().frames(), &[3, 8]);
/// assert_eq!(chain.coordinates().index_of_frame(3), None); // joint 3 is passive
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Coordinates {
    frames: Vec<usize>,
    names: Vec<String>,
    /// index_of_frame[j] for frames 0..=max frame.
    index: Vec<Option<usize>>,
    /// NL: the length of the tree arrays the entries scatter into.
    nl: usize,
    /// The robot's base floats: its state vectors have nq / nv entries, so a joint vector
    /// checked here (by a function that does not support floating bases) is refused.
    pub(crate) floating: bool,
}

impl Coordinates {
    /// The coordinates of `frames` (1-based frame numbers, increasing) with their joint names.
    pub(crate) fn new(frames: Vec<usize>, names: Vec<String>, nl: usize) -> Coordinates {
        debug_assert_eq!(frames.len(), names.len());
        let mut index = vec![None; nl + 1];
        for (k, &j) in frames.iter().enumerate() {
            index[j] = Some(k);
        }
        Coordinates {
            frames,
            names,
            index,
            nl,
            floating: false,
        }
    }

    /// Number of entries of a joint vector.
    #[inline]
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// True when the vectors are empty (a robot with no movable joint).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Frame numbers of the entries, in order.
    #[inline]
    pub fn frames(&self) -> &[usize] {
        &self.frames
    }

    /// Frame number of entry k.
    pub fn frame(&self, k: usize) -> usize {
        self.frames[k]
    }

    /// Joint name of entry k (the URDF joint name, else `j<frame>`).
    pub fn name(&self, k: usize) -> &str {
        &self.names[k]
    }

    /// Joint names, in order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Entry of frame j, if frame j is one of these joints.
    pub fn index_of_frame(&self, j: usize) -> Option<usize> {
        self.index.get(j).copied().flatten()
    }

    /// Entry of the joint named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// "movable joints [1, 2, 4]": what the entries are, for messages.
    pub(crate) fn describe(&self, what: &str) -> String {
        format!("{what} {:?}", self.frames)
    }

    /// Check a joint vector: length and finiteness (typed errors).
    pub(crate) fn check(&self, what: &str, v: &[f64], kind: &str) -> Result<()> {
        self.refuse_floating(what)?;
        check_vector(what, v, self.len(), || self.describe(kind))
    }

    /// Check the length of an output vector.
    pub(crate) fn check_output(&self, what: &str, v: &[f64], kind: &str) -> Result<()> {
        self.refuse_floating(what)?;
        if v.len() != self.len() {
            return Err(crate::Error::dimension(
                what,
                self.len(),
                v.len(),
                self.describe(kind),
            ));
        }
        Ok(())
    }

    /// The refusal of a joint vector of a floating robot by a function that takes joint
    /// vectors over the movable joints only (the floating-base models take nq / nv vectors and
    /// check them themselves).
    fn refuse_floating(&self, what: &str) -> Result<()> {
        if self.floating {
            return Err(crate::Error::Input(format!(
                "`{what}` over the {} movable joints: the robot has a floating base, which this \
                 function does not support yet (the floating-base models inverse_dynamics, \
                 inertia_matrix, h_vector, direct_dynamics and the kinematics take configurations of nq = 7 + {} \
                 and velocities of nv = 6 + {} entries)",
                self.len(),
                self.len(),
                self.len()
            )));
        }
        Ok(())
    }

    /// Write the entries into a tree array of NL entries (joint j at j-1); other entries are
    /// left as they are.
    #[inline]
    pub(crate) fn scatter(&self, v: &[f64], tree: &mut [f64]) {
        for (&j, &x) in self.frames.iter().zip(v) {
            tree[j - 1] = x;
        }
    }

    /// True when the entries are exactly the tree joints 1..NL (no scatter needed).
    #[inline]
    pub(crate) fn is_identity(&self) -> bool {
        self.frames.len() == self.nl
    }
}
