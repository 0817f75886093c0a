//! Attribute quantization for `KHR_mesh_quantization`: positions as normalized signed shorts
//! in a box that the node's translation and uniform scale map back to metres, normals as
//! normalized signed bytes, ambient colours as normalized unsigned bytes.

use glam::Vec3;

/// Largest value of a normalized signed short.
const SNORM16_MAX: f32 = 32_767.0;
/// Largest value of a normalized signed byte.
const SNORM8_MAX: f32 = 127.0;

/// The box positions are quantized in: node space = (world − `center`) / `half_extent`, which
/// lies in [−1, 1] on every axis for every point of the box. The node that draws quantized
/// data carries `center` as its translation and `half_extent` as its (uniform) scale; uniform,
/// so that rotations below it (leaf instances) stay rotations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Quantizer {
    pub(super) center: Vec3,
    pub(super) half_extent: f32,
}

impl Quantizer {
    /// The quantizer of the box `lo`..`hi`.
    pub(super) fn of((lo, hi): (Vec3, Vec3)) -> Self {
        Quantizer {
            center: (lo + hi) * 0.5,
            half_extent: ((hi - lo) * 0.5).max_element().max(1e-6),
        }
    }

    /// `p` (world metres) in node space.
    pub(super) fn node_from_world(&self, p: Vec3) -> Vec3 {
        (p - self.center) / self.half_extent
    }

    /// `p` (world metres) as normalized signed shorts, padded to 4 components (8 bytes, the
    /// 4-byte alignment vertex attributes need).
    pub(super) fn position(&self, p: [f32; 3]) -> [i16; 4] {
        let q = self.node_from_world(Vec3::from(p));
        [snorm16(q.x), snorm16(q.y), snorm16(q.z), 0]
    }

    /// The world point a quantized position stands for.
    #[cfg(test)]
    pub(super) fn dequantize(&self, q: [i16; 4]) -> Vec3 {
        let node = Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32) / SNORM16_MAX;
        self.center + node * self.half_extent
    }
}

/// The box texture coordinates are quantized in, as normalized unsigned shorts: the texture's
/// `KHR_texture_transform` maps a stored (u, v) in [0, 1]² back to `offset + scale · (u, v)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct UvBox {
    pub(super) offset: [f32; 2],
    pub(super) scale: [f32; 2],
}

impl UvBox {
    /// The unit square: coordinates stored as they are (no texture transform).
    pub(super) const UNIT: UvBox = UvBox {
        offset: [0.0; 2],
        scale: [1.0; 2],
    };

    /// The box of `uvs` (the unit square when there are none).
    pub(super) fn of<'a>(uvs: impl Iterator<Item = &'a [f32; 2]>) -> Self {
        let (lo, hi) = uvs.fold(
            ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]),
            |(lo, hi), uv| {
                (
                    [lo[0].min(uv[0]), lo[1].min(uv[1])],
                    [hi[0].max(uv[0]), hi[1].max(uv[1])],
                )
            },
        );
        if lo[0] > hi[0] {
            return UvBox {
                offset: [0.0; 2],
                scale: [1.0; 2],
            };
        }
        UvBox {
            offset: lo,
            scale: [(hi[0] - lo[0]).max(1e-6), (hi[1] - lo[1]).max(1e-6)],
        }
    }

    /// `uv` as normalized unsigned shorts.
    pub(super) fn quantize(&self, uv: [f32; 2]) -> [u16; 2] {
        let q = |k: usize| {
            (((uv[k] - self.offset[k]) / self.scale[k]).clamp(0.0, 1.0) * 65_535.0).round() as u16
        };
        [q(0), q(1)]
    }
}

/// `x` in [−1, 1] as a normalized signed short (glTF: value = max(c / 32767, −1)).
pub(super) fn snorm16(x: f32) -> i16 {
    (x.clamp(-1.0, 1.0) * SNORM16_MAX).round() as i16
}

/// [`snorm16`] rounded up: the value it stands for is never below `x`.
pub(super) fn snorm16_up(x: f32) -> i16 {
    (x.clamp(-1.0, 1.0) * SNORM16_MAX).ceil() as i16
}

/// A unit normal as normalized signed bytes, padded to 4 bytes.
pub(super) fn normal(n: [f32; 3]) -> [i8; 4] {
    let q = |x: f32| (x.clamp(-1.0, 1.0) * SNORM8_MAX).round() as i8;
    [q(n[0]), q(n[1]), q(n[2]), 0]
}

/// `x` in [0, 1] as a normalized unsigned byte.
pub(super) fn unorm8(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantized_positions_come_back_within_half_a_step_of_the_box() {
        let q = Quantizer::of((Vec3::new(-3.0, 0.0, -2.0), Vec3::new(5.0, 16.0, 2.5)));
        let step = q.half_extent / SNORM16_MAX;
        for p in [
            [-3.0, 0.0, -2.0],
            [5.0, 16.0, 2.5],
            [0.123, 7.777, -1.9],
            [4.99, 0.001, 2.49],
        ] {
            let back = q.dequantize(q.position(p));
            assert!(
                back.distance(Vec3::from(p)) <= 0.87 * step,
                "{p:?} came back as {back}"
            );
        }
    }

    #[test]
    fn quantized_normals_keep_their_direction_within_a_degree() {
        for n in [
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.577_35, 0.577_35, -0.577_35],
        ] {
            let q = normal(n);
            let back = Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32).normalize();
            assert!(
                back.angle_between(Vec3::from(n)) < 1f32.to_radians(),
                "{n:?}"
            );
        }
    }
}
