//! Scribbles: which pixels the artist marked with which color.
//!
//! In: either an RGBA layer of the line art's size (colored strokes on transparency), or a JSON
//! list of polylines with a color and a width in canvas px, rasterized here through lyon's
//! stroke tessellator (round joins and caps). Out: [`Scribbles`]: a label per pixel (0 = none,
//! k + 1 = palette color k) and the palette, in order of first appearance in raster order.
//!
//! All strokes of one color are one handle. In a layer, pixels at least
//! [`ScribbleOptions::alpha_threshold`] opaque count; colors within
//! [`ScribbleOptions::color_merge_tolerance`] of a more frequent one join it (antialiased strokes
//! exported with rounding keep slightly different RGB values on their rims).
//!
//! The JSON file:
//! ```json
//! {"strokes": [{"color": "#e04040", "width": 8, "points": [[120, 80], [160, 95]]}]}
//! ```
//! Points are in canvas px (pixel (i, j) covers [i, i+1) × [j, j+1)); a stroke of one point is
//! a dot of diameter `width`. Later strokes paint over earlier ones.

use crate::geom::Point;
use image::RgbaImage;
use lyon::math::point;
use lyon::path::Path;
use lyon::tessellation::{
    BuffersBuilder, FillOptions, FillTessellator, FillVertex, LineCap, LineJoin, StrokeOptions,
    StrokeTessellator, StrokeVertex, VertexBuffers,
};
use serde::{Deserialize, Serialize};

/// How a scribble layer is read.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ScribbleOptions {
    /// A layer pixel is part of a scribble when its alpha is at least this. Default 128.
    pub alpha_threshold: u8,
    /// Colors whose channels all lie within this of a more frequent color join it. Default 8.
    pub color_merge_tolerance: u8,
    /// At most this many colors (a photo given as scribbles is an error, not a 10⁵-handle
    /// solve). Default 64.
    pub max_colors: usize,
    /// lyon's flattening tolerance for round joins and caps, px. Default 0.05.
    pub stroke_tolerance: f32,
}

impl Default for ScribbleOptions {
    fn default() -> Self {
        ScribbleOptions {
            alpha_threshold: 128,
            color_merge_tolerance: 8,
            max_colors: 64,
            stroke_tolerance: 0.05,
        }
    }
}

/// Stroke coordinates and widths beyond this (px) are rejected: lyon tessellates in f32.
pub const MAX_COORDINATE_PX: f64 = 1.0e6;

/// The scribbles over the canvas.
#[derive(Clone, Debug, PartialEq)]
pub struct Scribbles {
    pub width: u32,
    pub height: u32,
    /// Per pixel, row-major: 0 = no scribble, k + 1 = `colors[k]`.
    pub labels: Vec<u16>,
    /// The scribble colors (RGB8).
    pub colors: Vec<[u8; 3]>,
}

/// What is wrong with the scribbles.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ScribbleError {
    #[error("the scribbles hold {0} colors, more than the {1} allowed (is this an RGBA layer of strokes on transparency?)")]
    TooManyColors(usize, usize),
    #[error("not a scribble file: {0}")]
    Json(String),
    #[error("stroke {0}: {1}")]
    Stroke(usize, String),
}

/// The JSON scribble file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StrokeFile {
    pub strokes: Vec<Stroke>,
}

/// One polyline scribble.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Stroke {
    /// `#rrggbb`.
    #[schemars(regex(pattern = r"^#[0-9a-fA-F]{6}$"))]
    pub color: String,
    /// Stroke width, px.
    pub width: f64,
    /// Polyline points, canvas px.
    #[schemars(length(min = 1), with = "Vec<[f64; 2]>")]
    pub points: Vec<Point>,
}

/// `#rrggbb` → RGB8.
pub fn parse_hex_color(text: &str) -> Option<[u8; 3]> {
    let hex = text.strip_prefix('#')?;
    if hex.len() != 6 || !hex.is_ascii() {
        return None;
    }
    let channel = |k: usize| u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).ok();
    Some([channel(0)?, channel(1)?, channel(2)?])
}

/// RGB8 → `rrggbb` (no `#`), for messages and file names.
pub fn hex(color: [u8; 3]) -> String {
    format!("{:02x}{:02x}{:02x}", color[0], color[1], color[2])
}

impl Scribbles {
    /// Reads a scribble layer (straight-alpha RGBA).
    pub fn from_layer(layer: &RgbaImage, options: &ScribbleOptions) -> Result<Self, ScribbleError> {
        let tolerance = options.color_merge_tolerance as i32;
        let key = |c: [u8; 3]| ((c[0] as u32) << 16) | ((c[1] as u32) << 8) | c[2] as u32;
        // Distinct colors: (count, first raster position).
        let mut seen: std::collections::HashMap<u32, (usize, usize)> = Default::default();
        for (i, px) in layer.pixels().enumerate() {
            if px[3] >= options.alpha_threshold {
                let e = seen.entry(key([px[0], px[1], px[2]])).or_insert((0, i));
                e.0 += 1;
            }
        }
        // The most frequent colors become representatives; the others join the first
        // representative within the tolerance. Ties break on raster order: deterministic.
        let mut distinct: Vec<(u32, usize, usize)> = seen
            .into_iter()
            .map(|(k, (n, first))| (k, n, first))
            .collect();
        distinct.sort_by(|a, b| b.1.cmp(&a.1).then(a.2.cmp(&b.2)));
        let unpack = |k: u32| [(k >> 16) as u8, (k >> 8) as u8, k as u8];
        let mut representatives: Vec<(u32, usize)> = Vec::new(); // (key, first position)
        let mut joins: std::collections::HashMap<u32, usize> = Default::default();
        for &(k, _, first) in &distinct {
            let c = unpack(k);
            let near = representatives.iter().position(|&(r, _)| {
                let r = unpack(r);
                (0..3).all(|ch| (c[ch] as i32 - r[ch] as i32).abs() <= tolerance)
            });
            let index = match near {
                Some(index) => {
                    representatives[index].1 = representatives[index].1.min(first);
                    index
                }
                None => {
                    representatives.push((k, first));
                    if representatives.len() > options.max_colors {
                        return Err(ScribbleError::TooManyColors(
                            distinct.len(),
                            options.max_colors,
                        ));
                    }
                    representatives.len() - 1
                }
            };
            joins.insert(k, index);
        }
        // Palette order: first appearance in raster order.
        let mut order: Vec<usize> = (0..representatives.len()).collect();
        order.sort_by_key(|&r| representatives[r].1);
        let mut label_of = vec![0u16; representatives.len()];
        for (position, &r) in order.iter().enumerate() {
            label_of[r] = position as u16 + 1;
        }
        let labels = layer
            .pixels()
            .map(|px| {
                if px[3] >= options.alpha_threshold {
                    label_of[joins[&key([px[0], px[1], px[2]])]]
                } else {
                    0
                }
            })
            .collect();
        Ok(Scribbles {
            width: layer.width(),
            height: layer.height(),
            labels,
            colors: order
                .iter()
                .map(|&r| unpack(representatives[r].0))
                .collect(),
        })
    }

    /// Rasterizes a JSON stroke file onto a `width` × `height` canvas.
    pub fn from_json(
        text: &str,
        width: u32,
        height: u32,
        options: &ScribbleOptions,
    ) -> Result<Self, ScribbleError> {
        let file: StrokeFile =
            serde_json::from_str(text).map_err(|e| ScribbleError::Json(e.to_string()))?;
        Self::from_strokes(&file.strokes, width, height, options)
    }

    /// Rasterizes strokes: a pixel belongs to a stroke when its center lies in one of the
    /// stroke's tessellated triangles.
    pub fn from_strokes(
        strokes: &[Stroke],
        width: u32,
        height: u32,
        options: &ScribbleOptions,
    ) -> Result<Self, ScribbleError> {
        let mut colors: Vec<[u8; 3]> = Vec::new();
        let mut labels = vec![0u16; width as usize * height as usize];
        for (s, stroke) in strokes.iter().enumerate() {
            let bad = |what: String| ScribbleError::Stroke(s, what);
            let color = parse_hex_color(&stroke.color)
                .ok_or_else(|| bad(format!("color '{}' is not #rrggbb", stroke.color)))?;
            if !(stroke.width.is_finite() && stroke.width > 0.0) {
                return Err(bad(format!(
                    "width {} is not a positive number",
                    stroke.width
                )));
            }
            if stroke.points.is_empty() {
                return Err(bad("has no points".into()));
            }
            if stroke
                .points
                .iter()
                .flat_map(|p| p.iter())
                .any(|c| !c.is_finite())
            {
                return Err(bad("has a coordinate that is not a number".into()));
            }
            // lyon works in f32: keep coordinates where f32 still resolves a pixel.
            let limit = MAX_COORDINATE_PX;
            if stroke.width > limit
                || stroke
                    .points
                    .iter()
                    .flat_map(|p| p.iter())
                    .any(|c| c.abs() > limit)
            {
                return Err(bad(format!(
                    "a coordinate or the width lies beyond ±{limit} px"
                )));
            }
            let label = match colors.iter().position(|&c| c == color) {
                Some(k) => k as u16 + 1,
                None => {
                    colors.push(color);
                    if colors.len() > options.max_colors {
                        return Err(ScribbleError::TooManyColors(
                            colors.len(),
                            options.max_colors,
                        ));
                    }
                    colors.len() as u16
                }
            };
            let triangles = tessellate(stroke, options.stroke_tolerance).map_err(bad)?;
            for t in triangles.chunks_exact(3) {
                fill_triangle([t[0], t[1], t[2]], width, height, |i| labels[i] = label);
            }
        }
        Ok(Scribbles {
            width,
            height,
            labels,
            colors,
        })
    }

    /// Per color, how many pixels carry it.
    pub fn pixel_counts(&self) -> Vec<usize> {
        let mut counts = vec![0; self.colors.len()];
        for &l in &self.labels {
            if l > 0 {
                counts[l as usize - 1] += 1;
            }
        }
        counts
    }
}

/// The stroke's triangles (three points each), canvas px.
fn tessellate(stroke: &Stroke, tolerance: f32) -> Result<Vec<[f32; 2]>, String> {
    let mut geometry: VertexBuffers<[f32; 2], u32> = VertexBuffers::new();
    let p = |a: &Point| point(a.x as f32, a.y as f32);
    let distinct = stroke.points.windows(2).any(|w| w[0] != w[1]);
    if !distinct {
        // A dot: lyon strokes nothing for a zero-length path.
        FillTessellator::new()
            .tessellate_circle(
                p(&stroke.points[0]),
                stroke.width as f32 / 2.0,
                &FillOptions::tolerance(tolerance),
                &mut BuffersBuilder::new(&mut geometry, |v: FillVertex| v.position().to_array()),
            )
            .map_err(|e| format!("cannot tessellate: {e:?}"))?;
    } else {
        let mut builder = Path::builder();
        builder.begin(p(&stroke.points[0]));
        for q in &stroke.points[1..] {
            builder.line_to(p(q));
        }
        builder.end(false);
        let path = builder.build();
        let options = StrokeOptions::tolerance(tolerance)
            .with_line_width(stroke.width as f32)
            .with_line_cap(LineCap::Round)
            .with_line_join(LineJoin::Round);
        StrokeTessellator::new()
            .tessellate_path(
                &path,
                &options,
                &mut BuffersBuilder::new(&mut geometry, |v: StrokeVertex| v.position().to_array()),
            )
            .map_err(|e| format!("cannot tessellate: {e:?}"))?;
    }
    Ok(geometry
        .indices
        .iter()
        .map(|&i| geometry.vertices[i as usize])
        .collect())
}

/// Calls `paint` with the row-major index of every pixel whose center lies in the triangle
/// (edges included), clipped to the canvas.
fn fill_triangle(t: [[f32; 2]; 3], width: u32, height: u32, mut paint: impl FnMut(usize)) {
    let [a, b, c] = t.map(|p| [p[0] as f64, p[1] as f64]);
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area == 0.0 {
        return;
    }
    let side = |p: [f64; 2], q: [f64; 2], x: f64, y: f64| {
        ((q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0])) * area.signum()
    };
    let lo = |k: usize| a[k].min(b[k]).min(c[k]);
    let hi = |k: usize| a[k].max(b[k]).max(c[k]);
    // Pixel i's center is i + 0.5.
    let x0 = (lo(0) - 0.5).ceil().max(0.0) as i64;
    let y0 = (lo(1) - 0.5).ceil().max(0.0) as i64;
    let x1 = ((hi(0) - 0.5).floor() as i64).min(width as i64 - 1);
    let y1 = ((hi(1) - 0.5).floor() as i64).min(height as i64 - 1);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            if side(a, b, px, py) >= 0.0 && side(b, c, px, py) >= 0.0 && side(c, a, px, py) >= 0.0 {
                paint(y as usize * width as usize + x as usize);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    #[test]
    fn a_layer_groups_pixels_by_color_in_order_of_appearance() {
        let mut layer = RgbaImage::new(4, 2);
        layer.put_pixel(3, 0, Rgba([0, 0, 255, 255]));
        layer.put_pixel(0, 1, Rgba([255, 0, 0, 255]));
        layer.put_pixel(1, 1, Rgba([255, 0, 0, 255]));
        layer.put_pixel(2, 1, Rgba([252, 3, 0, 200])); // a rim pixel: joins red
        layer.put_pixel(3, 1, Rgba([0, 255, 0, 40])); // too transparent
        let s = Scribbles::from_layer(&layer, &ScribbleOptions::default()).unwrap();
        assert_eq!(s.colors, vec![[0, 0, 255], [255, 0, 0]]);
        assert_eq!(s.labels, vec![0, 0, 0, 1, 2, 2, 2, 0]);
        assert_eq!(s.pixel_counts(), vec![1, 3]);
    }

    #[test]
    fn a_photo_is_too_many_colors() {
        let layer = RgbaImage::from_fn(16, 16, |x, y| Rgba([x as u8 * 16, y as u8 * 16, 0, 255]));
        let options = ScribbleOptions {
            color_merge_tolerance: 0,
            ..Default::default()
        };
        assert!(matches!(
            Scribbles::from_layer(&layer, &options),
            Err(ScribbleError::TooManyColors(_, 64))
        ));
    }

    #[test]
    fn strokes_rasterize_with_their_width() {
        let text = r##"{"strokes": [
            {"color": "#ff0000", "width": 4, "points": [[2, 10], [18, 10]]},
            {"color": "#00ff00", "width": 6, "points": [[10, 3]]}
        ]}"##;
        let s = Scribbles::from_json(text, 20, 20, &ScribbleOptions::default()).unwrap();
        assert_eq!(s.colors, vec![[255, 0, 0], [0, 255, 0]]);
        let at = |x: usize, y: usize| s.labels[y * 20 + x];
        // The horizontal stroke covers rows 8..=11 (centers 8.5..11.5 within 10 ± 2).
        assert_eq!((at(10, 7), at(10, 8), at(10, 11), at(10, 12)), (0, 1, 1, 0));
        // Round caps reach 2 px past the ends.
        assert_eq!((at(0, 10), at(1, 10), at(19, 10)), (1, 1, 1));
        assert_eq!(at(10, 3), 2);
        let counts = s.pixel_counts();
        // Area 16 × 4 + a disc of radius 2 ≈ 76.6; the dot: π·9 ≈ 28.
        assert!((70..84).contains(&counts[0]), "{counts:?}");
        assert!((22..34).contains(&counts[1]), "{counts:?}");
    }

    #[test]
    fn bad_strokes_are_errors() {
        let o = ScribbleOptions::default();
        for (text, what) in [
            (
                r#"{"strokes": [{"color": "red", "width": 4, "points": [[1, 1]]}]}"#,
                "color",
            ),
            (
                r##"{"strokes": [{"color": "#ff0000", "width": -1, "points": [[1, 1]]}]}"##,
                "width",
            ),
            (
                r##"{"strokes": [{"color": "#ff0000", "width": 2, "points": []}]}"##,
                "no points",
            ),
            (r#"{"lines": []}"#, "unknown field"),
            (
                r##"{"strokes": [{"color": "#ff0000", "width": 2, "points": [[1e30, 1]]}]}"##,
                "beyond",
            ),
        ] {
            let e = Scribbles::from_json(text, 8, 8, &o)
                .unwrap_err()
                .to_string();
            assert!(e.contains(what), "{e}");
        }
    }
}
