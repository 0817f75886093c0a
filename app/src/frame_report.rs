//! The window's frame-time report (`sylva view --frame-report N`): how long the UI takes per
//! drawn frame while footage plays and the tracker runs, as a median and a 95th percentile, with
//! the parts of a redraw (playing and tracking the footage, drawing the AR view, the UI,
//! submitting and presenting), and the process's CPU time per redraw (every thread: the UI, the
//! tracker's worker, lavapipe's rasteriser threads) with the load average, which on a loaded
//! machine say more than the wall-clock figures. A report, printed once, not a timed test.

use std::fmt;
use std::time::Instant;

/// Redraws left out at the start, after any seek has caught up (the first frame builds
/// pipelines and uploads the species' textures).
pub const WARM_UP_FRAMES: usize = 5;

/// What one redraw took, milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameSample {
    /// From the start of the previous redraw to the start of this one: the UI's frame time.
    pub frame_ms: f32,
    /// Playing the footage: the next frame's image, tracking, scene and growth.
    pub update_ms: f32,
    /// Encoding the AR view (meshes and images uploaded when they changed).
    pub render_ms: f32,
    /// Running and tessellating the egui UI.
    pub ui_ms: f32,
    /// Submitting and presenting (lavapipe rasterises here).
    pub present_ms: f32,
    /// The redraw happened while a seek was still catching up.
    pub seeking: bool,
    /// The redraw stretched the AR view it drew before (nothing in it had changed: no new
    /// footage frame yet) under the redrawn UI, instead of drawing the AR view again.
    pub scene_reused: bool,
    /// CPU time the process had used at the start of the redraw, seconds ([`process_cpu_s`]).
    pub process_cpu_s: f64,
}

/// CPU time used by the process so far (all its threads, user and system), seconds; 0 where
/// the platform does not say.
pub fn process_cpu_s() -> f64 {
    #[cfg(unix)]
    {
        // SAFETY: getrusage only writes the struct it is given.
        let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
        if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) } == 0 {
            let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
            return seconds(usage.ru_utime) + seconds(usage.ru_stime);
        }
    }
    0.0
}

/// The one-minute load average (`/proc/loadavg`), if the system has one.
pub fn load_average() -> Option<f32> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

/// Frame samples of a window, up to a count.
#[derive(Clone, Debug)]
pub struct FrameTimes {
    wanted: usize,
    samples: Vec<FrameSample>,
    last_start: Option<Instant>,
    /// Redraws since the last seek caught up.
    num_settled: usize,
    /// Redraws made while a seek was catching up.
    num_seek_redraws: usize,
    /// Footage frames shown while measuring (first, last).
    footage: Option<(usize, usize)>,
}

impl FrameTimes {
    /// Measures `wanted` redraws after [`WARM_UP_FRAMES`].
    pub fn new(wanted: usize) -> FrameTimes {
        FrameTimes {
            wanted,
            samples: Vec::with_capacity(wanted),
            last_start: None,
            num_settled: 0,
            num_seek_redraws: 0,
            footage: None,
        }
    }

    /// Marks the start of a redraw; returns the time since the previous one, milliseconds.
    pub fn start(&mut self, now: Instant) -> f32 {
        self.last_start
            .replace(now)
            .map_or(0.0, |last| (now - last).as_secs_f32() * 1000.0)
    }

    /// Records one redraw showing footage frame `footage_frame`: redraws while a seek catches
    /// up are counted apart, the others measured after the warm-up.
    pub fn record(&mut self, sample: FrameSample, footage_frame: usize) {
        if self.is_done() {
            return;
        }
        if sample.seeking {
            self.num_seek_redraws += 1;
            self.num_settled = 0;
            return;
        }
        self.num_settled += 1;
        if self.num_settled <= WARM_UP_FRAMES {
            return;
        }
        self.samples.push(sample);
        let (first, _) = self.footage.unwrap_or((footage_frame, footage_frame));
        self.footage = Some((first, footage_frame));
    }

    pub fn is_done(&self) -> bool {
        self.samples.len() >= self.wanted
    }

    /// The report over the samples so far (None without any).
    pub fn report(&self, size: (u32, u32)) -> Option<FrameReport> {
        if self.samples.is_empty() {
            return None;
        }
        let stat = |f: fn(&FrameSample) -> f32| {
            let mut values: Vec<f32> = self.samples.iter().map(f).collect();
            values.sort_by(f32::total_cmp);
            Stat {
                median_ms: percentile(&values, 0.5),
                p95_ms: percentile(&values, 0.95),
                max_ms: values.last().copied().unwrap_or(0.0),
            }
        };
        Some(FrameReport {
            size,
            num_frames: self.samples.len(),
            frame: stat(|s| s.frame_ms),
            update: stat(|s| s.update_ms),
            render: stat(|s| s.render_ms),
            ui: stat(|s| s.ui_ms),
            present: stat(|s| s.present_ms),
            cpu_ms_per_frame: cpu_ms_per_frame(&self.samples),
            load_average: load_average(),
            num_drawn_while_seeking: self.num_seek_redraws,
            num_scene_reused: self.samples.iter().filter(|s| s.scene_reused).count(),
            footage: self.footage.unwrap_or_default(),
        })
    }
}

/// The process's CPU time per redraw between the first and the last sample's start,
/// milliseconds (0 with fewer than two samples).
fn cpu_ms_per_frame(samples: &[FrameSample]) -> f32 {
    match (samples.first(), samples.last()) {
        (Some(first), Some(last)) if samples.len() > 1 => {
            let used_s = last.process_cpu_s - first.process_cpu_s;
            (used_s * 1000.0 / (samples.len() - 1) as f64) as f32
        }
        _ => 0.0,
    }
}

/// The value below which `fraction` of the sorted `values` lie (nearest rank).
pub fn percentile(sorted: &[f32], fraction: f32) -> f32 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = (fraction.clamp(0.0, 1.0) * sorted.len() as f32).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

/// Median, 95th percentile and maximum of one part, milliseconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stat {
    pub median_ms: f32,
    pub p95_ms: f32,
    pub max_ms: f32,
}

/// The frame-time report of a window.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameReport {
    /// Window size, pixels.
    pub size: (u32, u32),
    pub num_frames: usize,
    pub frame: Stat,
    pub update: Stat,
    pub render: Stat,
    pub ui: Stat,
    pub present: Stat,
    /// CPU time of the whole process (every thread) per measured redraw, milliseconds.
    pub cpu_ms_per_frame: f32,
    /// The one-minute load average when the report was made.
    pub load_average: Option<f32>,
    /// Redraws made while a seek was catching up, from the window's first one (the window kept
    /// drawing).
    pub num_drawn_while_seeking: usize,
    /// Measured redraws that stretched the AR view drawn before instead of drawing it again.
    pub num_scene_reused: usize,
    /// The first and last footage frame shown while measuring.
    pub footage: (usize, usize),
}

impl fmt::Display for FrameReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "frame_report window={}x{} frames={} footage_frames={}..{} drawn_while_seeking={} \
             scene_reused={}",
            self.size.0,
            self.size.1,
            self.num_frames,
            self.footage.0,
            self.footage.1,
            self.num_drawn_while_seeking,
            self.num_scene_reused
        )?;
        for (name, stat) in [
            ("frame", self.frame),
            ("update", self.update),
            ("render", self.render),
            ("ui", self.ui),
            ("present", self.present),
        ] {
            writeln!(
                f,
                "  {name:<8} median_ms={:.1} p95_ms={:.1} max_ms={:.1}",
                stat.median_ms, stat.p95_ms, stat.max_ms
            )?;
        }
        let load = self
            .load_average
            .map_or_else(|| "unknown".to_string(), |l| format!("{l:.2}"));
        writeln!(
            f,
            "  process  cpu_ms_per_frame={:.1} load_average={load}",
            self.cpu_ms_per_frame
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_take_the_nearest_rank() {
        let values: Vec<f32> = (1..=20).map(|v| v as f32).collect();
        assert_eq!(percentile(&values, 0.5), 10.0);
        assert_eq!(percentile(&values, 0.95), 19.0);
        assert_eq!(percentile(&values, 1.0), 20.0);
        assert_eq!(percentile(&[], 0.5), 0.0);
    }

    #[test]
    fn the_warm_up_is_left_out_and_counting_stops_at_the_wanted_number() {
        let mut times = FrameTimes::new(3);
        let t0 = Instant::now();
        for i in 0..20 {
            times.start(t0 + std::time::Duration::from_millis(10 * i));
            let sample = FrameSample {
                frame_ms: i as f32,
                seeking: i < 5,
                scene_reused: i % 2 == 1,
                process_cpu_s: 0.01 * i as f64,
                ..FrameSample::default()
            };
            times.record(sample, i as usize);
        }
        assert!(times.is_done());
        let report = times.report((1280, 800)).expect("samples");
        assert_eq!(report.num_frames, 3);
        // Seeking redraws (the first five) are counted apart; the warm-up follows them.
        let first = 5 + WARM_UP_FRAMES;
        assert_eq!(report.footage, (first, first + 2));
        assert_eq!(report.frame.median_ms, (first + 1) as f32);
        assert_eq!(report.num_drawn_while_seeking, 5);
        assert!((report.cpu_ms_per_frame - 10.0).abs() < 1e-3);
        // Of the measured redraws 10, 11, 12, one stretched the AR view it had drawn before.
        assert_eq!(report.num_scene_reused, 1);
        assert!(report.to_string().contains("frames=3"));
        assert!(report.to_string().contains("scene_reused=1"));
    }
}
