//! Numbered PNG frames in a folder: `frame_0000.png`, `frame_0001.png`, ….
//!
//! In: straight-alpha RGBA8 frames, frames per second (only for the report; PNG has no timing),
//! the folder (created if missing). Out: one PNG per frame, each written atomically, numbered from
//! 0 with enough zero-padding (at least [`MIN_DIGITS`]) that names sort in frame order.

use super::{check_fps, check_frames, write_error, SequenceError, SequenceFormat, SequenceReport};
use crate::io::atomic::write_atomic;
use crate::io::image::encode_png;
use image::RgbaImage;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Name of every frame file before its number.
pub const FRAME_PREFIX: &str = "frame_";
/// Digits in frame numbers at least (more when the count needs them).
pub const MIN_DIGITS: usize = 4;

/// Digits needed to number `count` frames from 0, at least [`MIN_DIGITS`].
pub fn digits_for(count: usize) -> usize {
    count.saturating_sub(1).to_string().len().max(MIN_DIGITS)
}

/// `frame_0007.png` for frame 7 of a sequence numbered with `digits` digits.
pub fn frame_file_name(index: usize, digits: usize) -> String {
    format!("{FRAME_PREFIX}{index:0digits$}.png")
}

/// Writes `frames` into the folder `dir` as numbered PNGs.
pub fn write_folder(
    frames: &[RgbaImage],
    fps: f64,
    dir: &Path,
) -> Result<SequenceReport, SequenceError> {
    let size = check_frames(frames)?;
    check_fps(fps)?;
    std::fs::create_dir_all(dir).map_err(write_error(dir))?;
    let digits = digits_for(frames.len());
    let paths: Vec<PathBuf> = (0..frames.len())
        .map(|i| dir.join(frame_file_name(i, digits)))
        .collect();
    // PNG compression dominates; frames are independent. Results are gathered in frame order so
    // the error reported (the first frame's) does not depend on scheduling.
    let results: Vec<Result<(), SequenceError>> = frames
        .par_iter()
        .zip(&paths)
        .map(|(frame, path)| {
            let bytes = encode_png(frame).map_err(|e| SequenceError::Encode {
                path: path.clone(),
                reason: e.to_string(),
            })?;
            write_atomic(path, &bytes).map_err(write_error(path))
        })
        .collect();
    results.into_iter().collect::<Result<(), _>>()?;
    let stale_files = stale_frames(dir, &paths);
    Ok(SequenceReport {
        format: SequenceFormat::Folder,
        files: paths,
        frame_count: frames.len(),
        frame_size_px: size,
        duration_s: frames.len() as f64 / fps,
        palette_colours: None,
        sheet_size_px: None,
        stale_files,
    })
}

/// Files named like frames (`frame_` + digits + `.png`) in `dir` that are not in `written`,
/// sorted. An unreadable folder listing gives none: the frames themselves were written.
fn stale_frames(dir: &Path, written: &[PathBuf]) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut stale: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .and_then(|n| n.strip_prefix(FRAME_PREFIX))
                .and_then(|n| n.strip_suffix(".png"))
                .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
        })
        .filter(|p| !written.contains(p))
        .collect();
    stale.sort();
    stale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_padded_to_the_count() {
        assert_eq!(digits_for(1), 4);
        assert_eq!(digits_for(10_000), 4);
        assert_eq!(digits_for(10_001), 5);
        assert_eq!(frame_file_name(7, 4), "frame_0007.png");
        assert_eq!(frame_file_name(12345, 5), "frame_12345.png");
    }
}
