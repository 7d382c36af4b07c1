//! Numbered PNG frames in a folder: `frame_0000.png`, `frame_0001.png`, ….
//!
//! In: straight-alpha RGBA8 frames, frames per second (only for the report; PNG has no timing),
//! the folder (created if missing). Out: one PNG per frame, numbered from 0 with enough
//! zero-padding (at least [`MIN_DIGITS`]) that names sort in frame order.
//!
//! The folder changes in one step: the frames are written into a hidden sibling folder
//! (`.NAME.PID.N.tmp`, see [`crate::io::atomic`]), which then takes the folder's place by one
//! atomic exchange of the two names (Linux's `renameat2(RENAME_EXCHANGE)`; elsewhere two
//! renames). So at any moment, a kill included, the folder holds exactly the previous complete
//! render or the new one; the previous render's frames (`frame_` + digits + `.png`) all go,
//! including those the new render has no number for. Files sinew did not write stay as they
//! are: each is hard-linked into the new folder before the exchange (the same file, untouched);
//! subfolders are moved over right after it. A temporary folder left by a killed run is tidied by
//! the next run into the same folder (its frames removed, anything else moved back).

use super::source::{
    check_chunk, chunks, first_frame_size, frames_in_flight, FrameSource, WriterCost,
};
use super::{check_fps, write_error, SequenceError, SequenceFormat, SequenceReport};
use crate::io::atomic::{
    exchange_folders, resolve_output, stale_temporaries, temporary_sibling, write_new, OutputKind,
};
use crate::io::image::encode_png;
use rayon::prelude::*;
use std::fs;
use std::path::Path;

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

/// Whether `name` is a frame file's name (`frame_` + digits + `.png`): what a render writes.
pub fn is_frame_name(name: &str) -> bool {
    name.strip_prefix(FRAME_PREFIX)
        .and_then(|n| n.strip_suffix(".png"))
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

/// Writes `frames` into the folder `dir` as numbered PNGs, replacing the render there (see the
/// module doc). `dir` may be a symbolic link to a folder (the folder it names is replaced); an
/// existing `dir` that is not a folder is refused.
pub fn write_folder<S: FrameSource + ?Sized>(
    frames: &S,
    fps: f64,
    dir: &Path,
) -> Result<SequenceReport, SequenceError> {
    let size = first_frame_size(frames)?;
    check_fps(fps)?;
    let count = frames.frame_count();
    // Each thread compressing a frame holds its PNG: at most about the frame's size.
    let encoding = WriterCost {
        per_thread_bytes: crate::budget::px_bytes(size, crate::budget::FRAME_BYTES_PER_PX),
        ..WriterCost::default()
    };
    let in_flight = frames_in_flight(frames, encoding, "numbered PNGs")?;
    let target = resolve_output(dir, OutputKind::Folder).map_err(write_error(dir))?;
    if let Some(parent) = target.parent().filter(|p| !p.as_os_str().is_empty()) {
        fs::create_dir_all(parent).map_err(write_error(parent))?;
    }
    for stale in stale_temporaries(&target) {
        tidy_stale_folder(&stale, &target);
    }
    let digits = digits_for(count);
    let names: Vec<String> = (0..count).map(|i| frame_file_name(i, digits)).collect();
    let staging = temporary_sibling(&target);
    fs::create_dir(&staging).map_err(write_error(&staging))?;
    let result = fill_and_swap(frames, size, in_flight, &names, &staging, &target);
    if result.is_err() {
        // Before the swap the staging folder holds only new frames and links; after a failed
        // swap the same. Nothing of the user's is in it.
        let _ = fs::remove_dir_all(&staging);
    }
    let removed = result?;
    Ok(SequenceReport {
        format: SequenceFormat::Folder,
        files: names.iter().map(|n| dir.join(n)).collect(),
        frame_count: count,
        frame_size_px: size,
        duration_s: count as f64 / fps,
        palette_colours: None,
        sheet_size_px: None,
        stale_files: removed.iter().map(|n| dir.join(n)).collect(),
    })
}

/// Writes the frames into `staging`, puts it in `target`'s place and returns the names of the
/// previous render's frames that the new one has no file for (removed with it), sorted.
fn fill_and_swap<S: FrameSource + ?Sized>(
    frames: &S,
    size: (u32, u32),
    in_flight: usize,
    names: &[String],
    staging: &Path,
    target: &Path,
) -> Result<Vec<String>, SequenceError> {
    // A chunk of `in_flight` frames at a time (bounded memory). PNG compression dominates;
    // frames are independent. Results are gathered in frame order so the error reported (the
    // first frame's) does not depend on scheduling.
    for range in chunks(frames.frame_count(), in_flight) {
        let drawn = frames.draw(range.clone())?;
        check_chunk(&drawn, range.start, size)?;
        let results: Vec<Result<(), SequenceError>> = drawn
            .par_iter()
            .zip(&names[range])
            .map(|(frame, name)| {
                let path = staging.join(name);
                let bytes = encode_png(frame).map_err(|e| SequenceError::Encode {
                    path: path.clone(),
                    reason: e.to_string(),
                })?;
                write_new(&path, &bytes).map_err(write_error(&path))
            })
            .collect();
        results.into_iter().collect::<Result<(), _>>()?;
    }
    if !target.exists() {
        fs::rename(staging, target).map_err(write_error(target))?;
        return Ok(Vec::new());
    }
    // The user's files and links come along as hard links; subfolders move after the swap.
    let mut after_swap = Vec::new();
    let mut removed = Vec::new();
    for entry in fs::read_dir(target).map_err(write_error(target))? {
        let entry = entry.map_err(write_error(target))?;
        let name = entry.file_name();
        if name.to_str().is_some_and(is_frame_name) {
            if !names.iter().any(|n| name.to_str() == Some(n)) {
                removed.push(name.to_string_lossy().into_owned());
            }
            continue;
        }
        let path = entry.path();
        // Where a hard link is not possible (another file system's rules), the entry moves
        // after the swap like a subfolder.
        if entry.file_type().map_err(write_error(&path))?.is_dir()
            || fs::hard_link(&path, staging.join(&name)).is_err()
        {
            after_swap.push(name);
        }
    }
    if let Ok(meta) = fs::metadata(target) {
        let _ = fs::set_permissions(staging, meta.permissions());
    }
    exchange_folders(staging, target).map_err(write_error(target))?;
    // `staging` now holds the previous render.
    for name in after_swap {
        let from = staging.join(&name);
        fs::rename(&from, target.join(&name)).map_err(write_error(&from))?;
    }
    let _ = fs::remove_dir_all(staging);
    removed.sort();
    Ok(removed)
}

/// Tidies a temporary folder a killed run left beside `target`: frames and links to files that
/// `target` also holds go; anything else is moved back into `target` where `target` lacks it
/// (or kept where it is when it cannot be); the folder goes when empty. A temporary *file* of
/// that name is removed.
fn tidy_stale_folder(stale: &Path, target: &Path) {
    let Ok(meta) = fs::symlink_metadata(stale) else {
        return;
    };
    if !meta.is_dir() {
        let _ = fs::remove_file(stale);
        return;
    }
    if let Ok(entries) = fs::read_dir(stale) {
        for entry in entries.filter_map(|e| e.ok()) {
            let name = entry.file_name();
            let path = entry.path();
            let back = target.join(&name);
            if name.to_str().is_some_and(is_frame_name) || same_file(&path, &back) {
                let _ = fs::remove_file(&path);
            } else if !back.exists() && target.is_dir() {
                let _ = fs::rename(&path, &back);
            }
        }
    }
    let _ = fs::remove_dir(stale);
}

/// Whether `a` and `b` are one file (hard links of it), not following symbolic links.
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (fs::symlink_metadata(a), fs::symlink_metadata(b)) {
            (Ok(x), Ok(y)) => !x.is_dir() && x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (a, b);
        false
    }
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
        assert!(is_frame_name("frame_0007.png"));
        assert!(!is_frame_name("frame_.png"));
        assert!(!is_frame_name("frame_07.PNG"));
        assert!(!is_frame_name("notes.txt"));
    }
}
