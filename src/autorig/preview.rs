//! A picture of a proposed rig: the layers on white with the cage, the bones and the point
//! handles drawn over them.
//!
//! In: the layers (straight RGBA, each at its offset on one canvas, back to front) and the
//! [`Handles`] (canvas px). Out: an RGBA image of the canvas size. Bones are drawn as kites from a wide head to a
//! pointed tail (root bones in red, the others in blue), with a ring at each head; points as
//! orange dots; cages as green polygons with square vertices.

use super::LayerRef;
use crate::render::{pixmap_from_rgba, rgba_from_pixmap, RenderError};
use crate::rig::Handles;
use image::RgbaImage;
use tiny_skia::{
    Color, FillRule, Paint, PathBuilder, Pixmap, PixmapPaint, Rect, Stroke, Transform,
};

/// Widest half-width of a bone's kite, px.
const BONE_HALF_WIDTH_PX: f32 = 7.0;
/// Radius of a point handle's dot, px.
const POINT_RADIUS_PX: f32 = 4.5;

fn paint(r: u8, g: u8, b: u8, a: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(r, g, b, a));
    p.anti_alias = true;
    p
}

/// Draws the rig over the layers, each placed at its offset on the first layer's canvas.
pub fn draw_preview(layers: &[LayerRef], handles: &Handles) -> Result<RgbaImage, RenderError> {
    let [w, h] = layers.first().map_or([0, 0], |l| l.canvas_px);
    let mut canvas = Pixmap::new(w, h).ok_or(RenderError::EmptyImage {
        width: w,
        height: h,
    })?;
    canvas.fill(Color::WHITE);
    for layer in layers {
        let pixmap = pixmap_from_rgba(layer.image)?;
        canvas.draw_pixmap(
            layer.offset_px[0],
            layer.offset_px[1],
            pixmap.as_ref(),
            &PixmapPaint::default(),
            Transform::identity(),
            None,
        );
    }
    let id = Transform::identity();
    let outline = Stroke {
        width: 1.2,
        ..Stroke::default()
    };
    for cage in &handles.cages {
        let mut pb = PathBuilder::new();
        for (k, p) in cage.polygon.iter().enumerate() {
            if k == 0 {
                pb.move_to(p[0] as f32, p[1] as f32);
            } else {
                pb.line_to(p[0] as f32, p[1] as f32);
            }
        }
        pb.close();
        if let Some(path) = pb.finish() {
            let stroke = Stroke {
                width: 2.0,
                ..Stroke::default()
            };
            canvas.stroke_path(&path, &paint(30, 150, 60, 220), &stroke, id, None);
        }
        for p in &cage.polygon {
            if let Some(r) = Rect::from_xywh(p[0] as f32 - 3.0, p[1] as f32 - 3.0, 6.0, 6.0) {
                canvas.fill_rect(r, &paint(30, 150, 60, 255), id, None);
            }
        }
    }
    for bone in &handles.bones {
        let (hx, hy) = (bone.head[0] as f32, bone.head[1] as f32);
        let (tx, ty) = (bone.tail[0] as f32, bone.tail[1] as f32);
        let (dx, dy) = (tx - hx, ty - hy);
        let len = (dx * dx + dy * dy).sqrt().max(1e-3);
        let half = (0.18 * len).min(BONE_HALF_WIDTH_PX);
        let (ux, uy) = (dx / len, dy / len);
        let (mx, my) = (hx + 0.2 * dx, hy + 0.2 * dy);
        let mut pb = PathBuilder::new();
        pb.move_to(hx, hy);
        pb.line_to(mx - uy * half, my + ux * half);
        pb.line_to(tx, ty);
        pb.line_to(mx + uy * half, my - ux * half);
        pb.close();
        let (fill, edge) = if bone.parent.is_none() {
            (paint(220, 50, 40, 150), paint(120, 20, 10, 255))
        } else {
            (paint(40, 90, 220, 140), paint(10, 30, 110, 255))
        };
        if let Some(path) = pb.finish() {
            canvas.fill_path(&path, &fill, FillRule::Winding, id, None);
            canvas.stroke_path(&path, &edge, &outline, id, None);
        }
        if let Some(circle) = PathBuilder::from_circle(hx, hy, (0.6 * half).max(1.5)) {
            canvas.stroke_path(&circle, &edge, &outline, id, None);
        }
    }
    for point in &handles.points {
        if let Some(dot) =
            PathBuilder::from_circle(point.at[0] as f32, point.at[1] as f32, POINT_RADIUS_PX)
        {
            canvas.fill_path(&dot, &paint(250, 150, 20, 230), FillRule::Winding, id, None);
            canvas.stroke_path(&dot, &paint(90, 40, 0, 255), &outline, id, None);
        }
    }
    Ok(rgba_from_pixmap(&canvas))
}
