//! Pyramidal Lucas–Kanade optical flow (Bouguet's formulation), written for the tracker's
//! budget: the frame's pyramid is built once and shared by every call (and by the keyframe that
//! keeps it), each point solves a 2 × 2 system per level with the template's gradients (the
//! Hessian is built once per level), and the window's bilinear weights are the same for all its
//! pixels, so a window is a few vector multiply-adds per row. The template's Scharr gradients
//! are taken on the interpolated patch: interpolation with fixed weights and the Scharr filter
//! are both shift-invariant linear filters, so this equals interpolating gradient images, which
//! the pyramid therefore does not store.
//!
//! Sums run over eight fixed lanes, so results are bit-identical whatever vector width the
//! compiler or the CPU offers (sessions replay identically across machines); an AVX2 build of
//! the same code is picked at run time where the CPU has it.

mod pyramid;

pub use pyramid::{Pyramid, PyramidScratch};

use glam::Vec2;

/// Window side, pixels (odd).
pub const WINDOW: usize = 21;
/// Pyramid levels above the base.
pub const LEVELS: usize = 3;
const HALF: usize = WINDOW / 2;
/// Border added around every level so a window, with one pixel more on each side for the
/// gradients and one for interpolation, may hang over the image edge by up to half its size.
const PAD: usize = HALF + 3;
/// Side of the template patch sampled with its one-pixel gradient border.
const OUTER: usize = WINDOW + 2;
/// Rows are computed in whole lanes: this many samples per row (the extra ones land where the
/// next row then writes, or in the zero tail), read from this many more columns of each level.
const ROW: usize = OUTER.div_ceil(LANES) * LANES;
const SLACK: usize = ROW - WINDOW;
/// Samples of a window.
const AREA: usize = WINDOW * WINDOW;
/// Lanes of every sum (fixed, so results do not depend on the vector width).
const LANES: usize = 8;
/// A window's samples in whole lanes.
const CHUNKS: usize = AREA.div_ceil(LANES);

/// A window's samples, row-major, in whole lanes (the tail is zero).
type Patch = [[f32; LANES]; CHUNKS];
/// Iterations per level and the step (pixels of the level) that ends them.
const MAX_ITERATIONS: usize = 20;
const EPSILON_PX: f32 = 0.03;
/// Smallest eigenvalue of the window's structure tensor per pixel ((grey levels / pixel)²)
/// for a trackable window; below it a level is skipped, and at the base the point is lost.
const MIN_EIGENVALUE: f32 = 0.1;

/// How a set of points is followed by [`track_points`].
#[derive(Clone, Copy, Debug)]
pub struct LkOptions {
    /// Pyramid levels above the base searched (coarse to fine); fewer when the guess is good.
    pub levels: usize,
    /// Forward-backward check: a track survives when tracking it back lands within this many
    /// pixels of where it started. None skips the backward pass (half the cost) where another
    /// test (a reprojection gate) rejects wrong matches.
    pub max_fb_error_px: Option<f32>,
}

/// Bilinear samples of a `SIDE`-pixel window of `plane` starting at `start` into `out`
/// (row-major, `SIDE` per row). Each row is computed [`ROW`] wide, the samples past `SIDE`
/// overwritten by the next row, so `out` holds `ROW − SIDE` floats of slack.
#[inline(always)]
fn sample<const SIDE: usize>(
    plane: &[f32],
    stride: usize,
    start: usize,
    w: [f32; 4],
    out: &mut [f32],
) {
    for r in 0..SIDE {
        let top = &plane[start + r * stride..][..ROW + 1];
        let bottom = &plane[start + (r + 1) * stride..][..ROW + 1];
        let row = &mut out[r * SIDE..][..ROW];
        for c in 0..ROW {
            row[c] = w[0] * top[c] + w[1] * top[c + 1] + w[2] * bottom[c] + w[3] * bottom[c + 1];
        }
    }
}

/// The vector kernels of a solve. [`Portable`] is plain code the compiler vectorises as the
/// target allows; [`Avx2`] spells the same operations, in the same order, with AVX2 intrinsics.
/// Both give bit-identical results.
trait Kernel {
    /// Σ a·b over the window, in eight fixed lanes.
    fn dot(a: &Patch, b: &Patch) -> f32;

    /// The template (centre of `outer`, a patch of side [`OUTER`]) and its Scharr gradients,
    /// (3 10 3) across and (−1 0 1) along, over 32: grey levels per pixel. The tails past the
    /// window stay zero.
    fn gradients(outer: &[f32], t: &mut Patch, gx: &mut Patch, gy: &mut Patch);

    /// Σ j·gx and Σ j·gy over the window.
    #[inline(always)]
    fn dot2(j: &Patch, gx: &Patch, gy: &Patch) -> (f32, f32) {
        (Self::dot(j, gx), Self::dot(j, gy))
    }
}

struct Portable;

impl Kernel for Portable {
    #[inline(always)]
    fn dot(a: &Patch, b: &Patch) -> f32 {
        let mut acc = [0.0f32; LANES];
        for c in 0..CHUNKS {
            for l in 0..LANES {
                acc[l] += a[c][l] * b[c][l];
            }
        }
        lane_sum(acc)
    }

    #[inline(always)]
    fn gradients(outer: &[f32], t: &mut Patch, gx: &mut Patch, gy: &mut Patch) {
        let (t, gx, gy) = (
            t.as_flattened_mut(),
            gx.as_flattened_mut(),
            gy.as_flattened_mut(),
        );
        for r in 0..WINDOW {
            let up = &outer[r * OUTER..][..ROW + 2];
            let mid = &outer[(r + 1) * OUTER..][..ROW + 2];
            let down = &outer[(r + 2) * OUTER..][..ROW + 2];
            let (t, gx, gy) = (
                &mut t[r * WINDOW..][..ROW],
                &mut gx[r * WINDOW..][..ROW],
                &mut gy[r * WINDOW..][..ROW],
            );
            for c in 0..ROW {
                t[c] = mid[c + 1];
                gx[c] = (3.0 * (up[c + 2] - up[c])
                    + 10.0 * (mid[c + 2] - mid[c])
                    + 3.0 * (down[c + 2] - down[c]))
                    * (1.0 / 32.0);
                gy[c] = (3.0 * (down[c] - up[c])
                    + 10.0 * (down[c + 1] - up[c + 1])
                    + 3.0 * (down[c + 2] - up[c + 2]))
                    * (1.0 / 32.0);
            }
        }
        // The last row's extra samples fall in the tail, which must stay zero.
        for plane in [t, gx, gy] {
            plane[AREA..].fill(0.0);
        }
    }
}

#[cfg(target_arch = "x86_64")]
struct Avx2;

#[cfg(target_arch = "x86_64")]
impl Kernel for Avx2 {
    #[inline(always)]
    fn dot(a: &Patch, b: &Patch) -> f32 {
        // SAFETY: `Avx2` is only used by `track_all_avx2`, called once AVX2 was detected.
        unsafe { avx2::dot(a, b) }
    }

    #[inline(always)]
    fn gradients(outer: &[f32], t: &mut Patch, gx: &mut Patch, gy: &mut Patch) {
        // SAFETY: as for `dot`.
        unsafe { avx2::gradients(outer, t, gx, gy) }
    }

    #[inline(always)]
    fn dot2(j: &Patch, gx: &Patch, gy: &Patch) -> (f32, f32) {
        // SAFETY: as for `dot`.
        unsafe { avx2::dot2(j, gx, gy) }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{AREA, CHUNKS, OUTER, Patch, ROW, WINDOW, lane_sum};
    use std::arch::x86_64::*;

    #[target_feature(enable = "avx2")]
    pub(super) fn dot(a: &Patch, b: &Patch) -> f32 {
        let mut acc = _mm256_setzero_ps();
        for c in 0..CHUNKS {
            // SAFETY: each chunk is eight floats.
            let (x, y) = unsafe {
                (
                    _mm256_loadu_ps(a[c].as_ptr()),
                    _mm256_loadu_ps(b[c].as_ptr()),
                )
            };
            acc = _mm256_add_ps(acc, _mm256_mul_ps(x, y));
        }
        let mut lanes = [0.0f32; 8];
        // SAFETY: `lanes` holds eight floats.
        unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), acc) };
        lane_sum(lanes)
    }

    /// [`dot`] of `j` with `gx` and with `gy` in one pass: two independent chains of adds,
    /// each in the order of its own [`dot`].
    #[target_feature(enable = "avx2")]
    pub(super) fn dot2(j: &Patch, gx: &Patch, gy: &Patch) -> (f32, f32) {
        let (mut ax, mut ay) = (_mm256_setzero_ps(), _mm256_setzero_ps());
        for c in 0..CHUNKS {
            // SAFETY: each chunk is eight floats.
            let (v, x, y) = unsafe {
                (
                    _mm256_loadu_ps(j[c].as_ptr()),
                    _mm256_loadu_ps(gx[c].as_ptr()),
                    _mm256_loadu_ps(gy[c].as_ptr()),
                )
            };
            ax = _mm256_add_ps(ax, _mm256_mul_ps(v, x));
            ay = _mm256_add_ps(ay, _mm256_mul_ps(v, y));
        }
        let (mut lx, mut ly) = ([0.0f32; 8], [0.0f32; 8]);
        // SAFETY: both arrays hold eight floats.
        unsafe {
            _mm256_storeu_ps(lx.as_mut_ptr(), ax);
            _mm256_storeu_ps(ly.as_mut_ptr(), ay);
        }
        (lane_sum(lx), lane_sum(ly))
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn gradients(outer: &[f32], t: &mut Patch, gx: &mut Patch, gy: &mut Patch) {
        let (t, gx, gy) = (
            t.as_flattened_mut(),
            gx.as_flattened_mut(),
            gy.as_flattened_mut(),
        );
        let (three, ten, scale) = (
            _mm256_set1_ps(3.0),
            _mm256_set1_ps(10.0),
            _mm256_set1_ps(1.0 / 32.0),
        );
        for r in 0..WINDOW {
            let up = &outer[r * OUTER..][..ROW + 2];
            let mid = &outer[(r + 1) * OUTER..][..ROW + 2];
            let down = &outer[(r + 2) * OUTER..][..ROW + 2];
            let (t, gx, gy) = (
                &mut t[r * WINDOW..][..ROW],
                &mut gx[r * WINDOW..][..ROW],
                &mut gy[r * WINDOW..][..ROW],
            );
            for c in (0..ROW).step_by(8) {
                // SAFETY: the rows hold ROW + 2 floats and the outputs ROW, so every load of
                // eight at c, c + 1 or c + 2 and every store at c is in bounds.
                unsafe {
                    let load = |row: &[f32], k: usize| _mm256_loadu_ps(row.as_ptr().add(c + k));
                    let (u0, u1, u2) = (load(up, 0), load(up, 1), load(up, 2));
                    let (m0, m1, m2) = (load(mid, 0), load(mid, 1), load(mid, 2));
                    let (d0, d1, d2) = (load(down, 0), load(down, 1), load(down, 2));
                    let x = _mm256_add_ps(
                        _mm256_add_ps(
                            _mm256_mul_ps(three, _mm256_sub_ps(u2, u0)),
                            _mm256_mul_ps(ten, _mm256_sub_ps(m2, m0)),
                        ),
                        _mm256_mul_ps(three, _mm256_sub_ps(d2, d0)),
                    );
                    let y = _mm256_add_ps(
                        _mm256_add_ps(
                            _mm256_mul_ps(three, _mm256_sub_ps(d0, u0)),
                            _mm256_mul_ps(ten, _mm256_sub_ps(d1, u1)),
                        ),
                        _mm256_mul_ps(three, _mm256_sub_ps(d2, u2)),
                    );
                    _mm256_storeu_ps(t.as_mut_ptr().add(c), m1);
                    _mm256_storeu_ps(gx.as_mut_ptr().add(c), _mm256_mul_ps(x, scale));
                    _mm256_storeu_ps(gy.as_mut_ptr().add(c), _mm256_mul_ps(y, scale));
                }
            }
        }
        for plane in [t, gx, gy] {
            plane[AREA..].fill(0.0);
        }
    }
}

#[inline(always)]
fn lane_sum(acc: [f32; LANES]) -> f32 {
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]))
}

/// Working memory of one point's solve.
struct Scratch {
    outer: [f32; OUTER * OUTER + ROW],
    template: Patch,
    grad_x: Patch,
    grad_y: Patch,
    moved: Patch,
}

impl Scratch {
    fn new() -> Box<Self> {
        Box::new(Self {
            outer: [0.0; OUTER * OUTER + ROW],
            template: [[0.0; LANES]; CHUNKS],
            grad_x: [[0.0; LANES]; CHUNKS],
            grad_y: [[0.0; LANES]; CHUNKS],
            moved: [[0.0; LANES]; CHUNKS],
        })
    }
}

/// Where `from` (base pixels in `prev`) lies in `next`, starting the search at `guess`.
#[inline(always)]
fn track_one<K: Kernel>(
    prev: &Pyramid,
    next: &Pyramid,
    from: Vec2,
    guess: Vec2,
    levels: usize,
    s: &mut Scratch,
) -> Option<Vec2> {
    let top = levels.min(LEVELS);
    let mut flow = (guess - from) / (1u32 << top) as f32;
    for level in (0..=top).rev() {
        let scale = 1.0 / (1u32 << level) as f32;
        let (lp, ln) = (&prev.levels[level], &next.levels[level]);
        let at = from * scale;
        let Some((start, w)) = lp.window(at, OUTER) else {
            if level == 0 {
                return None;
            }
            flow *= 2.0;
            continue;
        };
        sample::<OUTER>(&lp.image, lp.stride, start, w, &mut s.outer);
        K::gradients(&s.outer, &mut s.template, &mut s.grad_x, &mut s.grad_y);
        let (a11, a12, a22) = (
            K::dot(&s.grad_x, &s.grad_x),
            K::dot(&s.grad_x, &s.grad_y),
            K::dot(&s.grad_y, &s.grad_y),
        );
        let min_eigen = (a11 + a22 - ((a11 - a22) * (a11 - a22) + 4.0 * a12 * a12).sqrt())
            / (2.0 * AREA as f32);
        let det = a11 * a22 - a12 * a12;
        if min_eigen.is_nan() || min_eigen < MIN_EIGENVALUE || det <= f32::EPSILON {
            if level == 0 {
                return None;
            }
            flow *= 2.0;
            continue;
        }
        let inv_det = 1.0 / det;
        // Σ (J − T)·∇T = Σ J·∇T − Σ T·∇T; the second sum is fixed for the level.
        let (tx, ty) = K::dot2(&s.template, &s.grad_x, &s.grad_y);
        let mut previous_step = Vec2::ZERO;
        for iteration in 0..MAX_ITERATIONS {
            let Some((start, w)) = ln.window(at + flow, WINDOW) else {
                if level == 0 {
                    return None;
                }
                break;
            };
            sample::<WINDOW>(&ln.image, ln.stride, start, w, s.moved.as_flattened_mut());
            let (jx, jy) = K::dot2(&s.moved, &s.grad_x, &s.grad_y);
            let (bx, by) = (jx - tx, jy - ty);
            let step = Vec2::new(a12 * by - a22 * bx, a12 * bx - a11 * by) * inv_det;
            flow += step;
            if step.length_squared() <= EPSILON_PX * EPSILON_PX {
                break;
            }
            // Oscillating between two positions: settle half-way.
            if iteration > 0 && (step + previous_step).length_squared() < 1e-4 {
                flow -= step * 0.5;
                break;
            }
            previous_step = step;
        }
        if level > 0 {
            flow *= 2.0;
        }
    }
    let found = from + flow;
    let (width, height) = next.size();
    (found.is_finite()
        && found.x >= 0.0
        && found.y >= 0.0
        && found.x <= (width - 1) as f32
        && found.y <= (height - 1) as f32)
        .then_some(found)
}

#[inline(always)]
fn track_all<K: Kernel>(
    prev: &Pyramid,
    next: &Pyramid,
    from: &[Vec2],
    guess: &[Vec2],
    levels: usize,
) -> Vec<Option<Vec2>> {
    let mut scratch = Scratch::new();
    let mut found = Vec::with_capacity(from.len());
    for k in 0..from.len().min(guess.len()) {
        found.push(track_one::<K>(
            prev,
            next,
            from[k],
            guess[k],
            levels,
            &mut scratch,
        ));
    }
    found
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn track_all_avx2(
    prev: &Pyramid,
    next: &Pyramid,
    from: &[Vec2],
    guess: &[Vec2],
    levels: usize,
) -> Vec<Option<Vec2>> {
    track_all::<Avx2>(prev, next, from, guess, levels)
}

fn lk(
    prev: &Pyramid,
    next: &Pyramid,
    from: &[Vec2],
    guess: &[Vec2],
    levels: usize,
) -> Vec<Option<Vec2>> {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        return unsafe { track_all_avx2(prev, next, from, guess, levels) };
    }
    track_all::<Portable>(prev, next, from, guess, levels)
}

/// Pyramidal Lucas–Kanade from `prev` to `next`, optionally with a forward-backward check.
/// `guess` seeds the forward search (e.g. projections of map points). A point is None when its
/// window is untrackable (too little texture), leaves the image, or fails the check.
pub fn track_points(
    prev: &Pyramid,
    next: &Pyramid,
    from: &[Vec2],
    guess: Option<&[Vec2]>,
    options: LkOptions,
) -> Vec<Option<Vec2>> {
    let guess = guess.unwrap_or(from);
    let forward = lk(prev, next, from, guess, options.levels);
    check_forward_backward(prev, next, from, forward, options)
}

/// [`track_points`] for points whose true position is known to lie within `max_from_guess_px`
/// of their guess (a reprojection gate): a forward result farther than that is lost at once,
/// without the backward pass it would pay for nothing (in the local-map search most forward
/// results land outside the gate). Gives exactly what gating the result of [`track_points`]
/// would.
pub fn track_points_near_guess(
    prev: &Pyramid,
    next: &Pyramid,
    from: &[Vec2],
    guess: &[Vec2],
    max_from_guess_px: f32,
    options: LkOptions,
) -> Vec<Option<Vec2>> {
    let mut forward = lk(prev, next, from, guess, options.levels);
    for (found, seed) in forward.iter_mut().zip(guess) {
        if found.is_some_and(|f| f.distance(*seed) >= max_from_guess_px) {
            *found = None;
        }
    }
    check_forward_backward(prev, next, from, forward, options)
}

/// The forward-backward check of `options` on `forward` results, if it asks for one.
fn check_forward_backward(
    prev: &Pyramid,
    next: &Pyramid,
    from: &[Vec2],
    forward: Vec<Option<Vec2>>,
    options: LkOptions,
) -> Vec<Option<Vec2>> {
    let Some(max_fb_error_px) = options.max_fb_error_px else {
        return forward;
    };
    let checked: Result<_, std::convert::Infallible> =
        forward_backward(from, forward, max_fb_error_px, |there, back_guess| {
            Ok(lk(next, prev, there, back_guess, options.levels))
        });
    checked.unwrap_or_else(|never| match never {})
}

/// The forward-backward check shared by this tracker and OpenCV's ([`crate::cv`]): the points
/// found `forward` are tracked back by `backward(found, seeds)` (seeded at their origins), and
/// a point survives when it returns within `max_fb_error_px` of where it started.
pub fn forward_backward<E>(
    from: &[Vec2],
    forward: Vec<Option<Vec2>>,
    max_fb_error_px: f32,
    backward: impl FnOnce(&[Vec2], &[Vec2]) -> Result<Vec<Option<Vec2>>, E>,
) -> Result<Vec<Option<Vec2>>, E> {
    let alive: Vec<usize> = (0..from.len()).filter(|&i| forward[i].is_some()).collect();
    let there: Vec<Vec2> = alive.iter().filter_map(|&i| forward[i]).collect();
    let back_guess: Vec<Vec2> = alive.iter().map(|&i| from[i]).collect();
    let back = backward(&there, &back_guess)?;
    let mut result = vec![None; from.len()];
    for (k, &i) in alive.iter().enumerate() {
        if let Some(b) = back[k]
            && b.distance(from[i]) <= max_fb_error_px
        {
            result[i] = forward[i];
        }
    }
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::GrayImage;

    /// Smooth value noise on a lattice of `cell` pixels, continuous in (u, v).
    fn noise(u: f32, v: f32, cell: f32, seed: u32) -> f32 {
        let lattice = |i: i32, j: i32| -> f32 {
            let mut h = (i as u32).wrapping_mul(0x9E37_79B1) ^ (j as u32).wrapping_mul(0x85EB_CA77);
            h ^= seed.wrapping_mul(0xC2B2_AE3D);
            h = (h ^ (h >> 15)).wrapping_mul(0x2C1B_3C6D);
            h ^= h >> 12;
            (h & 0xFFFF) as f32 / 65535.0
        };
        let (x, y) = (u / cell, v / cell);
        let (i, j) = (x.floor(), y.floor());
        let smooth = |t: f32| t * t * (3.0 - 2.0 * t);
        let (a, b) = (smooth(x - i), smooth(y - j));
        let (i, j) = (i as i32, j as i32);
        let top = lattice(i, j) * (1.0 - a) + lattice(i + 1, j) * a;
        let bottom = lattice(i, j + 1) * (1.0 - a) + lattice(i + 1, j + 1) * a;
        top * (1.0 - b) + bottom * b
    }

    /// A non-repeating texture sampled at `(x, y) + shift` (so content moves by −shift).
    fn texture(width: u32, height: u32, shift: Vec2) -> GrayImage {
        let mut pixels = Vec::with_capacity((width * height) as usize);
        for y in 0..height {
            for x in 0..width {
                let (u, v) = (x as f32 + shift.x, y as f32 + shift.y);
                let value = 30.0
                    + 120.0 * noise(u, v, 11.0, 1)
                    + 70.0 * noise(u, v, 4.0, 2)
                    + 30.0 * noise(u, v, 2.5, 3);
                pixels.push(value.clamp(0.0, 255.0) as u8);
            }
        }
        GrayImage::from_pixels(width, height, pixels).expect("size matches")
    }

    fn grid() -> Vec<Vec2> {
        let mut points = Vec::new();
        for y in (60..200).step_by(35) {
            for x in (60..260).step_by(35) {
                points.push(Vec2::new(x as f32, y as f32));
            }
        }
        points
    }

    fn track(shift: Vec2, levels: usize) -> Vec<Option<Vec2>> {
        let prev = Pyramid::build(&texture(320, 240, Vec2::ZERO));
        let next = Pyramid::build(&texture(320, 240, shift));
        let options = LkOptions {
            levels,
            max_fb_error_px: Some(1.0),
        };
        track_points(&prev, &next, &grid(), None, options)
    }

    #[test]
    fn gating_at_the_guess_gives_exactly_the_gated_tracks() {
        let shift = Vec2::new(2.2, 1.4);
        let prev = Pyramid::build(&texture(320, 240, Vec2::ZERO));
        let next = Pyramid::build(&texture(320, 240, shift));
        let from = grid();
        // Every other guess is the true position, the rest are 9 pixels off: LK from a far
        // guess with one coarse level lands either on the point (far from its guess) or astray.
        let guess: Vec<Vec2> = from
            .iter()
            .enumerate()
            .map(|(i, p)| *p - shift + Vec2::new(if i % 2 == 0 { 0.0 } else { 9.0 }, 0.0))
            .collect();
        let options = LkOptions {
            levels: 1,
            max_fb_error_px: Some(1.0),
        };
        let gated = track_points_near_guess(&prev, &next, &from, &guess, 6.0, options);
        let filtered: Vec<Option<Vec2>> = track_points(&prev, &next, &from, Some(&guess), options)
            .into_iter()
            .zip(&guess)
            .map(|(found, seed)| found.filter(|f| f.distance(*seed) < 6.0))
            .collect();
        assert_eq!(gated, filtered);
        let kept = gated.iter().filter(|g| g.is_some()).count();
        assert!(kept >= from.len() / 2 - 1, "{kept} of {}", from.len());
        assert!(kept < from.len(), "the far guesses are gated");
    }

    #[test]
    fn a_subpixel_shift_is_recovered_to_a_twentieth_of_a_pixel() {
        let shift = Vec2::new(1.3, -0.6);
        let found = track(shift, 3);
        for (from, to) in grid().iter().zip(&found) {
            let to = to.expect("textured window tracks");
            assert!((to - (*from - shift)).length() < 0.05, "{from} -> {to}");
        }
    }

    #[test]
    fn the_pyramid_follows_a_motion_far_wider_than_the_window() {
        let shift = Vec2::new(-27.5, 14.25);
        let found = track(shift, 3);
        let good = grid()
            .iter()
            .zip(&found)
            .filter(|(from, to)| to.is_some_and(|to| (to - (**from - shift)).length() < 0.1))
            .count();
        assert!(good >= grid().len() * 9 / 10, "{good} of {}", grid().len());
        // Without the coarse levels the same motion is out of reach.
        let base_only = track(shift, 0);
        let good = grid()
            .iter()
            .zip(&base_only)
            .filter(|(from, to)| to.is_some_and(|to| (to - (**from - shift)).length() < 0.1))
            .count();
        assert!(good < grid().len() / 2, "{good}");
    }

    #[test]
    fn a_flat_window_and_a_point_outside_the_image_are_lost() {
        let flat = Pyramid::build(&GrayImage::filled(160, 120, 90));
        let options = LkOptions {
            levels: 2,
            max_fb_error_px: None,
        };
        let found = track_points(&flat, &flat, &[Vec2::new(80.0, 60.0)], None, options);
        assert_eq!(found, vec![None]);
        let textured = Pyramid::build(&texture(160, 120, Vec2::ZERO));
        let outside = [Vec2::new(-30.0, 60.0), Vec2::new(80.0, 400.0)];
        let found = track_points(&textured, &textured, &outside, None, options);
        assert_eq!(found, vec![None, None]);
    }

    #[test]
    fn the_forward_backward_check_rejects_a_window_whose_content_changed() {
        let prev_image = texture(320, 240, Vec2::ZERO);
        let mut next_image = texture(320, 240, Vec2::new(2.0, 1.0));
        // Another texture pasted over the neighbourhood of (130, 130).
        let other = texture(320, 240, Vec2::new(97.0, -53.0));
        for y in 110..150 {
            for x in 110..150 {
                let k = y * 320 + x;
                next_image.pixels[k] = other.pixels[k];
            }
        }
        let (prev, next) = (Pyramid::build(&prev_image), Pyramid::build(&next_image));
        let from = [Vec2::new(60.0, 60.0), Vec2::new(130.0, 130.0)];
        let options = LkOptions {
            levels: 3,
            max_fb_error_px: Some(0.5),
        };
        let found = track_points(&prev, &next, &from, None, options);
        assert!(found[0].is_some_and(|p| (p - Vec2::new(58.0, 59.0)).length() < 0.05));
        let unchecked = track_points(
            &prev,
            &next,
            &from,
            None,
            LkOptions {
                max_fb_error_px: None,
                ..options
            },
        );
        // Unchecked, Lucas–Kanade settles somewhere in the pasted texture; checked, it is lost.
        assert!(unchecked[1].is_some_and(|p| (p - Vec2::new(128.0, 129.0)).length() > 1.0));
        assert_eq!(found[1], None);
    }

    #[test]
    fn a_pyramid_built_in_recycled_memory_equals_a_fresh_one() {
        let mut scratch = PyramidScratch::default();
        // Memory first used for another size, then handed back.
        Pyramid::build_with(&texture(200, 150, Vec2::ZERO), &mut scratch).recycle(&mut scratch);
        let image = texture(320, 240, Vec2::new(0.5, 0.25));
        let reused = Pyramid::build_with(&image, &mut scratch);
        let fresh = Pyramid::build(&image);
        for (a, b) in reused.levels.iter().zip(fresh.levels.iter()) {
            assert_eq!((a.width, a.height, a.stride), (b.width, b.height, b.stride));
            assert!(
                a.image
                    .iter()
                    .zip(&b.image)
                    .all(|(x, y)| x.to_bits() == y.to_bits())
            );
        }
        // A pyramid a keyframe still shares is not taken back.
        let shared = reused.clone();
        reused.recycle(&mut scratch);
        assert!(scratch.spare.is_none());
        shared.recycle(&mut scratch);
        assert!(scratch.spare.is_some());
    }

    #[test]
    fn the_vector_build_gives_bit_identical_tracks() {
        let prev = Pyramid::build(&texture(320, 240, Vec2::ZERO));
        let next = Pyramid::build(&texture(320, 240, Vec2::new(5.7, -3.2)));
        let from = grid();
        let portable = track_all::<Portable>(&prev, &next, &from, &from, 3);
        assert!(portable.iter().all(Option::is_some));
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: AVX2 is present (checked just above).
            let vector = unsafe { track_all_avx2(&prev, &next, &from, &from, 3) };
            let bits = |v: &[Option<Vec2>]| -> Vec<Option<[u32; 2]>> {
                v.iter()
                    .map(|p| p.map(|p| [p.x.to_bits(), p.y.to_bits()]))
                    .collect()
            };
            assert_eq!(bits(&portable), bits(&vector));
        }
    }
}
