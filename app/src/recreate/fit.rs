//! Fitting the grown tree's foliage to the real crown's silhouettes: how large its leaves are and
//! how densely they sit decide whether the crown reads solid where the real one does. A few
//! leaf sizes and densities (steps of the species' own) are tried; the one whose foliage, drawn
//! as the renderer draws it (leaf cards, alpha-tested), agrees best with the crown's silhouettes
//! (intersection over union, mean over the views) is kept in the tree's own looks, so it saves,
//! edits and regrows with the tree.

use glam::Affine3A;
use sylva_core::Tree;

use super::footage::TrackedFootage;
use super::silhouette::{Silhouette, WorldTriangles};

/// A view of the real crown: the pixels of `frame` the foliage should cover (row-major, the
/// camera's size).
pub struct CrownTarget {
    pub frame: usize,
    pub inside: Vec<bool>,
}

/// What the fit chose.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FoliageFit {
    /// Leaf length and width, times the species'.
    pub leaf_scale: f32,
    /// Leaves per metre, times the species'.
    pub density_scale: f32,
    /// Shoots end at least this many hull voxels inside the crown's surface.
    pub trim_voxels: usize,
    /// Mean IoU of the foliage with the targets, the species' own foliage and the fitted.
    pub iou_before: f64,
    pub iou_after: f64,
}

/// Leaf sizes tried, times the species' (its own first).
const LEAF_SCALES: [f32; 6] = [1.0, 1.25, 1.6, 2.0, 2.5, 3.2];
/// Leaf densities tried, times the species'.
const DENSITY_SCALES: [f32; 4] = [1.0, 1.5, 2.2, 3.2];

/// Mean IoU of `tree`'s foliage (leaf cards only: the trunk below the crown is not the crown)
/// with `targets`.
pub fn foliage_iou(
    tree: &Tree,
    world_from_tree: &Affine3A,
    footage: &TrackedFootage,
    targets: &[&CrownTarget],
) -> f64 {
    let meshes = sylva_core::geometry::build_tree_level(tree, 0);
    let leaves = WorldTriangles::of_meshes(&meshes, world_from_tree).leaves_only();
    let sum: f64 = targets
        .iter()
        .map(|t| {
            let seen = Silhouette::render(footage, t.frame, &leaves);
            let width = seen.width as usize;
            seen.iou_with(|x, y| t.inside[y as usize * width + x as usize])
        })
        .sum();
    sum / targets.len().max(1) as f64
}

/// At most `n` of `targets`: those of the `first` frames, then others spread evenly.
pub fn spread<'a>(targets: &'a [CrownTarget], first: &[usize], n: usize) -> Vec<&'a CrownTarget> {
    let mut out: Vec<&CrownTarget> = targets
        .iter()
        .filter(|t| first.contains(&t.frame))
        .collect();
    let rest: Vec<&CrownTarget> = targets
        .iter()
        .filter(|t| !first.contains(&t.frame))
        .collect();
    let room = n.saturating_sub(out.len()).min(rest.len());
    for k in 0..room {
        out.push(rest[(2 * k + 1) * rest.len() / (2 * room)]);
    }
    out
}

fn with_foliage(tree: &Tree, length: f32, width: f32, per_metre: f32) -> Tree {
    let mut out = tree.clone();
    let mut looks = out.species.looks().clone();
    looks.leaf_length = length.clamp(0.001, 2.0);
    looks.leaf_width = width.clamp(0.0005, 2.0);
    looks.leaves_per_metre = per_metre.clamp(0.0, 2000.0);
    out.species.looks = Some(looks);
    out
}

/// Chooses the leaf size, then the density, that `score` (the foliage's agreement with the
/// crown's views, [`foliage_iou`]) rates best, and returns the tree with them in its looks.
pub fn fit_foliage(tree: &Tree, score: &dyn Fn(&Tree) -> f64) -> (Tree, FoliageFit) {
    let looks = tree.species.looks().clone();
    let scaled = |leaf: f32, density: f32| {
        with_foliage(
            tree,
            looks.leaf_length * leaf,
            looks.leaf_width * leaf,
            looks.leaves_per_metre * density,
        )
    };
    let before = score(tree);
    let (mut leaf, mut best) = (1.0, before);
    for &s in &LEAF_SCALES[1..] {
        let iou = score(&scaled(s, 1.0));
        if iou > best {
            (leaf, best) = (s, iou);
        } else {
            // The agreement rises to one size and falls past it.
            break;
        }
    }
    let mut density = 1.0;
    for &d in &DENSITY_SCALES[1..] {
        let iou = score(&scaled(leaf, d));
        if iou > best {
            (density, best) = (d, iou);
        } else {
            break;
        }
    }
    let fit = FoliageFit {
        leaf_scale: leaf,
        density_scale: density,
        trim_voxels: 0,
        iou_before: before,
        iou_after: best,
    };
    (scaled(leaf, density), fit)
}
