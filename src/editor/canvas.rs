//! The editor's canvas: the view transform (pan and zoom) and what is painted on it.
//!
//! In: the document's layers, the parts' meshes at given positions (canvas px), the handles.
//! Out: egui shapes in screen points. The canvas frame is the rig's (px, y down); the screen
//! frame is egui's (points, y down): `screen = origin + pan + zoom · canvas`.

use crate::geom::Point;
use crate::io::WeightsDoc;
use crate::rig::Handles;
use eframe::egui::{self, Color32, Pos2, Shape, Stroke, TextureHandle, Vec2};

/// Screen distance within which a click picks a handle, points.
pub const PICK_RADIUS_PT: f32 = 8.0;

/// Pan and zoom of the canvas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Screen points per canvas px.
    pub zoom: f32,
    /// Offset of the canvas origin from the canvas area's top-left corner, points.
    pub pan: Vec2,
}

impl Default for View {
    fn default() -> Self {
        View {
            zoom: 1.0,
            pan: Vec2::new(16.0, 16.0),
        }
    }
}

/// A view placed in a screen rectangle: converts between canvas px and screen points.
#[derive(Clone, Copy, Debug)]
pub struct Placed {
    pub view: View,
    pub origin: Pos2,
}

impl Placed {
    pub fn screen_from_canvas(&self, p: Point) -> Pos2 {
        self.origin + self.view.pan + Vec2::new(p.x as f32, p.y as f32) * self.view.zoom
    }

    pub fn canvas_from_screen(&self, s: Pos2) -> Point {
        let v = (s - self.origin - self.view.pan) / self.view.zoom;
        Point::new(v.x as f64, v.y as f64)
    }
}

/// The zoom that fits a `canvas_px` canvas into `available` points with a margin.
pub fn fit(canvas_px: [u32; 2], available: Vec2) -> View {
    let margin = 16.0;
    let zoom = ((available.x - 2.0 * margin) / canvas_px[0].max(1) as f32)
        .min((available.y - 2.0 * margin) / canvas_px[1].max(1) as f32)
        .clamp(0.05, 16.0);
    let size = Vec2::new(canvas_px[0] as f32, canvas_px[1] as f32) * zoom;
    View {
        zoom,
        pan: (available - size) / 2.0,
    }
}

/// An image of `size_px` whose top-left pixel lies at `offset_px` on the canvas, as one quad
/// at rest.
pub fn image_quad(
    placed: &Placed,
    texture: &TextureHandle,
    offset_px: [i32; 2],
    size_px: [u32; 2],
) -> Shape {
    let [x, y] = offset_px.map(f64::from);
    let rect = egui::Rect::from_two_pos(
        placed.screen_from_canvas(Point::new(x, y)),
        placed.screen_from_canvas(Point::new(
            x + f64::from(size_px[0]),
            y + f64::from(size_px[1]),
        )),
    );
    let uv = egui::Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
    Shape::image(texture.id(), rect, uv, Color32::WHITE)
}

/// Mesh edges as thin lines.
pub fn wireframe(placed: &Placed, positions: &[Point], triangles: &[[u32; 3]]) -> Vec<Shape> {
    let stroke = Stroke::new(0.5, Color32::from_rgba_unmultiplied(255, 255, 255, 70));
    triangles
        .iter()
        .map(|t| {
            let pts: Vec<Pos2> = t
                .iter()
                .map(|&i| {
                    let p = positions[i as usize];
                    placed.screen_from_canvas(p)
                })
                .collect();
            Shape::closed_line(pts, stroke)
        })
        .collect()
}

/// One handle's weights over a part as a heat map (blue 0 → red 1), drawn over the mesh.
pub fn heat_map(
    placed: &Placed,
    weights: &WeightsDoc,
    handle: &str,
    positions: &[Point],
    triangles: &[[u32; 3]],
) -> Option<Shape> {
    let column = weights.handles.iter().position(|h| h == handle)? as u32;
    let mut mesh = egui::Mesh::default();
    for (p, row) in positions.iter().zip(&weights.rows) {
        let w = row
            .iter()
            .find(|(j, _)| *j == column)
            .map_or(0.0, |(_, w)| *w);
        mesh.vertices.push(egui::epaint::Vertex {
            pos: placed.screen_from_canvas(*p),
            uv: egui::epaint::WHITE_UV,
            color: heat_color(w),
        });
    }
    mesh.indices = triangles.iter().flatten().copied().collect();
    Some(Shape::mesh(mesh))
}

/// Weight 0 → translucent blue, 1 → red, through green and yellow.
pub fn heat_color(w: f64) -> Color32 {
    let w = w.clamp(0.0, 1.0) as f32;
    let (r, g, b) = if w < 0.5 {
        (0.0, 2.0 * w, 1.0 - 2.0 * w)
    } else {
        (2.0 * w - 1.0, 2.0 - 2.0 * w, 0.0)
    };
    // Cold areas stay see-through so the drawing shows under them.
    let alpha = 70.0 + 130.0 * w;
    Color32::from_rgba_unmultiplied(
        (r * 255.0) as u8,
        (g * 255.0) as u8,
        (b * 255.0) as u8,
        alpha as u8,
    )
}

/// Bones as tapered outlines from head to tail, points as rings (a carried point dashed to its
/// bone); `selected` highlighted.
pub fn handles(placed: &Placed, handles: &Handles, selected: Option<&str>) -> Vec<Shape> {
    let mut shapes = Vec::new();
    let color = |name: &str| {
        if selected == Some(name) {
            Color32::from_rgb(255, 200, 40)
        } else {
            Color32::from_rgb(80, 220, 255)
        }
    };
    for bone in &handles.bones {
        let (h, t) = (
            placed.screen_from_canvas(bone.head),
            placed.screen_from_canvas(bone.tail),
        );
        let along = t - h;
        let width = (along.length() * 0.12).clamp(3.0, 10.0);
        let across = along.normalized().rot90() * width;
        let joint = h + along * 0.2;
        let stroke = Stroke::new(1.5, color(&bone.name));
        shapes.push(Shape::closed_line(
            vec![h, joint + across, t, joint - across],
            stroke,
        ));
        shapes.push(Shape::circle_stroke(h, 3.0, stroke));
    }
    for (i, point) in handles.points.iter().enumerate() {
        let s = placed.screen_from_canvas(point.at);
        // A carried point: a faint line to the nearest point of its bone.
        if let Some(bone) = handles.point_parent(i).map(|b| &handles.bones[b]) {
            let (_, t) = crate::geom::segment_distance(point.at, bone.head, bone.tail);
            let on_bone = bone.head + (bone.tail - bone.head) * t;
            let faint = color(&point.name).gamma_multiply(0.5);
            shapes.extend(Shape::dashed_line(
                &[s, placed.screen_from_canvas(on_bone)],
                Stroke::new(1.0, faint),
                4.0,
                3.0,
            ));
        }
        shapes.push(Shape::circle_stroke(
            s,
            5.0,
            Stroke::new(2.0, color(&point.name)),
        ));
    }
    for cage in &handles.cages {
        let pts: Vec<Pos2> = cage
            .polygon
            .iter()
            .map(|p| placed.screen_from_canvas(*p))
            .collect();
        shapes.push(Shape::closed_line(pts, Stroke::new(1.0, color(&cage.name))));
    }
    for region in &handles.regions {
        let pts: Vec<Pos2> = region
            .polygon
            .iter()
            .map(|p| placed.screen_from_canvas(*p))
            .collect();
        shapes.push(Shape::closed_line(
            pts,
            Stroke::new(1.0, color(&region.name)),
        ));
    }
    shapes
}

/// The handle nearest to `at` (screen points) within [`PICK_RADIUS_PT`], by name.
pub fn pick(placed: &Placed, handles: &Handles, at: Pos2) -> Option<String> {
    use crate::geom::segment_distance;
    // Measured in canvas px, then compared in screen points: the view only scales.
    let c = placed.canvas_from_screen(at);
    let bones = handles
        .bones
        .iter()
        .map(|b| (segment_distance(c, b.head, b.tail).0, &b.name));
    let points = handles.points.iter().map(|p| ((c - p.at).norm(), &p.name));
    // Cages and regions are picked by their outline.
    let outline = |polygon: &[Point]| {
        (0..polygon.len())
            .map(|k| {
                let (a, b) = (polygon[k], polygon[(k + 1) % polygon.len()]);
                segment_distance(c, a, b).0
            })
            .fold(f64::INFINITY, f64::min)
    };
    let cages = handles.cages.iter().map(|g| (outline(&g.polygon), &g.name));
    let regions = handles
        .regions
        .iter()
        .map(|r| (outline(&r.polygon), &r.name));
    bones
        .chain(points)
        .chain(cages)
        .chain(regions)
        .map(|(d_px, name)| (d_px as f32 * placed.view.zoom, name))
        .filter(|(d_pt, _)| *d_pt <= PICK_RADIUS_PT)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, name)| name.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screen_and_canvas_round_trip() {
        let placed = Placed {
            view: View {
                zoom: 2.5,
                pan: Vec2::new(10.0, -4.0),
            },
            origin: Pos2::new(100.0, 50.0),
        };
        let c = Point::new(12.5, 40.0);
        let back = placed.canvas_from_screen(placed.screen_from_canvas(c));
        assert!((back[0] - c[0]).abs() < 1e-4 && (back[1] - c[1]).abs() < 1e-4);
    }

    #[test]
    fn fit_centers_the_canvas() {
        let v = fit([400, 200], Vec2::new(832.0, 632.0));
        assert_eq!(v.zoom, 2.0);
        assert_eq!(v.pan, Vec2::new(16.0, 116.0));
    }

    #[test]
    fn heat_colors_run_blue_to_red() {
        let (cold, hot) = (heat_color(0.0), heat_color(1.0));
        assert!(cold.b() > 50 && cold.r() == 0 && cold.a() < hot.a());
        assert!(hot.r() > 100 && hot.b() == 0);
    }
}
