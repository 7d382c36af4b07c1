//! Where the writers get their frames: drawn on demand, a chunk at a time.
//!
//! In: a [`FrameSource`], anything that can draw frames `range` of a sequence of same-size
//! straight-alpha RGBA8 frames (frames already in memory, or an animation posed and drawn as
//! they are asked for, see [`crate::playback::AnimationFrames`]). Out: the frames in chunks of
//! at most [`STREAM_CHUNK_FRAMES`], in order, so a writer holds one chunk at a time and a render
//! of any length runs in bounded memory; [`frames_in_flight`] makes the chunks as small as the
//! memory budget ([`crate::budget`]) needs, and refuses frames of which not even one fits.

use super::SequenceError;
use image::RgbaImage;
use std::borrow::Cow;
use std::ops::Range;

/// Frames drawn (and held) at once by the streaming writers: enough to keep every core busy
/// drawing and compressing, few enough that 1080p chunks take ~130 MB.
pub const STREAM_CHUNK_FRAMES: usize = 16;

/// A sequence of same-size frames the writers pull a chunk at a time.
pub trait FrameSource: Sync {
    /// How many frames the sequence has.
    fn frame_count(&self) -> usize;
    /// The size every frame has, px (frame 0's for frames in memory; each chunk drawn is
    /// checked against it).
    fn frame_size_px(&self) -> (u32, u32);
    /// Frames `range` (within `0..frame_count()`), straight-alpha RGBA8, in order. Drawing
    /// the same range again gives the same pixels.
    fn draw(&self, range: Range<usize>) -> Result<Vec<Cow<'_, RgbaImage>>, SequenceError>;
    /// Whether the frames are held already, so drawing them again costs nothing (a writer that
    /// reads them twice need not keep copies). Default false.
    fn in_memory(&self) -> bool {
        false
    }
    /// Bytes a thread allocates to draw one frame besides the frame it returns (and may keep
    /// for its next one): [`crate::budget::DRAW_BYTES_PER_PX`] per px for a rendered frame.
    /// Default 0 (frames already drawn).
    fn draw_bytes_per_thread(&self) -> u64 {
        0
    }
}

impl FrameSource for [RgbaImage] {
    fn frame_count(&self) -> usize {
        self.len()
    }

    fn frame_size_px(&self) -> (u32, u32) {
        self.first().map_or((0, 0), |f| f.dimensions())
    }

    fn draw(&self, range: Range<usize>) -> Result<Vec<Cow<'_, RgbaImage>>, SequenceError> {
        Ok(self[range].iter().map(Cow::Borrowed).collect())
    }

    fn in_memory(&self) -> bool {
        true
    }
}

impl FrameSource for Vec<RgbaImage> {
    fn frame_count(&self) -> usize {
        self.len()
    }

    fn frame_size_px(&self) -> (u32, u32) {
        self.as_slice().frame_size_px()
    }

    fn draw(&self, range: Range<usize>) -> Result<Vec<Cow<'_, RgbaImage>>, SequenceError> {
        self.as_slice().draw(range)
    }

    fn in_memory(&self) -> bool {
        true
    }
}

/// The chunks `0..count` is pulled in: `chunk_frames` frames each (at least one), the last
/// shorter.
pub fn chunks(count: usize, chunk_frames: usize) -> impl Iterator<Item = Range<usize>> {
    let chunk_frames = chunk_frames.max(1);
    (0..count)
        .step_by(chunk_frames)
        .map(move |start| start..(start + chunk_frames).min(count))
}

/// What a writer holds besides the frames themselves (see [`frames_in_flight`]), bytes.
#[derive(Clone, Copy, Debug, Default)]
pub struct WriterCost {
    /// Held whatever the number of frames in flight (a palette table, a sheet).
    pub fixed_bytes: u64,
    /// Held per frame in flight besides the frame (a colour list, a trimmed copy).
    pub per_frame_bytes: u64,
    /// Allocated per thread busy with a frame (an encoded PNG).
    pub per_thread_bytes: u64,
}

/// What a writer with `cost` holds with frames of `source` in flight: each frame drawn (4 B/px
/// unless the source holds it already), each drawing thread's pixmap and scratch
/// ([`FrameSource::draw_bytes_per_thread`]) and the writer's own, on the current thread pool.
pub fn frame_cost<S: FrameSource + ?Sized>(
    source: &S,
    cost: WriterCost,
) -> crate::budget::FrameCost {
    use crate::budget::{px_bytes, FRAME_BYTES_PER_PX};
    let held = if source.in_memory() {
        0
    } else {
        px_bytes(source.frame_size_px(), FRAME_BYTES_PER_PX)
    };
    crate::budget::FrameCost {
        fixed_bytes: cost.fixed_bytes,
        per_frame_bytes: held.saturating_add(cost.per_frame_bytes),
        per_thread_bytes: source
            .draw_bytes_per_thread()
            .saturating_add(cost.per_thread_bytes),
        threads: rayon::current_num_threads(),
    }
}

/// How many frames of `source` a writer with `cost` may draw and hold at once: at most
/// [`STREAM_CHUNK_FRAMES`], as many as the memory budget in force allows
/// ([`crate::budget::memory_budget`]) — each frame drawn (4 B/px unless the source holds it
/// already), each drawing thread's pixmap and scratch, the writer's own. Fails before anything
/// is drawn when not even one frame fits; `writing` names the output ("numbered PNGs").
/// The output does not depend on the chunk size.
pub fn frames_in_flight<S: FrameSource + ?Sized>(
    source: &S,
    cost: WriterCost,
    writing: &str,
) -> Result<usize, SequenceError> {
    let size = source.frame_size_px();
    let max = STREAM_CHUNK_FRAMES.min(source.frame_count().max(1));
    let budget = crate::budget::memory_budget();
    let in_flight = budget.frames_in_flight(&frame_cost(source, cost), max, || {
        format!(
            "a {}×{} px frame drawn and written as {writing}",
            size.0, size.1
        )
    })?;
    Ok(in_flight)
}

/// Checks the frames of one chunk (starting at frame `first`) against the sequence's size
/// `expected` (frame 0's, px): every frame has pixels and that size.
pub fn check_chunk(
    frames: &[Cow<'_, RgbaImage>],
    first: usize,
    expected: (u32, u32),
) -> Result<(), SequenceError> {
    for (k, frame) in frames.iter().enumerate() {
        let index = first + k;
        let (width, height) = frame.dimensions();
        if width == 0 || height == 0 {
            return Err(SequenceError::EmptyFrame {
                index,
                width,
                height,
            });
        }
        if (width, height) != expected {
            return Err(SequenceError::MismatchedSize {
                index,
                width,
                height,
                expected_width: expected.0,
                expected_height: expected.1,
            });
        }
    }
    Ok(())
}

/// The frames' size, px, checked to have pixels; fails on an empty sequence. (Each chunk is
/// checked against it as it is drawn, [`check_chunk`].)
pub fn first_frame_size<S: FrameSource + ?Sized>(source: &S) -> Result<(u32, u32), SequenceError> {
    if source.frame_count() == 0 {
        return Err(SequenceError::NoFrames);
    }
    let (width, height) = source.frame_size_px();
    if width == 0 || height == 0 {
        return Err(SequenceError::EmptyFrame {
            index: 0,
            width,
            height,
        });
    }
    Ok((width, height))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_cover_every_frame_once_in_order() {
        assert_eq!(chunks(0, STREAM_CHUNK_FRAMES).count(), 0);
        let c: Vec<_> = chunks(2 * STREAM_CHUNK_FRAMES + 3, STREAM_CHUNK_FRAMES).collect();
        assert_eq!(
            c,
            vec![
                0..STREAM_CHUNK_FRAMES,
                STREAM_CHUNK_FRAMES..2 * STREAM_CHUNK_FRAMES,
                2 * STREAM_CHUNK_FRAMES..2 * STREAM_CHUNK_FRAMES + 3
            ]
        );
        let c: Vec<_> = chunks(5, 2).collect();
        assert_eq!(c, vec![0..2, 2..4, 4..5]);
        assert_eq!(chunks(2, 0).count(), 2);
    }

    #[test]
    fn sizes_are_checked_per_chunk() {
        let frames = vec![
            RgbaImage::new(4, 3),
            RgbaImage::new(4, 3),
            RgbaImage::new(3, 4),
        ];
        assert_eq!(first_frame_size(&frames).unwrap(), (4, 3));
        let drawn = frames.draw(1..3).unwrap();
        assert!(matches!(
            check_chunk(&drawn, 1, (4, 3)),
            Err(SequenceError::MismatchedSize { index: 2, .. })
        ));
        let none: Vec<RgbaImage> = Vec::new();
        assert!(matches!(
            first_frame_size(&none),
            Err(SequenceError::NoFrames)
        ));
        let empty = vec![RgbaImage::new(0, 3)];
        assert!(matches!(
            first_frame_size(&empty),
            Err(SequenceError::EmptyFrame { index: 0, .. })
        ));
    }
}
