//! Reading and writing PNG images.
//!
//! In: a path. Out: an 8-bit straight-alpha RGBA image (whatever the file's color type), or an
//! [`ImageError`] that names the file and says what is wrong. Writing is atomic.

use super::atomic::write_atomic;
use image::{ImageFormat, RgbaImage};
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// What is wrong with an image file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a PNG image")]
    NotPng { path: PathBuf },
    #[error("{path}: cannot decode PNG: {reason}")]
    Decode { path: PathBuf, reason: String },
    #[error("{path}: cannot write: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: cannot encode PNG: {reason}")]
    Encode { path: PathBuf, reason: String },
}

/// The 8 bytes every PNG file starts with.
const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

/// Loads a PNG file as straight-alpha RGBA8.
pub fn load_png(path: &Path) -> Result<RgbaImage, ImageError> {
    let bytes = std::fs::read(path).map_err(|source| ImageError::Read {
        path: path.into(),
        source,
    })?;
    if !bytes.starts_with(&PNG_SIGNATURE) {
        return Err(ImageError::NotPng { path: path.into() });
    }
    image::load_from_memory_with_format(&bytes, ImageFormat::Png)
        .map(|img| img.into_rgba8())
        .map_err(|e| ImageError::Decode {
            path: path.into(),
            reason: e.to_string(),
        })
}

/// Encodes `image` as PNG bytes.
pub fn encode_png(image: &RgbaImage) -> Result<Vec<u8>, image::ImageError> {
    let mut bytes = Vec::new();
    image.write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)?;
    Ok(bytes)
}

/// Writes `image` to `path` as PNG, atomically.
pub fn save_png(path: &Path, image: &RgbaImage) -> Result<(), ImageError> {
    let bytes = encode_png(image).map_err(|e| ImageError::Encode {
        path: path.into(),
        reason: e.to_string(),
    })?;
    write_atomic(path, &bytes).map_err(|source| ImageError::Write {
        path: path.into(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_bad_files() {
        let tmp = crate::test_scratch::scratch("image");
        let dir = tmp.path();
        let img = RgbaImage::from_fn(3, 2, |x, y| {
            image::Rgba([x as u8 * 80, y as u8 * 100, 7, 200])
        });
        let p = dir.join("a.png");
        save_png(&p, &img).unwrap();
        assert_eq!(load_png(&p).unwrap(), img);

        std::fs::write(dir.join("text.png"), b"hello").unwrap();
        assert!(matches!(
            load_png(&dir.join("text.png")),
            Err(ImageError::NotPng { .. })
        ));
        let bytes = std::fs::read(&p).unwrap();
        std::fs::write(dir.join("cut.png"), &bytes[..bytes.len() / 2]).unwrap();
        assert!(matches!(
            load_png(&dir.join("cut.png")),
            Err(ImageError::Decode { .. })
        ));
        assert!(matches!(
            load_png(&dir.join("missing.png")),
            Err(ImageError::Read { .. })
        ));
    }
}
