//! Measuring the real tree from the marks: the trunk base (the tapped pixel's ray onto the ground
//! plane), the crown's visual hull from the outlines, the tree's own points (tracked points inside
//! every outline and the hull), and the measures in metres with how each was obtained.
//!
//! * **Height** and **crown base**: in each marked view, the rays of the outline's highest and
//!   lowest points meet the trunk's vertical plane facing that camera (the plane through the
//!   trunk base across the view); the heights there, averaged over the views (the hull's top,
//!   an upper bound, caps the height).
//! * **Crown width**: a silhouette measures the crown's extent across its view: each outline's
//!   width on the trunk's plane, the largest of them. Its axes: that width, and the hull's extent
//!   across it (an upper bound: the hull is wider than the crown between the views).
//! * **One outline only**: the cone is open along the view, so the crown's depth comes from the
//!   tree's own points when enough lie in the cone near the trunk, else it is assumed round (as
//!   deep as wide); the report says which.

use glam::{DVec2, DVec3};
use serde::Serialize;

use super::footage::TrackedFootage;
use super::hull::{DepthSlab, Hull, OutlineMask};
use super::marks::{Marks, MarksError};

/// The measures and how each was obtained.
#[derive(Clone, Debug, Serialize)]
pub struct Measurements {
    /// Trunk base in the world (metres).
    pub trunk_base: [f64; 3],
    pub height_m: f64,
    pub crown_width_m: f64,
    /// Extents along the crown width's direction and across it.
    pub crown_axes_m: [f64; 2],
    pub crown_base_m: f64,
    pub num_views: usize,
    pub tree_points: usize,
    pub hull_voxels: usize,
    pub hull_voxel_m: f64,
    pub hull_top_m: f64,
    pub methods: Methods,
}

/// How each measure was obtained (sentences for the report and the screen).
#[derive(Clone, Debug, Serialize)]
pub struct Methods {
    pub trunk_base: String,
    pub height: String,
    pub crown_width: String,
    pub crown_axes: String,
    pub crown_base: String,
    /// Where the crown's depth came from with one outline (None with two or more).
    pub crown_depth: Option<String>,
}

/// Everything measured, with the hull and the points growth uses.
pub struct Recreation {
    pub measurements: Measurements,
    pub base: DVec3,
    pub hull: Hull,
    pub masks: Vec<OutlineMask>,
    pub own_points: Vec<DVec3>,
}

/// Fewer own points than this in a single view's cone do not measure the crown's depth.
const MIN_DEPTH_POINTS: usize = 20;
/// Grid cells across the hull's box along its longest side.
const HULL_CELLS: f64 = 110.0;
/// Farthest a trunk base may lie from the camera that tapped it (metres).
const MAX_BASE_DISTANCE_M: f64 = 60.0;

/// The vertical plane through `base` facing the camera of `frame`: unit horizontal directions
/// along the view and across it.
fn view_axes(footage: &TrackedFootage, frame: usize, base: DVec3) -> Option<(DVec3, DVec3)> {
    let pose = footage.world_from_camera[frame]?;
    let up = footage.ground.normal;
    let along = (base - pose.translation).reject_from(up).try_normalize()?;
    Some((along, up.cross(along).normalize()))
}

/// Where the ray of `pixel` in `frame` meets the vertical plane through `base` across the view.
fn on_trunk_plane(
    footage: &TrackedFootage,
    frame: usize,
    pixel: DVec2,
    base: DVec3,
) -> Option<DVec3> {
    let (origin, direction) = footage.ray(frame, pixel)?;
    let (along, _) = view_axes(footage, frame, base)?;
    let denominator = direction.dot(along);
    if denominator.abs() < 1e-6 {
        return None;
    }
    let t = (base - origin).dot(along) / denominator;
    (t > 0.0).then(|| origin + direction * t)
}

/// The trunk base: the tapped pixel's ray onto the ground plane.
fn trunk_base(footage: &TrackedFootage, marks: &Marks) -> Result<DVec3, MarksError> {
    let [u, v] = marks.base.pixel;
    let off_ground = || MarksError::BaseOffGround {
        mark: "base".into(),
        frame: marks.base.frame,
        u,
        v,
    };
    let (origin, direction) = footage
        .ray(marks.base.frame, DVec2::new(u, v))
        .ok_or_else(off_ground)?;
    let plane = &footage.ground;
    let along = direction.dot(plane.normal);
    // Looking down at the ground by at least half a degree.
    if along > -0.0087 {
        return Err(off_ground());
    }
    let t = -plane.signed_distance(origin) / along;
    if !(t > 0.0 && t <= MAX_BASE_DISTANCE_M) {
        return Err(off_ground());
    }
    Ok(origin + direction * t)
}

/// Checks that every marked frame was tracked.
fn check_tracked(footage: &TrackedFootage, marks: &Marks) -> Result<(), MarksError> {
    let tracked = |frame: usize| footage.world_from_camera[frame].is_some();
    if !tracked(marks.base.frame) {
        return Err(MarksError::FrameNotTracked {
            mark: "base".into(),
            frame: marks.base.frame,
        });
    }
    for (index, crown) in marks.crown.iter().enumerate() {
        if !tracked(crown.frame) {
            return Err(MarksError::FrameNotTracked {
                mark: format!("crown[{index}]"),
                frame: crown.frame,
            });
        }
    }
    Ok(())
}

/// Measures the tree (the marks already validated against the footage's size).
pub fn measure(footage: &TrackedFootage, marks: &Marks) -> Result<Recreation, MarksError> {
    check_tracked(footage, marks)?;
    let base = trunk_base(footage, marks)?;
    let (width, height) = (footage.camera.width, footage.camera.height);
    let masks: Vec<OutlineMask> = marks
        .crown
        .iter()
        .map(|c| OutlineMask::new(c.frame, c.points(), width, height))
        .collect();
    // Per view: the outline's top, bottom and half-width on the trunk's plane.
    let mut tops = Vec::new();
    let mut bottoms = Vec::new();
    let mut widths = Vec::new();
    let mut reach_m: f64 = 0.5;
    for (index, mask) in masks.iter().enumerate() {
        let on_plane: Vec<DVec3> = mask
            .outline
            .iter()
            .filter_map(|&p| on_trunk_plane(footage, mask.frame, p, base))
            .collect();
        if on_plane.len() < 3 {
            return Err(MarksError::NoArea {
                mark: format!("crown[{index}]"),
            });
        }
        let heights = on_plane.iter().map(|&p| footage.height_of(p));
        tops.push(heights.clone().fold(f64::NEG_INFINITY, f64::max));
        bottoms.push(heights.fold(f64::INFINITY, f64::min));
        let (_, across) = view_axes(footage, mask.frame, base).unwrap_or((DVec3::Z, DVec3::X));
        let lateral = on_plane.iter().map(|p| (*p - base).dot(across));
        let (left, right) = lateral
            .clone()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, r), v| {
                (l.min(v), r.max(v))
            });
        widths.push(right - left);
        for v in lateral {
            reach_m = reach_m.max(v.abs());
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let top_m = mean(&tops);
    let bottom_m = mean(&bottoms).max(0.0);
    // The hull's box: around the trunk, wider than any outline, above the tallest top.
    let half_m = 1.6 * reach_m + 0.3;
    let up = footage.ground.normal;
    let box_height_m = 1.2 * tops.iter().copied().fold(0.0, f64::max) + 0.3;
    let low = base + DVec3::new(-half_m, 0.0, -half_m) - up * 0.05;
    let high = base + DVec3::new(half_m, 0.0, half_m) + up * box_height_m;
    let voxel_m = (2.0 * half_m).max(box_height_m) / HULL_CELLS;
    let one_view = masks.len() == 1;
    let mut crown_depth = None;
    let slab = if one_view {
        let frame = masks[0].frame;
        let (along, _) = view_axes(footage, frame, base).unwrap_or((DVec3::Z, DVec3::X));
        let cone = Hull::carve(footage, &masks, None, low, high, voxel_m);
        let width_m = widths[0];
        let depths: Vec<f64> = footage
            .points
            .iter()
            .map(|p| p.world)
            .filter(|&p| {
                footage.height_of(p) >= bottom_m - 0.1
                    && ((p - base).dot(along)).abs() <= width_m
                    && cone.contains(p, 0)
            })
            .map(|p| (p - base).dot(along))
            .collect();
        let (centre, half_depth_m) = if depths.len() >= MIN_DEPTH_POINTS {
            let mut sorted = depths.clone();
            sorted.sort_by(f64::total_cmp);
            let q = |f: f64| sorted[((sorted.len() - 1) as f64 * f).round() as usize];
            let (a, b) = (q(0.05), q(0.95));
            crown_depth = Some(format!(
                "one outline: the crown's depth along the view ({:.2} m) from {} of the tree's own points",
                b - a,
                depths.len()
            ));
            (
                base + along * (0.5 * (a + b)),
                (0.5 * (b - a)).max(0.25 * width_m),
            )
        } else {
            crown_depth = Some(format!(
                "one outline: too few of the tree's own points ({}) in the cone, the crown assumed round (as deep as wide, {:.2} m)",
                depths.len(),
                width_m
            ));
            (base, 0.5 * width_m)
        };
        Some(DepthSlab {
            centre,
            axis: along,
            half_depth_m,
        })
    } else {
        None
    };
    let hull = Hull::carve(footage, &masks, slab, low, high, voxel_m);
    if hull.num_voxels() == 0 {
        return Err(MarksError::EmptyHull {
            marks: (0..masks.len())
                .map(|i| format!("crown[{i}]"))
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let hull_top_m = hull
        .voxels()
        .iter()
        .map(|&p| footage.height_of(p) + 0.5 * hull.voxel_m)
        .fold(0.0, f64::max);
    // Crown width: each outline's extent across its view on the trunk's plane, the largest.
    let (mut crown_width_m, mut width_axis) = (0.0, DVec3::X);
    for (mask, &width) in masks.iter().zip(&widths) {
        if width > crown_width_m
            && let Some((_, across)) = view_axes(footage, mask.frame, base)
        {
            (crown_width_m, width_axis) = (width, across);
        }
    }
    let across_width = up.cross(width_axis).normalize_or(DVec3::Z);
    let crown_axes_m = [crown_width_m, hull.extent_along(across_width)];
    let own_points: Vec<DVec3> = footage
        .points
        .iter()
        .map(|p| p.world)
        .filter(|&p| {
            footage.height_of(p) > 0.05
                && hull.contains(p, 1)
                && masks
                    .iter()
                    .all(|m| footage.project(m.frame, p).is_some_and(|px| m.contains(px)))
        })
        .collect();
    let height_m = top_m.min(hull_top_m);
    let n = masks.len();
    let methods = Methods {
        trunk_base: format!(
            "the ray of the tapped pixel in frame {} onto the ground plane",
            marks.base.frame
        ),
        height: if height_m < top_m {
            format!("hull: its top (below the outline tops on the trunk's plane, {top_m:.2} m)")
        } else {
            format!("outline tops on the trunk's vertical plane, mean of {n} view(s)")
        },
        crown_width: format!(
            "outline widths across the view on the trunk's vertical plane, largest of {n} view(s)"
        ),
        crown_axes: "the crown width, and the hull's extent across it (an upper bound)".into(),
        crown_base: format!("outline bottoms on the trunk's vertical plane, mean of {n} view(s)"),
        crown_depth,
    };
    Ok(Recreation {
        measurements: Measurements {
            trunk_base: base.to_array(),
            height_m,
            crown_width_m,
            crown_axes_m,
            crown_base_m: bottom_m.min(height_m),
            num_views: n,
            tree_points: own_points.len(),
            hull_voxels: hull.num_voxels(),
            hull_voxel_m: hull.voxel_m,
            hull_top_m,
            methods,
        },
        base,
        hull,
        masks,
        own_points,
    })
}
