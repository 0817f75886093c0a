//! Rigid transforms in f64, named for what they map (`camera_from_world`).

use glam::{DAffine3, DMat3, DQuat, DVec3};

/// A rigid transform `p ↦ R p + t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3 {
    pub rotation: DQuat,
    pub translation: DVec3,
}

impl Se3 {
    pub const IDENTITY: Self = Self {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    pub fn new(rotation: DQuat, translation: DVec3) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    pub fn inverse(&self) -> Self {
        let r = self.rotation.inverse();
        Self::new(r, -(r * self.translation))
    }

    /// The motion `self` stretched to `k` times its length (rotation angle and translation
    /// scaled): a per-frame velocity applied over `k` frame intervals.
    pub fn scaled(&self, k: f64) -> Self {
        Self::new(
            DQuat::from_scaled_axis(self.rotation.to_scaled_axis() * k),
            self.translation * k,
        )
    }

    /// `self ∘ other`.
    pub fn compose(&self, other: &Self) -> Self {
        Self::new(
            (self.rotation * other.rotation).normalize(),
            self.rotation * other.translation + self.translation,
        )
    }

    /// Left update by a twist `(ω, v)`: `exp(ω) R`, `exp(ω) t + v`.
    pub fn updated(&self, omega: DVec3, v: DVec3) -> Self {
        let dq = exp_so3(omega);
        Self::new((dq * self.rotation).normalize(), dq * self.translation + v)
    }

    pub fn to_affine(&self) -> DAffine3 {
        DAffine3::from_rotation_translation(self.rotation, self.translation)
    }

    pub fn from_affine(a: &DAffine3) -> Self {
        let (_, rotation, translation) = a.to_scale_rotation_translation();
        Self::new(rotation.normalize(), translation)
    }

    pub fn rotation_matrix(&self) -> DMat3 {
        DMat3::from_quat(self.rotation)
    }
}

/// Rotation of the axis-angle vector `ω`.
pub fn exp_so3(omega: DVec3) -> DQuat {
    let angle = omega.length();
    if angle < 1e-12 {
        DQuat::from_xyzw(omega.x * 0.5, omega.y * 0.5, omega.z * 0.5, 1.0).normalize()
    } else {
        DQuat::from_axis_angle(omega / angle, angle)
    }
}

/// Skew-symmetric matrix `[v]×`.
pub fn skew(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}
