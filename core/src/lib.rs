//! # sylva-core
//!
//! The tree model of Sylva: TreeSketch's self-organizing growth (space colonization,
//! shadow-propagation light, extended Borchert–Honda vigor, tropisms, gravimorphism), the
//! modelling operations that shape it, branch and leaf geometry, and export.
//!
//! Pure Rust: no GPU, UI or OpenCV dependency (CI checks `cargo tree -p sylva-core`), so the app,
//! replayed sessions and tests all drive exactly the same code.
//!
//! **Space and units.** World space is metres, Y up, origin on the ground plane at the tree's
//! base. Time is counted in growth iterations; a species states how many years one iteration is.
//!
//! Modules, one concept each: [`tree`] (arena of internodes and buds, frames), [`environment`]
//! (attraction points, shadow grid, scenes), [`growth`] (one iteration, step by step),
//! [`species`] (presets as data), [`edit`] (brush, lasso, prune, bend, widths, history),
//! [`geometry`] (branch and leaf meshes), [`export`] (glTF 2.0, OBJ), [`garden`] (several trees
//! growing together, competing for light and space).

pub mod edit;
pub mod environment;
pub mod export;
pub mod garden;
pub mod geometry;
pub mod growth;
pub mod rng;
pub mod safe_write;
pub mod species;
pub mod tree;

pub use growth::Tree;
pub use rng::Rng;
pub use tree::{Bud, Internode, NodeId, Skeleton};

/// `skip_serializing_if` for optional fields whose default means "not used": files leave them
/// out, so they stay as they were before the field existed.
pub(crate) fn is_default<T: Default + PartialEq>(value: &T) -> bool {
    *value == T::default()
}
