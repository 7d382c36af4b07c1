//! Alpha → outlines.
//!
//! In: an RGBA image (straight alpha) and [`TraceOptions`]. Out: the outlines of its opaque
//! regions, in canvas pixels: one [`Outline`] per connected component, each an outer ring plus
//! the rings of its holes.
//!
//! Stages: grey dilation of the alpha by a disk of radius `padding_px` (so that the antialiased
//! fringe ends up inside), marching squares on the pixel-center grid with linear interpolation
//! (sub-pixel), speck removal by area, then simplification to `simplify_tolerance_px` that keeps
//! the rings simple and disjoint.

use crate::geom::Point;
use serde::{Deserialize, Serialize};

/// How alpha becomes outlines. Defaults work on ordinary antialiased sprites.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TraceOptions {
    /// A pixel is opaque when its alpha is at least this (0–255). Default 128.
    pub alpha_threshold: u8,
    /// Outward padding in pixels, so the antialiased fringe lies inside the outline. Default 2.
    pub padding_px: f64,
    /// Components and holes smaller than this area (px²) are dropped. Default 8.
    pub min_area_px2: f64,
    /// Largest distance (px) between a simplified ring and the traced one. Default 0.5.
    pub simplify_tolerance_px: f64,
}

impl Default for TraceOptions {
    fn default() -> Self {
        TraceOptions {
            alpha_threshold: 128,
            padding_px: 2.0,
            min_area_px2: 8.0,
            simplify_tolerance_px: 0.5,
        }
    }
}

/// One connected opaque region.
///
/// Rings are closed implicitly (the last point connects to the first). `outer` has a positive
/// shoelace area in canvas coordinates (clockwise on screen, y down); holes have negative area.
#[derive(Clone, Debug, PartialEq)]
pub struct Outline {
    pub outer: Vec<Point>,
    pub holes: Vec<Vec<Point>>,
}

/// What the caller got wrong.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TraceError {
    #[error("the image has no pixel with alpha at or above {threshold}")]
    NoOpaquePixels { threshold: u8 },
    #[error("invalid trace option: {0}")]
    InvalidOptions(String),
}

/// Traces the opaque regions of `image`.
pub fn trace(image: &image::RgbaImage, options: &TraceOptions) -> Result<Vec<Outline>, TraceError> {
    let _ = (image, options);
    todo!("trace: being written")
}
