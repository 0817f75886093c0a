//! Tracking time per 640 × 480 frame on TUM fr1_rpy, image decode excluded, OpenCV on one
//! thread. Each iteration tracks the next frame of the sequence with one persistent tracker
//! (restarted, untimed, at the end), so the figure covers LK, pose, local-map search and the
//! keyframe / bundle-adjustment frames in their real proportion. Target: median ≤ 8 ms; after
//! criterion's figures (means per sample) the bench prints the median over every timed frame.
//!
//! `cargo bench -p sylva-tracking --bench track_fr1_rpy` (data: `$SYLVA_DATA`, default
//! `../shared/test-data`).

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::PathBuf;
use std::time::{Duration, Instant};
use sylva_tracking::sequence::{FrameSource, SourceEvent};
use sylva_tracking::{Frame, Tracker, TrackerConfig, TumSequence};

fn data_dir() -> PathBuf {
    std::env::var_os("SYLVA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/test-data"))
}

fn bench_tracking(c: &mut Criterion) {
    sylva_tracking::cv::configure_single_thread();
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
    let new_tracker = || Tracker::new(sequence.camera, TrackerConfig::default()).expect("tracker");
    let mut tracker = new_tracker();
    let mut next = 0;
    // Every timed frame's duration, for the per-frame median the target is stated in (criterion
    // reports statistics of per-sample means, each over many consecutive frames).
    let mut per_frame: Vec<Duration> = Vec::new();
    let mut group = c.benchmark_group("fr1_rpy");
    group
        .sample_size(30)
        .measurement_time(Duration::from_secs(20));
    group.bench_function("track_frame", |b| {
        b.iter_custom(|iterations| {
            let mut total = Duration::ZERO;
            for _ in 0..iterations {
                if next == frames.len() {
                    tracker = new_tracker();
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
    group.finish();
    if !per_frame.is_empty() {
        per_frame.sort_unstable();
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let mean = per_frame.iter().map(|d| ms(*d)).sum::<f64>() / per_frame.len() as f64;
        println!(
            "fr1_rpy/track_frame per frame over {} timed frames: median {:.2} ms, mean {:.2} ms, 90th percentile {:.2} ms",
            per_frame.len(),
            ms(per_frame[per_frame.len() / 2]),
            mean,
            ms(per_frame[per_frame.len() * 9 / 10]),
        );
    }
}

criterion_group!(benches, bench_tracking);
criterion_main!(benches);
