//! How a camera image is shown on a screen: turned upright and filling the view.
//!
//! A phone's camera sensor is mounted in landscape; held upright, the image it delivers lies on
//! its side. The platforms say how to show it (Android: the sensor orientation and the display
//! rotation, `ArFrame_transformCoordinates2d`; iOS: `ARFrame.displayTransform(for:viewportSize:)`):
//! turned by a number of quarter turns, then cropped to the view's shape, as the camera app shows
//! it (never squashed, never with bars). [`DisplayTransform`] does both to the image, to the
//! intrinsics and to the camera pose, so the tree is drawn over the shown image exactly where it
//! stands in the sensor's, and maps touches on the shown image back to sensor pixels (tracking,
//! the design state and sessions keep working in the sensor's image).

use glam::{Mat4, Vec2};
use image::RgbaImage;

use crate::render::{Intrinsics, ViewCamera};

/// The turn and crop from a sensor image to the view.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DisplayTransform {
    /// Clockwise quarter turns (as seen on screen) that show the sensor image upright (0–3).
    pub quarter_turns_cw: u8,
    /// Crop the turned image to the view's aspect so that it fills the view (a phone); without
    /// it the whole image is shown with bars (the desktop window, the default).
    pub fill: bool,
}

/// The shown part of the turned image: its offset in the turned image and its size, pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Crop {
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
}

impl DisplayTransform {
    /// The way a phone shows its camera: turned by `quarter_turns_cw`, filling the view.
    pub fn phone(quarter_turns_cw: u8) -> DisplayTransform {
        DisplayTransform {
            quarter_turns_cw: quarter_turns_cw % 4,
            fill: true,
        }
    }

    fn turns(&self) -> u8 {
        self.quarter_turns_cw % 4
    }

    /// Whether the image is shown as it is (no turn, no crop).
    pub fn is_identity(&self) -> bool {
        self.turns() == 0 && !self.fill
    }

    fn turned_size(&self, (width, height): (u32, u32)) -> (u32, u32) {
        if self.turns() % 2 == 1 {
            (height, width)
        } else {
            (width, height)
        }
    }

    /// The largest centred part of the turned image of a sensor image of `sensor_size` pixels
    /// with the aspect of `view_px` (all of it without `fill`).
    fn crop(&self, sensor_size: (u32, u32), view_px: (u32, u32)) -> Crop {
        let (width, height) = self.turned_size(sensor_size);
        let full = Crop {
            x0: 0,
            y0: 0,
            width,
            height,
        };
        if !self.fill || view_px.0 == 0 || view_px.1 == 0 {
            return full;
        }
        let view_aspect = f64::from(view_px.0) / f64::from(view_px.1);
        if f64::from(width) / f64::from(height) > view_aspect {
            let w = ((f64::from(height) * view_aspect).round() as u32).clamp(1, width);
            Crop {
                x0: (width - w) / 2,
                width: w,
                ..full
            }
        } else {
            let h = ((f64::from(width) / view_aspect).round() as u32).clamp(1, height);
            Crop {
                y0: (height - h) / 2,
                height: h,
                ..full
            }
        }
    }

    /// The intrinsics of the shown image (turned and cropped) for a view of `view_px`.
    pub fn shown_intrinsics(&self, k: &Intrinsics, view_px: (u32, u32)) -> Intrinsics {
        let crop = self.crop((k.width, k.height), view_px);
        let mut k = *k;
        for _ in 0..self.turns() {
            // (u, v) -> (h - v, u): normalised (x, y) -> (-y, x); the tangential terms follow.
            let [k1, k2, p1, p2, k3] = k.distortion;
            k = Intrinsics {
                width: k.height,
                height: k.width,
                fx: k.fy,
                fy: k.fx,
                cx: k.height as f32 - k.cy,
                cy: k.cx,
                distortion: [k1, k2, p2, -p1, k3],
            };
        }
        Intrinsics {
            width: crop.width,
            height: crop.height,
            cx: k.cx - crop.x0 as f32,
            cy: k.cy - crop.y0 as f32,
            ..k
        }
    }

    /// The camera that sees the shown image: `camera` (of the sensor's intrinsics) turned about
    /// its optical axis, with the shown intrinsics.
    pub fn shown_camera(&self, camera: &ViewCamera, view_px: (u32, u32)) -> ViewCamera {
        // A point (x, y, z) of the sensor's camera is (-y, x, z) in the turned camera's axes.
        let turned_from_sensor =
            Mat4::from_rotation_z(f32::from(self.turns()) * std::f32::consts::FRAC_PI_2);
        ViewCamera {
            intrinsics: self.shown_intrinsics(&camera.intrinsics, view_px),
            world_from_camera: camera.world_from_camera * turned_from_sensor.inverse(),
            ..*camera
        }
    }

    /// The shown image: `rgba` (the sensor's) turned and cropped for a view of `view_px`.
    pub fn shown_image(&self, rgba: &RgbaImage, view_px: (u32, u32)) -> RgbaImage {
        let turned = match self.turns() {
            1 => image::imageops::rotate90(rgba),
            2 => image::imageops::rotate180(rgba),
            3 => image::imageops::rotate270(rgba),
            _ => rgba.clone(),
        };
        let crop = self.crop(rgba.dimensions(), view_px);
        if (crop.width, crop.height) == turned.dimensions() {
            return turned;
        }
        image::imageops::crop_imm(&turned, crop.x0, crop.y0, crop.width, crop.height).to_image()
    }

    /// The sensor image's pixel under the shown image's pixel `shown_px`, for a sensor image of
    /// `sensor_size` pixels in a view of `view_px`.
    pub fn sensor_from_shown_px(
        &self,
        shown_px: Vec2,
        sensor_size: (u32, u32),
        view_px: (u32, u32),
    ) -> Vec2 {
        let crop = self.crop(sensor_size, view_px);
        let mut p = shown_px + Vec2::new(crop.x0 as f32, crop.y0 as f32);
        // Undo the turns one by one: (u', v') = (h - v, u) of a w x h image gives
        // (u, v) = (v', h - u').
        let mut size = self.turned_size(sensor_size);
        for _ in 0..self.turns() {
            // `size` is the turned image's; the image before this turn is (size.1, size.0).
            let h_before = size.0 as f32;
            p = Vec2::new(p.y, h_before - p.x);
            size = (size.1, size.0);
        }
        p
    }

    /// The shown image's pixel over the sensor image's pixel `sensor_px` (the inverse of
    /// [`DisplayTransform::sensor_from_shown_px`]).
    pub fn shown_from_sensor_px(
        &self,
        sensor_px: Vec2,
        sensor_size: (u32, u32),
        view_px: (u32, u32),
    ) -> Vec2 {
        let mut p = sensor_px;
        let mut size = sensor_size;
        for _ in 0..self.turns() {
            // (u, v) of a w x h image -> (h - v, u) of the h x w turned one.
            p = Vec2::new(size.1 as f32 - p.y, p.x);
            size = (size.1, size.0);
        }
        let crop = self.crop(sensor_size, view_px);
        p - Vec2::new(crop.x0 as f32, crop.y0 as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn sensor_camera() -> ViewCamera {
        let k = Intrinsics {
            distortion: [0.0; 5],
            ..Intrinsics::from_fov(640, 480, 60f32.to_radians())
        };
        let k = Intrinsics {
            cx: 330.0,
            cy: 236.0,
            ..k
        };
        ViewCamera::looking_at(k, Vec3::new(0.5, 1.4, 4.0), Vec3::new(0.0, 1.0, 0.0))
    }

    #[test]
    fn a_point_projects_onto_the_same_scene_pixel_of_the_turned_and_cropped_image() {
        let camera = sensor_camera();
        let sensor = (camera.intrinsics.width, camera.intrinsics.height);
        let portrait = (1080, 2340);
        for turns in 0..4 {
            let display = DisplayTransform::phone(turns);
            let shown = display.shown_camera(&camera, portrait);
            let k = shown.intrinsics;
            // Fills the portrait view: the shown image has the view's aspect.
            let aspect = k.width as f32 / k.height as f32;
            assert!(
                (aspect - 1080.0 / 2340.0).abs() < 0.01,
                "{turns} turns: {} x {}",
                k.width,
                k.height
            );
            for point in [Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.1, 1.3, 0.2)] {
                let in_sensor = camera.pixel_from_world(point).expect("seen");
                let Some(in_shown) = shown.pixel_from_world(point) else {
                    continue; // cropped away
                };
                let back = display.sensor_from_shown_px(in_shown, sensor, portrait);
                let forth = display.shown_from_sensor_px(in_sensor, sensor, portrait);
                assert!(
                    forth.distance(in_shown) < 0.01,
                    "{turns} turns: {forth} vs {in_shown}"
                );
                assert!(
                    back.distance(in_sensor) < 0.01,
                    "{turns} turns: {point} at {in_sensor} in the sensor image, {in_shown} shown, back {back}"
                );
            }
        }
    }

    #[test]
    fn the_shown_image_is_the_sensor_image_turned_clockwise_and_cropped_to_fill() {
        let mut sensor = RgbaImage::new(8, 6);
        sensor.put_pixel(0, 0, image::Rgba([255, 0, 0, 255])); // top left
        sensor.put_pixel(7, 5, image::Rgba([0, 0, 255, 255])); // bottom right
        let display = DisplayTransform {
            quarter_turns_cw: 1,
            fill: false,
        };
        let shown = display.shown_image(&sensor, (6, 8));
        assert_eq!(shown.dimensions(), (6, 8));
        // Turned clockwise: the top left goes to the top right.
        assert_eq!(shown.get_pixel(5, 0).0, [255, 0, 0, 255]);
        assert_eq!(shown.get_pixel(0, 7).0, [0, 0, 255, 255]);
        let pixel_centre = display.sensor_from_shown_px(Vec2::new(5.5, 0.5), (8, 6), (6, 8));
        assert!(
            pixel_centre.distance(Vec2::new(0.5, 0.5)) < 1e-5,
            "{pixel_centre}"
        );
        // A portrait view of an upright landscape image crops its sides, never squashes.
        let fill = DisplayTransform::phone(0);
        let shown = fill.shown_image(&RgbaImage::new(640, 480), (1080, 2340));
        assert_eq!(shown.dimensions(), (222, 480));
        let k = fill.shown_intrinsics(&Intrinsics::from_fov(640, 480, 1.0), (1080, 2340));
        assert_eq!((k.width, k.height, k.cx), (222, 480, 320.0 - 209.0));
        assert!(DisplayTransform::default().is_identity());
    }
}
