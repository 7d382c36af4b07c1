//! Sprite sheet: every frame trimmed and shelf-packed into one PNG, plus a JSON frame map in
//! TexturePacker's "JSON hash" layout (read by Phaser, PixiJS and most engine importers).
//!
//! In: straight-alpha RGBA8 frames of one size (a [`FrameSource`], pulled a chunk at a time:
//! only the distinct trimmed frames are kept, which is what the sheet holds), frames per
//! second, the sheet's path `NAME.png`, [`SheetOptions`]. Out: `NAME.png` (straight-alpha RGBA8) and `NAME.json` beside it, each
//! written atomically, the PNG first. Sheet coordinates: px, origin top-left, y down.
//!
//! The JSON, in this key order:
//! ```json
//! { "frames": { "NAME_0000.png": { "frame": {"x","y","w","h"}, "rotated": false,
//!                                   "trimmed": true, "spriteSourceSize": {"x","y","w","h"},
//!                                   "sourceSize": {"w","h"}, "duration": 42,
//!                                   "events": [ … ] }, … },
//!   "animations": { "NAME": ["NAME_0000.png", …] },
//!   "meta": { "app": "sinew", "version": "…", "image": "NAME.png", "format": "RGBA8888",
//!             "size": {"w","h"}, "scale": "1",
//!             "frameTags": [{"name": "NAME", "from": 0, "to": N-1, "direction": "forward"}] } }
//! ```
//! `frame` is the frame's rectangle in the sheet, `spriteSourceSize` where that rectangle sits
//! in the untrimmed frame of `sourceSize`. `animations` is PixiJS's list of frames per animation
//! (`spritesheet.animations.NAME`); `duration` (ms) and `meta.frameTags` are Aseprite's, which
//! Phaser's `anims.createFromAseprite` reads — but it looks frames up by their index as a string,
//! so use [`FrameNaming::Index`] for it; with the default names, Phaser users call
//! `anims.generateFrameNames(key, {prefix: "NAME_", suffix: ".png", zeroPad: 4, end: N-1})`.
//! Frames with identical trimmed pixels share one rectangle (TexturePacker's "alias").
//! `events` (sinew's; importers ignore it) lists the animation's events the frame fires
//! ([`crate::anim::frame_events`]: those after the previous frame's time up to its own; frame 0
//! also those after the last frame, fired as the loop wraps), each
//! `{"name", "time", "int", "float", "string", "audio"?, "volume", "balance"}`; it is left out
//! for a frame that fires none.

use super::folder::digits_for;
use super::source::{
    check_chunk, chunks, first_frame_size, frames_in_flight, FrameSource, WriterCost,
};
use super::timing::{frame_durations, MS_PER_S};
use super::{check_fps, write_error, SequenceError, SequenceFormat, SequenceReport};
use crate::anim::FiredEvent;
use crate::geom::pack::{pack_shelves, ShelfLayout};
use crate::io::image::encode_png;
use image::RgbaImage;
use rayon::prelude::*;
use serde::ser::SerializeMap;
use serde::{Deserialize, Serialize, Serializer};
use std::collections::{BTreeMap, HashMap};
use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::Path;

/// Empty pixels between packed frames (default of [`SheetOptions::padding_px`]): 2 keeps
/// bilinear sampling and mipmaps of one frame from picking up its neighbour's edge.
pub const DEFAULT_PADDING_PX: u32 = 2;
/// Largest sheet side by default: 4096 px is the texture size every WebGL 1 / GLES 2 device of
/// the last decade supports.
pub const DEFAULT_MAX_SIDE_PX: u32 = 4096;
/// Written as `meta.app`.
pub const APP_NAME: &str = "sinew";

/// How frames are named in the JSON.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrameNaming {
    /// `NAME_0000.png`, … (NAME = the sheet's file stem): unique across sheets, as PixiJS's
    /// global texture cache needs.
    #[default]
    Prefixed,
    /// `"0"`, `"1"`, …: what Phaser's `createFromAseprite` looks up.
    Index,
}

/// Sprite-sheet options; `Default` gives the documented defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SheetOptions {
    /// Empty pixels between frames (default 2).
    pub padding_px: u32,
    /// Largest width and height of the sheet, px (default 4096); larger is an error.
    pub max_side_px: u32,
    /// Trim each frame to the box of its pixels with alpha > 0 (default true).
    pub trim: bool,
    /// Store frames with identical trimmed pixels once (default true).
    pub dedupe: bool,
    /// Frame names in the JSON (default `Prefixed`).
    pub naming: FrameNaming,
}

impl Default for SheetOptions {
    fn default() -> Self {
        SheetOptions {
            padding_px: DEFAULT_PADDING_PX,
            max_side_px: DEFAULT_MAX_SIDE_PX,
            trim: true,
            dedupe: true,
            naming: FrameNaming::Prefixed,
        }
    }
}

/// A rectangle in px.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PxRect {
    pub x: u32,
    pub y: u32,
    pub w: u32,
    pub h: u32,
}

/// A size in px.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PxSize {
    pub w: u32,
    pub h: u32,
}

/// One frame's entry in the JSON.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FrameEntry {
    /// Where the frame's pixels are in the sheet.
    pub frame: PxRect,
    pub rotated: bool,
    pub trimmed: bool,
    /// Where those pixels go in the untrimmed frame.
    pub sprite_source_size: PxRect,
    pub source_size: PxSize,
    /// How long the frame shows, ms.
    pub duration: u32,
    /// The events the frame fires (see the module doc); left out when none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<FiredEvent>,
}

/// A built sheet: the image and the frame map.
#[derive(Debug, Clone, PartialEq)]
pub struct Sheet {
    pub image: RgbaImage,
    /// (name, entry) per frame, in frame order.
    pub frames: Vec<(String, FrameEntry)>,
    /// The JSON text, ending in a newline.
    pub json: String,
}

/// Builds the sheet of `frames` at `fps`; `name` names the animation (and prefixes frame names),
/// `image_file` is the sheet's file name written as `meta.image`. `events[i]` are the events
/// frame `i` fires (empty, or one list per frame).
pub fn build_sheet<S: FrameSource + ?Sized>(
    frames: &S,
    events: &[Vec<FiredEvent>],
    fps: f64,
    name: &str,
    image_file: &str,
    options: &SheetOptions,
) -> Result<Sheet, SequenceError> {
    let (width, height) = first_frame_size(frames)?;
    check_fps(fps)?;
    let count = frames.frame_count();
    if !(events.is_empty() || events.len() == count) {
        return Err(SequenceError::EventFrames {
            frames: count,
            events: events.len(),
        });
    }
    let full = PxRect {
        x: 0,
        y: 0,
        w: width,
        h: height,
    };

    // One pass, a chunk at a time: each frame's box, and which stored region it uses (the
    // first frame with the same pixels). Only the regions are kept: what the sheet holds.
    let mut sources: Vec<PxRect> = Vec::with_capacity(count);
    let mut region_of_frame = Vec::with_capacity(count);
    let mut regions: Vec<RgbaImage> = Vec::new();
    let mut by_hash: HashMap<u64, Vec<usize>> = HashMap::new();
    let max_area = u64::from(options.max_side_px).pow(2);
    // Held whatever the frames in flight: the stored regions (at most the sheet's area before
    // they are refused), the sheet and its PNG, 4 B/px each; per frame, its trimmed copy.
    let sheet_px = max_area.min(
        u64::from(width)
            .saturating_mul(u64::from(height))
            .saturating_mul(count as u64),
    );
    let holding = WriterCost {
        fixed_bytes: sheet_px.saturating_mul(12),
        per_frame_bytes: crate::budget::px_bytes((width, height), 4),
        per_thread_bytes: 0,
    };
    let in_flight = frames_in_flight(frames, holding, "a sprite sheet")?;
    let mut area = 0u64;
    for range in chunks(count, in_flight) {
        let drawn = frames.draw(range.clone())?;
        check_chunk(&drawn, range.start, (width, height))?;
        let boxes: Vec<PxRect> = drawn
            .par_iter()
            .map(|f| if options.trim { visible_rect(f) } else { full })
            .collect();
        for (frame, src) in drawn.iter().zip(boxes) {
            sources.push(src);
            let hash = options.dedupe.then(|| pixels_hash(frame, &src));
            let same = hash.and_then(|hash| {
                by_hash.get(&hash)?.iter().copied().find(|&r| {
                    let region = &regions[r];
                    same_pixels(region, &whole(region), frame, &src)
                })
            });
            if let Some(r) = same {
                region_of_frame.push(r);
                continue;
            }
            if let Some(hash) = hash {
                by_hash.entry(hash).or_default().push(regions.len());
            }
            region_of_frame.push(regions.len());
            regions
                .push(image::imageops::crop_imm(&**frame, src.x, src.y, src.w, src.h).to_image());
            area += u64::from(src.w) * u64::from(src.h);
        }
        // Regions that cannot fit are refused before more frames are drawn.
        if area > max_area {
            pack(
                &region_sizes(&regions),
                options.padding_px,
                options.max_side_px,
            )?;
        }
    }

    let packing = pack(
        &region_sizes(&regions),
        options.padding_px,
        options.max_side_px,
    )?;
    let mut image = RgbaImage::new(packing.width, packing.height);
    for (region, &(x, y)) in regions.iter().zip(&packing.positions) {
        image::imageops::replace(&mut image, region, i64::from(x), i64::from(y));
    }

    let digits = digits_for(count);
    let durations = frame_durations(count, fps, MS_PER_S);
    let entries: Vec<(String, FrameEntry)> = (0..count)
        .map(|i| {
            let frame_name = match options.naming {
                FrameNaming::Prefixed => format!("{name}_{i:0digits$}.png"),
                FrameNaming::Index => i.to_string(),
            };
            let region = region_of_frame[i];
            let (x, y) = packing.positions[region];
            let src = sources[i];
            let entry = FrameEntry {
                frame: PxRect {
                    x,
                    y,
                    w: src.w,
                    h: src.h,
                },
                rotated: false,
                trimmed: src != full,
                sprite_source_size: src,
                source_size: PxSize {
                    w: width,
                    h: height,
                },
                duration: durations[i],
                events: events.get(i).cloned().unwrap_or_default(),
            };
            (frame_name, entry)
        })
        .collect();

    let document = SheetJson {
        frames: OrderedFrames(&entries),
        animations: BTreeMap::from([(
            name.to_string(),
            entries.iter().map(|(n, _)| n.clone()).collect(),
        )]),
        meta: Meta {
            app: APP_NAME,
            version: env!("CARGO_PKG_VERSION"),
            image: image_file,
            format: "RGBA8888",
            size: PxSize {
                w: packing.width,
                h: packing.height,
            },
            scale: "1",
            frame_tags: vec![FrameTag {
                name,
                from: 0,
                to: count - 1,
                direction: "forward",
            }],
        },
    };
    let mut json = serde_json::to_string_pretty(&document).map_err(|e| SequenceError::Encode {
        path: image_file.into(),
        reason: e.to_string(),
    })?;
    json.push('\n');
    Ok(Sheet {
        image,
        frames: entries,
        json,
    })
}

/// Writes the sheet `path` (`NAME.png`) and its frame map `NAME.json` (with `events`, see
/// [`build_sheet`]).
pub fn write_sheet<S: FrameSource + ?Sized>(
    frames: &S,
    events: &[Vec<FiredEvent>],
    fps: f64,
    path: &Path,
    options: &SheetOptions,
) -> Result<SequenceReport, SequenceError> {
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let image_file = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let sheet = build_sheet(frames, events, fps, &name, &image_file, options)?;
    let png = encode_png(&sheet.image).map_err(|e| SequenceError::Encode {
        path: path.into(),
        reason: e.to_string(),
    })?;
    let json_path = path.with_extension("json");
    // The JSON names the image: renamed last, after the image it describes.
    crate::io::atomic::write_set(&[
        (path.to_path_buf(), png),
        (json_path.clone(), sheet.json.into_bytes()),
    ])
    .map_err(|(failed, e)| write_error(&failed)(e))?;
    let total_ms: u64 = sheet
        .frames
        .iter()
        .map(|(_, e)| u64::from(e.duration))
        .sum();
    Ok(SequenceReport {
        format: SequenceFormat::Sheet,
        files: vec![path.into(), json_path],
        frame_count: sheet.frames.len(),
        frame_size_px: (
            sheet.frames[0].1.source_size.w,
            sheet.frames[0].1.source_size.h,
        ),
        duration_s: total_ms as f64 / f64::from(MS_PER_S),
        palette_colours: None,
        sheet_size_px: Some(sheet.image.dimensions()),
        stale_files: Vec::new(),
    })
}

/// The box of pixels with alpha > 0; a 1×1 box at the origin when there are none (importers
/// choke on empty frames).
fn visible_rect(frame: &RgbaImage) -> PxRect {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (x, y, px) in frame.enumerate_pixels() {
        if px[3] > 0 {
            x0 = x0.min(x);
            y0 = y0.min(y);
            x1 = x1.max(x + 1);
            y1 = y1.max(y + 1);
        }
    }
    if x0 == u32::MAX {
        PxRect {
            x: 0,
            y: 0,
            w: 1,
            h: 1,
        }
    } else {
        PxRect {
            x: x0,
            y: y0,
            w: x1 - x0,
            h: y1 - y0,
        }
    }
}

fn region_rows<'a>(frame: &'a RgbaImage, r: &PxRect) -> impl Iterator<Item = &'a [u8]> + 'a {
    let stride = frame.width() as usize * 4;
    let (x, w) = (r.x as usize * 4, r.w as usize * 4);
    (r.y..r.y + r.h).map(move |y| {
        let start = y as usize * stride + x;
        &frame.as_raw()[start..start + w]
    })
}

/// The whole of `image` as a box.
fn whole(image: &RgbaImage) -> PxRect {
    PxRect {
        x: 0,
        y: 0,
        w: image.width(),
        h: image.height(),
    }
}

/// Each stored region's size, px.
fn region_sizes(regions: &[RgbaImage]) -> Vec<(u32, u32)> {
    regions.iter().map(|r| r.dimensions()).collect()
}

fn pixels_hash(frame: &RgbaImage, r: &PxRect) -> u64 {
    // DefaultHasher::new() has fixed keys, so the hash (used only to find candidates) is the same
    // in every run.
    let mut h = DefaultHasher::new();
    (r.w, r.h).hash(&mut h);
    region_rows(frame, r).for_each(|row| row.hash(&mut h));
    h.finish()
}

fn same_pixels(a: &RgbaImage, ra: &PxRect, b: &RgbaImage, rb: &PxRect) -> bool {
    (ra.w, ra.h) == (rb.w, rb.h) && region_rows(a, ra).eq(region_rows(b, rb))
}

/// Where each rectangle goes, and the sheet's size.
#[derive(Debug, Clone, PartialEq)]
struct Packing {
    positions: Vec<(u32, u32)>,
    width: u32,
    height: u32,
}

/// Shelf packing in the given order from the sheet's corner, shelves at most `shelf_width` wide
/// (see [`pack_shelves`]). Returns positions and the used (width, height); u64 so absurd inputs
/// cannot overflow.
fn shelves(sizes: &[(u32, u32)], padding: u64, shelf_width: u64) -> (Vec<(u64, u64)>, u64, u64) {
    let sizes: Vec<(u64, u64)> = sizes
        .iter()
        .map(|&(w, h)| (u64::from(w), u64::from(h)))
        .collect();
    let layout = ShelfLayout {
        width: shelf_width,
        padding,
        margin: 0,
        page_height: None,
    };
    let packed = pack_shelves(&sizes, &layout);
    let [width, height] = packed.pages[0];
    let positions = packed.placements.iter().map(|p| (p.x, p.y)).collect();
    (positions, width, height)
}

/// Packs the rectangles into a sheet about as wide as tall, or `max_side` wide if that is too
/// tall; fails when even that does not fit in `max_side` × `max_side`.
fn pack(sizes: &[(u32, u32)], padding: u32, max_side: u32) -> Result<Packing, SequenceError> {
    let padding = u64::from(padding);
    let widest = sizes.iter().map(|s| u64::from(s.0)).max().unwrap_or(0);
    let area: u64 = sizes
        .iter()
        .map(|&(w, h)| (u64::from(w) + padding) * (u64::from(h) + padding))
        .sum();
    let square = (area as f64).sqrt().ceil() as u64;
    let max = u64::from(max_side);
    let mut attempt = shelves(sizes, padding, square.max(widest));
    if attempt.1 > max || attempt.2 > max {
        attempt = shelves(sizes, padding, max.max(widest));
    }
    let (positions, width, height) = attempt;
    if width > max || height > max {
        return Err(SequenceError::SheetTooLarge {
            width,
            height,
            max_side_px: max_side,
        });
    }
    // Both sides are ≤ max_side (a u32) here, so every coordinate fits in u32.
    Ok(Packing {
        positions: positions
            .into_iter()
            .map(|(x, y)| (x as u32, y as u32))
            .collect(),
        width: width as u32,
        height: height as u32,
    })
}

/// The JSON document; field order is the file's key order.
#[derive(Serialize)]
struct SheetJson<'a> {
    frames: OrderedFrames<'a>,
    animations: BTreeMap<String, Vec<String>>,
    meta: Meta<'a>,
}

/// Frames as a JSON object whose keys keep frame order.
struct OrderedFrames<'a>(&'a [(String, FrameEntry)]);

impl Serialize for OrderedFrames<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (name, entry) in self.0 {
            map.serialize_entry(name, entry)?;
        }
        map.end()
    }
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Meta<'a> {
    app: &'a str,
    version: &'a str,
    image: &'a str,
    format: &'a str,
    size: PxSize,
    scale: &'a str,
    frame_tags: Vec<FrameTag<'a>>,
}

#[derive(Serialize)]
struct FrameTag<'a> {
    name: &'a str,
    from: usize,
    to: usize,
    direction: &'a str,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shelves_fill_rows_in_order_with_padding() {
        let sizes = [(10, 5), (10, 8), (10, 5), (30, 2)];
        let (pos, w, h) = shelves(&sizes, 2, 25);
        assert_eq!(pos, vec![(0, 0), (12, 0), (0, 10), (0, 17)]);
        assert_eq!((w, h), (30, 19));
    }

    #[test]
    fn packing_is_squarish_and_bounded() {
        let sizes = [(100, 100); 16];
        let p = pack(&sizes, 2, 4096).unwrap();
        assert_eq!((p.width, p.height), (406, 406));
        // Too tall when square: falls back to the full width.
        let p = pack(&[(100, 100); 16], 2, 250).err().unwrap();
        assert!(matches!(
            p,
            SequenceError::SheetTooLarge {
                max_side_px: 250,
                ..
            }
        ));
        // Six per 68-px shelf when square makes it 100 px tall; at 90 px one full-width shelf.
        let p = pack(&[(10, 50); 9], 0, 90).unwrap();
        assert_eq!((p.width, p.height), (90, 50));
        assert!(matches!(
            pack(&[(5000, 1)], 0, 4096),
            Err(SequenceError::SheetTooLarge { width: 5000, .. })
        ));
    }

    #[test]
    fn trims_to_visible_pixels() {
        let mut f = RgbaImage::new(8, 6);
        f.put_pixel(2, 1, image::Rgba([1, 2, 3, 1]));
        f.put_pixel(5, 4, image::Rgba([1, 2, 3, 255]));
        assert_eq!(
            visible_rect(&f),
            PxRect {
                x: 2,
                y: 1,
                w: 4,
                h: 4
            }
        );
        assert_eq!(
            visible_rect(&RgbaImage::new(3, 3)),
            PxRect {
                x: 0,
                y: 0,
                w: 1,
                h: 1
            }
        );
    }
}
