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
    /// Not a PNG: what the file is instead, by its content, and what was asked for.
    #[error("{}", not_png_message(path, found, *expected))]
    NotPng {
        path: PathBuf,
        found: FileKind,
        expected: Expected,
    },
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
        return Err(ImageError::NotPng {
            path: path.into(),
            found: FileKind::of(&bytes),
            expected: Expected::Png,
        });
    }
    image::load_from_memory_with_format(&bytes, ImageFormat::Png)
        .map(|img| img.into_rgba8())
        .map_err(|e| ImageError::Decode {
            path: path.into(),
            reason: e.to_string(),
        })
}

/// What a file that should have been a PNG image is instead, told by its first bytes (not its
/// name), for the message that refuses it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Empty,
    Jpeg,
    Gif,
    WebP,
    Bmp,
    Tiff,
    /// HEIC, HEIF or AVIF (an ISO media file of still images).
    Heif,
    /// Photoshop: `psb` false for PSD (version 1), true for PSB (version 2).
    Photoshop {
        psb: bool,
    },
    /// A zip whose `mimetype` entry says `image/openraster`.
    OpenRaster,
    /// A zip whose `mimetype` entry says `application/x-krita`.
    Krita,
    /// GIMP's own format.
    Xcf,
    /// Clip Studio Paint's own format.
    ClipStudio,
    Pdf,
    Svg,
    /// Any other zip archive.
    Zip,
    /// Text (UTF-8 without control characters other than white space).
    Text,
    /// Nothing recognized.
    Unknown,
}

impl FileKind {
    /// Sniffs the kind of a file from its bytes.
    pub fn of(bytes: &[u8]) -> FileKind {
        let starts = |sig: &[u8]| bytes.starts_with(sig);
        if bytes.is_empty() {
            FileKind::Empty
        } else if starts(&[0xff, 0xd8, 0xff]) {
            FileKind::Jpeg
        } else if starts(b"GIF87a") || starts(b"GIF89a") {
            FileKind::Gif
        } else if starts(b"RIFF") && bytes.get(8..12) == Some(b"WEBP") {
            FileKind::WebP
        } else if starts(b"BM") && bytes.len() >= 26 {
            FileKind::Bmp
        } else if starts(b"II*\0") || starts(b"MM\0*") {
            FileKind::Tiff
        } else if bytes.get(4..8) == Some(b"ftyp")
            && bytes.get(8..12).is_some_and(|brand| {
                [
                    &b"heic"[..],
                    b"heix",
                    b"heif",
                    b"mif1",
                    b"msf1",
                    b"avif",
                    b"avis",
                ]
                .contains(&brand)
            })
        {
            FileKind::Heif
        } else if starts(b"8BPS") {
            FileKind::Photoshop {
                psb: bytes.get(4..6) == Some(&[0, 2]),
            }
        } else if starts(b"gimp xcf") {
            FileKind::Xcf
        } else if starts(b"CSFCHUNK") {
            FileKind::ClipStudio
        } else if starts(b"%PDF-") {
            FileKind::Pdf
        } else if starts(b"PK\x03\x04") {
            match zip_mimetype(bytes) {
                Some(b"image/openraster") => FileKind::OpenRaster,
                Some(b"application/x-krita") => FileKind::Krita,
                _ => FileKind::Zip,
            }
        } else {
            let head = &bytes[..bytes.len().min(4096)];
            // A multi-byte character cut at the end of the head is still text.
            let text = match std::str::from_utf8(head) {
                Ok(t) => Some(t),
                Err(e) if e.error_len().is_none() => {
                    std::str::from_utf8(&head[..e.valid_up_to()]).ok()
                }
                Err(_) => None,
            };
            match text {
                Some(t) if t.chars().all(|c| !c.is_control() || c.is_whitespace()) => {
                    let t = t.trim_start_matches('\u{feff}').trim_start();
                    if t.starts_with("<svg") || (t.starts_with("<?xml") && t.contains("<svg")) {
                        FileKind::Svg
                    } else {
                        FileKind::Text
                    }
                }
                _ => FileKind::Unknown,
            }
        }
    }

    /// The kind in a message: `a JPEG image`, `a Krita document`.
    fn described(self) -> &'static str {
        match self {
            FileKind::Empty => "an empty file",
            FileKind::Jpeg => "a JPEG image",
            FileKind::Gif => "a GIF image",
            FileKind::WebP => "a WebP image",
            FileKind::Bmp => "a BMP image",
            FileKind::Tiff => "a TIFF image",
            FileKind::Heif => "a HEIC or AVIF image",
            FileKind::Photoshop { psb: false } => "a Photoshop document (PSD)",
            FileKind::Photoshop { psb: true } => "a large Photoshop document (PSB)",
            FileKind::OpenRaster => "an OpenRaster document (ORA)",
            FileKind::Krita => "a Krita document (KRA)",
            FileKind::Xcf => "a GIMP document (XCF)",
            FileKind::ClipStudio => "a Clip Studio Paint document",
            FileKind::Pdf => "a PDF document",
            FileKind::Svg => "an SVG drawing",
            FileKind::Zip => "a zip archive",
            FileKind::Text => "a text file",
            FileKind::Unknown => "not an image format sinew knows",
        }
    }
}

/// The first entry of a zip when it is `mimetype`, stored uncompressed (as OpenRaster and Krita
/// write it): its content.
fn zip_mimetype(bytes: &[u8]) -> Option<&[u8]> {
    let u16_at = |at: usize| Some(u16::from_le_bytes(bytes.get(at..at + 2)?.try_into().ok()?));
    let u32_at = |at: usize| Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?));
    let (method, size) = (u16_at(8)?, u32_at(18)? as usize);
    let (name_len, extra_len) = (u16_at(26)? as usize, u16_at(28)? as usize);
    if method != 0 || bytes.get(30..30 + name_len)? != b"mimetype" || size > 256 {
        return None;
    }
    let start = 30 + name_len + extra_len;
    bytes.get(start..start + size)
}

/// What a command asked the file to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expected {
    /// A PNG image (line art, a scribble layer, a rig's part image).
    Png,
    /// Art to rig: a PNG image or a layered file (see [`crate::art`]).
    Art,
}

/// The formats art to rig may come in (those [`crate::io::layered::LayeredFormat`] reads
/// besides PNG).
const ART_FORMATS: &str =
    "PNG images, layered PSD, PSB or OpenRaster (.ora) files, or a Spine export script's .json";

/// The one line refusing `path`, found to be `found`, where `expected` was wanted.
fn not_png_message(path: &Path, found: &FileKind, expected: Expected) -> String {
    let path = path.display();
    let what = match found {
        FileKind::Unknown => "not a PNG image".to_string(),
        other => format!("{}, not a PNG image", other.described()),
    };
    let layered_ext = match found {
        FileKind::Photoshop { psb: false } => Some(".psd"),
        FileKind::Photoshop { psb: true } => Some(".psb"),
        FileKind::OpenRaster => Some(".ora"),
        _ => None,
    };
    let advice = match (expected, found, layered_ext) {
        (Expected::Art, _, Some(ext)) => {
            format!("name it {ext} to read its layers")
        }
        (Expected::Art, FileKind::Krita, _) => format!(
            "sinew reads art as {ART_FORMATS}: in Krita, File ▸ Export as OpenRaster (.ora) or \
             Photoshop (.psd) keeps the layers"
        ),
        (Expected::Art, FileKind::Xcf, _) => format!(
            "sinew reads art as {ART_FORMATS}: in GIMP, File ▸ Export As .ora or .psd keeps the layers"
        ),
        (Expected::Art, FileKind::ClipStudio, _) => format!(
            "sinew reads art as {ART_FORMATS}: a copy saved from Clip Studio Paint as Photoshop \
             (.psd) keeps the layers"
        ),
        (Expected::Art, _, _) => format!("sinew reads art as {ART_FORMATS}; export or save it as PNG"),
        (Expected::Png, _, _) => "export or save it as PNG".to_string(),
    };
    format!("{path}: {what}; {advice}")
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
            Err(ImageError::NotPng {
                found: FileKind::Text,
                expected: Expected::Png,
                ..
            })
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

    /// The start of a zip whose first entry is `name`, stored, holding `content`.
    fn zip_head(name: &str, content: &[u8]) -> Vec<u8> {
        let mut out = b"PK\x03\x04".to_vec();
        out.extend([20, 0, 0, 0, 0, 0]); // version, flags, method 0 (stored)
        out.extend([0u8; 8]); // time, date, CRC
        out.extend((content.len() as u32).to_le_bytes());
        out.extend((content.len() as u32).to_le_bytes());
        out.extend((name.len() as u16).to_le_bytes());
        out.extend(0u16.to_le_bytes());
        out.extend(name.as_bytes());
        out.extend(content);
        out.extend(b"PK\x03\x04 and the rest");
        out
    }

    #[test]
    fn a_file_that_is_not_a_png_is_told_by_its_content() {
        let cases: [(&[u8], FileKind); 12] = [
            (b"", FileKind::Empty),
            (b"\xff\xd8\xff\xe0\0\x10JFIF", FileKind::Jpeg),
            (b"GIF89a\x01\0", FileKind::Gif),
            (b"RIFF\0\0\0\0WEBPVP8 ", FileKind::WebP),
            (b"\0\0\0\x18ftypheic", FileKind::Heif),
            (b"8BPS\0\x01\0\0", FileKind::Photoshop { psb: false }),
            (b"8BPS\0\x02\0\0", FileKind::Photoshop { psb: true }),
            (b"gimp xcf v011\0", FileKind::Xcf),
            (b"%PDF-1.7\n", FileKind::Pdf),
            (b"<?xml version=\"1.0\"?>\n<svg xmlns=\"\">", FileKind::Svg),
            (b"these are notes \xc3\xa9t\xc3", FileKind::Text),
            (b"\x01\x02\x03\x04", FileKind::Unknown),
        ];
        for (bytes, kind) in cases {
            assert_eq!(FileKind::of(bytes), kind, "{bytes:?}");
        }
        let kra = zip_head("mimetype", b"application/x-krita");
        assert_eq!(FileKind::of(&kra), FileKind::Krita);
        let ora = zip_head("mimetype", b"image/openraster");
        assert_eq!(FileKind::of(&ora), FileKind::OpenRaster);
        assert_eq!(FileKind::of(&zip_head("a.txt", b"hi")), FileKind::Zip);
        assert_eq!(FileKind::of(&kra[..20]), FileKind::Zip, "cut short");

        // The message says what the file is and what to do, on one line.
        let tmp = crate::test_scratch::scratch("image-kinds");
        let path = tmp.path().join("cat.kra");
        std::fs::write(&path, &kra).unwrap();
        let Err(e) = load_png(&path) else {
            panic!("a Krita file read as PNG")
        };
        let png = e.to_string();
        assert!(
            png.contains("cat.kra: a Krita document (KRA), not a PNG image"),
            "{png}"
        );
        let ImageError::NotPng { path, found, .. } = e else {
            panic!("{png}")
        };
        let art = ImageError::NotPng {
            path,
            found,
            expected: Expected::Art,
        }
        .to_string();
        for part in ["Krita", "PSD, PSB or OpenRaster (.ora)", "File ▸ Export"] {
            assert!(art.contains(part), "{art}");
        }
        assert!(!art.contains('\n'));
    }
}
