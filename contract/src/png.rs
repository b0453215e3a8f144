//! The dataset's PNG files (feature `png`): how every observation frame, mask and depth
//! image is encoded — fast deflate with the Sub filter — and written atomically. One
//! function, so the renderer's frames, its masks and the scorer's test frames have the
//! same bytes for the same pixels.

use std::path::Path;

/// The pixel layout of a PNG.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PngColor {
    /// 8-bit RGB, 3 bytes a pixel (frames).
    Rgb8,
    /// 16-bit greyscale, 2 bytes a pixel in native byte order (instance-id masks, depth
    /// in mm).
    L16,
}

/// The PNG bytes of `pixels` (`width` × `height`, rows top to bottom, `color` layout).
pub fn encode_png(
    pixels: &[u8],
    width: u32,
    height: u32,
    color: PngColor,
) -> Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let (color, bytes_per_pixel) = match color {
        PngColor::Rgb8 => (image::ExtendedColorType::Rgb8, 3),
        PngColor::L16 => (image::ExtendedColorType::L16, 2),
    };
    // The encoder asserts the length; a wrong one is an error here, not a panic.
    let expected = width as usize * height as usize * bytes_per_pixel;
    if pixels.len() != expected {
        return Err(format!(
            "{} bytes of pixels for a {width}x{height} image, expected {expected}",
            pixels.len()
        ));
    }
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new_with_quality(
        &mut bytes,
        image::codecs::png::CompressionType::Fast,
        image::codecs::png::FilterType::Sub,
    )
    .write_image(pixels, width, height, color)
    .map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// Encodes `pixels` ([`encode_png`]) and writes them to `path` atomically
/// ([`crate::fsio::write_atomic`]); an error names the file.
pub fn write_png(
    path: &Path,
    pixels: &[u8],
    width: u32,
    height: u32,
    color: PngColor,
) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let bytes = encode_png(pixels, width, height, color).map_err(|e| fail(&e))?;
    crate::fsio::write_atomic(path, &bytes).map_err(|e| fail(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodes_both_layouts_and_refuses_a_short_buffer() {
        let rgb = encode_png(&[255, 0, 0, 0, 255, 0], 2, 1, PngColor::Rgb8).unwrap();
        assert_eq!(&rgb[1..4], b"PNG");
        // IHDR: width 2, height 1, bit depth 8, colour type 2 (RGB).
        assert_eq!(&rgb[16..26], &[0, 0, 0, 2, 0, 0, 0, 1, 8, 2]);
        let l16 = encode_png(&[1, 0, 2, 0], 2, 1, PngColor::L16).unwrap();
        // Bit depth 16, colour type 0 (greyscale).
        assert_eq!(&l16[24..26], &[16, 0]);
        assert!(encode_png(&[0; 5], 2, 1, PngColor::Rgb8).is_err());
        let dir = std::env::temp_dir().join(format!("rh-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.png");
        write_png(&path, &[1, 2, 3], 1, 1, PngColor::Rgb8).unwrap();
        assert_eq!(
            std::fs::read(&path).unwrap(),
            encode_png(&[1, 2, 3], 1, 1, PngColor::Rgb8).unwrap()
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
