//! Where the writers get their frames: drawn on demand, a chunk at a time.
//!
//! In: a [`FrameSource`], anything that can draw frames `range` of a sequence of same-size
//! straight-alpha RGBA8 frames (frames already in memory, or an animation posed and drawn as
//! they are asked for, see [`crate::playback::AnimationFrames`]). Out: the frames in chunks of
//! [`STREAM_CHUNK_FRAMES`], in order, so a writer holds one chunk at a time and a render of any
//! length runs in bounded memory.

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

/// The chunks `0..count` is pulled in: [`STREAM_CHUNK_FRAMES`] frames each, the last shorter.
pub fn chunks(count: usize) -> impl Iterator<Item = Range<usize>> {
    (0..count)
        .step_by(STREAM_CHUNK_FRAMES)
        .map(move |start| start..(start + STREAM_CHUNK_FRAMES).min(count))
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
        assert_eq!(chunks(0).count(), 0);
        let c: Vec<_> = chunks(2 * STREAM_CHUNK_FRAMES + 3).collect();
        assert_eq!(
            c,
            vec![
                0..STREAM_CHUNK_FRAMES,
                STREAM_CHUNK_FRAMES..2 * STREAM_CHUNK_FRAMES,
                2 * STREAM_CHUNK_FRAMES..2 * STREAM_CHUNK_FRAMES + 3
            ]
        );
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
