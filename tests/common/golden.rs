//! Golden images: compare a render with its reviewed PNG in `golden/`, or bless it.
//!
//! `SINEW_BLESS=1` writes the actual image as the new reference (look at it before committing).
//! A failing comparison writes `target/golden-failures/<name>.actual.png` and `<name>.diff.png`
//! (channel differences ×[`DIFF_GAIN`]) and names them in the panic.

use image::{Rgba, RgbaImage};
use sinew::io::{load_png, save_png};
use sinew::render;
use std::path::PathBuf;

/// Largest premultiplied channel difference accepted by [`premultiplied_tolerance`], of 255.
pub const MAX_CHANNEL_DIFF: u8 = 2;
/// Smallest premultiplied PSNR accepted by [`premultiplied_tolerance`], dB.
pub const MIN_PSNR_DB: f64 = 50.0;
/// Scale of the difference image, so that small errors are visible.
pub const DIFF_GAIN: u16 = 8;

/// (largest premultiplied channel difference, premultiplied PSNR in dB).
pub fn premultiplied_difference(a: &RgbaImage, b: &RgbaImage) -> (u8, f64) {
    let max = render::max_channel_diff(&render::premultiplied(a), &render::premultiplied(b));
    (max, render::psnr_premultiplied(a, b))
}

/// The project's default tolerance: on premultiplied RGBA8 (what compositing shows), max
/// channel difference ≤ [`MAX_CHANNEL_DIFF`] and PSNR ≥ [`MIN_PSNR_DB`].
pub fn premultiplied_tolerance(actual: &RgbaImage, expected: &RgbaImage) -> Result<(), String> {
    let (max, psnr) = premultiplied_difference(actual, expected);
    if max <= MAX_CHANNEL_DIFF && psnr >= MIN_PSNR_DB {
        Ok(())
    } else {
        Err(format!(
            "max channel difference {max} (allowed {MAX_CHANNEL_DIFF}), PSNR {psnr:.1} dB (required {MIN_PSNR_DB})"
        ))
    }
}

/// Compares `actual` with `golden/<name>.png` by `accept` (which explains a failure), or blesses
/// it; `test` names the test target for the bless hint.
pub fn check(
    name: &str,
    actual: &RgbaImage,
    test: &str,
    accept: impl Fn(&RgbaImage, &RgbaImage) -> Result<(), String>,
) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let golden = root.join("golden").join(format!("{name}.png"));
    if std::env::var("SINEW_BLESS").is_ok_and(|v| v == "1") {
        save_png(&golden, actual).expect("writes the golden image");
        eprintln!("blessed {}", golden.display());
        return;
    }
    let expected = load_png(&golden).unwrap_or_else(|e| {
        panic!("{e}: no golden image for '{name}'; review it and bless with SINEW_BLESS=1 cargo test --test {test}")
    });
    let problem = if actual.dimensions() == expected.dimensions() {
        match accept(actual, &expected) {
            Ok(()) => return,
            Err(problem) => problem,
        }
    } else {
        format!(
            "size {:?} vs {:?}",
            actual.dimensions(),
            expected.dimensions()
        )
    };
    let out = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"))
        .join("golden-failures");
    std::fs::create_dir_all(&out).expect("creates the failures folder");
    let actual_path = out.join(format!("{name}.actual.png"));
    let diff_path = out.join(format!("{name}.diff.png"));
    save_png(&actual_path, actual).expect("writes the actual image");
    if actual.dimensions() == expected.dimensions() {
        save_png(&diff_path, &diff_image(actual, &expected)).expect("writes the diff");
    }
    panic!(
        "'{name}' differs from {}: {problem}; actual: {}, diff: {}",
        golden.display(),
        actual_path.display(),
        diff_path.display()
    );
}

/// Premultiplied channel differences ×[`DIFF_GAIN`], opaque.
fn diff_image(a: &RgbaImage, b: &RgbaImage) -> RgbaImage {
    let (pa, pb) = (render::premultiplied(a), render::premultiplied(b));
    let (pa, pb) = (pa.as_raw(), pb.as_raw());
    RgbaImage::from_fn(a.width(), a.height(), |x, y| {
        let i = 4 * (y * a.width() + x) as usize;
        let d = |k: usize| (u16::from(pa[i + k].abs_diff(pb[i + k])) * DIFF_GAIN).min(255) as u8;
        let alpha = d(3);
        Rgba([d(0).max(alpha), d(1).max(alpha), d(2).max(alpha), 255])
    })
}
