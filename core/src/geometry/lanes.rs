//! Four 3-vectors at once, one per lane of glam's `Vec4` (SIMD on x86-64): the petiole and
//! the parent-surface projection run four independent computations side by side with exactly
//! the arithmetic of their one-at-a-time paths.

use glam::{BVec4A, Vec3, Vec4};

/// Four vectors, one per lane of glam's `Vec4` (SIMD on x86-64), stored by component. The
/// operations repeat glam's `Vec3` arithmetic operation for operation, lane by lane.
#[derive(Clone, Copy)]
pub(crate) struct V4 {
    pub x: Vec4,
    pub y: Vec4,
    pub z: Vec4,
}

impl V4 {
    #[inline(always)]
    pub(crate) fn gather(v: [Vec3; 4]) -> V4 {
        V4 {
            x: Vec4::new(v[0].x, v[1].x, v[2].x, v[3].x),
            y: Vec4::new(v[0].y, v[1].y, v[2].y, v[3].y),
            z: Vec4::new(v[0].z, v[1].z, v[2].z, v[3].z),
        }
    }

    #[inline(always)]
    pub(crate) fn splat(v: Vec3) -> V4 {
        V4 {
            x: Vec4::splat(v.x),
            y: Vec4::splat(v.y),
            z: Vec4::splat(v.z),
        }
    }

    #[inline(always)]
    pub(crate) fn lane(&self, i: usize) -> [f32; 3] {
        [self.x[i], self.y[i], self.z[i]]
    }

    #[inline(always)]
    pub(crate) fn add(self, o: V4) -> V4 {
        V4 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    #[inline(always)]
    pub(crate) fn sub(self, o: V4) -> V4 {
        V4 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    #[inline(always)]
    pub(crate) fn scale(self, s: Vec4) -> V4 {
        V4 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    #[inline(always)]
    pub(crate) fn dot(self, o: V4) -> Vec4 {
        (self.x * o.x) + (self.y * o.y) + (self.z * o.z)
    }

    #[inline(always)]
    pub(crate) fn cross(self, o: V4) -> V4 {
        V4 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    /// Division of every component by `s` (glam's `Vec3 / f32`).
    #[inline(always)]
    pub(crate) fn div(self, s: Vec4) -> V4 {
        V4 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }

    /// `a` in the lanes where `mask` is set, `b` elsewhere.
    #[inline(always)]
    pub(crate) fn select(mask: BVec4A, a: V4, b: V4) -> V4 {
        V4 {
            x: Vec4::select(mask, a.x, b.x),
            y: Vec4::select(mask, a.y, b.y),
            z: Vec4::select(mask, a.z, b.z),
        }
    }

    /// glam's `length` in every lane.
    #[inline(always)]
    pub(crate) fn length(self) -> Vec4 {
        sqrt(self.dot(self))
    }

    /// glam's `try_normalize` in every lane; `None` when it fails in any.
    #[inline(always)]
    pub(crate) fn try_normalize(self) -> Option<V4> {
        let recip = Vec4::ONE / self.length();
        (recip.is_finite() && recip.cmpgt(Vec4::ZERO).all()).then(|| self.scale(recip))
    }
}

/// `f32::sqrt` in every lane.
#[inline(always)]
pub(crate) fn sqrt(v: Vec4) -> Vec4 {
    Vec4::new(v.x.sqrt(), v.y.sqrt(), v.z.sqrt(), v.w.sqrt())
}
