//! Layered art files: Photoshop (PSD/PSB), OpenRaster (ORA, what Krita, GIMP and MyPaint
//! write) and the trimmed PNGs + skeleton JSON that Spine's export scripts write.
//!
//! In: a path. Out: a [`LayeredImage`]: the canvas size (px) and its pixel layers back to
//! front, each trimmed to its opaque pixels, with its canvas offset (px, top-left origin, y
//! down), straight-alpha RGBA8 pixels (layer masks applied, opacity not), opacity, visibility,
//! blend mode and name path (`arm_l/hand` for a layer `hand` in a group `arm_l`), plus the group
//! tree for a tree view and one-line warnings for what was skipped or approximated. Spine's
//! layer-name tags are applied here (see [`tags`] and docs/formats.md). Every size read from a
//! file is checked against [`LayeredLimits`] before anything is allocated for it.

pub mod composite;
pub mod ora;
pub mod psd;
pub mod spine_json;
pub mod tags;
mod tree;

pub use composite::composite;
pub use tree::{build_layers, RawLayer, RawNode};

use image::RgbaImage;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One pixel layer of a layered file.
#[derive(Clone, Debug, PartialEq)]
pub struct ArtLayer {
    /// The layer's own name, tags removed.
    pub name: String,
    /// The names of the groups it is in and its own, joined with `/` (`arm_l/hand`); unique
    /// within the file (a repeated path gets ` 2`, ` 3`… appended).
    pub path: String,
    /// Canvas position of the image's top-left pixel, px (may be negative or past the canvas:
    /// pixels outside the canvas are kept).
    pub offset_px: [i32; 2],
    /// Straight-alpha RGBA8, trimmed to the pixels with alpha > 0, layer mask applied.
    pub image: RgbaImage,
    /// Opacity in [0, 1]: the layer's own times its groups'.
    pub opacity: f32,
    /// Whether it is drawn: it and all its groups are visible.
    pub visible: bool,
    pub blend: BlendMode,
}

/// How a layer combines with what is below it. Only [`BlendMode::Normal`] is drawn as such by
/// sinew; a layer with another mode is drawn as normal and a warning says so.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BlendMode {
    Normal,
    /// A group that does not isolate its children (Photoshop's and ORA's default for groups).
    PassThrough,
    Multiply,
    Screen,
    Overlay,
    Darken,
    Lighten,
    Add,
    /// Any other mode, by the file's name for it (`diff`, `svg:color-dodge`, …).
    Other(String),
}

/// A node of the group tree, back to front within its group.
#[derive(Clone, Debug, PartialEq)]
pub enum TreeNode {
    /// A group with its (tag-free) name, own visibility and opacity, and children.
    Group {
        name: String,
        visible: bool,
        opacity: f32,
        children: Vec<TreeNode>,
    },
    /// The layer at this index of [`LayeredImage::layers`].
    Layer(usize),
}

/// A bone origin marked in the file: a layer tagged `[origin]` or named `pivot`/`origin`
/// (see docs/formats.md): the centre of its opaque pixels, canvas px.
#[derive(Clone, Debug, PartialEq)]
pub struct Pivot {
    /// The path of the group it is in (empty at the top level).
    pub group: String,
    pub at_px: crate::geom::Point,
}

/// A layered file read into memory.
#[derive(Clone, Debug, PartialEq)]
pub struct LayeredImage {
    /// Canvas width and height, px.
    pub canvas_px: [u32; 2],
    /// The pixel layers, back to front.
    pub layers: Vec<ArtLayer>,
    /// The group tree (top level, back to front); leaves index `layers`.
    pub tree: Vec<TreeNode>,
    /// Pivot layers (not among `layers`).
    pub pivots: Vec<Pivot>,
    /// One line each: layers skipped or drawn differently from the file, naming the layer.
    pub warnings: Vec<String>,
}

/// The sizes a layered file may declare; anything larger is refused before allocating.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct LayeredLimits {
    /// Widest or highest canvas or layer, px. Default 30,000 (Photoshop's PSD limit).
    pub max_side_px: u32,
    /// Pixels of all layers together (and of the canvas). Default 2^28 (268 M px, 1 GiB RGBA).
    pub max_total_px: u64,
    /// Layers and groups in one file. Default 10,000.
    pub max_layers: usize,
    /// Deepest group nesting. Default 32.
    pub max_depth: usize,
    /// Size of the file itself, bytes. Default 2 GiB.
    pub max_file_bytes: u64,
    /// Uncompressed size of one ORA zip entry, bytes. Default 1 GiB.
    pub max_entry_bytes: u64,
}

impl Default for LayeredLimits {
    fn default() -> Self {
        Self {
            max_side_px: 30_000,
            max_total_px: 1 << 28,
            max_layers: 10_000,
            max_depth: 32,
            max_file_bytes: 2 << 30,
            max_entry_bytes: 1 << 30,
        }
    }
}

/// What is wrong with a layered file (the file's name is added by [`LayeredFileError`]).
#[derive(Debug, thiserror::Error)]
pub enum LayeredError {
    #[error("cannot read: {0}")]
    Read(#[from] std::io::Error),
    #[error("not {expected}")]
    NotFormat { expected: &'static str },
    #[error("truncated: {what} ends past the end of the file")]
    Truncated { what: String },
    #[error("malformed: {0}")]
    Malformed(String),
    #[error("unsupported: {0}")]
    Unsupported(String),
    #[error("too large: {what} ({got} {unit}); sinew reads at most {limit} {unit}")]
    TooLarge {
        what: String,
        got: u64,
        limit: u64,
        /// What `got` and `limit` count, in the user's words (`px`, `layers`, `bytes`).
        unit: &'static str,
    },
    #[error("groups nested {got} deep; sinew reads groups at most {limit} deep")]
    TooDeep { got: usize, limit: usize },
    #[error("zip archive: {0}")]
    Zip(String),
    #[error("{entry}: {reason}")]
    Entry { entry: String, reason: String },
    #[error("no pixel layers (every layer is empty, hidden by a tag or skipped)")]
    NoLayers,
}

/// A [`LayeredError`] with the file it is about.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", .path.display())]
pub struct LayeredFileError {
    pub path: PathBuf,
    #[source]
    pub source: LayeredError,
}

/// The farthest from the canvas's top-left corner an ORA or Spine-script layer may be placed,
/// px, either way on each axis: 2^30, far past any canvas, so that a position plus a layer's
/// size stays within `i32`.
pub const MAX_OFFSET_PX: i32 = 1 << 30;

/// The layered formats, by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayeredFormat {
    /// `.psd` and `.psb`.
    Photoshop,
    /// `.ora`.
    OpenRaster,
    /// `.json`: a Spine skeleton of region attachments next to its trimmed PNGs.
    SpineJson,
}

impl LayeredFormat {
    /// The format `path`'s extension names (case-insensitive), if layered.
    pub fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "psd" | "psb" => Some(Self::Photoshop),
            "ora" => Some(Self::OpenRaster),
            "json" => Some(Self::SpineJson),
            _ => None,
        }
    }
}

/// Reads the layered file at `path` (format by extension, see [`LayeredFormat::of`]).
pub fn load_layered(path: &Path, limits: &LayeredLimits) -> Result<LayeredImage, LayeredFileError> {
    let wrap = |source| LayeredFileError {
        path: path.to_path_buf(),
        source,
    };
    let format = LayeredFormat::of(path).ok_or_else(|| {
        wrap(LayeredError::NotFormat {
            expected: "a layered file (.psd, .psb, .ora or Spine .json)",
        })
    })?;
    match format {
        LayeredFormat::SpineJson => spine_json::load(path, limits).map_err(wrap),
        _ => {
            let bytes = read_limited(path, limits).map_err(wrap)?;
            match format {
                LayeredFormat::Photoshop => psd::parse(&bytes, limits),
                _ => ora::parse(&bytes, limits),
            }
            .map_err(wrap)
        }
    }
}

/// Reads a whole file after checking its size against [`LayeredLimits::max_file_bytes`].
pub(crate) fn read_limited(path: &Path, limits: &LayeredLimits) -> Result<Vec<u8>, LayeredError> {
    let len = std::fs::metadata(path)?.len();
    check_limit("the file", len, limits.max_file_bytes, "bytes")?;
    Ok(std::fs::read(path)?)
}

/// `Err(TooLarge)` when `got > limit`.
pub(crate) fn check_limit(
    what: &str,
    got: u64,
    limit: u64,
    unit: &'static str,
) -> Result<(), LayeredError> {
    if got > limit {
        return Err(LayeredError::TooLarge {
            what: what.to_string(),
            got,
            limit,
            unit,
        });
    }
    Ok(())
}

/// Checks a `w`×`h` px image against the side limit and adds it to the running total.
pub(crate) fn check_size(
    what: &str,
    size: [u64; 2],
    total_px: &mut u64,
    limits: &LayeredLimits,
) -> Result<(), LayeredError> {
    let side = size[0].max(size[1]);
    check_limit(what, side, limits.max_side_px as u64, "px a side")?;
    *total_px = total_px.saturating_add(size[0] * size[1]);
    check_limit("all layers together", *total_px, limits.max_total_px, "px")
}

/// One layer as a part's image: its pixels on the canvas (those outside it dropped), opacity
/// applied to alpha, trimmed to the pixels left with alpha > 0; with the canvas position of
/// the image's top-left pixel (px). `None` when no pixel is left.
pub fn part_image(layer: &ArtLayer, canvas_px: [u32; 2]) -> Option<(RgbaImage, [i32; 2])> {
    let [ox, oy] = layer.offset_px.map(i64::from);
    let alpha = |x: u32, y: u32| {
        let a = layer.image.get_pixel(x, y)[3];
        (f32::from(a) * layer.opacity).round() as u8
    };
    let on_canvas = |x: u32, y: u32| {
        let (cx, cy) = (ox + i64::from(x), oy + i64::from(y));
        cx >= 0 && cy >= 0 && cx < i64::from(canvas_px[0]) && cy < i64::from(canvas_px[1])
    };
    // The box of the pixels that stay, in the layer's own px.
    let mut bounds: Option<[u32; 4]> = None;
    for (x, y, _) in layer.image.enumerate_pixels() {
        if alpha(x, y) == 0 || !on_canvas(x, y) {
            continue;
        }
        let b = bounds.get_or_insert([x, y, x, y]);
        *b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
    }
    let [x0, y0, x1, y1] = bounds?;
    let mut out = RgbaImage::new(x1 - x0 + 1, y1 - y0 + 1);
    for (x, y, q) in out.enumerate_pixels_mut() {
        let (sx, sy) = (x0 + x, y0 + y);
        if !on_canvas(sx, sy) {
            continue;
        }
        let mut p = *layer.image.get_pixel(sx, sy);
        p[3] = alpha(sx, sy);
        if p[3] > 0 {
            *q = p;
        }
    }
    // Within the canvas, so within i32.
    let offset_px = [(ox + i64::from(x0)) as i32, (oy + i64::from(y0)) as i32];
    Some((out, offset_px))
}

#[cfg(test)]
mod tests;
