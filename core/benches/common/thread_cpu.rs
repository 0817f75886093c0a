//! CPU time of the calling thread, shared by the timing examples and the geometry benchmark.
//!
//! `clock_gettime(CLOCK_THREAD_CPUTIME_ID)` counts the running slice up to the call, so it
//! resolves short steps (a brush iteration, a mesh); `/proc/thread-self/schedstat`, used before,
//! only moves at scheduler ticks (4 ms on the development VM).

/// Nanoseconds this thread has run on a CPU; `None` where the clock is missing.
pub fn thread_cpu_ns() -> Option<u64> {
    cpu_clock_ns(
        #[cfg(unix)]
        libc::CLOCK_THREAD_CPUTIME_ID,
    )
}

/// Nanoseconds all threads of this process have run on a CPU (growth runs on several);
/// `None` where the clock is missing.
#[allow(dead_code)]
pub fn process_cpu_ns() -> Option<u64> {
    cpu_clock_ns(
        #[cfg(unix)]
        libc::CLOCK_PROCESS_CPUTIME_ID,
    )
}

/// Milliseconds of this thread's CPU that `f` takes; NaN where the clock is missing.
#[allow(dead_code)]
pub fn cpu_ms(f: impl FnOnce()) -> f64 {
    let start = thread_cpu_ns();
    f();
    match (start, thread_cpu_ns()) {
        (Some(a), Some(b)) => (b - a) as f64 / 1e6,
        _ => f64::NAN,
    }
}

/// The median of timing samples (the upper one of an even count).
#[allow(dead_code)]
pub fn median_ms(mut samples: Vec<f64>) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn cpu_clock_ns(#[cfg(unix)] clock: libc::clockid_t) -> Option<u64> {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `ts` is a valid, writable timespec; the call only writes to it.
        let status = unsafe { libc::clock_gettime(clock, &mut ts) };
        (status == 0).then(|| ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64)
    }
    #[cfg(not(unix))]
    {
        None
    }
}
