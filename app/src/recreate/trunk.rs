//! The real trunk found in the footage, below the crown: where it stands and how thick it is.
//! The tapped base fixes the trunk only along the tap's ray up to the ground plane's error, which
//! a grazing ray magnifies (a few centimetres of height are a decimetre of depth); and the grown
//! model's trunk is as thick as its pipe model makes it, not as thick as the real one.
//!
//! In each of a few frames the trunk's axis (the vertical from the base to the crown base) is
//! projected, and across it, row by row, every pixel votes trunk or background by two colour
//! models: the trunk's (the pixels on the axis just above the tap, in the tapped frame, where
//! the axis is the tap's own) and the background's (pixels beside the axis, well past any trunk,
//! in the same frame). The run of offsets across the axis that most rows call trunk (the
//! largest sum of votes) is the trunk in that view: its centre is the trunk's offset from the
//! projected axis, its length its width. The offsets of all views, each along its view's
//! across direction, give the base's move on the ground by least squares (views that disagree
//! left out); the widths' median, in metres at the trunk's depth, is its diameter.

use glam::{DVec2, DVec3};

use super::footage::TrackedFootage;
use super::segment::{ColourModel, FrameSource};

/// What the footage shows of the trunk.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TrunkFound {
    /// The trunk base where the views see the trunk (world, metres).
    pub base: [f64; 3],
    /// How far that is from the tapped base (m).
    pub shift_m: f64,
    /// The trunk's diameter below the crown (m): the median over the views.
    pub diameter_m: f64,
    /// Views the trunk was found in, and of them those that agree on the base.
    pub views: usize,
    pub agreeing_views: usize,
}

/// Heights sampled on the axis, between these fractions of the crown base.
const ROWS: usize = 16;
const LOW: f64 = 0.15;
const HIGH: f64 = 0.85;
/// The trunk is looked for this far either side of the projected axis (m).
const SEARCH_M: f64 = 0.35;
/// The background's colours: this far beside the axis (m).
const BACKGROUND_M: (f64, f64) = (0.45, 0.8);
/// The trunk's colours: pixels this close to the axis in the tapped frame (m, at least 1 px).
const CORE_M: f64 = 0.02;
/// A view's trunk: a run of offsets whose mean vote (+1 trunk, −1 background, over the rows)
/// is at least this.
const MIN_MEAN_VOTE: f64 = 0.4;
/// At least this many rows of a view must lie in the image.
const MIN_ROWS: usize = ROWS / 2;
/// A view agrees on the base when its offset is within this (m) or three median residuals.
const AGREE_M: f64 = 0.03;
/// The base moves at most this far (m); a larger move means the trunk was not found.
const MAX_SHIFT_M: f64 = 0.5;
/// At most this many looks, each from the last one's base, until the base moves less than this (m).
const LOOKS: usize = 5;
const CONVERGED_M: f64 = 0.005;
/// The base's move is pulled toward none by this weight (views count one each).
const PRIOR_WEIGHT: f64 = 0.5;

/// One view's look across the axis: per row, the axis pixel and the image step of one pixel
/// across (along the view's horizontal across direction), and the pixels per metre there.
struct ViewRows {
    across: DVec3,
    rows: Vec<(DVec2, DVec2, f64)>,
}

fn view_rows(
    footage: &TrackedFootage,
    frame: usize,
    base: DVec3,
    crown_base_m: f64,
) -> Option<ViewRows> {
    let pose = footage.world_from_camera.get(frame).copied().flatten()?;
    let camera_from_world = pose.inverse();
    let up = footage.ground.normal.try_normalize()?;
    let along = (base - pose.translation).reject_from(up).try_normalize()?;
    let across = up.cross(along).normalize();
    let (width, height) = (footage.camera.width as f64, footage.camera.height as f64);
    let mut rows = Vec::new();
    for r in 0..ROWS {
        let h = crown_base_m * (LOW + (HIGH - LOW) * r as f64 / (ROWS - 1) as f64);
        let p = base + up * h;
        let Some((axis, _)) = footage.pixel_and_depth(&camera_from_world, p) else {
            continue;
        };
        let Some((side, _)) = footage.pixel_and_depth(&camera_from_world, p + across * 0.01) else {
            continue;
        };
        let per_metre = (side - axis).length() * 100.0;
        let Some(step) = (side - axis).try_normalize() else {
            continue;
        };
        let reach = BACKGROUND_M.1 * per_metre;
        let inside = |q: DVec2| q.x >= 0.0 && q.y >= 0.0 && q.x < width && q.y < height;
        if per_metre > 0.0 && inside(axis + step * reach) && inside(axis - step * reach) {
            rows.push((axis, step, per_metre));
        }
    }
    (rows.len() >= MIN_ROWS).then_some(ViewRows { across, rows })
}

fn pixel_at(image: &image::RgbImage, q: DVec2) -> Option<image::Rgb<u8>> {
    let (x, y) = (q.x.round(), q.y.round());
    (x >= 0.0 && y >= 0.0 && x < image.width() as f64 && y < image.height() as f64)
        .then(|| *image.get_pixel(x as u32, y as u32))
}

/// Pixels of `view` at `offset_px` across the axis, for offsets `(lo, hi)` in metres.
fn band(image: &image::RgbImage, view: &ViewRows, (lo, hi): (f64, f64)) -> Vec<image::Rgb<u8>> {
    let mut out = Vec::new();
    for &(axis, step, per_metre) in &view.rows {
        let (a, b) = (
            (lo * per_metre).round() as i64,
            (hi * per_metre).round() as i64,
        );
        for k in a..=b.max(a) {
            for side in [-1.0, 1.0] {
                if k == 0 && side > 0.0 {
                    continue;
                }
                if let Some(p) = pixel_at(image, axis + step * (side * k as f64)) {
                    out.push(p);
                }
            }
        }
    }
    out
}

/// The trunk in one view: (offset of its centre along the view's across direction, width), m.
fn trunk_in_view(
    image: &image::RgbImage,
    view: &ViewRows,
    trunk: &ColourModel,
) -> Option<(f64, f64)> {
    let background = ColourModel::of_samples(band(image, view, BACKGROUND_M).into_iter())?;
    let per_metre = view.rows.iter().map(|r| r.2).sum::<f64>() / view.rows.len() as f64;
    let reach = (SEARCH_M * per_metre).round() as i64;
    if reach < 2 {
        return None;
    }
    // Votes per offset across the axis (pixels), summed over the rows.
    let mut votes = vec![0.0f64; (2 * reach + 1) as usize];
    for &(axis, step, _) in &view.rows {
        for k in -reach..=reach {
            if let Some(p) = pixel_at(image, axis + step * k as f64) {
                let vote = if trunk.at(&p) > background.at(&p) {
                    1.0
                } else {
                    -1.0
                };
                votes[(k + reach) as usize] += vote;
            }
        }
    }
    // The run with the largest sum (Kadane).
    let (mut best, mut best_run) = (0.0, None);
    let (mut sum, mut start) = (0.0, 0usize);
    for (i, v) in votes.iter().enumerate() {
        if sum <= 0.0 {
            (sum, start) = (0.0, i);
        }
        sum += v;
        if sum > best {
            (best, best_run) = (sum, Some((start, i)));
        }
    }
    let (lo, hi) = best_run?;
    let length = hi - lo + 1;
    let mean_vote = best / (length as f64 * view.rows.len() as f64);
    // The whole search band (or the run touching its ends) is not a trunk standing out.
    if mean_vote < MIN_MEAN_VOTE || lo == 0 || hi + 1 == votes.len() {
        return None;
    }
    let centre_px = 0.5 * (lo + hi) as f64 - reach as f64;
    Some((centre_px / per_metre, length as f64 / per_metre))
}

/// Finds the trunk below the crown base in `frames` of the footage (their images from
/// `images`), the tapped base `base` in `tap_frame`. None when the tapped frame does not show it
/// (no colour model of it) or fewer than two views do.
pub fn find_trunk(
    footage: &TrackedFootage,
    base: DVec3,
    tap_frame: usize,
    crown_base_m: f64,
    frames: &[usize],
    images: FrameSource,
) -> Option<TrunkFound> {
    if crown_base_m <= 0.0 {
        return None;
    }
    let tapped = images(tap_frame)?;
    let tap_view = view_rows(footage, tap_frame, base, crown_base_m)?;
    let core = tap_view
        .rows
        .iter()
        .map(|r| r.2)
        .fold(f64::INFINITY, f64::min)
        .recip()
        .max(CORE_M);
    let trunk = ColourModel::of_samples(band(&tapped, &tap_view, (0.0, core)).into_iter())?;
    let loaded: Vec<(usize, image::RgbImage)> = {
        use rayon::prelude::*;
        frames
            .par_iter()
            .filter_map(|&f| images(f).map(|image| (f, image)))
            .collect()
    };
    let up = footage.ground.normal.try_normalize()?;
    let e1 = up.any_orthonormal_vector();
    let e2 = up.cross(e1);
    let mut moved = base;
    let mut found = None;
    // The offsets are linear near the axis only: each look starts from the last move, until the
    // move is small.
    for _ in 0..LOOKS {
        let seen: Vec<(DVec3, f64, f64)> = loaded
            .iter()
            .filter_map(|(f, image)| {
                let view = view_rows(footage, *f, moved, crown_base_m)?;
                let (offset, width) = trunk_in_view(image, &view, &trunk)?;
                Some((view.across, offset, width))
            })
            .collect();
        if seen.len() < 2 {
            return None;
        }
        // Least squares for the move d on the ground: d · across_v = offset_v, pulled to none.
        let solve = |views: &[&(DVec3, f64, f64)]| {
            let (mut a11, mut a12, mut a22) = (PRIOR_WEIGHT, 0.0, PRIOR_WEIGHT);
            let (mut b1, mut b2) = (0.0, 0.0);
            for (across, offset, _) in views {
                let (u, v) = (across.dot(e1), across.dot(e2));
                a11 += u * u;
                a12 += u * v;
                a22 += v * v;
                b1 += u * offset;
                b2 += v * offset;
            }
            let det = a11 * a22 - a12 * a12;
            let x = (a22 * b1 - a12 * b2) / det;
            let y = (a11 * b2 - a12 * b1) / det;
            e1 * x + e2 * y
        };
        let all: Vec<&(DVec3, f64, f64)> = seen.iter().collect();
        let first = solve(&all);
        let mut residuals: Vec<f64> = seen
            .iter()
            .map(|(across, offset, _)| (first.dot(*across) - offset).abs())
            .collect();
        residuals.sort_by(f64::total_cmp);
        let tolerance = (3.0 * residuals[residuals.len() / 2]).max(AGREE_M);
        let agreeing: Vec<&(DVec3, f64, f64)> = seen
            .iter()
            .filter(|(across, offset, _)| (first.dot(*across) - offset).abs() <= tolerance)
            .collect();
        if agreeing.len() < 2 {
            return None;
        }
        let step = solve(&agreeing);
        let mut widths: Vec<f64> = agreeing.iter().map(|v| v.2).collect();
        widths.sort_by(f64::total_cmp);
        let next = moved + step;
        if next.distance(base) > MAX_SHIFT_M {
            return None;
        }
        moved = next;
        let converged = step.length() < CONVERGED_M;
        found = Some(TrunkFound {
            base: moved.to_array(),
            shift_m: moved.distance(base),
            diameter_m: widths[widths.len() / 2],
            views: seen.len(),
            agreeing_views: agreeing.len(),
        });
        if converged {
            break;
        }
    }
    found
}

/// The tree's trunk made as thick as `diameter_m` at `height_m` (tree space, Y up) by scaling
/// the species' tip diameter: the pipe model scales every width with it, so the branches keep
/// their proportions to the trunk, and the tree regrows with it. A ratio outside 1/4 to 4 is
/// clamped there. Returns the ratio applied.
pub fn fit_trunk_diameter(tree: &mut sylva_core::Tree, diameter_m: f64, height_m: f32) -> f32 {
    let nodes = &tree.skeleton.internodes;
    let mut node = 0;
    while node < nodes.len() && nodes[node].end.y < height_m {
        let Some(next) = nodes[node].main_child else {
            break;
        };
        node = next.index();
    }
    let Some(model) = nodes.get(node).map(|n| n.diameter) else {
        return 1.0;
    };
    if model <= 0.0 || diameter_m <= 0.0 {
        return 1.0;
    }
    let ratio = (diameter_m as f32 / model).clamp(0.25, 4.0);
    tree.species.tip_diameter_m = (tree.species.tip_diameter_m * ratio).clamp(1e-4, 1.0);
    tree.update_widths();
    ratio
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bark_strip_beside_the_projected_axis_is_found_with_its_offset_and_width() {
        // Grass, speckled; a bark strip 13 px wide at x = 100..=112; the axis projected at x = 95.
        let image = image::RgbImage::from_fn(200, 120, |x, y| {
            let n = ((x * 7 + y * 13) % 9) as u8;
            if (100..=112).contains(&x) {
                image::Rgb([110 + n, 90 + n, 70 + n])
            } else {
                image::Rgb([60 + n, 140 + 2 * n, 40 + n])
            }
        });
        // 100 px per metre across, rows down the image.
        let view = ViewRows {
            across: DVec3::X,
            rows: (0..ROWS)
                .map(|r| (DVec2::new(95.0, 10.0 + 6.0 * r as f64), DVec2::X, 100.0))
                .collect(),
        };
        let bark: Vec<image::Rgb<u8>> = (0..120)
            .flat_map(|y| (103..110).map(move |x| (x, y)))
            .map(|(x, y)| *image.get_pixel(x, y))
            .collect();
        let trunk = ColourModel::of_samples(bark.into_iter()).expect("bark colours");
        let (offset, width) = trunk_in_view(&image, &view, &trunk).expect("the strip");
        assert!((offset - 0.11).abs() < 0.011, "offset {offset} m");
        assert!((width - 0.13).abs() < 0.011, "width {width} m");
    }

    #[test]
    fn without_a_strip_no_trunk_is_found() {
        let image = image::RgbImage::from_fn(200, 120, |x, y| {
            let n = ((x * 7 + y * 13) % 9) as u8;
            image::Rgb([60 + n, 140 + 2 * n, 40 + n])
        });
        let view = ViewRows {
            across: DVec3::X,
            rows: (0..ROWS)
                .map(|r| (DVec2::new(95.0, 10.0 + 6.0 * r as f64), DVec2::X, 100.0))
                .collect(),
        };
        let bark = (0..50).map(|i| image::Rgb([110 + (i % 9) as u8, 90, 70]));
        let trunk = ColourModel::of_samples(bark).expect("bark colours");
        assert!(trunk_in_view(&image, &view, &trunk).is_none());
    }

    #[test]
    fn the_fitted_trunk_has_the_measured_diameter_and_the_twigs_keep_their_proportion() {
        let species = sylva_core::species::Species::by_name("birch").expect("birch preset");
        let mut tree = sylva_core::Tree::new(species, 4);
        tree.grow_years(6.0);
        let before = tree.trunk_diameter_at(0.5).expect("a trunk at 0.5 m");
        let ratio = fit_trunk_diameter(&mut tree, 2.0 * before as f64, 0.5);
        let after = tree.trunk_diameter_at(0.5).expect("a trunk at 0.5 m");
        assert!((ratio - 2.0).abs() < 1e-3, "ratio {ratio}");
        assert!(
            (after / before - 2.0).abs() < 1e-3,
            "{before} m -> {after} m"
        );
        assert!(tree.sanity_check().is_ok());
    }
}
