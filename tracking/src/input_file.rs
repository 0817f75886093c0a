//! Bounded reads of input files: only regular files are opened (a FIFO would block the reader
//! forever, `/dev/zero` would feed it until memory runs out) and no more than a stated number of
//! bytes is read. Errors are `std::io::Error`s whose text says what is wrong; callers name the
//! file.

use std::fs::{File, Metadata};
use std::io::{self, Read};
use std::path::Path;

/// Largest `camera.txt`, bytes (a real one is under 1 KB).
pub const MAX_CAMERA_FILE_BYTES: u64 = 1 << 20;
/// Largest list file (`rgb.txt`, `depth.txt`, `groundtruth.txt`, `accelerometer.txt`), bytes:
/// millions of rows, hours of footage.
pub const MAX_LIST_FILE_BYTES: u64 = 256 << 20;
/// Largest image file (a frame or a depth map), bytes.
pub const MAX_IMAGE_FILE_BYTES: u64 = 256 << 20;
/// Most memory an image decoder may allocate, bytes (a 16384 × 16384 RGBA8 image is 1 GiB).
pub const MAX_DECODE_BYTES: u64 = 1 << 30;

/// What kind of thing a non-regular path is, for the error.
fn kind_of(metadata: &Metadata) -> &'static str {
    let file_type = metadata.file_type();
    if file_type.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a named pipe (FIFO)";
        }
        if file_type.is_char_device() || file_type.is_block_device() {
            return "a device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

fn check_regular(metadata: &Metadata) -> io::Result<()> {
    if metadata.is_file() {
        Ok(())
    } else {
        Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("not a regular file ({})", kind_of(metadata)),
        ))
    }
}

fn too_large(size: u64, max_bytes: u64) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("file is larger than the {max_bytes} bytes allowed (at least {size} bytes)"),
    )
}

/// The bytes of the regular file at `path`, at most `max_bytes` of them. The path is looked at
/// before it is opened, so a FIFO or a device is refused without opening it, and the opened
/// handle is checked again (in case the path was swapped in between).
pub fn read_regular_file(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    let metadata = std::fs::metadata(path)?;
    check_regular(&metadata)?;
    if metadata.len() > max_bytes {
        return Err(too_large(metadata.len(), max_bytes));
    }
    let file = File::open(path)?;
    let opened = file.metadata()?;
    check_regular(&opened)?;
    let capacity = usize::try_from(opened.len().min(max_bytes)).unwrap_or(0);
    let mut bytes = Vec::with_capacity(capacity);
    // A file that grows while it is read stops one byte past the limit.
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64, max_bytes));
    }
    Ok(bytes)
}

/// The text of the regular file at `path` (UTF-8), at most `max_bytes` long.
pub fn read_regular_text(path: &Path, max_bytes: u64) -> io::Result<String> {
    let bytes = read_regular_file(path, max_bytes)?;
    String::from_utf8(bytes).map_err(|e| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// True when something (a file, a folder, a device, even a dangling link) is at `path`.
pub fn exists(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok()
}

/// Decoding limits for an image expected to be at most `max_width` × `max_height` pixels.
pub fn decode_limits(max_width: u32, max_height: u32) -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(max_width);
    limits.max_image_height = Some(max_height);
    limits.max_alloc = Some(MAX_DECODE_BYTES);
    limits
}

/// Decodes image bytes within `limits` (the size is checked from the header, before pixels are
/// allocated).
pub fn decode_image(bytes: &[u8], limits: image::Limits) -> Result<image::DynamicImage, String> {
    let mut reader = image::ImageReader::new(io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    reader.limits(limits);
    reader.decode().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_path(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("sylva-input-{}-{name}", std::process::id()))
    }

    #[test]
    fn a_regular_file_within_the_limit_is_read_whole() {
        let path = temp_path("small.txt");
        std::fs::write(&path, b"width 640\n").expect("write");
        let text = read_regular_text(&path, 64).expect("reads");
        std::fs::remove_file(&path).ok();
        assert_eq!(text, "width 640\n");
    }

    #[test]
    fn a_file_over_the_limit_is_refused_saying_so() {
        let path = temp_path("large.txt");
        std::fs::write(&path, vec![b'x'; 100]).expect("write");
        let err = read_regular_file(&path, 99).expect_err("over the limit");
        std::fs::remove_file(&path).ok();
        assert!(
            err.to_string().contains("larger than the 99 bytes"),
            "{err}"
        );
    }

    #[test]
    fn a_folder_is_not_read_as_a_file() {
        let err = read_regular_file(&std::env::temp_dir(), 10).expect_err("a folder");
        assert!(err.to_string().contains("folder"), "{err}");
    }

    #[cfg(unix)]
    #[test]
    fn dev_zero_is_refused_without_reading_it() {
        let err = read_regular_file(Path::new("/dev/zero"), 1 << 40).expect_err("a device");
        assert!(err.to_string().contains("device"), "{err}");
    }

    #[test]
    fn text_that_is_not_utf8_is_an_error_not_a_panic() {
        let path = temp_path("latin1.txt");
        std::fs::write(&path, b"fx 5\xe900\n").expect("write");
        let err = read_regular_text(&path, 64).expect_err("not UTF-8");
        std::fs::remove_file(&path).ok();
        assert!(err.to_string().contains("offset 4"), "{err}");
    }

    #[test]
    fn an_image_larger_than_its_limits_is_refused_before_decoding() {
        let image = image::GrayImage::new(64, 32);
        let mut png = Vec::new();
        image
            .write_to(&mut io::Cursor::new(&mut png), image::ImageFormat::Png)
            .expect("encode");
        assert!(decode_image(&png, decode_limits(64, 32)).is_ok());
        assert!(decode_image(&png, decode_limits(63, 32)).is_err());
    }
}
