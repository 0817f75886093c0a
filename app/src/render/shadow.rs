//! The sun's shadow: the orthographic view of the tree's bounding sphere that the shadow map is
//! drawn from, and the part of the ground where that shadow can fall (the only part the AR view's
//! shadow catcher needs to draw: elsewhere it adds nothing).

use glam::{Mat4, Vec3, Vec4};

/// The shadow map's half width as a share of the tree's bounding radius.
const MAP_MARGIN: f32 = 1.05;

/// Orthographic view of the tree's bounding sphere from the sun (depth 0..1).
pub fn sun_clip_from_world(sun: Vec3, centre: Vec3, radius: f32) -> Mat4 {
    let eye = centre + sun * radius * 2.0;
    let (s, u) = sun_axes(sun);
    let f = -sun;
    let view = Mat4::from_cols(
        Vec4::new(s.x, u.x, -f.x, 0.0),
        Vec4::new(s.y, u.y, -f.y, 0.0),
        Vec4::new(s.z, u.z, -f.z, 0.0),
        Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    );
    orthographic(radius * MAP_MARGIN, radius * 0.5, radius * 4.0) * view
}

/// The shadow map's right and up axes for unit `sun` (a right-handed view looking along −sun).
fn sun_axes(sun: Vec3) -> (Vec3, Vec3) {
    let up = if sun.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let f = (-sun).normalize_or(Vec3::NEG_Y);
    let s = f.cross(up).normalize_or(Vec3::X);
    (s, s.cross(f))
}

/// Orthographic projection of the box |x|, |y| ≤ `half` between `near` and `far` in front of
/// the view, to wgpu clip space (depth 0..1).
fn orthographic(half: f32, near: f32, far: f32) -> Mat4 {
    let depth = 1.0 / (near - far);
    Mat4::from_cols(
        Vec4::new(1.0 / half, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 1.0 / half, 0.0, 0.0),
        Vec4::new(0.0, 0.0, depth, 0.0),
        Vec4::new(0.0, 0.0, depth * near, 1.0),
    )
}

/// A parallelogram on the ground: centre and two half axes, world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundPatch {
    pub centre: Vec3,
    pub half_a: Vec3,
    pub half_b: Vec3,
}

impl GroundPatch {
    pub fn area_m2(&self) -> f32 {
        4.0 * self.half_a.cross(self.half_b).length()
    }
}

/// The ground (through `ground_point`, unit `normal`) the shadow map covers, seen along unit
/// `sun`: the sun's rays through the map's square, met with the ground. Every shadow the map
/// holds falls inside it. None when the sun is (nearly) in the ground's plane or below it.
pub fn shadow_footprint(
    sun: Vec3,
    centre: Vec3,
    radius: f32,
    ground_point: Vec3,
    normal: Vec3,
) -> Option<GroundPatch> {
    let towards_sun = normal.dot(sun);
    if towards_sun < 0.05 {
        return None;
    }
    let (s, u) = sun_axes(sun);
    // Along the sun's ray onto the ground: X − sun · n·(X − p)/n·sun.
    let onto_ground = |axis: Vec3| axis - sun * normal.dot(axis) / towards_sun;
    let half = radius * MAP_MARGIN;
    Some(GroundPatch {
        centre: centre - sun * normal.dot(centre - ground_point) / towards_sun,
        half_a: onto_ground(s) * half,
        half_b: onto_ground(u) * half,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sun_view_contains_the_tree_bounds() {
        let m = sun_clip_from_world(Vec3::new(0.3, 0.9, 0.2).normalize(), Vec3::Y, 1.0);
        for p in [
            Vec3::ZERO,
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.6, 1.0, -0.6),
        ] {
            let c = m * Vec4::from((p, 1.0));
            let n = c.truncate() / c.w;
            assert!(
                n.x.abs() <= 1.0 && n.y.abs() <= 1.0 && (0.0..=1.0).contains(&n.z),
                "{p} -> {n}"
            );
        }
    }

    #[test]
    fn the_footprint_holds_the_shadow_of_every_point_the_map_covers_and_no_more() {
        let sun = Vec3::new(0.45, 0.8, 0.35).normalize();
        let (centre, radius) = (Vec3::new(0.2, 1.5, -0.1), 1.2);
        let (point, normal) = (Vec3::new(0.0, -0.02, 0.0), Vec3::Y);
        let patch = shadow_footprint(sun, centre, radius, point, normal).expect("sun up");
        let m = sun_clip_from_world(sun, centre, radius);
        // Patch coordinates of a ground point (a, b), |a|, |b| <= 1 inside.
        let coords = |p: Vec3| {
            let d = p - patch.centre;
            let (aa, ab, bb) = (
                patch.half_a.length_squared(),
                patch.half_a.dot(patch.half_b),
                patch.half_b.length_squared(),
            );
            let (da, db) = (d.dot(patch.half_a), d.dot(patch.half_b));
            let det = aa * bb - ab * ab;
            ((da * bb - db * ab) / det, (db * aa - da * ab) / det)
        };
        for i in 0..200 {
            // Points on the ground in a 12 m square; inside the patch exactly where the map sees
            // them.
            let p = Vec3::new(
                (i % 20) as f32 * 0.6 - 6.0,
                -0.02,
                (i / 20) as f32 * 1.2 - 6.0,
            );
            let c = m * Vec4::from((p, 1.0));
            let in_map = c.x.abs() <= c.w && c.y.abs() <= c.w;
            let (a, b) = coords(p);
            let in_patch = a.abs() <= 1.0 + 1e-4 && b.abs() <= 1.0 + 1e-4;
            assert_eq!(in_map, in_patch, "{p}: map {in_map}, patch ({a}, {b})");
            assert!(normal.dot(p - point).abs() < 1e-5);
        }
        assert!(patch.area_m2() < 36.0 * radius * radius);
        assert_eq!(shadow_footprint(-sun, centre, radius, point, normal), None);
    }
}
