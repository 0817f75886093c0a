//! The tree's surroundings: attraction points (competition for space), the shadow grid
//! (competition for light) and scenes (real or simple obstacles).
//!
//! Space: world metres, Y up, the tree's base at the origin. Lengths of the growth model
//! (occupancy radius r, perception distance d) are given in internode lengths by the species and
//! converted to metres by the caller.

mod attraction;
mod grid;
mod scene;
mod shadow;

pub use attraction::{AttractionPoint, AttractionPoints};
pub use grid::SpatialGrid;
pub use scene::{BoxScene, HalfSpace, Scene, SceneMode, SphereScene};
pub use shadow::ShadowGrid;

use serde::{Deserialize, Serialize};

/// Everything around one tree that its growth state depends on.
///
/// Only the persistent attraction points are saved; the shadow grid is a function of the
/// skeleton (exact integer sums, so it is rebuilt bit-for-bit on load).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Environment {
    pub attraction: AttractionPoints,
    #[serde(skip)]
    pub shadow: ShadowGrid,
}
