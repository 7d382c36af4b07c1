//! Animated GIF: one global palette, 1-bit transparency, delays from the frame rate, looping.
//!
//! In: straight-alpha RGBA8 frames of one size (a [`FrameSource`], pulled a chunk at a time),
//! frames per second, [`GifOptions`]. Out: GIF89a bytes (or a file, written atomically) that
//! loop forever.
//!
//! - Palette: one for all frames, so colours do not flicker between frames ([`super::palette`]:
//!   Wu's quantizer + k-means over the pooled histogram; exact when the colours fit).
//! - Transparency: GIF has one transparent palette index and no partial alpha. A pixel whose
//!   alpha is below `alpha_threshold` becomes transparent; any other pixel becomes opaque with
//!   its own straight (unpremultiplied) colour. So antialiased edges keep the shape's colour and
//!   look right on any page background, at the price of a hard, 1-pixel-stepped edge. For a known
//!   background, composite the frames over it first (`composite_over_background`): the edges are
//!   then blended properly and nothing is transparent. Index 0 is the transparent one, which is
//!   also the screen's background index, so viewers that paint the "background colour" on
//!   disposal paint transparency.
//! - Timing: delays in 1/100 s, rounding spread so the total is exact ([`super::timing`]).
//!   Browsers play delays below 2/100 s as 1/10 s, so more than 50 fps is refused.
//! - Disposal: every frame is "restore to background", so a frame never shows through the next.
//!   Since the canvas is thus clear before each frame, a frame is stored cropped to the box of
//!   its visible pixels, which saves the transparent margins' bytes.

use super::palette::{pack_rgb, quantize, Histogram};
use super::source::{
    check_chunk, chunks, first_frame_size, frame_cost, frames_in_flight, FrameSource, WriterCost,
};
use super::timing::{frame_durations, GIF_TICKS_PER_S};
use super::{check_fps, write_error, SequenceError, SequenceFormat, SequenceReport};
use crate::io::atomic::write_atomic;
use ::gif::{DisposalMethod, Encoder, Frame, Repeat};
use image::RgbaImage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::path::Path;

/// Pixels with alpha below this become transparent; the others opaque (default of
/// [`GifOptions::alpha_threshold`]): half coverage, so a shape keeps its area.
pub const DEFAULT_ALPHA_THRESHOLD: u8 = 128;
/// Palette entries at most, the transparent one included (GIF's limit).
pub const MAX_PALETTE_SIZE: u16 = 256;
/// Palette entries at least: one colour and the transparent entry.
pub const MIN_PALETTE_SIZE: u16 = 2;
/// Highest frame rate browsers play as written: their shortest honoured delay is 2/100 s.
pub const MAX_GIF_FPS: f64 = 50.0;
/// GIF stores sizes and offsets as 16-bit numbers.
pub const MAX_GIF_SIDE_PX: u32 = u16::MAX as u32;
/// The palette index written for transparent pixels.
pub const TRANSPARENT_INDEX: u8 = 0;

/// GIF options; `Default` gives the documented defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GifOptions {
    /// Alpha below which a pixel is transparent (0–255; default 128).
    pub alpha_threshold: u8,
    /// Palette entries at most, transparent entry included (2–256; default 256).
    pub palette_size: u16,
    /// Frames drawn on demand (a render, not frames in memory) that the two passes share at
    /// most, MiB: below, the second pass encodes the frames the first drew; above, it draws
    /// them again, so memory stays bounded whatever the length. Default 256.
    pub keep_frames_mib: u64,
}

impl Default for GifOptions {
    fn default() -> Self {
        GifOptions {
            alpha_threshold: DEFAULT_ALPHA_THRESHOLD,
            palette_size: MAX_PALETTE_SIZE,
            keep_frames_mib: DEFAULT_KEEP_FRAMES_MIB,
        }
    }
}

/// An encoded GIF and what it holds.
#[derive(Debug, Clone, PartialEq)]
pub struct EncodedGif {
    pub bytes: Vec<u8>,
    /// Colours in the palette, the transparent entry not counted.
    pub palette_colours: usize,
    /// Delay of each frame, 1/100 s.
    pub delays_cs: Vec<u16>,
    /// The frames' size, px.
    pub size_px: (u32, u32),
}

/// Default of [`GifOptions::keep_frames_mib`].
pub const DEFAULT_KEEP_FRAMES_MIB: u64 = 256;

/// Encodes `frames` (straight alpha) at `fps` as a looping GIF. Two passes over the frames,
/// a chunk at a time: the pooled colour histogram, then each frame mapped to the palette and
/// compressed.
pub fn encode_gif<S: FrameSource + ?Sized>(
    frames: &S,
    fps: f64,
    options: &GifOptions,
) -> Result<EncodedGif, SequenceError> {
    let (width, height) = first_frame_size(frames)?;
    check_fps(fps)?;
    if fps > MAX_GIF_FPS {
        return Err(SequenceError::GifFrameRateTooHigh {
            fps,
            max_fps: MAX_GIF_FPS,
        });
    }
    if width > MAX_GIF_SIDE_PX || height > MAX_GIF_SIDE_PX {
        return Err(SequenceError::GifTooLarge {
            width,
            height,
            max: MAX_GIF_SIDE_PX,
        });
    }
    if !(MIN_PALETTE_SIZE..=MAX_PALETTE_SIZE).contains(&options.palette_size) {
        return Err(SequenceError::BadPaletteSize {
            got: options.palette_size,
            min: MIN_PALETTE_SIZE,
            max: MAX_PALETTE_SIZE,
        });
    }
    let threshold = options.alpha_threshold;
    let visible = |px: &image::Rgba<u8>| px[3] >= threshold;
    let count = frames.frame_count();

    // What the two passes hold, within the memory budget (the frames in flight are chosen
    // for it; frames are kept for the second pass only where that still fits).
    let frame_bytes = u64::from(width) * u64::from(height) * 4;
    let kept_bytes = (count as u64).saturating_mul(frame_bytes);
    let mut keep =
        !frames.in_memory() && kept_bytes <= options.keep_frames_mib.saturating_mul(1024 * 1024);
    let cost = |keep: bool| gif_cost((width, height), if keep { kept_bytes } else { 0 });
    let in_flight = match frames_in_flight(frames, cost(keep), "a GIF") {
        Err(_) if keep => {
            keep = false;
            frames_in_flight(frames, cost(false), "a GIF")?
        }
        other => other?,
    };
    let in_flight_bytes = frame_cost(frames, cost(keep)).peak_bytes(in_flight);

    // Pass 1: the histogram of every frame's visible colours, pooled chunk by chunk.
    let mut kept: Vec<RgbaImage> = Vec::new();
    let mut histogram = Histogram::default();
    for range in chunks(count, in_flight) {
        let drawn = frames.draw(range.clone())?;
        check_chunk(&drawn, range.start, (width, height))?;
        let part = Histogram::from_frames(
            drawn
                .par_iter()
                .map(|f| {
                    f.pixels()
                        .filter(|p| visible(p))
                        .map(|p| pack_rgb(p[0], p[1], p[2]))
                        .collect()
                })
                .collect(),
        );
        histogram = histogram.merge(&part);
        // The histogram's size is known only as it grows: checked with the chunk's frames.
        let need = in_flight_bytes.saturating_add(
            (histogram.colours.len() as u64).saturating_mul(HISTOGRAM_BYTES_PER_COLOUR),
        );
        crate::budget::memory_budget().check(need, || {
            format!(
                "a GIF of {count} frames of {width}×{height} px ({} colours by frame {})",
                histogram.colours.len(),
                range.end
            )
        })?;
        if keep {
            kept.extend(drawn.into_iter().map(Cow::into_owned));
        }
    }
    // Entry 0 is always reserved for transparency, even in a fully opaque animation: that costs
    // one colour at most and keeps the index layout the same for every input.
    let quantized = quantize(&histogram, usize::from(options.palette_size) - 1);
    let mut palette_bytes = vec![0u8; 3];
    palette_bytes.extend(quantized.palette.iter().flatten());

    // Palette index of every occurring colour, looked up directly by its 24 bits. The table is
    // 16 MiB of zeroed memory that the OS maps lazily: only pages of used colours are touched.
    let mut index_of = vec![0u8; 1 << 24];
    for (&colour, &i) in histogram.colours.iter().zip(&quantized.index_of_colour) {
        index_of[colour as usize] = i + 1;
    }
    let palette_colours = quantized.palette.len();
    drop((histogram, quantized));

    let delays_cs: Vec<u16> = frame_durations(count, fps, GIF_TICKS_PER_S)
        .into_iter()
        .map(|d| d.min(u32::from(u16::MAX)) as u16)
        .collect();

    // Pass 2: index mapping, cropping and LZW compression are independent per frame: done in
    // parallel, then written in order, so the bytes do not depend on the thread count.
    let encode_frame = |frame: &RgbaImage, delay: u16| {
        let indices: Vec<u8> = frame
            .pixels()
            .map(|p| {
                if visible(p) {
                    index_of[pack_rgb(p[0], p[1], p[2]) as usize]
                } else {
                    TRANSPARENT_INDEX
                }
            })
            .collect();
        let (left, top, w, h) = visible_box(&indices, width, height);
        let cropped: Vec<u8> = (top..top + h)
            .flat_map(|y| {
                let row = (y * width) as usize;
                indices[row + left as usize..row + (left + w) as usize]
                    .iter()
                    .copied()
            })
            .collect();
        let mut gif_frame = Frame {
            delay,
            dispose: DisposalMethod::Background,
            transparent: Some(TRANSPARENT_INDEX),
            left: left as u16,
            top: top as u16,
            width: w as u16,
            height: h as u16,
            buffer: Cow::Owned(cropped),
            ..Frame::default()
        };
        gif_frame.make_lzw_pre_encoded();
        gif_frame
    };
    let mut encoded_frames: Vec<Frame<'static>> = Vec::with_capacity(count);
    let mut encoded_bytes = 0u64;
    for range in chunks(count, in_flight) {
        let done = range.clone();
        let delays = &delays_cs[range.clone()];
        if keep {
            encoded_frames.par_extend(
                kept[range]
                    .par_iter()
                    .zip(delays)
                    .map(|(f, &d)| encode_frame(f, d)),
            );
        } else {
            let drawn = frames.draw(range.clone())?;
            check_chunk(&drawn, range.start, (width, height))?;
            encoded_frames.par_extend(
                drawn
                    .par_iter()
                    .zip(delays)
                    .map(|(f, &d)| encode_frame(f, d)),
            );
        }
        // The compressed frames stay until the file is assembled from them (a second copy):
        // their size is known only now, so they are checked as they come.
        encoded_bytes = encoded_frames[done.clone()]
            .iter()
            .map(|f| f.buffer.len() as u64)
            .fold(encoded_bytes, u64::saturating_add);
        let need = in_flight_bytes.saturating_add(encoded_bytes.saturating_mul(2));
        crate::budget::memory_budget().check(need, || {
            format!(
                "a GIF of {count} frames of {width}×{height} px (compressed: {} by frame {})",
                crate::budget::format_bytes(encoded_bytes),
                done.end
            )
        })?;
    }

    let mut bytes = Vec::new();
    let encode = |e: ::gif::EncodingError| encode_error(e.to_string());
    {
        let mut encoder = Encoder::new(&mut bytes, width as u16, height as u16, &palette_bytes)
            .map_err(encode)?;
        encoder.set_repeat(Repeat::Infinite).map_err(encode)?;
        for gif_frame in &encoded_frames {
            encoder
                .write_lzw_pre_encoded_frame(gif_frame)
                .map_err(encode)?;
        }
        // Writes the trailer; dropping the encoder would too, but would swallow an error.
        encoder.into_inner().map_err(encode)?;
    }
    Ok(EncodedGif {
        bytes,
        palette_colours,
        delays_cs,
        size_px: (width, height),
    })
}

/// Distinct colours a frame may have at most (24-bit RGB).
const MAX_COLOURS: u64 = 1 << 24;
/// Bytes per distinct colour of the pooled histogram while pass 1 merges into it and the
/// quantizer reads it: colour and count (12), the merge's copy (12), the quantizer's work (8).
const HISTOGRAM_BYTES_PER_COLOUR: u64 = 32;

/// What [`encode_gif`] holds for frames of `size_px` besides the frames themselves, bytes
/// (upper bounds): fixed, the colour-to-index table (16 MiB) and `kept_bytes` of frames kept
/// for the second pass; per frame of pass 1, its list of visible colours (4 B/px) and its and
/// the chunk's runs (12 B per distinct colour, twice); per thread of pass 2, the frame's
/// palette indices, their cropped copy and the compressed frame (1 + 1 + 1.5 B/px). The
/// pooled histogram and the compressed frames, whose sizes are known only as they grow, are
/// checked as they do.
fn gif_cost(size_px: (u32, u32), kept_bytes: u64) -> WriterCost {
    let px = u64::from(size_px.0) * u64::from(size_px.1);
    WriterCost {
        fixed_bytes: MAX_COLOURS.saturating_add(kept_bytes),
        per_frame_bytes: px
            .saturating_mul(4)
            .saturating_add(px.min(MAX_COLOURS).saturating_mul(24)),
        per_thread_bytes: px.saturating_mul(7) / 2,
    }
}

/// An encoding failure before there is a path to blame: reported against the GIF being built.
fn encode_error(reason: String) -> SequenceError {
    SequenceError::Encode {
        path: "<GIF>".into(),
        reason,
    }
}

/// (left, top, width, height) of the non-transparent indices, px; a 1×1 box at the origin for
/// a frame with none (GIF frames cannot be empty).
fn visible_box(indices: &[u8], width: u32, height: u32) -> (u32, u32, u32, u32) {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for y in 0..height {
        let row = &indices[(y * width) as usize..((y + 1) * width) as usize];
        let Some(first) = row.iter().position(|&i| i != TRANSPARENT_INDEX) else {
            continue;
        };
        let last = row
            .iter()
            .rposition(|&i| i != TRANSPARENT_INDEX)
            .unwrap_or(first);
        x0 = x0.min(first as u32);
        x1 = x1.max(last as u32 + 1);
        y0 = y0.min(y);
        y1 = y + 1;
    }
    if x0 == u32::MAX {
        (0, 0, 1, 1)
    } else {
        (x0, y0, x1 - x0, y1 - y0)
    }
}

/// Encodes `frames` as a GIF and writes it to `path` atomically.
pub fn write_gif<S: FrameSource + ?Sized>(
    frames: &S,
    fps: f64,
    path: &Path,
    options: &GifOptions,
) -> Result<SequenceReport, SequenceError> {
    let gif = encode_gif(frames, fps, options).map_err(|e| match e {
        SequenceError::Encode { reason, .. } => SequenceError::Encode {
            path: path.into(),
            reason,
        },
        other => other,
    })?;
    write_atomic(path, &gif.bytes).map_err(write_error(path))?;
    let total_cs: u64 = gif.delays_cs.iter().map(|&d| u64::from(d)).sum();
    Ok(SequenceReport {
        format: SequenceFormat::Gif,
        files: vec![path.into()],
        frame_count: gif.delays_cs.len(),
        frame_size_px: gif.size_px,
        duration_s: total_cs as f64 / f64::from(GIF_TICKS_PER_S),
        palette_colours: Some(gif.palette_colours),
        sheet_size_px: None,
        stale_files: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visible_box_crops_to_content() {
        let t = TRANSPARENT_INDEX;
        #[rustfmt::skip]
        let indices = [
            t, t, t, t,
            t, 3, t, t,
            t, t, 2, t,
        ];
        assert_eq!(visible_box(&indices, 4, 3), (1, 1, 2, 2));
        assert_eq!(visible_box(&[t; 6], 3, 2), (0, 0, 1, 1));
        assert_eq!(visible_box(&[1; 6], 3, 2), (0, 0, 3, 2));
    }

    #[test]
    fn options_and_rates_are_checked() {
        let frames = vec![RgbaImage::new(2, 2)];
        let err = encode_gif(&frames, 60.0, &GifOptions::default()).unwrap_err();
        assert!(
            matches!(err, SequenceError::GifFrameRateTooHigh { .. }),
            "{err}"
        );
        let bad = GifOptions {
            palette_size: 1,
            ..GifOptions::default()
        };
        assert!(matches!(
            encode_gif(&frames, 10.0, &bad),
            Err(SequenceError::BadPaletteSize { got: 1, .. })
        ));
        let wide = vec![RgbaImage::new(MAX_GIF_SIDE_PX + 1, 1)];
        assert!(matches!(
            encode_gif(&wide, 10.0, &GifOptions::default()),
            Err(SequenceError::GifTooLarge { .. })
        ));
        // A fully transparent animation is still a valid GIF.
        let gif = encode_gif(&frames, 50.0, &GifOptions::default()).unwrap();
        assert_eq!(gif.palette_colours, 0);
        assert_eq!(gif.delays_cs, vec![2]);
    }
}
