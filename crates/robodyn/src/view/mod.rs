//! A 3D view of a robot in one self-contained HTML page (feature `view`).
//!
//! [`page`] writes an HTML file that opens offline (no network, no server): three.js r170
//! (vendored, MIT; `view/assets/three/README.md` says where from) is embedded through an import
//! map of `data:` URLs, the robot's Khalil–Kleinfinger geometry is embedded as JSON, and a small
//! script of the page (`view/assets/viewer.js`) computes the forward kinematics from it in
//! double precision and draws:
//!
//! - every frame R_j: x_j (red) and z_j (blue), labelled with j; revolute joints as cylinders
//!   and prismatic joints as prisms along z_j; fixed frames (sigma = 2) as small grey cubes;
//! - the links as segments following iT_j = Rot(z, gamma) Trans(z, b) Rot(x, alpha)
//!   Trans(x, d) Rot(z, theta) Trans(z, r): b along z_i, d along the common normal (the x axis
//!   after Rot(z, gamma)), r along z_j;
//! - cut joints (frames NL+1..NJ) in pink, their twin frames (NJ+1..NF, fixed on the other link
//!   of the loop) with dashed axes: when the loop is closed, R_k and R_{k+B} coincide;
//! - the base R_0, the gravity vector and a ground grid perpendicular to it;
//! - URDF meshes (STL, [`urdf_visuals`]) and primitive shapes, when given;
//! - a slider per movable joint for trees, the frames table (the row under the mouse and its
//!   frame highlighted), and with a [`Trajectory`] a time slider, play/pause, speed and the
//!   joint curves with a cursor.
//!
//! A closed robot is shown assembled: the passive joints and the cut-joint variables come from
//! the library's loop closure (its assembly branch, [`crate::ClosedChain`]); its sliders show the
//! values but do not move (moving an actuated joint needs loop closure, which the page does not
//! do: give the actuated values to [`Pose::Actuated`] or a trajectory).
//!
//! The page exposes `window.robodynView` (`frameTransforms()`, `setJoints(q)`, `setTime(t)`,
//! `play()`, ...) for tests and scripts; the browser tests compare the frame origins it draws
//! with [`crate::geometry::frame_transforms`].
//!
//! ```
//! # fn main() -> robodyn::Result<()> {
//! use robodyn::view::{page, Pose, ViewOptions};
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/sr400.toml");
//! let sr400 = robodyn::io::load(path)?;
//! let options = ViewOptions {
//!     pose: Pose::Actuated(vec![0.1, 0.2, 0.3, 0.4, 0.5, 1.6]), // loop closure gives q_p
//!     ..ViewOptions::default()
//! };
//! let page = page(&sr400, &options)?;
//! assert!(page.html.starts_with("<!DOCTYPE html>"));
//! assert!(page.warnings.is_empty()); // the loop is closed
//! # Ok(())
//! # }
//! ```

mod meshes;
mod page;
mod scene;
mod trajectory;

pub use meshes::{urdf_visuals, MeshOptions, Visuals, DEFAULT_MESH_BYTES};
pub use page::{page, save, Page};
pub use trajectory::{JointColumns, Trajectory, MAX_SAMPLES};

/// The joint values the page starts from.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Pose {
    /// Trees: q = 0; closed chains: the assembly of the robot file (else q = 0), closed by loop
    /// closure.
    #[default]
    Default,
    /// The movable joints of the (equivalent) tree, frame order ([`crate::Robot::coordinates`]).
    /// For a closed robot the loops are drawn as these values place them, closed or not (the
    /// page reports the gap of each loop).
    Tree(Vec<f64>),
    /// Closed chains: the actuated joints ([`crate::ClosedChain::coordinates`]); the passive
    /// joints come from loop closure on the assembly branch (continuation from the assembly).
    Actuated(Vec<f64>),
}

/// A fixed-camera picture: the 3D view alone, filling a window of this size (pixels), for a
/// screenshot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Picture {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// What the page shows besides the robot.
#[derive(Clone, Debug, Default)]
pub struct ViewOptions {
    /// The joint values shown first (with a trajectory: [`Pose::Default`], the page starts at
    /// its first sample).
    pub pose: Pose,
    /// A motion to play back (time slider, play/pause, speed, joint curves).
    pub trajectory: Option<Trajectory>,
    /// Meshes and shapes of the links (URDF), drawn with the frames.
    pub visuals: Option<Visuals>,
    /// The page as a picture of the 3D view alone (no panels), for a screenshot.
    pub picture: Option<Picture>,
}
