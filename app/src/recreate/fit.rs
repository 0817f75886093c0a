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
    /// The fitted foliage's mean IoU with each trim tried (0, 1, ... voxels inside).
    pub trim_iou: Vec<f64>,
    /// Mean IoU of the foliage with the targets, the species' own foliage and the fitted.
    pub iou_before: f64,
    pub iou_after: f64,
}

/// Leaf sizes tried, times the species'.
const LEAF_SCALES: [f32; 9] = [0.5, 0.63, 0.8, 1.0, 1.25, 1.6, 2.0, 2.5, 3.2];
/// Leaf densities tried, times the species'.
const DENSITY_SCALES: [f32; 8] = [1.0, 1.5, 2.2, 3.2, 4.6, 6.4, 9.0, 12.8];
/// The species' own size and density among them.
const OWN: (usize, usize) = (3, 0);

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

/// Chooses the leaf size and density that `score` (the foliage's agreement with the crown's
/// views, [`foliage_iou`]) rates best, and returns the tree with them in its looks. From the
/// species' own, each in turn moves a step up or down its scale while that scores better, until
/// neither does: smaller leaves, denser, fringe the crown's outline less than large ones filling
/// the same area, and the best balance differs from crown to crown.
pub fn fit_foliage(tree: &Tree, score: &dyn Fn(&Tree) -> f64) -> (Tree, FoliageFit) {
    fit_foliage_from(tree, score, None)
}

/// [`fit_foliage`], the descent starting at `start` (a leaf size and density the fit chose for a
/// like tree: the same tree trimmed a little differently) instead of the species' own, so it
/// ends in a few scores when the optimum barely moved. The species' own is still scored, for
/// [`FoliageFit::iou_before`].
pub fn fit_foliage_from(
    tree: &Tree,
    score: &dyn Fn(&Tree) -> f64,
    start: Option<&FoliageFit>,
) -> (Tree, FoliageFit) {
    let looks = tree.species.looks().clone();
    let scaled = |(leaf, density): (usize, usize)| {
        let (leaf, density) = (LEAF_SCALES[leaf], DENSITY_SCALES[density]);
        with_foliage(
            tree,
            looks.leaf_length * leaf,
            looks.leaf_width * leaf,
            looks.leaves_per_metre * density,
        )
    };
    let mut scores: std::collections::HashMap<(usize, usize), f64> = Default::default();
    let mut rate = |at: (usize, usize)| -> f64 {
        *scores.entry(at).or_insert_with(|| {
            if at == OWN {
                score(tree)
            } else {
                score(&scaled(at))
            }
        })
    };
    let before = rate(OWN);
    let index_of = |scales: &[f32], v: f32| scales.iter().position(|&s| s == v);
    let first = start
        .and_then(|f| {
            Some((
                index_of(&LEAF_SCALES, f.leaf_scale)?,
                index_of(&DENSITY_SCALES, f.density_scale)?,
            ))
        })
        .unwrap_or(OWN);
    let (mut at, mut best) = (first, rate(first));
    loop {
        let mut moved = false;
        for axis in 0..2 {
            let len = [LEAF_SCALES.len(), DENSITY_SCALES.len()][axis];
            for step in [1i64, -1] {
                loop {
                    let mut next = [at.0, at.1];
                    let k = next[axis] as i64 + step;
                    if k < 0 || k >= len as i64 {
                        break;
                    }
                    next[axis] = k as usize;
                    let next = (next[0], next[1]);
                    let iou = rate(next);
                    if iou > best {
                        (at, best, moved) = (next, iou, true);
                    } else {
                        break;
                    }
                }
            }
        }
        if !moved {
            break;
        }
    }
    let fit = FoliageFit {
        leaf_scale: LEAF_SCALES[at.0],
        density_scale: DENSITY_SCALES[at.1],
        trim_voxels: 0,
        trim_iou: Vec::new(),
        iou_before: before,
        iou_after: best,
    };
    (scaled(at), fit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    /// A score peaked at one leaf size and density of the scales (concave along each).
    fn peaked(own: &sylva_core::geometry::Looks, leaf: f32, density: f32) -> impl Fn(&Tree) -> f64 {
        let (length, per_metre) = (own.leaf_length, own.leaves_per_metre);
        move |t: &Tree| {
            let l = t.species.looks();
            let a = (l.leaf_length / (length * leaf)).ln();
            let b = (l.leaves_per_metre / (per_metre * density)).ln();
            1.0 - f64::from(a * a + b * b)
        }
    }

    #[test]
    fn the_descent_finds_the_peak_and_a_warm_start_there_needs_few_scores() {
        let tree = Tree::new(sylva_core::species::Species::presets().remove(0), 3);
        let score = peaked(tree.species.looks(), 0.63, 6.4);
        let calls = Cell::new(0);
        let counted = |t: &Tree| {
            calls.set(calls.get() + 1);
            score(t)
        };
        let (_, cold) = fit_foliage(&tree, &counted);
        assert_eq!((cold.leaf_scale, cold.density_scale), (0.63, 6.4));
        let cold_calls = calls.replace(0);
        let (fitted, warm) = fit_foliage_from(&tree, &counted, Some(&cold));
        assert_eq!((warm.leaf_scale, warm.density_scale), (0.63, 6.4));
        assert_eq!(warm.iou_before, cold.iou_before);
        assert!((score(&fitted) - warm.iou_after).abs() < 1e-12);
        // The species' own, the start and its four neighbours.
        assert_eq!(calls.get(), 6, "{cold_calls} scores cold");
        assert!(calls.get() < cold_calls);
    }
}
