//! Comparing a rendered image with a committed golden under a stated tolerance: on failure the
//! image and a difference map are written beside the golden (`NAME-actual.png`,
//! `NAME-difference.png`); `SYLVA_BLESS=1` rewrites the golden.

use std::path::Path;

use image::{Rgba, RgbaImage};

/// Asserts that `actual` matches `dir/NAME.png`: at most `max_fraction` of the pixels differ by
/// more than `tolerance` in a channel.
pub fn assert_matches_golden(
    dir: &Path,
    name: &str,
    actual: &RgbaImage,
    tolerance: u8,
    max_fraction: f64,
) {
    let path = dir.join(format!("{name}.png"));
    if std::env::var_os("SYLVA_BLESS").is_some() {
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
    assert_eq!(expected.dimensions(), actual.dimensions(), "{name}: size");
    let mut difference = RgbaImage::new(actual.width(), actual.height());
    let mut num_differing = 0usize;
    for (x, y, a) in actual.enumerate_pixels() {
        let e = expected.get_pixel(x, y);
        if a.0.iter().zip(e.0).any(|(p, q)| p.abs_diff(q) > tolerance) {
            num_differing += 1;
            difference.put_pixel(x, y, Rgba([255, 0, 0, 255]));
        } else {
            let l = a.0[0] / 3 + a.0[1] / 3 + a.0[2] / 3;
            difference.put_pixel(x, y, Rgba([l, l, l, 255]));
        }
    }
    let fraction = num_differing as f64 / f64::from(actual.width() * actual.height());
    if fraction > max_fraction {
        actual
            .save(dir.join(format!("{name}-actual.png")))
            .expect("write actual");
        difference
            .save(dir.join(format!("{name}-difference.png")))
            .expect("write difference");
        panic!(
            "{name}: {num_differing} pixels ({:.3} %) differ by more than {tolerance}, allowed {:.3} %; see {name}-actual.png and {name}-difference.png in {}",
            fraction * 100.0,
            max_fraction * 100.0,
            dir.display()
        );
    }
}
