//! Learns the portable ORB's test pattern and compares descriptors on real footage.
//!
//! `learn_orb_pattern learn SEQUENCE OUT.rs`: ORB's greedy search (Rublee et al. 2011, §4.3,
//! [`sylva_tracking::vision::orb::learn_pattern`]) over the steered patches of the Shi–Tomasi
//! corners of every frame of a TUM sequence; writes the pattern as Rust
//! (`tracking/src/vision/orb_pattern.rs` was made from `tum_fr3_cabinet`).
//!
//! `learn_orb_pattern compare SEQUENCE`: on frame pairs `GAP` frames apart (env, default 5),
//! corners of the first followed into the second by Lucas–Kanade give true correspondences;
//! each descriptor (the committed learned pattern, BRIEF's Gaussian pattern as the portable
//! backend had it, OpenCV's ORB) is scored by the true pairs' median Hamming distance, the
//! share of true pairs within 40 bits (keyframe re-finding's limit) and, matching every
//! described corner of the first frame against all of the second's with the tracker's ratio
//! test, how many matches are accepted and how many of those are right (within 2 px).

use glam::Vec2;
use std::path::Path;
use sylva_tracking::sequence::decode_gray;
use sylva_tracking::vision::{self, Orb, SplitMix64};
use sylva_tracking::{GrayImage, TumSequence, lk};

fn frames(root: &Path) -> (TumSequence, Vec<GrayImage>) {
    let sequence = TumSequence::open(root).unwrap_or_else(|e| panic!("{}: {e}", root.display()));
    let images = sequence
        .frames
        .iter()
        .filter_map(|f| decode_gray(&f.path, &sequence.camera).ok())
        .collect();
    (sequence, images)
}

fn learn(root: &Path, out: &Path) {
    let (_, images) = frames(root);
    let mut samples = Vec::new();
    for image in &images {
        let corners = vision::detect_corners(image, 600, 10.0, &[]);
        samples.extend(vision::orb::training_samples(image, &corners));
    }
    eprintln!(
        "{} frames, {} training patches",
        images.len(),
        samples.len()
    );
    let pattern = vision::orb::learn_pattern(&samples, 256).expect("a pattern");
    let mut text = String::new();
    text += "//! The portable ORB's 256 test pairs `[x1, y1, x2, y2]`, learned by\n";
    text +=
        "//! [`super::orb::learn_pattern`] on the steered patches of the Shi–Tomasi corners of\n";
    text += &format!(
        "//! {} ({} frames, {} patches); made by `cargo run --release -p sylva-tracking\n",
        root.file_name().map_or("?".into(), |n| n.to_string_lossy()),
        images.len(),
        samples.len()
    );
    text += "//! --example learn_orb_pattern -- learn SEQUENCE OUT.rs`. Changing it changes every descriptor.\n\n";
    text += "#[rustfmt::skip]\npub const LEARNED_PATTERN: [[i8; 4]; 256] = [\n";
    for [a, b] in &pattern {
        text += &format!("    [{}, {}, {}, {}],\n", a.0, a.1, b.0, b.1);
    }
    text += "];\n";
    std::fs::write(out, text).expect("pattern written");
}

/// BRIEF's isotropic Gaussian pattern (σ = 31 / 5, inside a disc of radius 13) as the portable
/// backend generated it before the learned one.
fn brief_pattern() -> Vec<[(i8, i8); 2]> {
    let mut rng = SplitMix64::new(0x0B0B_5EED);
    let sigma = 31.0 / 5.0;
    let mut point = || loop {
        let (u1, u2) = (rng.unit().max(1e-300), rng.unit());
        let radius = (-2.0 * u1.ln()).sqrt() * sigma;
        let theta = std::f64::consts::TAU * u2;
        let (x, y) = (radius * theta.cos(), radius * theta.sin());
        if x * x + y * y <= 13.0 * 13.0 {
            break (x.round() as i8, y.round() as i8);
        }
    };
    let mut pattern = Vec::new();
    while pattern.len() < 256 {
        let (a, b) = (point(), point());
        if a != b {
            pattern.push([a, b]);
        }
    }
    pattern
}

type Describe<'a> = Box<dyn FnMut(&GrayImage, &[Vec2]) -> Vec<Option<vision::Descriptor>> + 'a>;

fn compare(root: &Path) {
    let gap: usize = std::env::var("GAP")
        .ok()
        .and_then(|g| g.parse().ok())
        .unwrap_or(5);
    let (_, images) = frames(root);
    let learned = Orb::new();
    let brief = Orb::with_pattern(&brief_pattern());
    let mut describers: Vec<(&str, Describe)> = vec![
        (
            "learned",
            Box::new(|i: &GrayImage, p: &[Vec2]| learned.describe(i, p)),
        ),
        (
            "brief",
            Box::new(|i: &GrayImage, p: &[Vec2]| brief.describe(i, p)),
        ),
    ];
    #[cfg(feature = "opencv")]
    {
        let mut cv_orb = sylva_tracking::cv::OrbFeatures::new(1000).expect("OpenCV ORB");
        describers.push((
            "opencv",
            Box::new(move |i: &GrayImage, p: &[Vec2]| cv_orb.describe(i, p).expect("OpenCV")),
        ));
    }
    for (name, describe) in describers.iter_mut() {
        let (mut true_d, mut accepted, mut right) = (Vec::new(), 0usize, 0usize);
        for start in (0..images.len().saturating_sub(gap)).step_by(10) {
            let (a, b) = (&images[start], &images[start + gap]);
            let corners = vision::detect_corners(a, 500, 10.0, &[]);
            let moved = lk::track_points(
                &lk::Pyramid::build(a),
                &lk::Pyramid::build(b),
                &corners,
                None,
                lk::LkOptions {
                    levels: 3,
                    max_fb_error_px: Some(1.0),
                },
            );
            let second = vision::detect_corners(b, 500, 10.0, &[]);
            let (da, db_tracked, db) = (
                describe(a, &corners),
                describe(
                    b,
                    &moved
                        .iter()
                        .map(|m| m.unwrap_or(Vec2::ZERO))
                        .collect::<Vec<_>>(),
                ),
                describe(b, &second),
            );
            for k in 0..corners.len() {
                let (Some(x), Some(m)) = (da[k], moved[k]) else {
                    continue;
                };
                if let Some(y) = db_tracked[k] {
                    true_d.push(vision::hamming(&x, &y));
                }
                let mut nearest = vision::NearestTwo::default();
                for (j, d) in db.iter().enumerate() {
                    if let Some(d) = d {
                        nearest.offer(vision::hamming(&x, d), j);
                    }
                }
                if let Some((j, _)) = nearest.accepted(40, 0.8) {
                    accepted += 1;
                    if second[j].distance(m) <= 2.0 {
                        right += 1;
                    }
                }
            }
        }
        true_d.sort_unstable();
        let within = true_d.iter().filter(|&&d| d <= 40).count();
        println!(
            "{name:8} true pairs {} median {} within 40: {:.3}; ratio-test matches {accepted}, right {:.3}",
            true_d.len(),
            true_d[true_d.len() / 2],
            within as f64 / true_d.len() as f64,
            right as f64 / accepted.max(1) as f64
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(String::as_str) {
        Some("learn") if args.len() == 4 => learn(Path::new(&args[2]), Path::new(&args[3])),
        Some("compare") if args.len() == 3 => compare(Path::new(&args[2])),
        _ => {
            eprintln!("usage: learn_orb_pattern learn SEQUENCE OUT.rs | compare SEQUENCE");
            std::process::exit(2);
        }
    }
}
