//! Width constraints (Longay 2014 §5.3.2): fix the diameter of any internode. Constraints split
//! the tree into subtrees whose pipe exponents n are re-solved (Newton–Raphson, in
//! [`crate::growth`]) so that d^n = Σ dᵢ^n holds in each and all widths follow.

use super::EditError;
use crate::growth::Tree;
use crate::tree::NodeId;

/// Sets (`Some(diameter_m)`) or clears (`None`) the width constraint of `node`, then recomputes
/// every width.
pub fn set_width_constraint(
    tree: &mut Tree,
    node: NodeId,
    diameter_m: Option<f32>,
) -> Result<(), EditError> {
    let count = tree.skeleton.len();
    if node.index() >= count {
        return Err(EditError::NoSuchInternode { id: node.0, count });
    }
    if let Some(d) = diameter_m
        && !crate::growth::is_width_constraint(d)
    {
        return Err(EditError::BadParameter {
            name: "width constraint diameter",
            value: d,
        });
    }
    tree.skeleton.internodes[node.index()].width_constraint = diameter_m;
    tree.update_widths();
    Ok(())
}
