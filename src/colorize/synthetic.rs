//! Test line art with known true colorings, drawn with tiny-skia.
//!
//! In: a [`SceneSpec`] (size, number of shapes, line width and gray, paper or transparency,
//! gaps in the outlines, an undrawn color boundary). Out: a [`Scene`]: the line art, the true
//! coloring (each shape's fill, the background's one or two colors), the scribbles as polyline
//! strokes (one short stroke per region), and the mask of pixels any line touches (left out of
//! the score).
//!
//! Shapes (circles, rectangles, ellipses) sit on a grid in the middle of the canvas; every
//! outline is horizontal at its top, where a gap of `gap_px` is cut (erased with paper, or
//! cleared on transparency) when asked. With `split_background`, the background's upper half
//! and lower half have different true colors and no line between them; their scribbles lie in
//! the top and bottom margins, symmetric about the true boundary.

use super::scribbles::{hex, Stroke};
use crate::geom::Point;
use image::RgbaImage;
use tiny_skia::{
    BlendMode, Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Shader, Stroke as SkStroke,
    Transform,
};

/// Region colors: shapes take them in order; the background takes the last one or two.
pub const PALETTE: [[u8; 3]; 12] = [
    [230, 80, 70],
    [70, 140, 230],
    [90, 190, 90],
    [240, 200, 60],
    [170, 90, 200],
    [60, 200, 200],
    [240, 140, 40],
    [150, 110, 70],
    [240, 150, 190],
    [120, 120, 240],
    [250, 245, 225],
    [150, 215, 120],
];

/// What to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSpec {
    /// Canvas side, px.
    pub size: u32,
    /// Number of closed shapes (at most 10).
    pub shapes: usize,
    /// Line width, px.
    pub line_width: f32,
    /// Line gray level (0 = black).
    pub line_gray: u8,
    /// Lines on transparency instead of white paper.
    pub transparent: bool,
    /// A gap this wide (px) at the top of every outline.
    pub gap_px: Option<f32>,
    /// Two background colors, split at mid-height, with no line between them.
    pub split_background: bool,
    /// Antialiased lines.
    pub antialias: bool,
}

impl Default for SceneSpec {
    fn default() -> Self {
        SceneSpec {
            size: 256,
            shapes: 4,
            line_width: 3.0,
            line_gray: 0,
            transparent: false,
            gap_px: None,
            split_background: false,
            antialias: true,
        }
    }
}

/// Line art, truth and scribbles.
#[derive(Clone, Debug)]
pub struct Scene {
    pub lineart: RgbaImage,
    pub truth: RgbaImage,
    pub strokes: Vec<Stroke>,
    /// Per pixel: some line covers it (left out of the score).
    pub is_line: Vec<bool>,
    /// Number of distinct scribble colors.
    pub colors: usize,
}

#[derive(Clone, Copy)]
enum Shape {
    Circle,
    Rect,
    Ellipse,
}

/// Draws the scene.
pub fn scene(spec: &SceneSpec) -> Scene {
    let shapes = spec.shapes.min(10);
    let size = spec.size as f32;
    let margin = size / 8.0;
    let cols = (shapes as f32).sqrt().ceil().max(1.0) as usize;
    let rows = shapes.div_ceil(cols).max(1);
    let (cell_w, cell_h) = (
        (size - 2.0 * margin) / cols as f32,
        (size - 2.0 * margin) / rows as f32,
    );
    let scribble_width = (size / 100.0).max(3.0);
    let mut truth = Pixmap::new(spec.size, spec.size).expect("a positive size");
    let mut lines = Pixmap::new(spec.size, spec.size).expect("a positive size");
    let mut strokes = Vec::new();
    let stroke = |color: [u8; 3], points: Vec<Point>| Stroke {
        color: format!("#{}", hex(color)),
        width: scribble_width as f64,
        points,
    };
    // Background.
    let top = PALETTE[10];
    let bottom = if spec.split_background {
        PALETTE[11]
    } else {
        top
    };
    let fill_rect = |pixmap: &mut Pixmap, rect: Rect, c: [u8; 3]| {
        let mut paint = Paint::default();
        paint.set_color_rgba8(c[0], c[1], c[2], 255);
        paint.anti_alias = false;
        pixmap.fill_rect(rect, &paint, Transform::identity(), None);
    };
    let half = (spec.size / 2) as f32;
    fill_rect(
        &mut truth,
        Rect::from_xywh(0.0, 0.0, size, half).expect("rect"),
        top,
    );
    fill_rect(
        &mut truth,
        Rect::from_xywh(0.0, half, size, size - half).expect("rect"),
        bottom,
    );
    let (y_top, y_bottom) = (margin as f64 / 2.0, size as f64 - margin as f64 / 2.0);
    let (x0, x1) = (size as f64 * 0.3, size as f64 * 0.7);
    strokes.push(stroke(
        top,
        vec![Point::new(x0, y_top), Point::new(x1, y_top)],
    ));
    if spec.split_background {
        strokes.push(stroke(
            bottom,
            vec![Point::new(x0, y_bottom), Point::new(x1, y_bottom)],
        ));
    }
    let ink = |alpha: u8| {
        let mut paint = Paint::default();
        paint.set_color_rgba8(spec.line_gray, spec.line_gray, spec.line_gray, alpha);
        paint.anti_alias = spec.antialias;
        paint
    };
    let line_style = SkStroke {
        width: spec.line_width,
        ..Default::default()
    };
    for k in 0..shapes {
        let (cx, cy) = (
            margin + cell_w * ((k % cols) as f32 + 0.5),
            margin + cell_h * ((k / cols) as f32 + 0.5),
        );
        let (rx, ry) = (cell_w * 0.36, cell_h * 0.36);
        let kind = [Shape::Circle, Shape::Rect, Shape::Ellipse][k % 3];
        let path = match kind {
            Shape::Circle => PathBuilder::from_circle(cx, cy, rx.min(ry)),
            Shape::Rect => Rect::from_xywh(cx - rx, cy - ry * 0.8, 2.0 * rx, 1.6 * ry)
                .map(PathBuilder::from_rect),
            Shape::Ellipse => Rect::from_xywh(cx - rx, cy - ry * 0.6, 2.0 * rx, 1.2 * ry)
                .and_then(PathBuilder::from_oval),
        }
        .expect("a shape inside the canvas");
        let color = PALETTE[k];
        let mut paint = Paint::default();
        paint.set_color_rgba8(color[0], color[1], color[2], 255);
        paint.anti_alias = false;
        truth.fill_path(
            &path,
            &paint,
            FillRule::Winding,
            Transform::identity(),
            None,
        );
        lines.stroke_path(&path, &ink(255), &line_style, Transform::identity(), None);
        let top_y = path.bounds().top();
        if let Some(gap) = spec.gap_px {
            // Erase a band `gap` wide across the outline's top.
            let band = Rect::from_xywh(
                cx - gap / 2.0,
                top_y - spec.line_width * 2.0,
                gap,
                spec.line_width * 4.0,
            )
            .expect("a band");
            let eraser = Paint {
                shader: Shader::SolidColor(Color::TRANSPARENT),
                blend_mode: BlendMode::Clear,
                anti_alias: spec.antialias,
                ..Default::default()
            };
            lines.fill_rect(band, &eraser, Transform::identity(), None);
        }
        let r = (rx.min(ry) * 0.3) as f64;
        strokes.push(stroke(
            color,
            vec![
                Point::new(cx as f64 - r, cy as f64),
                Point::new(cx as f64 + r, cy as f64),
            ],
        ));
    }
    let is_line: Vec<bool> = lines.pixels().iter().map(|p| p.alpha() > 0).collect();
    let mut art = if spec.transparent {
        Pixmap::new(spec.size, spec.size).expect("a positive size")
    } else {
        let mut paper = Pixmap::new(spec.size, spec.size).expect("a positive size");
        paper.fill(Color::WHITE);
        paper
    };
    art.draw_pixmap(
        0,
        0,
        lines.as_ref(),
        &tiny_skia::PixmapPaint::default(),
        Transform::identity(),
        None,
    );
    Scene {
        lineart: crate::render::rgba_from_pixmap(&art),
        truth: crate::render::rgba_from_pixmap(&truth),
        strokes,
        is_line,
        colors: shapes + 1 + spec.split_background as usize,
    }
}
