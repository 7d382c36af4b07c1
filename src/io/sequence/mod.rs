//! Writing rendered animation frames to the files a game or a web page uses.
//!
//! In: a sequence of frames, all the same size, as straight-alpha RGBA8 images (what
//! `render::rgba_from_pixmap` makes of the renderer's premultiplied pixmaps), and the frame rate
//! in frames per second. The frames come from a [`FrameSource`]: frames in memory, or an
//! animation drawn as the writers pull it, a chunk at a time, so a render of any length is
//! written in bounded memory: within the memory budget ([`crate::budget`]), which sets how many
//! frames a chunk holds and refuses, before drawing, what does not fit. Out, chosen by the target path:
//!
//! - an existing folder, or a path without extension: numbered PNGs `frame_0000.png`, … ([`folder`]);
//! - `NAME.gif`: an animated GIF looping forever, one global palette ([`gif`]);
//! - `NAME.png`: a sprite sheet with `NAME.json` beside it, TexturePacker's "JSON hash" layout
//!   ([`sheet`]).
//!
//! Every file is written atomically (a frame folder as a whole), through symbolic links, and never
//! over anything but a regular file (a folder for frames); identical input gives byte-identical
//! files.

pub mod background;
pub mod folder;
pub mod gif;
pub mod palette;
pub mod sheet;
pub mod source;
pub mod synthetic;
pub mod timing;

pub use background::{composite_over_background, parse_rgba_hex};
pub use folder::write_folder;
pub use gif::{encode_gif, write_gif, GifOptions};
pub use sheet::{build_sheet, write_sheet, FrameNaming, SheetOptions};
pub use source::{frames_in_flight, FrameSource, WriterCost, STREAM_CHUNK_FRAMES};

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What went wrong while writing a sequence; each message is one line.
#[derive(Debug, thiserror::Error)]
pub enum SequenceError {
    #[error("no frames to write")]
    NoFrames,
    #[error("{events} lists of frame events for {frames} frames")]
    EventFrames { frames: usize, events: usize },
    #[error("frame {index} has no pixels ({width}×{height} px)")]
    EmptyFrame {
        index: usize,
        width: u32,
        height: u32,
    },
    #[error(
        "frame {index} is {width}×{height} px but frame 0 is {expected_width}×{expected_height} px"
    )]
    MismatchedSize {
        index: usize,
        width: u32,
        height: u32,
        expected_width: u32,
        expected_height: u32,
    },
    #[error("frame rate must be a positive finite number of frames per second, got {fps}")]
    BadFrameRate { fps: f64 },
    #[error("a GIF cannot play {fps} fps (browsers slow frames shorter than 2/100 s down); use at most {max_fps} fps")]
    GifFrameRateTooHigh { fps: f64, max_fps: f64 },
    #[error("GIF frames are at most {max}×{max} px, got {width}×{height} px")]
    GifTooLarge { width: u32, height: u32, max: u32 },
    #[error("GIF palette size must be between {min} and {max} colours, got {got}")]
    BadPaletteSize { got: u16, min: u16, max: u16 },
    #[error("the sprite sheet needs {width}×{height} px, more than the {max_side_px} px limit: use fewer or smaller frames, or raise the limit")]
    SheetTooLarge {
        width: u64,
        height: u64,
        max_side_px: u32,
    },
    #[error("{path}: not a sequence target: use a folder, NAME.gif or NAME.png (sprite sheet + NAME.json)")]
    UnknownFormat { path: PathBuf },
    #[error("{path}: cannot write: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: cannot encode: {reason}")]
    Encode { path: PathBuf, reason: String },
    #[error("bad colour {text:?}: expected #rrggbb or #rrggbbaa")]
    BadColour { text: String },
    /// Drawing the frames failed (posing or rendering them as they were asked for).
    #[error("{0}")]
    Draw(String),
    /// Not even one frame, or what the format must hold, fits in the memory budget.
    #[error(transparent)]
    Budget(#[from] crate::budget::BudgetError),
}

/// The kind of file(s) a target path asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SequenceFormat {
    /// Numbered PNGs in a folder.
    Folder,
    /// One animated GIF.
    Gif,
    /// A sprite-sheet PNG and its JSON frame map.
    Sheet,
}

/// Options of every writer; `Default` gives the documented defaults.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SequenceOptions {
    pub gif: GifOptions,
    pub sheet: SheetOptions,
}

/// What was written.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SequenceReport {
    pub format: SequenceFormat,
    /// Every file written, in the order written.
    pub files: Vec<PathBuf>,
    pub frame_count: usize,
    /// Size of every frame, px.
    pub frame_size_px: (u32, u32),
    /// Playing time of the whole sequence as the file stores it, s (GIF delays are rounded to
    /// 1/100 s, sheet durations to 1 ms, but their sums stay on the exact total).
    pub duration_s: f64,
    /// GIF only: colours in the palette, the transparent entry not counted.
    pub palette_colours: Option<usize>,
    /// Sheet only: the sheet's size, px.
    pub sheet_size_px: Option<(u32, u32)>,
    /// Folder only: `frame_N.png` files of the previous render that this one has no frame for
    /// (it was longer); they went with the previous render (see [`folder`]).
    pub stale_files: Vec<PathBuf>,
}

/// Picks the format from the target path: an existing folder or a path without extension is a
/// folder; `.gif` a GIF; `.png` a sprite sheet (extension case ignored).
pub fn format_for_path(path: &Path) -> Result<SequenceFormat, SequenceError> {
    if path.is_dir() {
        return Ok(SequenceFormat::Folder);
    }
    match path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
    {
        None => Ok(SequenceFormat::Folder),
        Some(ext) if ext == "gif" => Ok(SequenceFormat::Gif),
        Some(ext) if ext == "png" => Ok(SequenceFormat::Sheet),
        Some(_) => Err(SequenceError::UnknownFormat { path: path.into() }),
    }
}

/// Writes `frames` (straight alpha, `fps` frames per second) to `path` in the format its
/// extension asks for (see [`format_for_path`]). `events` (empty, or one list per frame: what
/// each frame fires) go into a sprite sheet's JSON; a GIF or a folder has no place for them.
pub fn write_sequence<S: FrameSource + ?Sized>(
    frames: &S,
    events: &[Vec<crate::anim::FiredEvent>],
    fps: f64,
    path: &Path,
    options: &SequenceOptions,
) -> Result<SequenceReport, SequenceError> {
    match format_for_path(path)? {
        SequenceFormat::Folder => write_folder(frames, fps, path),
        SequenceFormat::Gif => write_gif(frames, fps, path, &options.gif),
        SequenceFormat::Sheet => write_sheet(frames, events, fps, path, &options.sheet),
    }
}

/// Checks the frame rate: positive and finite.
pub fn check_fps(fps: f64) -> Result<(), SequenceError> {
    if fps.is_finite() && fps > 0.0 {
        Ok(())
    } else {
        Err(SequenceError::BadFrameRate { fps })
    }
}

/// Wraps an I/O error with the path it concerns.
fn write_error(path: &Path) -> impl FnOnce(std::io::Error) -> SequenceError + '_ {
    move |source| SequenceError::Write {
        path: path.into(),
        source,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_follows_the_extension() {
        let p = |s: &str| format_for_path(Path::new(s));
        assert_eq!(p("out/walk.gif").unwrap(), SequenceFormat::Gif);
        assert_eq!(p("out/walk.GIF").unwrap(), SequenceFormat::Gif);
        assert_eq!(p("out/walk.png").unwrap(), SequenceFormat::Sheet);
        assert_eq!(p("out/walk").unwrap(), SequenceFormat::Folder);
        assert_eq!(
            format_for_path(&std::env::temp_dir()).unwrap(),
            SequenceFormat::Folder
        );
        let err = p("out/walk.webp").unwrap_err();
        assert!(matches!(err, SequenceError::UnknownFormat { .. }));
        assert!(!err.to_string().contains('\n'));
    }

    #[test]
    fn options_read_from_json_with_defaults() {
        let empty: SequenceOptions = serde_json::from_str("{}").unwrap();
        assert_eq!(empty, SequenceOptions::default());
        let some: SequenceOptions = serde_json::from_str(
            r#"{"gif": {"alpha_threshold": 1}, "sheet": {"naming": "index", "max_side_px": 2048}}"#,
        )
        .unwrap();
        assert_eq!(some.gif.alpha_threshold, 1);
        assert_eq!(some.gif.palette_size, 256);
        assert_eq!(some.sheet.naming, FrameNaming::Index);
        assert_eq!(some.sheet.max_side_px, 2048);
        assert_eq!(some.sheet.padding_px, 2);
        let text = serde_json::to_string(&some).unwrap();
        assert_eq!(
            serde_json::from_str::<SequenceOptions>(&text).unwrap(),
            some
        );
    }

    #[test]
    fn frame_rates_are_checked() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                check_fps(bad),
                Err(SequenceError::BadFrameRate { .. })
            ));
        }
        assert!(check_fps(23.976).is_ok());
    }
}
