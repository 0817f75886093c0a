//! Phone cameras deliver YUV 4:2:0 (Android's `YUV_420_888` from ARCore and Camera2, iOS's
//! bi-planar `420f` from ARKit): the shown image is converted to RGBA here, BT.601.

use image::RgbaImage;

/// The planes of a YUV 4:2:0 image: a full-size luma plane and quarter-size chroma planes, each
/// with its strides (ARKit's interleaved CbCr plane is `u = &cbcr[0..]`, `v = &cbcr[1..]` with
/// a pixel stride of 2).
#[derive(Clone, Copy, Debug)]
pub struct YuvPlanes<'a> {
    pub width: u32,
    pub height: u32,
    pub y: &'a [u8],
    pub y_row_stride: usize,
    pub u: &'a [u8],
    pub v: &'a [u8],
    pub uv_row_stride: usize,
    pub uv_pixel_stride: usize,
    /// Full range (0–255 luma, JPEG/JFIF) rather than video range (16–235).
    pub full_range: bool,
}

/// The RGBA image of `planes`; None when a plane is too short for the size and strides.
pub fn rgba_from_yuv420(planes: &YuvPlanes) -> Option<RgbaImage> {
    let (w, h) = (planes.width as usize, planes.height as usize);
    if w == 0 || h == 0 || planes.uv_pixel_stride == 0 {
        return None;
    }
    let last_y = (h - 1) * planes.y_row_stride + w;
    let (cw, ch) = (w.div_ceil(2), h.div_ceil(2));
    let last_uv = (ch - 1) * planes.uv_row_stride + (cw - 1) * planes.uv_pixel_stride + 1;
    if planes.y.len() < last_y || planes.u.len() < last_uv || planes.v.len() < last_uv {
        return None;
    }
    let (luma_scale, luma_offset, chroma_scale) = if planes.full_range {
        (1.0, 0.0, 1.0)
    } else {
        (255.0 / 219.0, 16.0, 255.0 / 224.0)
    };
    let mut rgba = RgbaImage::new(planes.width, planes.height);
    for (row, pixels) in rgba.rows_mut().enumerate() {
        for (column, pixel) in pixels.enumerate() {
            let y = (f32::from(planes.y[row * planes.y_row_stride + column]) - luma_offset)
                * luma_scale;
            let c = (row / 2) * planes.uv_row_stride + (column / 2) * planes.uv_pixel_stride;
            let u = (f32::from(planes.u[c]) - 128.0) * chroma_scale;
            let v = (f32::from(planes.v[c]) - 128.0) * chroma_scale;
            let to_u8 = |x: f32| x.round().clamp(0.0, 255.0) as u8;
            pixel.0 = [
                to_u8(y + 1.402 * v),
                to_u8(y - 0.344_136 * u - 0.714_136 * v),
                to_u8(y + 1.772 * u),
                255,
            ];
        }
    }
    Some(rgba)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grey_stays_grey_and_chroma_gives_the_bt601_colours() {
        // 4 x 2: left half grey, right half with a red chroma sample; NV21-like interleaving.
        let y = [128u8; 8];
        let vu = [128u8, 128, 240, 90];
        let planes = YuvPlanes {
            width: 4,
            height: 2,
            y: &y,
            y_row_stride: 4,
            u: &vu[1..],
            v: &vu[0..],
            uv_row_stride: 4,
            uv_pixel_stride: 2,
            full_range: true,
        };
        let rgba = rgba_from_yuv420(&planes).expect("converts");
        assert_eq!(rgba.get_pixel(0, 1).0, [128, 128, 128, 255]);
        let [r, g, b, _] = rgba.get_pixel(3, 0).0;
        assert!(r > 240 && g < 80 && b < 80, "red, got {r} {g} {b}");
        let short = YuvPlanes {
            y: &y[..7],
            ..planes
        };
        assert!(
            rgba_from_yuv420(&short).is_none(),
            "a short luma plane is refused"
        );
    }

    #[test]
    fn video_range_black_and_white_reach_the_ends() {
        let y = [16u8, 235];
        let uv = [128u8];
        let planes = YuvPlanes {
            width: 2,
            height: 1,
            y: &y,
            y_row_stride: 2,
            u: &uv,
            v: &uv,
            uv_row_stride: 1,
            uv_pixel_stride: 1,
            full_range: false,
        };
        let rgba = rgba_from_yuv420(&planes).expect("converts");
        assert_eq!(rgba.get_pixel(0, 0).0, [0, 0, 0, 255]);
        assert_eq!(rgba.get_pixel(1, 0).0, [255, 255, 255, 255]);
    }
}
