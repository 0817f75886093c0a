//! The grammar tree's primitives (capsules of wood, spheres of foliage) and a bounding volume
//! hierarchy over them, so a ray costs a few box tests instead of one test per primitive, and
//! rays that miss the tree cost one box test.

use glam::Vec3;

use super::tree::TreePart;

/// One primitive of the tree.
#[derive(Clone, Copy, Debug)]
pub enum Primitive {
    /// The segment `a → b` swept by a ball of `radius_m`.
    Capsule {
        a: Vec3,
        b: Vec3,
        radius_m: f32,
    },
    Sphere {
        centre: Vec3,
        radius_m: f32,
    },
}

/// A ray's hit on the tree.
#[derive(Clone, Copy, Debug)]
pub struct TreeHit {
    pub distance: f32,
    pub normal: Vec3,
    pub part: TreePart,
    /// Surface coordinates in metres for texturing: (around, along) on wood, (longitude · r,
    /// latitude · r) on foliage.
    pub surface_m: glam::Vec2,
    /// Index of the primitive, to vary texture per primitive.
    pub primitive: u32,
}

impl Primitive {
    pub fn capsule(a: Vec3, b: Vec3, radius_m: f32) -> Self {
        Self::Capsule { a, b, radius_m }
    }

    pub fn sphere(centre: Vec3, radius_m: f32) -> Self {
        Self::Sphere { centre, radius_m }
    }

    /// The primitive with every position's X scaled by `factor` (radii kept).
    pub fn squashed_x(self, factor: f32) -> Self {
        let s = |p: Vec3| Vec3::new(p.x * factor, p.y, p.z);
        match self {
            Self::Capsule { a, b, radius_m } => Self::Capsule {
                a: s(a),
                b: s(b),
                radius_m,
            },
            Self::Sphere { centre, radius_m } => Self::Sphere {
                centre: s(centre),
                radius_m,
            },
        }
    }

    pub fn part(&self) -> TreePart {
        match self {
            Self::Capsule { .. } => TreePart::Wood,
            Self::Sphere { .. } => TreePart::Foliage,
        }
    }

    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match *self {
            Self::Capsule { a, b, radius_m } => (
                a.min(b) - Vec3::splat(radius_m),
                a.max(b) + Vec3::splat(radius_m),
            ),
            Self::Sphere { centre, radius_m } => (
                centre - Vec3::splat(radius_m),
                centre + Vec3::splat(radius_m),
            ),
        }
    }

    /// Projection onto the unit `axis`: (centre of the projected interval, half its length).
    pub fn extent_along(&self, axis: Vec3) -> (f32, f32) {
        match *self {
            Self::Capsule { a, b, radius_m } => {
                let (pa, pb) = (a.dot(axis), b.dot(axis));
                (0.5 * (pa + pb), 0.5 * (pa - pb).abs() + radius_m)
            }
            Self::Sphere { centre, radius_m } => (centre.dot(axis), radius_m),
        }
    }

    fn intersect(
        &self,
        origin: Vec3,
        direction: Vec3,
        limit: f32,
    ) -> Option<(f32, Vec3, glam::Vec2)> {
        match *self {
            Self::Sphere { centre, radius_m } => {
                let t = ray_sphere(origin, direction, centre, radius_m, limit)?;
                let normal = (origin + direction * t - centre) / radius_m;
                let longitude = normal.z.atan2(normal.x);
                let latitude = normal.y.clamp(-1.0, 1.0).asin();
                Some((t, normal, glam::Vec2::new(longitude, latitude) * radius_m))
            }
            Self::Capsule { a, b, radius_m } => {
                let (t, normal, along) = ray_capsule(origin, direction, a, b, radius_m, limit)?;
                let axis = (b - a).try_normalize().unwrap_or(Vec3::Y);
                let reference = axis.any_orthonormal_vector();
                let side = axis.cross(reference);
                let around = normal.dot(side).atan2(normal.dot(reference)) * radius_m;
                Some((t, normal, glam::Vec2::new(around, along)))
            }
        }
    }
}

/// Nearest positive root of |o + t d − c| = r below `limit` (d unit).
fn ray_sphere(origin: Vec3, direction: Vec3, centre: Vec3, radius: f32, limit: f32) -> Option<f32> {
    let oc = origin - centre;
    let b = oc.dot(direction);
    let c = oc.length_squared() - radius * radius;
    let h = b * b - c;
    if h < 0.0 {
        return None;
    }
    let h = h.sqrt();
    let t = if -b - h > 1e-4 { -b - h } else { -b + h };
    (t > 1e-4 && t < limit).then_some(t)
}

/// Ray against a capsule (Quílez's closed form): distance, outward normal, and the distance
/// along the axis from `a` at the hit (metres).
fn ray_capsule(
    origin: Vec3,
    direction: Vec3,
    a: Vec3,
    b: Vec3,
    radius: f32,
    limit: f32,
) -> Option<(f32, Vec3, f32)> {
    let ba = b - a;
    let oa = origin - a;
    let baba = ba.dot(ba);
    let bard = ba.dot(direction);
    let baoa = ba.dot(oa);
    let rdoa = direction.dot(oa);
    let oaoa = oa.dot(oa);
    let qa = baba - bard * bard;
    let qb = baba * rdoa - baoa * bard;
    let qc = baba * oaoa - baoa * baoa - radius * radius * baba;
    let mut t = None;
    if qa > 1e-12 {
        let h = qb * qb - qa * qc;
        if h >= 0.0 {
            let candidate = (-qb - h.sqrt()) / qa;
            let y = baoa + candidate * bard;
            if y > 0.0 && y < baba && candidate > 1e-4 {
                t = Some(candidate);
            }
        }
    }
    if t.is_none() {
        // The caps: the nearer of the two end balls.
        t = [a, b]
            .into_iter()
            .filter_map(|c| ray_sphere(origin, direction, c, radius, limit))
            .reduce(f32::min);
    }
    let t = t.filter(|&t| t < limit)?;
    let p = origin + direction * t;
    let along = ((p - a).dot(ba) / baba.max(1e-12)).clamp(0.0, 1.0);
    let on_axis = a + ba * along;
    let normal = (p - on_axis).try_normalize().unwrap_or(Vec3::Y);
    Some((t, normal, along * baba.sqrt()))
}

#[derive(Clone, Copy, Debug)]
struct Node {
    min: Vec3,
    max: Vec3,
    /// Leaf: first primitive and count; inner: index of the left child (right = left + 1).
    first: u32,
    count: u32,
}

/// A bounding volume hierarchy (median splits along the longest axis, leaves of up to 4).
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    primitives: Vec<Primitive>,
    /// Index of each sorted primitive in the order it was given.
    order: Vec<u32>,
}

const LEAF_SIZE: usize = 4;

fn slab(origin: Vec3, inverse: Vec3, min: Vec3, max: Vec3, limit: f32) -> Option<f32> {
    let t0 = (min - origin) * inverse;
    let t1 = (max - origin) * inverse;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element().min(limit);
    (near <= far).then_some(near)
}

impl Bvh {
    pub fn build(primitives: Vec<Primitive>) -> Self {
        let mut items: Vec<(u32, Primitive)> = primitives
            .into_iter()
            .enumerate()
            .map(|(i, p)| (i as u32, p))
            .collect();
        let mut nodes = vec![Node {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
            first: 0,
            count: 0,
        }];
        if !items.is_empty() {
            Self::split(&mut nodes, 0, &mut items, 0);
        }
        Self {
            nodes,
            order: items.iter().map(|(i, _)| *i).collect(),
            primitives: items.into_iter().map(|(_, p)| p).collect(),
        }
    }

    fn split(nodes: &mut Vec<Node>, node: usize, items: &mut [(u32, Primitive)], first: usize) {
        let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for (_, p) in items.iter() {
            let (lo, hi) = p.bounds();
            min = min.min(lo);
            max = max.max(hi);
        }
        nodes[node].min = min;
        nodes[node].max = max;
        if items.len() <= LEAF_SIZE {
            nodes[node].first = first as u32;
            nodes[node].count = items.len() as u32;
            return;
        }
        let size = max - min;
        let axis = if size.x >= size.y && size.x >= size.z {
            0
        } else if size.y >= size.z {
            1
        } else {
            2
        };
        let centre = |p: &Primitive| {
            let (lo, hi) = p.bounds();
            (lo + hi)[axis]
        };
        items.sort_by(|x, y| centre(&x.1).total_cmp(&centre(&y.1)));
        let left = nodes.len();
        let blank = Node {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
            first: 0,
            count: 0,
        };
        nodes.push(blank);
        nodes.push(blank);
        nodes[node].first = left as u32;
        nodes[node].count = 0;
        let half = items.len() / 2;
        let (low, high) = items.split_at_mut(half);
        Self::split(nodes, left, low, first);
        Self::split(nodes, left + 1, high, first + half);
    }

    /// The primitives (in the hierarchy's order).
    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }

    /// Bounds of the whole tree.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.nodes[0].min, self.nodes[0].max)
    }

    /// Nearest hit along `origin + t·direction` (unit) for `t` in `(0, limit)`.
    pub fn intersect(&self, origin: Vec3, direction: Vec3, limit: f32) -> Option<TreeHit> {
        if self.primitives.is_empty() {
            return None;
        }
        let inverse = direction.recip();
        let mut best: Option<TreeHit> = None;
        let mut limit = limit;
        let mut stack = [0u32; 64];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let node = self.nodes[stack[depth] as usize];
            if slab(origin, inverse, node.min, node.max, limit).is_none() {
                continue;
            }
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for index in range {
                    let primitive = &self.primitives[index];
                    if let Some((t, normal, surface_m)) =
                        primitive.intersect(origin, direction, limit)
                    {
                        limit = t;
                        best = Some(TreeHit {
                            distance: t,
                            normal,
                            part: primitive.part(),
                            surface_m,
                            primitive: self.order[index],
                        });
                    }
                }
            } else if depth + 2 <= stack.len() {
                stack[depth] = node.first;
                stack[depth + 1] = node.first + 1;
                depth += 2;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hierarchy_finds_the_same_nearest_hit_as_testing_every_primitive() {
        let mut rng = crate::synthetic::rng::SplitMix64::new(5);
        let mut primitives = Vec::new();
        for i in 0..200 {
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0;
            if i % 2 == 0 {
                primitives.push(Primitive::sphere(c, 0.1 + 0.2 * rng.next_f32()));
            } else {
                let d = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
                primitives.push(Primitive::capsule(c, c + d, 0.05));
            }
        }
        let bvh = Bvh::build(primitives.clone());
        for _ in 0..500 {
            let origin = Vec3::new(rng.next_f32() * 4.0, rng.next_f32() * 4.0, -3.0);
            let direction = (Vec3::new(rng.next_f32(), rng.next_f32(), 1.0)
                - Vec3::new(0.5, 0.5, 0.0))
            .normalize();
            let brute = primitives
                .iter()
                .filter_map(|p| p.intersect(origin, direction, 100.0).map(|h| h.0))
                .fold(f32::INFINITY, f32::min);
            let fast = bvh
                .intersect(origin, direction, 100.0)
                .map_or(f32::INFINITY, |h| h.distance);
            assert!(
                (brute - fast).abs() < 1e-5 || (brute.is_infinite() && fast.is_infinite()),
                "brute {brute} vs hierarchy {fast}"
            );
        }
    }

    #[test]
    fn a_ray_across_a_capsule_hits_its_side_at_the_radius() {
        let capsule = Primitive::capsule(Vec3::ZERO, Vec3::Y, 0.1);
        let (t, normal, along) = capsule
            .intersect(Vec3::new(0.0, 0.5, -2.0), Vec3::Z, 10.0)
            .expect("hit");
        assert!((t - 1.9).abs() < 1e-5 && (normal + Vec3::Z).length() < 1e-4);
        assert!((along.y - 0.5).abs() < 1e-5);
    }
}
