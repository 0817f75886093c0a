//! The comparison overlay of the Recreate mode: the model drawn over the real tree in one tracked
//! frame, filled at an opacity or as its outline only, with the crown outlines the user traced
//! in that frame. One RGBA layer the size of the camera image (transparent off the drawing): the
//! app lays it over the view, and [`composite`] puts it on the camera image for pictures.

use glam::DVec2;
use image::{Rgba, RgbaImage};

use super::footage::TrackedFootage;
use super::marks::CrownMark;
use super::silhouette::{Silhouette, WorldTriangles};

/// The model's colour in the overlay.
const MODEL: [u8; 3] = [60, 230, 90];
/// The traced outlines' colour.
const TRACED: [u8; 3] = [255, 210, 40];

/// How the model is drawn: filled at `opacity` (0 to 1), or its outline only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlayStyle {
    pub opacity: f32,
    pub outline_only: bool,
}

/// The overlay layer of `frame`: the model (its silhouette as drawn, leaf cards alpha-tested)
/// and the outlines traced in that frame.
pub fn overlay_layer(
    footage: &TrackedFootage,
    frame: usize,
    model: &WorldTriangles,
    outlines: &[CrownMark],
    style: OverlayStyle,
) -> RgbaImage {
    let seen = Silhouette::render(footage, frame, model);
    let (width, height) = (seen.width, seen.height);
    let mut layer = RgbaImage::new(width, height);
    let solid = outer_shape(&seen);
    let w = width as usize;
    let is_solid = |x: i64, y: i64| {
        x >= 0
            && y >= 0
            && x < i64::from(width)
            && y < i64::from(height)
            && solid[y as usize * w + x as usize]
    };
    let fill_alpha = (style.opacity.clamp(0.0, 1.0) * 255.0).round() as u8;
    for y in 0..i64::from(height) {
        for x in 0..i64::from(width) {
            let i = y as usize * w + x as usize;
            let edge = solid[i]
                && !(is_solid(x - 1, y)
                    && is_solid(x + 1, y)
                    && is_solid(x, y - 1)
                    && is_solid(x, y + 1));
            let alpha = if edge {
                255
            } else if !style.outline_only && seen.inside[i] {
                fill_alpha
            } else {
                0
            };
            if alpha > 0 {
                let [r, g, b] = MODEL;
                layer.put_pixel(x as u32, y as u32, Rgba([r, g, b, alpha]));
            }
        }
    }
    for outline in outlines.iter().filter(|o| o.frame == frame) {
        let points = outline.points();
        for (i, &a) in points.iter().enumerate() {
            let b = points[(i + 1) % points.len()];
            draw_line(&mut layer, a, b, TRACED);
        }
    }
    layer
}

/// Gaps between leaves narrower than this close in the outer shape, pixels.
const GAP_PX: i64 = 2;

/// The silhouette's outer shape: what the background, flooded in from the image's border, does
/// not reach once the silhouette is dilated by [`GAP_PX`] (the gaps between leaves closed, so
/// the outline follows the crown, not every leaf).
fn outer_shape(seen: &Silhouette) -> Vec<bool> {
    let (w, h) = (seen.width as i64, seen.height as i64);
    let mut blocked = vec![false; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            if !seen.inside[(y * w + x) as usize] {
                continue;
            }
            for yy in (y - GAP_PX).max(0)..=(y + GAP_PX).min(h - 1) {
                for xx in (x - GAP_PX).max(0)..=(x + GAP_PX).min(w - 1) {
                    blocked[(yy * w + xx) as usize] = true;
                }
            }
        }
    }
    let mut background = vec![false; blocked.len()];
    let mut stack: Vec<(i64, i64)> = Vec::new();
    for x in 0..w {
        stack.push((x, 0));
        stack.push((x, h - 1));
    }
    for y in 0..h {
        stack.push((0, y));
        stack.push((w - 1, y));
    }
    while let Some((x, y)) = stack.pop() {
        if x < 0 || y < 0 || x >= w || y >= h {
            continue;
        }
        let i = (y * w + x) as usize;
        if background[i] || blocked[i] {
            continue;
        }
        background[i] = true;
        stack.extend([(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)]);
    }
    background.iter().map(|b| !b).collect()
}

/// A two-pixel-wide line from `a` to `b`, opaque.
fn draw_line(layer: &mut RgbaImage, a: DVec2, b: DVec2, colour: [u8; 3]) {
    let steps = (b - a).abs().max_element().ceil().max(1.0) as usize;
    let (width, height) = (i64::from(layer.width()), i64::from(layer.height()));
    for s in 0..=steps {
        let p = a + (b - a) * (s as f64 / steps as f64);
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let (x, y) = (p.x.floor() as i64 + dx, p.y.floor() as i64 + dy);
            if (0..width).contains(&x) && (0..height).contains(&y) {
                layer.put_pixel(
                    x as u32,
                    y as u32,
                    Rgba([colour[0], colour[1], colour[2], 255]),
                );
            }
        }
    }
}

/// `layer` over `image` (same size), by its alpha.
pub fn composite(image: &RgbaImage, layer: &RgbaImage) -> RgbaImage {
    let mut out = image.clone();
    for (o, l) in out.pixels_mut().zip(layer.pixels()) {
        let a = u16::from(l[3]);
        for c in 0..3 {
            o[c] = ((u16::from(l[c]) * a + u16::from(o[c]) * (255 - a) + 127) / 255) as u8;
        }
        o[3] = 255;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_layer_over_an_image_keeps_it_where_transparent_and_covers_it_where_opaque() {
        let image = RgbaImage::from_pixel(2, 1, Rgba([10, 20, 30, 255]));
        let mut layer = RgbaImage::new(2, 1);
        layer.put_pixel(1, 0, Rgba([255, 0, 0, 255]));
        let out = composite(&image, &layer);
        assert_eq!(out.get_pixel(0, 0), &Rgba([10, 20, 30, 255]));
        assert_eq!(out.get_pixel(1, 0), &Rgba([255, 0, 0, 255]));
    }
}
