//! Modelling operations (Longay 2014 §5.2–5.3, appendices A and B), independent of any UI so that
//! the app, replayed sessions and tests drive the same code.
//!
//! One concept per module: [`brush`] (brushing and sketching on a brush plane that follows the
//! device, sketch tropism, selective growth), [`lasso`] (silhouette → chordal axis → envelope → attraction points),
//! [`prune`], [`bend`] (PriMo on skeletons), [`widths`] (width constraints), [`history`]
//! (operation-level undo/redo), [`timeline`] (ungrow/regrow). The depth constraint is one slab kept by the
//! tree's environment ([`crate::environment::DepthConstraint`]); brush and lasso add no point
//! outside it.
//!
//! Space: world metres, Y up, origin on the ground at the tree's base.

pub mod bend;
mod bend_solver;
pub mod brush;
mod diff;
pub mod history;
mod horn;
pub mod lasso;
pub mod prune;
pub mod timeline;
pub mod widths;

pub use bend::{Bend, BendPose, BendSettings, PositionalConstraint};
pub use brush::{
    BrushPlane, BrushSettings, BrushStroke, StrokeCamera, StrokePoint, begin_selective_growth,
    end_selective_growth,
};
pub use history::{History, OperationKind};
pub use lasso::{Lasso, LassoEnvelope};
pub use prune::{Pruned, branch_to_prune, nearest_internode, prune_at};
pub use timeline::{Timeline, skeleton_at_iteration};
pub use widths::set_width_constraint;

/// What an edit refused to do, and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EditError {
    #[error("internode {id} does not exist (the tree has {count})")]
    NoSuchInternode { id: u32, count: usize },
    #[error("internode {id} is not on the path above base internode {base}")]
    NotOnPath { id: u32, base: u32 },
    #[error("parameter {name} = {value} is out of range")]
    BadParameter { name: &'static str, value: f32 },
    #[error("{what} is not finite")]
    NonFinite { what: &'static str },
    #[error("the lasso needs at least 3 distinct points enclosing an area, got {points}")]
    DegenerateLasso { points: usize },
    #[error("the tree has no internodes")]
    EmptyTree,
    #[error("no branching point below the picked internode: pruning there would remove the trunk")]
    NothingToPrune,
    #[error("the tree has no living bud to grow from")]
    NoLivingBud,
    #[error("iteration {iteration} is not kept in the timeline (kept: {range:?})")]
    IterationNotKept {
        iteration: u32,
        range: Option<(u32, u32)>,
    },
}
