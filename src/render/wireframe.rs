//! A mesh's edges and vertices as lines and dots, for preview images.
//!
//! In: vertex positions in world pixels, triangles, a `canvas_from_world` view transform, a
//! colour and a line width in canvas pixels. Out: antialiased strokes on the canvas.

use tiny_skia::{Color, FillRule, LineCap, Paint, PathBuilder, Pixmap, Stroke, Transform};

use crate::geom::Point;

/// Radius of a vertex dot, as a multiple of the line width: large enough to stand out on the
/// lines meeting there.
const VERTEX_DOT_RADIUS_PER_WIDTH: f32 = 1.25;

/// Draws each edge of the mesh once as an antialiased line `width_px` wide (canvas pixels,
/// unaffected by the transform's scale), with a dot on each vertex a triangle uses.
///
/// Edges with an index past `positions_px` or a non-finite end are left out, as is everything
/// when the width is not a positive number.
pub fn draw_wireframe(
    canvas: &mut Pixmap,
    positions_px: &[Point],
    triangles: &[[u32; 3]],
    canvas_from_world: Transform,
    color: Color,
    width_px: f32,
) {
    if !(width_px > 0.0 && width_px.is_finite()) {
        return;
    }
    let canvas_px: Vec<Option<[f32; 2]>> = positions_px
        .iter()
        .map(|p| to_canvas(*p, canvas_from_world))
        .collect();
    let edges = unique_edges(triangles, &canvas_px);
    let mut paint = Paint::default();
    paint.set_color(color);
    paint.anti_alias = true;
    stroke_edges(canvas, &canvas_px, &edges, &paint, width_px);
    fill_vertex_dots(
        canvas,
        &canvas_px,
        &edges,
        &paint,
        width_px * VERTEX_DOT_RADIUS_PER_WIDTH,
    );
}

/// A world position in canvas pixels (f32, as tiny-skia takes), or `None` if not finite.
fn to_canvas(p: Point, t: Transform) -> Option<[f32; 2]> {
    let [sx, kx, tx, ky, sy, ty] = [t.sx, t.kx, t.tx, t.ky, t.sy, t.ty].map(f64::from);
    let q = [
        (sx * p.x + kx * p.y + tx) as f32,
        (ky * p.x + sy * p.y + ty) as f32,
    ];
    (q[0].is_finite() && q[1].is_finite()).then_some(q)
}

/// The distinct undirected edges of the triangles whose ends both have a drawable position.
fn unique_edges(triangles: &[[u32; 3]], canvas_px: &[Option<[f32; 2]>]) -> Vec<(u32, u32)> {
    let drawable = |v: u32| matches!(canvas_px.get(v as usize), Some(Some(_)));
    let mut edges: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .filter(|&(a, b)| a != b && drawable(a) && drawable(b))
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// Strokes all edges as one path, so overlapping line ends are not blended twice.
fn stroke_edges(
    canvas: &mut Pixmap,
    canvas_px: &[Option<[f32; 2]>],
    edges: &[(u32, u32)],
    paint: &Paint,
    width_px: f32,
) {
    let mut builder = PathBuilder::new();
    for &(a, b) in edges {
        if let (Some([ax, ay]), Some([bx, by])) = (canvas_px[a as usize], canvas_px[b as usize]) {
            builder.move_to(ax, ay);
            builder.line_to(bx, by);
        }
    }
    let Some(path) = builder.finish() else {
        return;
    };
    let stroke = Stroke {
        width: width_px,
        line_cap: LineCap::Round,
        ..Stroke::default()
    };
    canvas.stroke_path(&path, paint, &stroke, Transform::identity(), None);
}

/// Fills a dot of `radius_px` on every vertex that ends an edge.
fn fill_vertex_dots(
    canvas: &mut Pixmap,
    canvas_px: &[Option<[f32; 2]>],
    edges: &[(u32, u32)],
    paint: &Paint,
    radius_px: f32,
) {
    let mut vertices: Vec<u32> = edges.iter().flat_map(|&(a, b)| [a, b]).collect();
    vertices.sort_unstable();
    vertices.dedup();
    let mut builder = PathBuilder::new();
    for v in vertices {
        if let Some([x, y]) = canvas_px[v as usize] {
            builder.push_circle(x, y, radius_px);
        }
    }
    if let Some(path) = builder.finish() {
        canvas.fill_path(&path, paint, FillRule::Winding, Transform::identity(), None);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn alpha_at(canvas: &Pixmap, x: u32, y: u32) -> u8 {
        canvas.pixel(x, y).map_or(0, |p| p.alpha())
    }

    #[test]
    fn draws_along_edges_and_not_inside() {
        let mut canvas = Pixmap::new(64, 64).expect("non-empty canvas");
        let positions = [
            Point::new(4.0, 4.0),
            Point::new(60.0, 4.0),
            Point::new(4.0, 60.0),
            Point::new(60.0, 60.0),
        ];
        let triangles = [[0, 1, 2], [1, 3, 2]];
        draw_wireframe(
            &mut canvas,
            &positions,
            &triangles,
            Transform::identity(),
            Color::from_rgba8(255, 0, 0, 255),
            1.5,
        );
        // Midpoints of the outer edges and of the shared diagonal.
        for (x, y) in [(32, 4), (4, 32), (60, 32), (32, 60), (32, 32)] {
            assert!(alpha_at(&canvas, x, y) > 0, "nothing at ({x}, {y})");
        }
        // Well inside each triangle, away from every edge.
        for (x, y) in [(16, 16), (48, 48)] {
            assert_eq!(alpha_at(&canvas, x, y), 0, "paint at ({x}, {y})");
        }
    }

    #[test]
    fn bad_input_draws_nothing_and_does_not_panic() {
        let mut canvas = Pixmap::new(8, 8).expect("non-empty canvas");
        let positions = [Point::new(1.0, 1.0), Point::new(f64::NAN, 2.0)];
        let triangles = [[0, 1, 7]];
        let red = Color::from_rgba8(255, 0, 0, 255);
        draw_wireframe(
            &mut canvas,
            &positions,
            &triangles,
            Transform::identity(),
            red,
            1.0,
        );
        draw_wireframe(
            &mut canvas,
            &positions,
            &[[0, 0, 0]],
            Transform::identity(),
            red,
            -1.0,
        );
        assert!(canvas.data().iter().all(|&b| b == 0));
    }
}
