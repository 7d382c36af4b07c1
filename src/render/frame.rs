//! A frame: the parts the caller lists, drawn back to front, each with its own positions, tint
//! and visibility.
//!
//! In: a canvas (premultiplied RGBA), every part's fixed render state ([`RenderPart`]: mesh and
//! texture, built once per rig), a list of [`PartDraw`]s in draw order (first = furthest back),
//! and the view's `canvas_from_world` transform. Out: the visible parts composited source-over
//! onto the canvas. The list may name a part several times (each draw is independent) or leave
//! parts out.

use tiny_skia::{Pixmap, Transform};

use crate::geom::Point;

use super::blend::Tint;
use super::mesh_renderer::{DrawScratch, MeshRenderer};
use super::texture::Texture;
use super::RenderError;

/// What drawing a part needs that does not change between frames.
pub struct RenderPart {
    pub mesh: MeshRenderer,
    /// Sampled in the texture pixels of the mesh's rest positions.
    pub texture: Texture,
}

/// One part in one frame.
#[derive(Clone, Copy, Debug)]
pub struct PartDraw<'a> {
    /// Index of the part in the `parts` given to [`draw_parts`].
    pub part: usize,
    /// The part's vertex positions, world pixels, one per mesh vertex.
    pub positions_px: &'a [Point],
    pub tint: Tint,
    /// A hidden part is skipped (its positions are not even checked).
    pub visible: bool,
}

impl<'a> PartDraw<'a> {
    /// Part `part` at `positions_px`, visible and untinted.
    pub fn new(part: usize, positions_px: &'a [Point]) -> Self {
        PartDraw {
            part,
            positions_px,
            tint: Tint::WHITE,
            visible: true,
        }
    }
}

/// Draws `draws` in order onto `canvas` through `canvas_from_world`.
///
/// Checks the whole list first and draws nothing if a visible draw names a part that does not
/// exist or brings the wrong number of positions. Within a part the rules of
/// [`MeshRenderer::draw`] hold (non-finite positions or a zero tint alpha draw nothing).
pub fn draw_parts(
    canvas: &mut Pixmap,
    parts: &[RenderPart],
    draws: &[PartDraw],
    canvas_from_world: Transform,
) -> Result<(), RenderError> {
    for draw in draws.iter().filter(|d| d.visible) {
        let part = parts.get(draw.part).ok_or(RenderError::UnknownPart {
            part: draw.part,
            parts: parts.len(),
        })?;
        let expected = part.mesh.vertex_count();
        if draw.positions_px.len() != expected {
            return Err(RenderError::PositionCount {
                part: draw.part,
                got: draw.positions_px.len(),
                expected,
            });
        }
    }
    SCRATCH.with(|kept| {
        // A fresh one only if this thread is already drawing (a draw inside a draw).
        let mut fresh = DrawScratch::default();
        let mut kept = kept.try_borrow_mut();
        let scratch = match kept.as_deref_mut() {
            Ok(kept) => kept,
            Err(_) => &mut fresh,
        };
        for draw in draws.iter().filter(|d| d.visible) {
            let part = &parts[draw.part];
            part.mesh.draw_with(
                canvas,
                &part.texture,
                draw.positions_px,
                canvas_from_world,
                draw.tint,
                scratch,
            );
        }
    });
    Ok(())
}

thread_local! {
    /// Buffers kept between frames (a part's coverage region is up to a few MB on a large
    /// canvas; growing and zeroing them anew each frame costs more than drawing small parts).
    /// What they hold never reaches the output: every draw clears or rewrites what it reads.
    static SCRATCH: std::cell::RefCell<DrawScratch> = std::cell::RefCell::new(DrawScratch::default());
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::test_support::{canvas, colorful_texture, grid_mesh, linspace};

    /// Two overlapping squares (parts 0 and 1), the second shifted right by 8 px.
    fn two_parts() -> (Vec<RenderPart>, Vec<Point>, Vec<Point>) {
        let (uv, triangles) = grid_mesh(&linspace(4.0, 20.0, 3), &linspace(4.0, 20.0, 3));
        let part = |opaque: bool| RenderPart {
            mesh: MeshRenderer::new(&uv, &triangles).expect("valid mesh"),
            texture: if opaque {
                colorful_texture(24, 24, |_, _| true)
            } else {
                Texture::from_rgba(&image::RgbaImage::from_pixel(
                    24,
                    24,
                    image::Rgba([250, 250, 250, 255]),
                ))
                .expect("non-empty")
            },
        };
        let shifted = uv.iter().map(|p| Point::new(p.x + 8.0, p.y)).collect();
        (vec![part(true), part(false)], uv, shifted)
    }

    fn pixel(p: &Pixmap, x: u32, y: u32) -> [u8; 4] {
        let c = p.pixel(x, y).expect("inside");
        [c.red(), c.green(), c.blue(), c.alpha()]
    }

    #[test]
    fn later_draws_cover_earlier_ones_in_the_callers_order() {
        let (parts, at_rest, shifted) = two_parts();
        let id = Transform::identity();
        let mut back_to_front = canvas(32, 24);
        let draws = [PartDraw::new(0, &at_rest), PartDraw::new(1, &shifted)];
        draw_parts(&mut back_to_front, &parts, &draws, id).expect("valid draws");
        let mut reversed = canvas(32, 24);
        let draws = [PartDraw::new(1, &shifted), PartDraw::new(0, &at_rest)];
        draw_parts(&mut reversed, &parts, &draws, id).expect("valid draws");
        // Pixel (15, 12) lies in both squares.
        assert_eq!(pixel(&back_to_front, 15, 12), [250, 250, 250, 255]);
        assert_ne!(pixel(&reversed, 15, 12), [250, 250, 250, 255]);
        assert_eq!(pixel(&reversed, 15, 12)[3], 255);
    }

    #[test]
    fn hidden_parts_are_skipped_and_tints_apply() {
        let (parts, at_rest, shifted) = two_parts();
        let id = Transform::identity();
        let mut out = canvas(32, 24);
        let hidden = PartDraw {
            visible: false,
            ..PartDraw::new(0, &[])
        };
        let tinted = PartDraw {
            tint: Tint {
                r: 1.0,
                g: 0.0,
                b: 0.5,
                a: 1.0,
            },
            ..PartDraw::new(1, &shifted)
        };
        draw_parts(&mut out, &parts, &[hidden, tinted], id).expect("valid draws");
        assert_eq!(pixel(&out, 8, 12), [0; 4], "only part 1 is drawn");
        assert_eq!(pixel(&out, 20, 12), [250, 0, 125, 255]);
        let _ = at_rest;
    }

    #[test]
    fn bad_draws_draw_nothing() {
        let (parts, at_rest, _) = two_parts();
        let id = Transform::identity();
        let mut out = canvas(32, 24);
        let good = PartDraw::new(0, &at_rest);
        assert_eq!(
            draw_parts(&mut out, &parts, &[good, PartDraw::new(2, &at_rest)], id),
            Err(RenderError::UnknownPart { part: 2, parts: 2 })
        );
        assert_eq!(
            draw_parts(
                &mut out,
                &parts,
                &[good, PartDraw::new(1, &at_rest[1..])],
                id
            ),
            Err(RenderError::PositionCount {
                part: 1,
                got: 8,
                expected: 9
            })
        );
        assert!(out.data().iter().all(|&b| b == 0));
    }

    #[test]
    fn output_is_the_same_whatever_the_thread_count() {
        let (parts, at_rest, shifted) = two_parts();
        let view = Transform::from_row(2.3, 0.4, -0.5, 2.1, 3.7, 1.9);
        let draws = [PartDraw::new(0, &at_rest), PartDraw::new(1, &shifted)];
        let frame_with = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool");
            pool.install(|| {
                let mut out = canvas(96, 64);
                draw_parts(&mut out, &parts, &draws, view).expect("valid draws");
                out
            })
        };
        let one = frame_with(1);
        assert!(one.data().iter().any(|&b| b != 0));
        assert_eq!(one.data(), frame_with(2).data());
        assert_eq!(one.data(), frame_with(1).data());
    }

    #[test]
    fn output_does_not_depend_on_the_scratch_history() {
        let (parts, at_rest, shifted) = two_parts();
        let view = Transform::from_row(1.7, 0.2, -0.3, 1.6, 2.3, -1.1);
        let mut once = canvas(48, 40);
        draw_parts(&mut once, &parts, &[PartDraw::new(1, &shifted)], view).expect("valid");
        let mut after = canvas(48, 40);
        let draws = [PartDraw::new(0, &at_rest), PartDraw::new(1, &shifted)];
        draw_parts(&mut after, &parts, &draws, view).expect("valid");
        let mut fresh = canvas(48, 40);
        draw_parts(&mut fresh, &parts, &[PartDraw::new(0, &at_rest)], view).expect("valid");
        draw_parts(&mut fresh, &parts, &[PartDraw::new(1, &shifted)], view).expect("valid");
        assert_eq!(after.data(), fresh.data());
        assert_ne!(once.data(), fresh.data());
    }
}
