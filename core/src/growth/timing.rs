//! Time spent in each step of [`super::Tree::step`], summed over every iteration of every tree
//! since the last [`reset_phase_times`], for reports (`examples/growth_timing.rs`). Off unless
//! [`enable_phase_times`] gave it a clock (wall time, or a CPU clock, which a loaded machine
//! inflates less): a step then reads one flag per phase and takes no clock.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// The steps of an iteration, in the order they run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Bud collection: expired buds, light exposure, the bud list (step 1).
    Collect,
    /// Autonomous attraction points generated in the buds' perception volumes.
    Points,
    /// Competition for space: grids, occupancy, perception (step 2).
    Space,
    /// Bud input Q (step 3).
    BudInput,
    /// Vigor, basipetal then acropetal (step 4), and the choice of branches to shed.
    Vigor,
    /// Shoot growth with shadow updates and consumption of points (steps 5 and 6).
    Shoots,
    /// Shedding's removal of branches from the arena (step 7) and pruning to a scene.
    Shed,
    /// End of the iteration: consumed and transient points dropped.
    Finish,
    /// Pipe-model widths (step 8).
    Widths,
}

/// Every phase, in [`Phase`] order.
pub const PHASES: [Phase; 9] = [
    Phase::Collect,
    Phase::Points,
    Phase::Space,
    Phase::BudInput,
    Phase::Vigor,
    Phase::Shoots,
    Phase::Shed,
    Phase::Finish,
    Phase::Widths,
];

impl Phase {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Collect => "buds",
            Phase::Points => "points",
            Phase::Space => "space",
            Phase::BudInput => "input",
            Phase::Vigor => "vigor",
            Phase::Shoots => "shoots",
            Phase::Shed => "shed",
            Phase::Finish => "finish",
            Phase::Widths => "widths",
        }
    }
}

static ENABLED: AtomicBool = AtomicBool::new(false);
static CLOCK: Mutex<Option<fn() -> u64>> = Mutex::new(None);
static NANOS: [AtomicU64; PHASES.len()] = [const { AtomicU64::new(0) }; PHASES.len()];

/// Nanoseconds of wall-clock time since the first call (a clock for [`enable_phase_times`]).
pub fn wall_clock_ns() -> u64 {
    static START: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    let start = *START.get_or_init(Instant::now);
    u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX)
}

/// Times the phases by `clock` (nanoseconds, never decreasing; e.g. [`wall_clock_ns`] or the
/// process's CPU time), or stops timing them (`None`, the default).
pub fn enable_phase_times(clock: Option<fn() -> u64>) {
    if let Ok(mut c) = CLOCK.lock() {
        *c = clock;
    }
    ENABLED.store(clock.is_some(), Ordering::Relaxed);
}

/// Sets every phase's total back to zero.
pub fn reset_phase_times() {
    for n in &NANOS {
        n.store(0, Ordering::Relaxed);
    }
}

/// The time summed in each phase since the last reset, in [`PHASES`] order.
pub fn phase_times() -> [(Phase, Duration); PHASES.len()] {
    PHASES.map(|p| {
        (
            p,
            Duration::from_nanos(NANOS[p as usize].load(Ordering::Relaxed)),
        )
    })
}

/// The clock of one step: [`PhaseClock::lap`] charges the time since the previous lap to a
/// phase.
pub(crate) struct PhaseClock(Option<(fn() -> u64, u64)>);

impl PhaseClock {
    pub(crate) fn start() -> Self {
        if !ENABLED.load(Ordering::Relaxed) {
            return PhaseClock(None);
        }
        let clock = CLOCK.lock().ok().and_then(|c| *c);
        PhaseClock(clock.map(|f| (f, f())))
    }

    pub(crate) fn lap(&mut self, phase: Phase) {
        if let Some((clock, last)) = &mut self.0 {
            let now = clock();
            NANOS[phase as usize].fetch_add(now.saturating_sub(*last), Ordering::Relaxed);
            *last = now;
        }
    }
}
