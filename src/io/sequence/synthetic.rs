//! A synthetic looping animation: the test card for the sequence writers' tests, benchmark and
//! browser check.
//!
//! In: canvas side (px) and frame count. Out: that many straight-alpha RGBA8 frames, one loop:
//! a square filled with a red–yellow–blue gradient circles the canvas centre while spinning
//! twice, an orange disc at 60 % opacity slides left and right, and a grey shadow at 30 %
//! opacity lies under them. Every edge is antialiased, so the frames hold smooth gradients,
//! partial alpha on both sides of a GIF's alpha threshold, and fully transparent background.

use crate::render::rgba_from_pixmap;
use image::RgbaImage;
use std::f32::consts::TAU;
use tiny_skia::{
    Color, FillRule, GradientStop, LinearGradient, Paint, PathBuilder, Pixmap, Point, Rect,
    SpreadMode, Transform,
};

/// The animation's frames; empty when `side_px` or `count` is 0.
pub fn synthetic_animation(side_px: u32, count: usize) -> Vec<RgbaImage> {
    (0..count)
        .filter_map(|i| draw_frame(side_px, i as f32 / count as f32))
        .collect()
}

/// The frame at loop phase `t` ∈ [0, 1).
fn draw_frame(side_px: u32, t: f32) -> Option<RgbaImage> {
    let mut pixmap = Pixmap::new(side_px, side_px)?;
    let s = side_px as f32;
    let centre = s / 2.0;

    // Shadow: a flat ellipse, 30 % grey.
    let shadow = PathBuilder::from_oval(Rect::from_xywh(0.15 * s, 0.8 * s, 0.7 * s, 0.1 * s)?)?;
    let mut paint = Paint::default();
    paint.set_color(Color::from_rgba(0.2, 0.2, 0.2, 0.3)?);
    paint.anti_alias = true;
    pixmap.fill_path(
        &shadow,
        &paint,
        FillRule::Winding,
        Transform::identity(),
        None,
    );

    // Disc: orange at 60 %, sliding on a cosine.
    let disc_x = centre + 0.3 * s * (TAU * t).cos();
    let disc = PathBuilder::from_circle(disc_x, 0.72 * s, 0.1 * s)?;
    paint.set_color(Color::from_rgba(1.0, 0.55, 0.1, 0.6)?);
    pixmap.fill_path(
        &disc,
        &paint,
        FillRule::Winding,
        Transform::identity(),
        None,
    );

    // Square: gradient in its own frame, so the gradient turns with it.
    let half = 0.17 * s;
    let square = PathBuilder::from_rect(Rect::from_xywh(-half, -half, 2.0 * half, 2.0 * half)?);
    let orbit = TAU * t;
    let (cx, cy) = (
        centre + 0.2 * s * orbit.cos(),
        0.42 * s + 0.15 * s * orbit.sin(),
    );
    let world_from_square = Transform::from_rotate(720.0 * t).post_translate(cx, cy);
    paint.shader = LinearGradient::new(
        Point::from_xy(-half, -half),
        Point::from_xy(half, half),
        vec![
            GradientStop::new(0.0, Color::from_rgba8(220, 30, 40, 255)),
            GradientStop::new(0.5, Color::from_rgba8(250, 220, 40, 255)),
            GradientStop::new(1.0, Color::from_rgba8(30, 70, 220, 255)),
        ],
        SpreadMode::Pad,
        Transform::identity(),
    )?;
    pixmap.fill_path(&square, &paint, FillRule::Winding, world_from_square, None);
    Some(rgba_from_pixmap(&pixmap))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_move_and_have_partial_alpha() {
        let frames = synthetic_animation(64, 4);
        assert_eq!(frames.len(), 4);
        assert_ne!(frames[0], frames[1]);
        let alphas: std::collections::BTreeSet<u8> = frames[0].pixels().map(|p| p[3]).collect();
        assert!(alphas.contains(&0) && alphas.contains(&255));
        assert!(alphas.iter().any(|&a| a > 0 && a < 128));
        assert!(alphas.iter().any(|a| (128..255).contains(a)));
        assert!(synthetic_animation(0, 3).is_empty());
    }
}
