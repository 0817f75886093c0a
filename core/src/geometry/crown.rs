//! Crown measures of a tree mesh, by rasterising it: the one-sided leaf (blade) area, the
//! crown's projected area on the ground, the leaf area index, and the optical porosity of a side
//! view. Leaves are alpha-tested against their card texture, so a card counts only where its
//! texture is opaque, as a renderer draws it.
//!
//! Views are orthographic: the top view looks down −Y onto the ground plane (x, z), the side
//! view looks along −Z onto (x, y). The crown's outline in a view is the convex hull of its leaf
//! pixels; its porosity is the fraction of the pixels inside that hull that show the background
//! (neither leaf, bark nor fruit).

use glam::{Vec2, Vec3};
use image::RgbaImage;

use super::leaf_card::card_texture;
use super::{TreeMesh, TreeMeshes, build_tree_meshes};
use crate::growth::Tree;

/// An orthographic view of a tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Looking down onto the ground: pixel (x, y) = world (x, z).
    Top,
    /// Looking along −Z: pixel (x, y) = world (x, −y), so the image is upright.
    Side,
}

impl View {
    fn project(self, p: Vec3) -> Vec2 {
        match self {
            View::Top => Vec2::new(p.x, p.z),
            View::Side => Vec2::new(p.x, -p.y),
        }
    }
}

/// Which parts of a tree cover each pixel of a view.
#[derive(Clone, Debug, PartialEq)]
pub struct Coverage {
    pub width: usize,
    pub height: usize,
    /// Side of a pixel, metres.
    pub pixel_size_m: f32,
    /// [`LEAF`] | [`WOOD`] per pixel, row-major.
    pub pixels: Vec<u8>,
}

/// A pixel covered by a leaf.
pub const LEAF: u8 = 1;
/// A pixel covered by bark or fruit.
pub const WOOD: u8 = 2;

/// Opacity of a leaf card texture, sampled like a renderer's alpha test (alpha ≥ 128).
#[derive(Clone, Debug, PartialEq)]
pub struct AlphaMask {
    width: usize,
    height: usize,
    opaque: Vec<bool>,
}

impl AlphaMask {
    pub fn from_texture(texture: &RgbaImage) -> Self {
        AlphaMask {
            width: texture.width() as usize,
            height: texture.height() as usize,
            opaque: texture.pixels().map(|p| p[3] >= 128).collect(),
        }
    }

    /// A card opaque everywhere.
    pub fn solid() -> Self {
        AlphaMask {
            width: 1,
            height: 1,
            opaque: vec![true],
        }
    }

    /// Fraction of the card that is opaque: blade area over card area.
    pub fn opaque_fraction(&self) -> f32 {
        let n = self.opaque.iter().filter(|&&o| o).count();
        n as f32 / self.opaque.len().max(1) as f32
    }

    /// Whether the texture is opaque at `uv` (glTF convention: v = 0 on the top row).
    pub fn is_opaque(&self, uv: Vec2) -> bool {
        let x = ((uv.x.clamp(0.0, 1.0) * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y.clamp(0.0, 1.0) * self.height as f32) as usize).min(self.height - 1);
        self.opaque[y * self.width + x]
    }
}

/// Crown measures of one level of detail of a tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrownMeasures {
    /// One-sided area of the leaf blades (card area × the card's opaque fraction), m².
    pub leaf_area_m2: f32,
    /// Area of the convex hull of the leaves seen from above, m².
    pub crown_projection_m2: f32,
    /// Leaf area over crown projection.
    pub leaf_area_index: f32,
    /// Background pixels inside the side view's crown hull, over the hull's pixels.
    pub side_porosity: f32,
    /// Area of the side view's leaf, bark and fruit silhouette, m².
    pub side_silhouette_m2: f32,
    pub num_leaf_cards: usize,
}

/// Measures level `lod` of `meshes`, whose leaf cards are textured with `leaf_mask`, at pixels
/// of `pixel_size_m` metres. `None` when the level has no leaves.
pub fn crown_measures(
    meshes: &TreeMeshes,
    lod: usize,
    leaf_mask: &AlphaMask,
    pixel_size_m: f32,
) -> Option<CrownMeasures> {
    let level = meshes.lods.get(lod)?;
    let num_leaf_indices = level.num_leaf_indices;
    if num_leaf_indices == 0 {
        return None;
    }
    let card_area_m2 = leaf_card_area_m2(level.leaves_in(&meshes.leaves), num_leaf_indices);
    let leaf_area_m2 = card_area_m2 * leaf_mask.opaque_fraction();
    let top = rasterise(meshes, lod, leaf_mask, View::Top, pixel_size_m)?;
    let side = rasterise(meshes, lod, leaf_mask, View::Side, pixel_size_m)?;
    let pixel_area_m2 = pixel_size_m * pixel_size_m;
    let (top_hull, _) = top.hull_pixels(LEAF);
    let crown_projection_m2 = top_hull as f32 * pixel_area_m2;
    let (side_hull, side_open) = side.hull_pixels(LEAF);
    Some(CrownMeasures {
        leaf_area_m2,
        crown_projection_m2,
        leaf_area_index: leaf_area_m2 / crown_projection_m2.max(f32::MIN_POSITIVE),
        side_porosity: side_open as f32 / side_hull.max(1) as f32,
        side_silhouette_m2: side.num_covered(LEAF | WOOD) as f32 * pixel_area_m2,
        num_leaf_cards: num_leaf_indices / 6,
    })
}

/// Pixel size of [`tree_crown_measures`]: a centimetre, finer than the narrowest leaf.
pub const MEASURE_PIXEL_M: f32 = 0.01;

/// Side of the card texture measures alpha-test, pixels.
pub const CARD_TEXTURE_SIZE: u32 = 256;

/// [`crown_measures`] of level `lod` of a grown tree with its species' look and leaf texture.
pub fn tree_crown_measures(tree: &Tree, lod: usize) -> Option<CrownMeasures> {
    let meshes = build_tree_meshes(tree);
    let mask = AlphaMask::from_texture(&card_texture(&meshes, CARD_TEXTURE_SIZE));
    crown_measures(&meshes, lod, &mask, MEASURE_PIXEL_M)
}

/// Sum of the areas of the leaf cards (quads of 6 indices) in the first `num_indices` indices.
pub fn leaf_card_area_m2(leaves: &TreeMesh, num_indices: usize) -> f32 {
    let mut area = 0.0;
    let (triangles, _) = leaves.indices[..num_indices.min(leaves.indices.len())].as_chunks::<3>();
    for triangle in triangles {
        let [a, b, c] = triangle.map(|i| Vec3::from(leaves.positions[i as usize]));
        area += 0.5 * (b - a).cross(c - a).length();
    }
    area
}

/// The coverage of level `lod` of `meshes` in `view`, over the level's bounds; `None` for an
/// empty level.
pub fn rasterise(
    meshes: &TreeMeshes,
    lod: usize,
    leaf_mask: &AlphaMask,
    view: View,
    pixel_size_m: f32,
) -> Option<Coverage> {
    let bounds = meshes.bounds(lod)?;
    Some(rasterise_within(
        meshes,
        lod,
        leaf_mask,
        view,
        pixel_size_m,
        bounds,
    ))
}

/// [`rasterise`] onto the pixels covering `bounds` (world min, max), so that two levels of
/// detail rasterised within the same bounds can be compared pixel by pixel
/// ([`Coverage::num_differing`]).
pub fn rasterise_within(
    meshes: &TreeMeshes,
    lod: usize,
    leaf_mask: &AlphaMask,
    view: View,
    pixel_size_m: f32,
    (lo, hi): (Vec3, Vec3),
) -> Coverage {
    let Some(level) = meshes.lods.get(lod) else {
        return Coverage {
            width: 0,
            height: 0,
            pixel_size_m,
            pixels: Vec::new(),
        };
    };
    let (a, b) = (view.project(lo), view.project(hi));
    let origin = a.min(b);
    let extent = a.max(b) - origin;
    let pixel_size_m = pixel_size_m.max(1e-4);
    let width = (extent.x / pixel_size_m).ceil() as usize + 2;
    let height = (extent.y / pixel_size_m).ceil() as usize + 2;
    let mut coverage = Coverage {
        width,
        height,
        pixel_size_m,
        pixels: vec![0; width * height],
    };
    let to_pixel = |p: [f32; 3]| (view.project(Vec3::from(p)) - origin) / pixel_size_m + Vec2::ONE;
    let solid = AlphaMask::solid();
    let parts: [(&TreeMesh, usize, u8, &AlphaMask); 3] = [
        (&level.branches, level.branches.indices.len(), WOOD, &solid),
        (
            level.leaves_in(&meshes.leaves),
            level.num_leaf_indices,
            LEAF,
            leaf_mask,
        ),
        (&meshes.fruit, level.num_fruit_indices, WOOD, &solid),
    ];
    for (mesh, num_indices, flag, mask) in parts {
        for triangle in mesh.indices[..num_indices.min(mesh.indices.len())].chunks_exact(3) {
            let corner = |k: usize| {
                let i = triangle[k] as usize;
                (to_pixel(mesh.positions[i]), Vec2::from(mesh.uvs[i]))
            };
            coverage.fill([corner(0), corner(1), corner(2)], mask, flag);
        }
    }
    coverage
}

impl Coverage {
    /// Sets `flag` on the pixels whose centres lie in the triangle and where `mask` is opaque
    /// at the interpolated uv.
    fn fill(&mut self, corners: [(Vec2, Vec2); 3], mask: &AlphaMask, flag: u8) {
        let [(a, ua), (b, ub), (c, uc)] = corners;
        let area = (b - a).perp_dot(c - a);
        if area.abs() < 1e-12 {
            return;
        }
        let lo = a.min(b).min(c).floor().max(Vec2::ZERO);
        let hi = a
            .max(b)
            .max(c)
            .ceil()
            .min(Vec2::new(self.width as f32 - 1.0, self.height as f32 - 1.0));
        if lo.x > hi.x || lo.y > hi.y {
            return;
        }
        for y in lo.y as usize..=hi.y as usize {
            for x in lo.x as usize..=hi.x as usize {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let wa = (b - p).perp_dot(c - p) / area;
                let wb = (c - p).perp_dot(a - p) / area;
                let wc = 1.0 - wa - wb;
                if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                    continue;
                }
                if mask.is_opaque(ua * wa + ub * wb + uc * wc) {
                    self.pixels[y * self.width + x] |= flag;
                }
            }
        }
    }

    /// Number of pixels covered by any of `flags`.
    pub fn num_covered(&self, flags: u8) -> usize {
        self.pixels.iter().filter(|&&p| p & flags != 0).count()
    }

    /// Pixels inside the convex hull of the pixels covered by `flags`, and how many of those are
    /// covered by nothing.
    pub fn hull_pixels(&self, flags: u8) -> (usize, usize) {
        let (mut inside, mut open) = (0, 0);
        for (y, span) in self.hull_spans(flags).into_iter().enumerate() {
            let Some((first, last)) = span else {
                continue;
            };
            let row = &self.pixels[y * self.width..][first..=last];
            inside += row.len();
            open += row.iter().filter(|&&p| p == 0).count();
        }
        (inside, open)
    }

    /// Per row, the first and last pixel inside the convex hull of the pixels covered by
    /// `flags` (`None` for a row the hull misses); all `None` when the hull is degenerate.
    pub fn hull_spans(&self, flags: u8) -> Vec<Option<(usize, usize)>> {
        // The hull of the covered pixels' squares is the hull of each row's outermost squares.
        let mut points = Vec::new();
        for y in 0..self.height {
            let row = &self.pixels[y * self.width..][..self.width];
            let first = row.iter().position(|&p| p & flags != 0);
            let last = row.iter().rposition(|&p| p & flags != 0);
            if let (Some(first), Some(last)) = (first, last) {
                let (x0, x1, y0) = (first as f32, last as f32 + 1.0, y as f32);
                points.extend([
                    Vec2::new(x0, y0),
                    Vec2::new(x0, y0 + 1.0),
                    Vec2::new(x1, y0),
                    Vec2::new(x1, y0 + 1.0),
                ]);
            }
        }
        let hull = convex_hull(points);
        let mut spans = vec![None; self.height];
        if hull.len() < 3 {
            return spans;
        }
        for (y, span) in spans.iter_mut().enumerate() {
            // The hull is convex: its pixels in a row form one span, found from the edges.
            let cy = y as f32 + 0.5;
            let (mut x_lo, mut x_hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for (k, &p) in hull.iter().enumerate() {
                let q = hull[(k + 1) % hull.len()];
                if (p.y - cy) * (q.y - cy) > 0.0 || p.y == q.y {
                    continue;
                }
                let x = p.x + (cy - p.y) / (q.y - p.y) * (q.x - p.x);
                x_lo = x_lo.min(x);
                x_hi = x_hi.max(x);
            }
            if x_lo > x_hi {
                continue;
            }
            let first = (x_lo - 0.5).ceil().max(0.0) as usize;
            let last = ((x_hi - 0.5).floor() as usize).min(self.width - 1);
            if first <= last {
                *span = Some((first, last));
            }
        }
        spans
    }

    /// Background share of the convex hull of the pixels covered by `flags`, in the middle
    /// `middle` of each row's span and in the rest (the rim at both ends): (middle, rim). A
    /// crown dense inside but with a lobed or conical outline shows a low middle and a high rim.
    pub fn hull_sky_middle_and_rim(&self, flags: u8, middle: f32) -> (f32, f32) {
        let (lo, hi) = (0.5 - 0.5 * middle, 0.5 + 0.5 * middle);
        let (mut mid, mut mid_open, mut rim, mut rim_open) = (0usize, 0usize, 0usize, 0usize);
        for (y, span) in self.hull_spans(flags).into_iter().enumerate() {
            let Some((first, last)) = span else {
                continue;
            };
            let n = (last - first + 1) as f32;
            for x in first..=last {
                let t = (x - first) as f32 / n;
                let open = usize::from(self.pixels[y * self.width + x] == 0);
                if (lo..hi).contains(&t) {
                    mid += 1;
                    mid_open += open;
                } else {
                    rim += 1;
                    rim_open += open;
                }
            }
        }
        let share = |open: usize, all: usize| open as f32 / all.max(1) as f32;
        (share(mid_open, mid), share(rim_open, rim))
    }

    /// Pixels covered by `flags` in exactly one of `self` and `other`, which must be of the
    /// same size: the difference of two silhouettes. `None` for coverages of different sizes.
    pub fn num_differing(&self, other: &Coverage, flags: u8) -> Option<usize> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        let n = self
            .pixels
            .iter()
            .zip(&other.pixels)
            .filter(|&(&a, &b)| (a & flags != 0) != (b & flags != 0))
            .count();
        Some(n)
    }
}

impl Coverage {
    /// How far the image of `other` departs from this one's when both are seen at `block` ×
    /// `block` pixels per screen pixel, as a renderer filters them at a distance: the sum over
    /// screen pixels of |Δ opacity| (opacity = covered fraction of the block) over the sum of
    /// this image's opacity. `None` for coverages of different sizes.
    pub fn filtered_difference(&self, other: &Coverage, flags: u8, block: usize) -> Option<f32> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        let block = block.max(1);
        let (mut differing, mut total) = (0u64, 0u64);
        for by in (0..self.height).step_by(block) {
            for bx in (0..self.width).step_by(block) {
                let (mut a, mut b) = (0i64, 0i64);
                for y in by..(by + block).min(self.height) {
                    for x in bx..(bx + block).min(self.width) {
                        let i = y * self.width + x;
                        a += i64::from(self.pixels[i] & flags != 0);
                        b += i64::from(other.pixels[i] & flags != 0);
                    }
                }
                differing += (a - b).unsigned_abs();
                total += a as u64;
            }
        }
        Some(differing as f32 / total.max(1) as f32)
    }
}

/// Convex hull by Andrew's monotone chain, counter-clockwise in pixel space (y down).
pub fn convex_hull(mut points: Vec<Vec2>) -> Vec<Vec2> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let turn = |o: Vec2, a: Vec2, b: Vec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &Vec2>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in ordered {
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An empty coverage of `width` × `height` pixels of `pixel_size_m`.
    fn empty(width: usize, height: usize, pixel_size_m: f32) -> Coverage {
        Coverage {
            width,
            height,
            pixel_size_m,
            pixels: vec![0; width * height],
        }
    }

    #[test]
    fn the_hull_of_a_filled_square_is_the_square_with_no_open_pixels() {
        let mut coverage = empty(20, 20, 0.1);
        for y in 5..15 {
            for x in 5..15 {
                coverage.pixels[y * 20 + x] = LEAF;
            }
        }
        assert_eq!(coverage.hull_pixels(LEAF), (100, 0));
        // A hole in the middle is open; the hull stays the same.
        coverage.pixels[10 * 20 + 10] = 0;
        assert_eq!(coverage.hull_pixels(LEAF), (100, 1));
    }

    #[test]
    fn the_hull_of_three_corner_pixels_spans_the_triangle_between_them() {
        let mut coverage = empty(10, 10, 1.0);
        coverage.pixels[0] = LEAF;
        coverage.pixels[9 * 10 + 9] = LEAF;
        coverage.pixels[9 * 10] = LEAF;
        let (inside, open) = coverage.hull_pixels(LEAF);
        // The hull of the three corner squares: row y holds min(y + 2, 10) pixel centres.
        assert_eq!(inside, 64);
        assert_eq!(open, 61);
    }

    #[test]
    fn a_crown_full_in_the_middle_with_an_empty_rim_shows_sky_only_in_the_rim() {
        // A square hull (leaves on its left and right edges) filled in its middle 40% only.
        let mut coverage = empty(20, 20, 0.1);
        for y in 0..20 {
            for x in [0, 19].into_iter().chain(6..14) {
                coverage.pixels[y * 20 + x] = LEAF;
            }
        }
        let (middle, rim) = coverage.hull_sky_middle_and_rim(LEAF, 0.4);
        assert_eq!(middle, 0.0);
        assert!((rim - 10.0 / 12.0).abs() < 1e-6, "rim {rim}");
        assert_eq!(coverage.hull_pixels(LEAF), (400, 200));
    }
}
