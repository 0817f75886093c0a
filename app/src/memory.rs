//! Giving freed memory back to the system.
//!
//! Growth, undo and ungrow allocate and free working memory of about the tree's size many times
//! a second. The C allocator keeps what is freed for reuse, in every thread's arena, so over a
//! long session the resident memory creeps far above what the design holds (the soak example:
//! 4.5 MiB resident for 2.1 MiB of heap) — on a phone, the figure the system kills apps by.
//! After the design has changed, [`FreeMemory`] asks the allocator to return its free pages, at
//! most once a second of design time. Between two releases the big blocks (a tree's arena, a
//! grid, a copy kept for undo: anything of [`OWN_PAGES_BYTES`] or more) go back to the system
//! as soon as they are freed: glibc gives such blocks pages of their own only up to a threshold
//! that it raises to the largest block freed so far, so without a fixed threshold every
//! tree-sized block ends up among the pages the allocator keeps (a realistic soak: 16 MiB
//! resident for 9 MiB of heap).

/// Design time between two releases, seconds.
const RELEASE_INTERVAL_S: f64 = 1.0;

/// Blocks of at least this many bytes get pages of their own from the system, unmapped when
/// freed (glibc's `M_MMAP_THRESHOLD`, fixed). Below it blocks share the allocator's pages; a
/// tree's arena of a few hundred internodes is already this big, and mapping such a block costs
/// a page fault per 4 KiB written, a small part of filling it.
pub const OWN_PAGES_BYTES: usize = 256 * 1024;

/// When the design last gave its free memory back.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FreeMemory {
    released_revision: u64,
    released_at_s: f64,
}

impl Default for FreeMemory {
    /// Also makes big blocks return to the system when freed ([`return_big_blocks_when_freed`]).
    fn default() -> Self {
        return_big_blocks_when_freed();
        FreeMemory {
            released_revision: 0,
            released_at_s: 0.0,
        }
    }
}

/// Makes the allocator give blocks of [`OWN_PAGES_BYTES`] or more pages of their own, returned
/// to the system when the block is freed, and trim the top of its heap beyond as much free
/// (glibc; once per process, as the design first starts). Elsewhere the allocators do either
/// already (musl, bionic's scudo and jemalloc, Apple's large-block zone) or are left as they are.
pub fn return_big_blocks_when_freed() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        #[cfg(all(target_os = "linux", target_env = "gnu"))]
        // SAFETY: mallopt only changes the allocator's thresholds; it is safe at any time.
        unsafe {
            let bytes = OWN_PAGES_BYTES as libc::c_int;
            libc::mallopt(libc::M_MMAP_THRESHOLD, bytes);
            libc::mallopt(libc::M_TRIM_THRESHOLD, bytes);
        }
    });
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
