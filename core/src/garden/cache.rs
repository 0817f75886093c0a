//! What an edit of one tree reuses from the last: the other trees do not change between edits
//! of one tree, so what is measured of them (crown boxes, crown areas) and the neighbours'
//! nodes handed to the edited tree as occupied space are kept, each with the versions of the
//! trees it was taken from, and used again while those versions stand.
//!
//! A tree's version is a number from one process-wide counter, taken anew whenever its nodes
//! change (it grows a round, is edited or put back, is planted): the same version always means
//! the same nodes at the same place. Version 0 (a tree just loaded) is never trusted.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{Vec2, Vec3};

static NEXT_VERSION: AtomicU64 = AtomicU64::new(1);

/// A version no tree has had.
pub(super) fn fresh_version() -> u64 {
    NEXT_VERSION.fetch_add(1, Ordering::Relaxed)
}

/// Nodes kept with the (index, version) of each tree they were taken from.
pub(super) type KeptNodes = (Vec<(u32, u64)>, Vec<Vec3>);

/// A tree's version and what was measured of it at that version (derived, never saved).
#[derive(Clone, Debug, Default)]
pub(crate) struct EditCache {
    pub(super) version: u64,
    pub(super) crown_box: Option<(u64, (Vec2, Vec2))>,
    pub(super) crown_area_m2: Option<(u64, f32)>,
    /// All the linked neighbours' nodes, in this tree's space, with the neighbours (index,
    /// version) they were taken from.
    pub(super) neighbour_nodes: Option<KeptNodes>,
}

/// Derived from the trees: never part of a garden's value.
impl PartialEq for EditCache {
    fn eq(&self, _: &EditCache) -> bool {
        true
    }
}

impl EditCache {
    /// A tree whose nodes just changed.
    pub(super) fn changed(&mut self) {
        self.version = fresh_version();
    }

    /// A value kept at `version`, if that is the tree's current one.
    fn current<T: Copy>(&self, kept: Option<(u64, T)>) -> Option<T> {
        kept.filter(|&(v, _)| v == self.version && v != 0)
            .map(|(_, value)| value)
    }

    /// The crown box kept at the current version.
    pub(super) fn kept_crown_box(&self) -> Option<(Vec2, Vec2)> {
        self.current(self.crown_box)
    }

    pub(super) fn keep_crown_box(&mut self, b: (Vec2, Vec2)) {
        self.crown_box = Some((self.version, b));
    }

    /// The crown area kept at the current version, m².
    pub(super) fn kept_crown_area_m2(&self) -> Option<f32> {
        self.current(self.crown_area_m2)
    }

    pub(super) fn keep_crown_area_m2(&mut self, a: f32) {
        self.crown_area_m2 = Some((self.version, a));
    }
}
