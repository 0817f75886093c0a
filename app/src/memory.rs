//! Giving freed memory back to the system.
//!
//! Growth, undo and ungrow allocate and free working memory of about the tree's size many times
//! a second. The C allocator keeps what is freed for reuse, in every thread's arena, so over a
//! long session the resident memory creeps far above what the design holds (the soak example:
//! 4.5 MiB resident for 2.1 MiB of heap) — on a phone, the figure the system kills apps by.
//! After the design has changed, [`FreeMemory`] asks the allocator to return its free pages, at
//! most once a second of design time.

/// Design time between two releases, seconds.
const RELEASE_INTERVAL_S: f64 = 1.0;

/// When the design last gave its free memory back.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FreeMemory {
    released_revision: u64,
    released_at_s: f64,
}

impl FreeMemory {
    /// Releases free memory when the design's `revision` moved since the last release and at
    /// least [`RELEASE_INTERVAL_S`] passed (`time_s`: design time; a seek back counts too).
    pub(crate) fn after_frame(&mut self, revision: u64, time_s: f64) {
        if revision != self.released_revision
            && (time_s - self.released_at_s).abs() >= RELEASE_INTERVAL_S
        {
            release_free_memory();
            self.released_revision = revision;
            self.released_at_s = time_s;
        }
    }
}

/// Asks the allocator to return the memory it holds free to the system (glibc: every arena's
/// free pages; Android's bionic: purge its caches; Apple: relieve every malloc zone).
pub fn release_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases free pages; it is safe to call at any time.
    unsafe {
        libc::malloc_trim(0);
    }
    #[cfg(target_os = "android")]
    {
        /// bionic's `M_PURGE` (API 28 and later; older releases ignore the request).
        const M_PURGE: libc::c_int = -101;
        unsafe extern "C" {
            fn mallopt(param: libc::c_int, value: libc::c_int) -> libc::c_int;
        }
        // SAFETY: mallopt with M_PURGE only releases cached free memory.
        unsafe {
            mallopt(M_PURGE, 0);
        }
    }
    #[cfg(any(target_os = "ios", target_os = "macos"))]
    {
        unsafe extern "C" {
            fn malloc_zone_pressure_relief(zone: *mut std::ffi::c_void, goal: usize) -> usize;
        }
        // SAFETY: a null zone relieves every zone; goal 0 asks for as much as possible.
        unsafe {
            malloc_zone_pressure_relief(std::ptr::null_mut(), 0);
        }
    }
    // Elsewhere (musl, Windows) the allocator returns large frees by itself.
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_release_waits_for_a_change_and_a_second_of_design_time() {
        let mut memory = FreeMemory::default();
        memory.after_frame(0, 5.0);
        assert_eq!(memory.released_at_s, 0.0, "nothing changed");
        memory.after_frame(1, 0.5);
        assert_eq!(memory.released_revision, 0, "too soon");
        memory.after_frame(1, 1.5);
        assert_eq!((memory.released_revision, memory.released_at_s), (1, 1.5));
        memory.after_frame(2, 2.0);
        assert_eq!(memory.released_revision, 1, "within a second of the last");
        memory.after_frame(2, 2.6);
        assert_eq!(memory.released_revision, 2);
    }
}
