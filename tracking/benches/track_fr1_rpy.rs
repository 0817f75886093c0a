//! Tracking time per 640 × 480 frame on TUM fr1_rpy, image decode excluded, one thread, for
//! each vision backend the build has (OpenCV, portable). Each criterion iteration tracks the
//! next frame of the sequence with one persistent tracker per backend (restarted, untimed, at
//! the end), so the figure covers LK, pose, local-map search and the keyframe /
//! bundle-adjustment frames in their real proportion. Target: median ≤ 8 ms.
//!
//! After criterion's figures (means per sample) the bench runs the backends side by side: the
//! whole sequence once, every frame tracked by each backend's tracker in turn (the order
//! alternating frame by frame, so load changes hit both alike), and prints each backend's
//! median per frame and the portable / OpenCV ratio of medians (issue #22 item 4: ≤ 1.5).
//!
//! `cargo bench -p sylva-tracking --bench track_fr1_rpy` (data: `$SYLVA_DATA`, default
//! `../shared/test-data`); `taskset -c 0` keeps it on one core.

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::PathBuf;
use std::time::{Duration, Instant};
use sylva_tracking::sequence::{FrameSource, SourceEvent};
use sylva_tracking::{Frame, Tracker, TrackerConfig, TumSequence, VisionBackend};

fn data_dir() -> PathBuf {
    std::env::var_os("SYLVA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/test-data"))
}

fn backends() -> Vec<VisionBackend> {
    [VisionBackend::OpenCv, VisionBackend::Portable]
        .into_iter()
        .filter(|b| b.available())
        .collect()
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn median_ms(mut v: Vec<Duration>) -> f64 {
    v.sort_unstable();
    ms(v[v.len() / 2])
}

fn bench_tracking(c: &mut Criterion) {
    let root = data_dir().join("tum_fr1_rpy");
    let sequence = TumSequence::open(&root).unwrap_or_else(|e| panic!("fr1_rpy is needed: {e}"));
    let mut source = sequence.source();
    let mut frames: Vec<Frame> = Vec::new();
    while let Some(event) = source.next_event() {
        if let SourceEvent::Frame(frame) = event {
            frames.push(frame);
        }
    }
    assert!(frames.len() > 700, "only {} frames decoded", frames.len());
    let ups: Vec<_> = frames
        .iter()
        .map(|f| sequence.up_in_camera_at(f.timestamp_s))
        .collect();
    let new_tracker = |backend: VisionBackend| {
        let config = TrackerConfig {
            backend,
            ..TrackerConfig::default()
        };
        Tracker::new(sequence.camera, config).expect("tracker")
    };
    let mut group = c.benchmark_group("fr1_rpy");
    group
        .sample_size(30)
        .measurement_time(Duration::from_secs(20));
    for backend in backends() {
        let mut tracker = new_tracker(backend);
        let mut next = 0;
        // Every timed frame's duration, for the per-frame median the target is stated in
        // (criterion reports statistics of per-sample means, each over many frames).
        let mut per_frame: Vec<Duration> = Vec::new();
        group.bench_function(format!("track_frame/{}", backend.name()), |b| {
            b.iter_custom(|iterations| {
                let mut total = Duration::ZERO;
                for _ in 0..iterations {
                    if next == frames.len() {
                        tracker = new_tracker(backend);
                        next = 0;
                    }
                    let start = Instant::now();
                    let output = tracker.track(&frames[next], ups[next].map(|u| u * 9.81));
                    let elapsed = start.elapsed();
                    total += elapsed;
                    per_frame.push(elapsed);
                    std::hint::black_box(output.expect("tracking"));
                    next += 1;
                }
                total
            })
        });
        if !per_frame.is_empty() {
            let n = per_frame.len();
            let mean = per_frame.iter().map(|d| ms(*d)).sum::<f64>() / n as f64;
            per_frame.sort_unstable();
            println!(
                "fr1_rpy/track_frame/{} per frame over {n} timed frames: median {:.2} ms, mean {mean:.2} ms, 90th percentile {:.2} ms",
                backend.name(),
                ms(per_frame[n / 2]),
                ms(per_frame[n * 9 / 10]),
            );
        }
    }
    group.finish();

    // Side by side: one pass over the sequence, each frame tracked by every backend in turn.
    let backends = backends();
    let mut trackers: Vec<Tracker> = backends.iter().map(|b| new_tracker(*b)).collect();
    let mut times: Vec<Vec<Duration>> = vec![Vec::with_capacity(frames.len()); backends.len()];
    for (i, frame) in frames.iter().enumerate() {
        for k in 0..backends.len() {
            let k = if i % 2 == 0 {
                k
            } else {
                backends.len() - 1 - k
            };
            let start = Instant::now();
            let output = trackers[k].track(frame, ups[i].map(|u| u * 9.81));
            times[k].push(start.elapsed());
            std::hint::black_box(output.expect("tracking"));
        }
    }
    let medians: Vec<f64> = times.into_iter().map(median_ms).collect();
    for (backend, median) in backends.iter().zip(&medians) {
        println!(
            "fr1_rpy side by side, {}: median {median:.2} ms per frame over {} frames",
            backend.name(),
            frames.len()
        );
    }
    if let [opencv, portable] = medians[..] {
        println!(
            "fr1_rpy side by side: portable / OpenCV median ratio {:.2}",
            portable / opencv
        );
    }
}

criterion_group!(benches, bench_tracking);
criterion_main!(benches);
