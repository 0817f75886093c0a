//! Convex polygons in plan (on the ground, seen from above) for the solids on the ground: the
//! hull of a group's footprints, widened when it is a sliver, shrunk by the points' noise and
//! cut by half-planes where the free space seen along rays passes through it.
//!
//! Every polygon here is convex and counter-clockwise; every operation keeps it so.

use glam::Vec2;

/// Counter-clockwise convex hull (Andrew's monotone chain); collinear points dropped.
pub(crate) fn convex_hull(mut points: Vec<Vec2>) -> Vec<Vec2> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let cross = |o: Vec2, a: Vec2, b: Vec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vec2>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The hull, widened to `min_width` across when it is thinner (a segment or a sliver);
/// `None` for a single point.
pub(crate) fn widened(hull: Vec<Vec2>, min_width: f32) -> Option<Vec<Vec2>> {
    let (first, last) = (*hull.first()?, *hull.last()?);
    // The longest chord from the first vertex gives the hull's direction.
    let far = hull
        .iter()
        .copied()
        .max_by(|a, b| {
            a.distance_squared(first)
                .total_cmp(&b.distance_squared(first))
        })
        .unwrap_or(last);
    let along = (far - first).try_normalize()?;
    let across = along.perp();
    let (lo, hi) = hull.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
        let d = (*p - first).dot(across);
        (lo.min(d), hi.max(d))
    });
    if hull.len() >= 3 && hi - lo >= min_width {
        return Some(hull);
    }
    let (a_lo, a_hi) = hull.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
        let d = (*p - first).dot(along);
        (lo.min(d), hi.max(d))
    });
    let mid = 0.5 * (lo + hi);
    let half = 0.5 * min_width;
    let corner = |a: f32, c: f32| first + along * a + across * c;
    Some(vec![
        corner(a_lo, mid - half),
        corner(a_hi, mid - half),
        corner(a_hi, mid + half),
        corner(a_lo, mid + half),
    ])
}

/// Area of a counter-clockwise polygon (negative when clockwise).
pub(crate) fn area(polygon: &[Vec2]) -> f32 {
    (0..polygon.len())
        .map(|i| polygon[i].perp_dot(polygon[(i + 1) % polygon.len()]))
        .sum::<f32>()
        * 0.5
}

/// The part of a convex polygon where `normal · p <= offset` (Sutherland–Hodgman, one plane).
pub(crate) fn clipped(polygon: &[Vec2], normal: Vec2, offset: f32) -> Vec<Vec2> {
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for i in 0..polygon.len() {
        let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
        let (da, db) = (normal.dot(a) - offset, normal.dot(b) - offset);
        if da <= 0.0 {
            out.push(a);
        }
        if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// The convex polygon with every edge moved inwards by `distance` (empty when it vanishes).
pub(crate) fn shrunk(polygon: &[Vec2], distance: f32) -> Vec<Vec2> {
    if distance <= 0.0 || polygon.len() < 3 {
        return polygon.to_vec();
    }
    let mut out = polygon.to_vec();
    for i in 0..polygon.len() {
        let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
        // Outward normal of a counter-clockwise edge.
        let Some(outward) = (b - a).perp().try_normalize().map(|n| -n) else {
            continue;
        };
        out = clipped(&out, outward, outward.dot(a) - distance);
        if out.len() < 3 {
            return Vec::new();
        }
    }
    out
}

/// The parameters `[t0, t1]` (within 0..=1) of the segment `a + t (b - a)` inside a convex
/// counter-clockwise polygon (Cyrus–Beck), `None` if it misses it.
pub(crate) fn segment_inside(polygon: &[Vec2], a: Vec2, b: Vec2) -> Option<(f32, f32)> {
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    let d = b - a;
    for i in 0..polygon.len() {
        let (p, q) = (polygon[i], polygon[(i + 1) % polygon.len()]);
        // Inside is left of p→q: (q - p) × (x - p) >= 0.
        let edge = q - p;
        let start = edge.perp_dot(a - p);
        let rate = edge.perp_dot(d);
        if rate.abs() < 1e-12 {
            if start < 0.0 {
                return None;
            }
            continue;
        }
        let t = -start / rate;
        if rate > 0.0 {
            t0 = t0.max(t);
        } else {
            t1 = t1.min(t);
        }
        if t0 > t1 {
            return None;
        }
    }
    Some((t0, t1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Vec<Vec2> {
        vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ]
    }

    #[test]
    fn points_in_one_vertical_line_make_a_thin_wall_not_nothing() {
        let hull = widened(
            convex_hull(vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.5, 0.0),
            ]),
            0.04,
        )
        .expect("a segment widens");
        assert_eq!(hull.len(), 4);
        let width = hull.iter().map(|p| p.y).fold(f32::MIN, f32::max)
            - hull.iter().map(|p| p.y).fold(f32::MAX, f32::min);
        assert!((width - 0.04).abs() < 1e-6, "width {width}");
    }

    #[test]
    fn a_square_shrunk_by_a_tenth_loses_a_tenth_on_every_side() {
        let inner = shrunk(&square(), 0.1);
        assert!((area(&inner) - 0.64).abs() < 1e-5, "area {}", area(&inner));
        assert!(
            inner
                .iter()
                .all(|p| p.min_element() > 0.099 && p.max_element() < 0.901)
        );
        assert!(shrunk(&square(), 0.6).is_empty(), "shrunk past its middle");
    }

    #[test]
    fn a_half_plane_cuts_a_square_into_a_convex_part() {
        // Keep x + y <= 1: the lower-left triangle.
        let part = clipped(&square(), Vec2::new(1.0, 1.0), 1.0);
        assert!((area(&part) - 0.5).abs() < 1e-6, "area {}", area(&part));
        assert!(clipped(&square(), Vec2::X, -0.5).is_empty());
    }

    #[test]
    fn a_segment_through_a_square_is_inside_between_its_crossings() {
        let (t0, t1) =
            segment_inside(&square(), Vec2::new(-1.0, 0.5), Vec2::new(3.0, 0.5)).expect("crosses");
        assert!(
            (t0 - 0.25).abs() < 1e-6 && (t1 - 0.5).abs() < 1e-6,
            "{t0} {t1}"
        );
        assert!(segment_inside(&square(), Vec2::new(-1.0, 2.0), Vec2::new(3.0, 2.0)).is_none());
    }
}
