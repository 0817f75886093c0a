//! The golden-image comparison shared by the tests that render (`golden.rs`,
//! `phone_screenshots.rs`, `garden_session.rs`).
//!
//! Tolerance: a pixel differs when any channel differs by more than 12 (of 255); an image matches
//! when at most 0.5 % of its pixels differ. On a mismatch the test writes `NAME-actual.png` and
//! `NAME-difference.png` next to the golden. `SYLVA_BLESS=1` rewrites the goldens. A test may
//! leave out regions that show wall-clock figures.

#![allow(dead_code)]

use std::path::PathBuf;

use image::{Rgba, RgbaImage};

pub const CHANNEL_TOLERANCE: u8 = 12;
pub const MAX_DIFFERING_FRACTION: f64 = 0.005;

pub fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

pub fn differs(a: &Rgba<u8>, b: &Rgba<u8>, tolerance: u8) -> bool {
    a.0.iter()
        .zip(b.0.iter())
        .any(|(x, y)| x.abs_diff(*y) > tolerance)
}

/// Compares with the golden `name`.png under the stated tolerance.
pub fn assert_matches_golden(name: &str, actual: &RgbaImage) {
    assert_matches_golden_except(name, actual, &[]);
}

/// [`assert_matches_golden`] with the pixels inside `ignored` (x, y, width, height) left out
/// (what shows wall-clock figures).
pub fn assert_matches_golden_except(name: &str, actual: &RgbaImage, ignored: &[[u32; 4]]) {
    let is_ignored = |x: u32, y: u32| {
        ignored
            .iter()
            .any(|[ix, iy, w, h]| (*ix..ix + w).contains(&x) && (*iy..iy + h).contains(&y))
    };
    let dir = golden_dir();
    let path = dir.join(format!("{name}.png"));
    if std::env::var_os("SYLVA_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap_or(&dir)).expect("golden dir");
        actual.save(&path).expect("write golden");
        return;
    }
    let expected = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "golden {} unreadable ({e}); run with SYLVA_BLESS=1 to create it",
                path.display()
            )
        })
        .to_rgba8();
    assert_eq!(
        expected.dimensions(),
        actual.dimensions(),
        "{name}: size differs"
    );
    let mut difference = RgbaImage::new(actual.width(), actual.height());
    let mut num_differing = 0usize;
    for (x, y, a) in actual.enumerate_pixels() {
        let e = expected.get_pixel(x, y);
        if !is_ignored(x, y) && differs(a, e, CHANNEL_TOLERANCE) {
            num_differing += 1;
            difference.put_pixel(x, y, Rgba([255, 0, 0, 255]));
        } else {
            let l = a.0[0] / 3 + a.0[1] / 3 + a.0[2] / 3;
            difference.put_pixel(x, y, Rgba([l, l, l, 255]));
        }
    }
    let fraction = num_differing as f64 / (actual.width() * actual.height()) as f64;
    if fraction > MAX_DIFFERING_FRACTION {
        actual
            .save(dir.join(format!("{name}-actual.png")))
            .expect("write actual");
        difference
            .save(dir.join(format!("{name}-difference.png")))
            .expect("write difference");
        panic!(
            "{name}: {num_differing} pixels ({:.3} %) differ by more than {CHANNEL_TOLERANCE}, allowed {:.3} %; see {name}-actual.png and {name}-difference.png in {}",
            fraction * 100.0,
            MAX_DIFFERING_FRACTION * 100.0,
            dir.display()
        );
    }
}
