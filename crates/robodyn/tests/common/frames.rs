//! The placements 0T_j from a per-frame array (frames 1..NL, fixed frames included, or 1..NJ
//! with the cut-joint variables), through the public checked entry point
//! `geometry::frame_transforms_with_cuts` (movable joints + cut joints).
#![allow(dead_code)]

use robodyn::geometry::{frame_transforms_with_cuts, Transform};
use robodyn::Robot;

/// 0T_j for j = 1..NF from per-frame values `q` (missing cut-joint values taken as 0).
pub fn per_frame(r: &Robot, q: &[f64]) -> Vec<Transform> {
    let movable: Vec<f64> = r.coordinates().frames().iter().map(|&j| q[j - 1]).collect();
    let cuts: Vec<f64> = (r.nl() + 1..=r.nj())
        .map(|j| q.get(j - 1).copied().unwrap_or(0.0))
        .collect();
    frame_transforms_with_cuts(r, &movable, &cuts).expect("a finite state of the right size")
}
