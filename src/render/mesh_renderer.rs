//! One part's textured, deformed mesh → a layer → the canvas (see the module doc of
//! [`super`] for the approach).
//!
//! Spaces: texture pixels (the mesh's rest positions), world pixels (the deformed positions),
//! canvas pixels (world through `canvas_from_world`) and layer pixels (canvas pixels shifted
//! by the integer origin of the part's layer).

use tiny_skia::{
    BlendMode, FillRule, FilterQuality, Mask, Paint, PathBuilder, Pattern, Pixmap, PixmapRef,
    SpreadMode, Transform,
};

use crate::geom::Point;

use super::composite::{composite_layer, Coverage};
use super::pixel_math::CHANNEL_MAX;
use super::topology::{BoundaryEdge, Mat2, TexturedTriangle, Topology, DEGENERATE_AREA2_PX2};
use super::RenderError;

/// How far, in output pixels, the skirt extends the mesh past its boundary edges.
///
/// A pixel that the antialiased boundary covers partly has its center at most √2/2 px outside
/// the boundary, and needs texture colour there; 1 px covers that with margin.
pub const SKIRT_PX: f64 = 1.0;

/// Longest skirt offset at a vertex, as a multiple of [`SKIRT_PX`]. A mitre grows as
/// 1/sin(θ/2) at a corner of angle θ; past this (corners sharper than ~29°, as SVG's default
/// miter limit) the skirt is cut short and the very tip of the corner loses a little coverage.
const MAX_MITER_RATIO: f64 = 4.0;

/// Length, in px, below which an edge or a sum of normals has no usable direction.
const MIN_DIRECTION_PX: f64 = 1e-9;

/// Extra pixels kept around the part's bounding box in its layer, so that rounding in the
/// rasterizer can never push coverage off the layer.
const LAYER_MARGIN_PX: f64 = 1.0;

/// Scale added to a pattern map that is a pure translation by a fractional offset: tiny-skia
/// samples any pure translation with nearest-neighbour filtering, which would snap a part moved
/// by a fraction of a pixel to whole pixels. The change is below 0.001 px over 2000 px.
const BILINEAR_NUDGE: f32 = 4.0 * f32::EPSILON;

/// The per-mesh state rendering needs that does not change between frames.
pub struct MeshRenderer {
    topology: Topology,
}

impl MeshRenderer {
    /// Precomputes what drawing needs from the mesh's connectivity and rest positions
    /// (`uv_px`: texture pixels): the texture-space basis of each triangle, the boundary edges
    /// and the boundary loops.
    ///
    /// Triangles with (near) zero area in texture space are kept out: they cannot carry a
    /// texture map and cover no pixels. Fails on an empty mesh, an index past the last vertex
    /// or a non-finite position.
    pub fn new(uv_px: &[Point], triangles: &[[u32; 3]]) -> Result<Self, RenderError> {
        Ok(MeshRenderer {
            topology: Topology::new(uv_px, triangles)?,
        })
    }

    /// Number of vertices the mesh has, and so of positions [`MeshRenderer::draw`] expects.
    pub fn vertex_count(&self) -> usize {
        self.topology.vertex_count
    }

    /// Draws the mesh textured with `texture` (premultiplied, sampled in texture pixels)
    /// source-over onto `canvas`, with its vertices at `positions_px` (world pixels, one per
    /// vertex, in the order of `uv_px`) mapped through `canvas_from_world`, at `opacity`
    /// (0..=1) for the part as a whole.
    ///
    /// Draws nothing when the positions do not match the mesh (wrong count, NaN or infinite),
    /// when opacity is not positive, or when the part lies off the canvas. Triangles flipped by
    /// the deformation are drawn; triangles collapsed to (near) zero area are skipped.
    pub fn draw(
        &self,
        canvas: &mut Pixmap,
        texture: PixmapRef,
        positions_px: &[Point],
        canvas_from_world: Transform,
        opacity: f32,
    ) {
        let opacity = opacity_u8(opacity);
        if opacity == 0 || self.topology.triangles.is_empty() {
            return;
        }
        let Some(mut points) =
            canvas_positions(positions_px, self.topology.vertex_count, canvas_from_world)
        else {
            return;
        };
        let Some(region) = LayerRegion::around(&points, canvas.width(), canvas.height()) else {
            return;
        };
        let Some(mut layer) = Pixmap::new(region.width, region.height) else {
            return;
        };
        region.shift_to_layer(&mut points);
        self.paint_layer(&mut layer, texture, &points);

        let mask = if self.topology.loops.is_empty() {
            None
        } else {
            match self.boundary_mask(&points, region.width, region.height) {
                Some(mask) => Some(mask),
                None => return,
            }
        };
        let coverage = match &mask {
            Some(mask) => Coverage::Masked(mask),
            // No boundary (every edge shared twice): nothing to antialias against.
            None => Coverage::Everywhere,
        };
        composite_layer(canvas, &layer, coverage, (region.x, region.y), opacity);
    }

    /// Fills the skirts, then every triangle, into `layer` (transparent, layer pixels).
    ///
    /// Skirts go first so that where one reaches over the mesh (at a concave corner) the
    /// triangle's own texture replaces it.
    fn paint_layer(&self, layer: &mut Pixmap, texture: PixmapRef, layer_px: &[[f64; 2]]) {
        let maps: Vec<Option<Affine>> = self
            .topology
            .triangles
            .iter()
            .map(|t| Affine::texture_to_layer(t, layer_px))
            .collect();
        let mut painter = TexturePainter::new(texture, layer.width(), layer.height());

        let offsets = skirt_offsets(&self.topology, layer_px);
        for edge in &self.topology.boundary_edges {
            if let Some(map) = maps[edge.triangle] {
                let (a, b) = (layer_px[edge.from as usize], layer_px[edge.to as usize]);
                let quad = [
                    a,
                    b,
                    add(b, offsets[edge.to_slot]),
                    add(a, offsets[edge.from_slot]),
                ];
                painter.fill(layer, &quad, map);
            }
        }
        for (triangle, map) in self.topology.triangles.iter().zip(&maps) {
            if let Some(map) = *map {
                let corners = triangle.vertices.map(|v| layer_px[v as usize]);
                painter.fill(layer, &corners, map);
            }
        }
    }

    /// An antialiased coverage mask of the boundary loops, layer-sized; `None` when it cannot
    /// be built (then nothing should be drawn).
    fn boundary_mask(&self, layer_px: &[[f64; 2]], width: u32, height: u32) -> Option<Mask> {
        let mut builder = PathBuilder::new();
        for ring in &self.topology.loops {
            let mut vertices = ring.iter().map(|&v| layer_px[v as usize]);
            let Some([x, y]) = vertices.next() else {
                continue;
            };
            builder.move_to(x as f32, y as f32);
            for [x, y] in vertices {
                builder.line_to(x as f32, y as f32);
            }
            builder.close();
        }
        let path = builder.finish()?;
        let mut mask = Mask::new(width, height)?;
        // Non-zero winding: holes run opposite to the outer boundary and stay empty, while a
        // mirrored or folded-over part still counts as inside.
        mask.fill_path(&path, FillRule::Winding, true, Transform::identity());
        Some(mask)
    }
}

/// Opacity 0..=1 as an 8-bit coverage factor; NaN and negatives become 0.
fn opacity_u8(opacity: f32) -> u8 {
    if opacity > 0.0 {
        (opacity.min(1.0) * CHANNEL_MAX as f32).round() as u8
    } else {
        0
    }
}

/// World positions mapped to canvas pixels, or `None` unless there is exactly one finite
/// position per vertex.
fn canvas_positions(
    positions_px: &[Point],
    vertex_count: usize,
    canvas_from_world: Transform,
) -> Option<Vec<[f64; 2]>> {
    if positions_px.len() != vertex_count {
        return None;
    }
    let t = canvas_from_world;
    let [sx, kx, tx, ky, sy, ty] = [t.sx, t.kx, t.tx, t.ky, t.sy, t.ty].map(f64::from);
    positions_px
        .iter()
        .map(|p| {
            let q = [sx * p.x + kx * p.y + tx, ky * p.x + sy * p.y + ty];
            (q[0].is_finite() && q[1].is_finite()).then_some(q)
        })
        .collect()
}

/// The canvas pixels a part's layer covers: its bounding box with a margin, clipped to the
/// canvas.
struct LayerRegion {
    x: u32,
    y: u32,
    width: u32,
    height: u32,
}

impl LayerRegion {
    /// The region around `points` (canvas pixels, finite), or `None` if it misses the canvas.
    fn around(points: &[[f64; 2]], canvas_width: u32, canvas_height: u32) -> Option<Self> {
        let (min, max) = points.iter().fold(
            ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
            |(min, max), p| {
                (
                    [min[0].min(p[0]), min[1].min(p[1])],
                    [max[0].max(p[0]), max[1].max(p[1])],
                )
            },
        );
        let (x, width) = clipped_span(min[0], max[0], canvas_width)?;
        let (y, height) = clipped_span(min[1], max[1], canvas_height)?;
        Some(LayerRegion {
            x,
            y,
            width,
            height,
        })
    }

    /// Shifts canvas pixel positions into this layer's pixels.
    fn shift_to_layer(&self, points: &mut [[f64; 2]]) {
        let (dx, dy) = (f64::from(self.x), f64::from(self.y));
        for p in points {
            *p = [p[0] - dx, p[1] - dy];
        }
    }
}

/// The whole pixels touched by [lo, hi] plus the margin, clipped to 0..limit, as
/// (start, length); `None` if empty.
fn clipped_span(lo: f64, hi: f64, limit: u32) -> Option<(u32, u32)> {
    let limit = f64::from(limit);
    let start = (lo.floor() - LAYER_MARGIN_PX).clamp(0.0, limit);
    let end = (hi.ceil() + LAYER_MARGIN_PX).clamp(0.0, limit);
    (end > start).then_some((start as u32, (end - start) as u32))
}

/// An affine map from texture pixels to layer pixels: `linear · uv + translation`.
#[derive(Clone, Copy)]
struct Affine {
    linear: Mat2,
    translation: [f64; 2],
}

impl Affine {
    /// The map taking the triangle's rest corners onto its corners in `layer_px`, or `None`
    /// when the triangle has (near) zero area there.
    fn texture_to_layer(triangle: &TexturedTriangle, layer_px: &[[f64; 2]]) -> Option<Self> {
        let [p0, p1, p2] = triangle.vertices.map(|v| layer_px[v as usize]);
        let (e1, e2) = (sub(p1, p0), sub(p2, p0));
        if cross(e1, e2).abs() <= DEGENERATE_AREA2_PX2 {
            return None;
        }
        let edges = [[e1[0], e2[0]], [e1[1], e2[1]]];
        let linear = mat_mul(edges, triangle.uv_basis_inverse);
        let translation = sub(p0, mat_vec(linear, triangle.uv_origin));
        Some(Affine {
            linear,
            translation,
        })
    }

    /// The map as a tiny-skia pattern transform, nudged off pure fractional translations so
    /// that it is still sampled bilinearly (see [`BILINEAR_NUDGE`]).
    fn to_pattern_transform(self) -> Transform {
        let [[sx, kx], [ky, sy]] = self.linear.map(|row| row.map(|v| v as f32));
        let [tx, ty] = self.translation.map(|v| v as f32);
        let mut t = Transform::from_row(sx, ky, kx, sy, tx, ty);
        if t.is_translate() && (tx.fract() != 0.0 || ty.fract() != 0.0) {
            t.sx += BILINEAR_NUDGE;
            t.sy += BILINEAR_NUDGE;
        }
        t
    }
}

/// Fills polygons into a layer with the texture under a per-polygon affine map, reusing one
/// path allocation throughout.
struct TexturePainter<'a> {
    texture: PixmapRef<'a>,
    builder: Option<PathBuilder>,
    width: f64,
    height: f64,
}

impl<'a> TexturePainter<'a> {
    fn new(texture: PixmapRef<'a>, width: u32, height: u32) -> Self {
        TexturePainter {
            texture,
            builder: Some(PathBuilder::new()),
            width: f64::from(width),
            height: f64::from(height),
        }
    }

    /// Fills the polygon `corners` (layer pixels) without antialiasing, replacing what is
    /// there: every pixel whose center lies inside gets the texture sampled through `map`.
    fn fill(&mut self, layer: &mut Pixmap, corners: &[[f64; 2]], map: Affine) {
        if self.misses_layer(corners) {
            return;
        }
        let mut builder = self.builder.take().unwrap_or_default();
        let mut corner_iter = corners.iter();
        if let Some(&[x, y]) = corner_iter.next() {
            builder.move_to(x as f32, y as f32);
        }
        for &[x, y] in corner_iter {
            builder.line_to(x as f32, y as f32);
        }
        builder.close();
        let Some(path) = builder.finish() else {
            return;
        };
        let paint = Paint {
            shader: Pattern::new(
                self.texture,
                SpreadMode::Pad,
                FilterQuality::Bilinear,
                1.0,
                map.to_pattern_transform(),
            ),
            blend_mode: BlendMode::Source,
            anti_alias: false,
            ..Paint::default()
        };
        layer.fill_path(
            &path,
            &paint,
            FillRule::Winding,
            Transform::identity(),
            None,
        );
        self.builder = Some(path.clear());
    }

    /// Whether the polygon's bounding box lies entirely off the layer (saves tiny-skia's
    /// per-fill setup for parts of a zoomed-in view that are off screen).
    fn misses_layer(&self, corners: &[[f64; 2]]) -> bool {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for c in corners {
            lo = [lo[0].min(c[0]), lo[1].min(c[1])];
            hi = [hi[0].max(c[0]), hi[1].max(c[1])];
        }
        hi[0] < 0.0 || hi[1] < 0.0 || lo[0] > self.width || lo[1] > self.height
    }
}

/// Per boundary vertex (indexed like `Topology::boundary_vertices`), the displacement from the
/// vertex to its skirt corner, in layer pixels: along the bisector of the outward normals of
/// its boundary edges, long enough that every edge's skirt is [`SKIRT_PX`] wide (a mitre),
/// capped at [`MAX_MITER_RATIO`].
fn skirt_offsets(topology: &Topology, layer_px: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let edges = &topology.boundary_edges;
    let normals: Vec<Option<[f64; 2]>> =
        edges.iter().map(|e| outward_normal(e, layer_px)).collect();

    let slots = topology.boundary_vertices.len();
    let mut sums = vec![[0.0; 2]; slots];
    for (e, n) in edges.iter().zip(&normals) {
        if let Some(n) = *n {
            sums[e.from_slot] = add(sums[e.from_slot], n);
            sums[e.to_slot] = add(sums[e.to_slot], n);
        }
    }
    // Opposite normals cancel at a needle tip or a vertex with no usable edge; such a vertex
    // gets no skirt corner, which only thins the skirt next to it.
    let bisectors: Vec<Option<[f64; 2]>> = sums.into_iter().map(unit).collect();

    let mut min_cos = vec![1.0f64; slots];
    for (e, n) in edges.iter().zip(&normals) {
        if let Some(n) = *n {
            for slot in [e.from_slot, e.to_slot] {
                if let Some(b) = bisectors[slot] {
                    min_cos[slot] = min_cos[slot].min(dot(b, n));
                }
            }
        }
    }
    bisectors
        .iter()
        .zip(&min_cos)
        .map(|(b, &cos)| match b {
            Some(b) => scale(*b, SKIRT_PX / cos.max(1.0 / MAX_MITER_RATIO)),
            None => [0.0; 2],
        })
        .collect()
}

/// The unit normal of a boundary edge pointing away from its triangle in the current
/// deformation (so it follows flips and mirroring), or `None` when the edge or the triangle has
/// collapsed.
fn outward_normal(edge: &BoundaryEdge, layer_px: &[[f64; 2]]) -> Option<[f64; 2]> {
    let [a, b, c] = [edge.from, edge.to, edge.opposite].map(|v| layer_px[v as usize]);
    let along = sub(b, a);
    let length = dot(along, along).sqrt();
    if length < MIN_DIRECTION_PX {
        return None;
    }
    let normal = [along[1] / length, -along[0] / length];
    let inward_reach = dot(normal, sub(c, a));
    if (inward_reach * length).abs() <= DEGENERATE_AREA2_PX2 {
        return None;
    }
    Some(if inward_reach > 0.0 {
        scale(normal, -1.0)
    } else {
        normal
    })
}

fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn scale(a: [f64; 2], s: f64) -> [f64; 2] {
    [a[0] * s, a[1] * s]
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `a` scaled to length 1, or `None` if it is too short to have a direction.
fn unit(a: [f64; 2]) -> Option<[f64; 2]> {
    let length = dot(a, a).sqrt();
    (length >= MIN_DIRECTION_PX).then(|| scale(a, 1.0 / length))
}

fn mat_mul(a: Mat2, b: Mat2) -> Mat2 {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

fn mat_vec(m: Mat2, v: [f64; 2]) -> [f64; 2] {
    [
        m[0][0] * v[0] + m[0][1] * v[1],
        m[1][0] * v[0] + m[1][1] * v[1],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::point_in_ring;
    use crate::render::test_support::{
        canvas, colorful_image, colorful_texture, distance_to_ring, fan_mesh, grid_mesh, linspace,
    };
    use crate::render::{max_channel_diff_where, pixmap_from_rgba, psnr_rgba, rgba_from_pixmap};

    /// PSNR, in dB, above which a render counts as reproducing its texture.
    const REST_POSE_MIN_PSNR_DB: f64 = 45.0;
    /// Largest channel difference allowed inside the mesh at rest.
    const REST_POSE_MAX_DIFF: u8 = 2;

    fn alpha_at(p: &Pixmap, x: u32, y: u32) -> u8 {
        p.pixel(x, y).map_or(0, |c| c.alpha())
    }

    fn pixel_center(x: u32, y: u32) -> Point {
        Point::new(f64::from(x) + 0.5, f64::from(y) + 0.5)
    }

    /// Rotation by `degrees` and uniform `scale` about `center`, plus a smooth wobble so that
    /// the deformation is not affine.
    fn deform(p: Point, center: Point, degrees: f64, scale: f64, wobble_px: f64) -> Point {
        let (s, c) = degrees.to_radians().sin_cos();
        let d = p - center;
        Point::new(
            center.x + scale * (c * d.x - s * d.y) + wobble_px * (p.y / 9.0).sin(),
            center.y + scale * (s * d.x + c * d.y) + wobble_px * (p.x / 11.0).sin(),
        )
    }

    fn draw_rest_pose(uv: &[Point], triangles: &[[u32; 3]], texture: &Pixmap) -> Pixmap {
        let renderer = MeshRenderer::new(uv, triangles).expect("valid mesh");
        let mut out = canvas(texture.width(), texture.height());
        renderer.draw(&mut out, texture.as_ref(), uv, Transform::identity(), 1.0);
        out
    }

    #[test]
    fn rest_pose_grid_reproduces_texture() {
        let inside = |x: f64, y: f64| (8.0..56.0).contains(&x) && (8.0..56.0).contains(&y);
        let expected = colorful_image(64, 64, inside);
        let texture = pixmap_from_rgba(&expected).expect("non-empty");
        let (uv, triangles) = grid_mesh(&linspace(4.0, 60.0, 9), &linspace(4.0, 60.0, 9));

        let got = rgba_from_pixmap(&draw_rest_pose(&uv, &triangles, &texture));

        let psnr = psnr_rgba(&expected, &got);
        assert!(psnr >= REST_POSE_MIN_PSNR_DB, "PSNR {psnr} dB");
        let in_mesh = |x, y| (4..60).contains(&x) && (4..60).contains(&y);
        assert!(max_channel_diff_where(&expected, &got, in_mesh) <= REST_POSE_MAX_DIFF);
    }

    #[test]
    fn rest_pose_fan_of_thin_triangles_reproduces_texture() {
        let center = Point::new(32.0, 32.0);
        let expected = colorful_image(64, 64, |x, y| (Point::new(x, y) - center).norm() < 22.0);
        let texture = pixmap_from_rgba(&expected).expect("non-empty");
        let (uv, triangles) = fan_mesh(center, 28.0, 90);

        let got = rgba_from_pixmap(&draw_rest_pose(&uv, &triangles, &texture));

        let psnr = psnr_rgba(&expected, &got);
        assert!(psnr >= REST_POSE_MIN_PSNR_DB, "PSNR {psnr} dB");
        let in_mesh = |x, y| (pixel_center(x, y) - center).norm() < 27.0;
        assert!(max_channel_diff_where(&expected, &got, in_mesh) <= REST_POSE_MAX_DIFF);
    }

    #[test]
    fn view_transform_moves_the_part() {
        let expected = colorful_image(32, 32, |x, y| x > 4.0 && y > 4.0 && x < 28.0 && y < 28.0);
        let texture = pixmap_from_rgba(&expected).expect("non-empty");
        let (uv, triangles) = grid_mesh(&linspace(2.0, 30.0, 5), &linspace(2.0, 30.0, 5));
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let mut out = canvas(48, 48);
        let shift = Transform::from_translate(10.0, 5.0);

        renderer.draw(&mut out, texture.as_ref(), &uv, shift, 1.0);

        let got = rgba_from_pixmap(&out);
        let moved = image::imageops::crop_imm(&got, 10, 5, 32, 32).to_image();
        assert_eq!(max_channel_diff_where(&expected, &moved, |_, _| true), 0);
    }

    #[test]
    fn deformed_mesh_with_slivers_has_no_seams() {
        let texture = colorful_texture(128, 128, |_, _| true);
        // A grid with a few columns and rows only a hair apart: cells there split into
        // slivers down to 0.001 px wide.
        let mut xs = linspace(16.0, 112.0, 17);
        xs.extend([22.02, 46.001, 70.05, 94.003]);
        xs.sort_by(f64::total_cmp);
        let mut ys = linspace(16.0, 112.0, 17);
        ys.extend([40.01, 76.002]);
        ys.sort_by(f64::total_cmp);
        let (uv, triangles) = grid_mesh(&xs, &ys);
        let center = Point::new(64.0, 64.0);
        let positions: Vec<Point> = uv
            .iter()
            .map(|&p| deform(p, center, 7.0, 1.04, 1.5))
            .collect();
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let mut out = canvas(128, 128);

        renderer.draw(
            &mut out,
            texture.as_ref(),
            &positions,
            Transform::identity(),
            1.0,
        );

        let (nx, ny) = (xs.len(), ys.len());
        let perimeter: Vec<usize> = (0..nx)
            .chain((1..ny).map(|j| j * nx + nx - 1))
            .chain((0..nx - 1).rev().map(|i| (ny - 1) * nx + i))
            .chain((1..ny - 1).rev().map(|j| j * nx))
            .collect();
        let ring: Vec<Point> = perimeter.iter().map(|&v| positions[v]).collect();
        // A 3×3 neighbourhood reaches √2 px from the center; keep clear of the boundary's
        // antialiasing beyond that.
        let clearance = 2.5;
        let mut checked = 0;
        for y in 0..out.height() {
            for x in 0..out.width() {
                let c = pixel_center(x, y);
                if point_in_ring(c, &ring) && distance_to_ring(c, &ring) >= clearance {
                    assert_eq!(alpha_at(&out, x, y), 255, "seam at ({x}, {y})");
                    checked += 1;
                }
            }
        }
        assert!(checked > 8000, "only {checked} pixels checked");
    }

    /// Largest difference between a pixel's alpha and 255 × its exact coverage by the shape:
    /// tiny-skia antialiases with 4 × 4 supersampling (and coverage here is itself sampled).
    const AA_ALPHA_TOLERANCE: f64 = 40.0;
    /// Samples per axis for measuring how much of a pixel a polygon covers.
    const COVERAGE_SAMPLES: u32 = 16;

    /// The fraction of pixel (x, y) inside the polygon `ring`, by dense sampling.
    fn area_fraction_inside(x: u32, y: u32, ring: &[Point]) -> f64 {
        let n = COVERAGE_SAMPLES;
        let step = 1.0 / f64::from(n);
        let inside = (0..n * n)
            .filter(|k| {
                let sample = Point::new(
                    f64::from(x) + (f64::from(k % n) + 0.5) * step,
                    f64::from(y) + (f64::from(k / n) + 0.5) * step,
                );
                point_in_ring(sample, ring)
            })
            .count();
        inside as f64 / f64::from(n * n)
    }

    #[test]
    fn rotated_square_alpha_follows_its_area_coverage() {
        let texture = colorful_texture(64, 64, |_, _| true);
        let uv =
            [(16.0, 16.0), (48.0, 16.0), (48.0, 48.0), (16.0, 48.0)].map(|(x, y)| Point::new(x, y));
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let center = Point::new(32.0, 32.0);
        let positions = uv.map(|p| deform(p, center, 30.0, 1.0, 0.0));
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let mut out = canvas(64, 64);

        renderer.draw(
            &mut out,
            texture.as_ref(),
            &positions,
            Transform::identity(),
            1.0,
        );

        let mut partial = 0;
        for y in 0..64 {
            for x in 0..64 {
                let expected = 255.0 * area_fraction_inside(x, y, &positions);
                let alpha = alpha_at(&out, x, y);
                assert!(
                    (f64::from(alpha) - expected).abs() <= AA_ALPHA_TOLERANCE,
                    "alpha {alpha} at ({x}, {y}), coverage {expected:.0}"
                );
                if (1..255).contains(&alpha) {
                    partial += 1;
                }
            }
        }
        // The perimeter is 128 px long; most pixels along it are partly covered.
        assert!(partial > 100, "only {partial} partially covered pixels");
    }

    /// An 8×8 opaque texture, black left of x = 4 and white right of it.
    fn black_white_texture() -> Pixmap {
        let img = image::RgbaImage::from_fn(8, 8, |x, _| {
            let v = if x < 4 { 0 } else { 255 };
            image::Rgba([v, v, v, 255])
        });
        pixmap_from_rgba(&img).expect("non-empty")
    }

    fn red_at(p: &Pixmap, x: u32, y: u32) -> i32 {
        p.pixel(x, y).map_or(-1, |c| i32::from(c.red()))
    }

    #[test]
    fn magnified_texture_is_interpolated_bilinearly() {
        let texture = black_white_texture();
        let (uv, triangles) = grid_mesh(&linspace(0.0, 8.0, 3), &linspace(0.0, 8.0, 3));
        let positions: Vec<Point> = uv.iter().map(|p| Point::from(p.coords * 2.0)).collect();
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let mut out = canvas(16, 16);

        renderer.draw(
            &mut out,
            texture.as_ref(),
            &positions,
            Transform::identity(),
            1.0,
        );

        // Pixel 7's center maps to texture x = 3.75, a quarter of the way from the black texel
        // center (3.5) to the white one (4.5); pixel 8's to 4.25.
        let row: Vec<i32> = (0..16).map(|x| red_at(&out, x, 8)).collect();
        assert_eq!(row[6], 0, "{row:?}");
        assert!((row[7] - 64).abs() <= 2, "{row:?}");
        assert!((row[8] - 191).abs() <= 2, "{row:?}");
        assert_eq!(row[9], 255, "{row:?}");
        assert!(row.windows(2).all(|w| w[0] <= w[1]), "{row:?}");
    }

    #[test]
    fn subpixel_translation_is_interpolated_too() {
        let texture = black_white_texture();
        let (uv, triangles) = grid_mesh(&linspace(0.0, 8.0, 3), &linspace(0.0, 8.0, 3));
        let positions: Vec<Point> = uv
            .iter()
            .map(|p| p + nalgebra::Vector2::new(4.5, 0.0))
            .collect();
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let mut out = canvas(16, 8);

        renderer.draw(
            &mut out,
            texture.as_ref(),
            &positions,
            Transform::identity(),
            1.0,
        );

        // Pixel 8's center maps to texture x = 4.0, halfway between black and white.
        let row: Vec<i32> = (0..16).map(|x| red_at(&out, x, 4)).collect();
        assert_eq!(row[7], 0, "{row:?}");
        assert!((row[8] - 128).abs() <= 1, "{row:?}");
        assert_eq!(row[9], 255, "{row:?}");
    }

    #[test]
    fn translucent_texture_blends_source_over_at_opacity() {
        let straight = image::RgbaImage::from_pixel(16, 16, image::Rgba([200, 0, 0, 128]));
        let texture = pixmap_from_rgba(&straight).expect("non-empty");
        let (uv, triangles) = grid_mesh(&linspace(0.0, 16.0, 3), &linspace(0.0, 16.0, 3));
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let mut out = canvas(16, 16);
        out.fill(tiny_skia::Color::from_rgba8(100, 100, 100, 255));
        let opacity = 0.5;

        renderer.draw(
            &mut out,
            texture.as_ref(),
            &uv,
            Transform::identity(),
            opacity,
        );

        let src_alpha = 128.0 / 255.0 * f64::from(opacity);
        let expected_red = 200.0 * src_alpha + 100.0 * (1.0 - src_alpha);
        let expected_green = 100.0 * (1.0 - src_alpha);
        let px = out.pixel(8, 8).expect("inside the canvas");
        assert!((f64::from(px.red()) - expected_red).abs() <= 1.0, "{px:?}");
        assert!(
            (f64::from(px.green()) - expected_green).abs() <= 1.0,
            "{px:?}"
        );
        assert_eq!(px.alpha(), 255);
    }

    #[test]
    fn bad_meshes_are_rejected() {
        let uv = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(0.0, 1.0),
        ];
        assert!(matches!(
            MeshRenderer::new(&uv, &[[0, 1, 3]]),
            Err(RenderError::TriangleIndexOutOfRange {
                triangle: 0,
                index: 3,
                vertex_count: 3
            })
        ));
        assert!(matches!(
            MeshRenderer::new(&uv, &[]),
            Err(RenderError::EmptyMesh { .. })
        ));
        assert!(matches!(
            MeshRenderer::new(&[], &[[0, 0, 0]]),
            Err(RenderError::EmptyMesh { .. })
        ));
        let nan = [uv[0], Point::new(f64::NAN, 0.0), uv[2]];
        assert!(matches!(
            MeshRenderer::new(&nan, &[[0, 1, 2]]),
            Err(RenderError::NonFiniteCoordinate { vertex: 1 })
        ));
    }

    #[test]
    fn degenerate_triangles_are_skipped_without_panicking() {
        let texture = colorful_texture(32, 32, |_, _| true);
        let (mut uv, mut triangles) = grid_mesh(&linspace(4.0, 28.0, 3), &linspace(4.0, 28.0, 3));
        // Collinear in texture space, and one with a repeated vertex.
        uv.push(Point::new(40.0, 4.0));
        triangles.push([0, 1, 9]);
        triangles.push([4, 4, 5]);
        let renderer =
            MeshRenderer::new(&uv, &triangles).expect("degenerate triangles are allowed");
        // Collapse the first cell's triangles to zero area in output space.
        let mut positions = uv.clone();
        positions[3] = Point::new(4.0, 4.0);
        positions[4] = Point::new(16.0, 4.0);
        let mut out = canvas(32, 32);

        renderer.draw(
            &mut out,
            texture.as_ref(),
            &positions,
            Transform::identity(),
            1.0,
        );

        assert_eq!(
            alpha_at(&out, 22, 22),
            255,
            "the intact triangles are drawn"
        );
    }

    #[test]
    fn all_degenerate_or_bad_positions_draw_nothing() {
        let texture = colorful_texture(16, 16, |_, _| true);
        let good = [
            Point::new(2.0, 2.0),
            Point::new(14.0, 2.0),
            Point::new(2.0, 14.0),
        ];
        let tri = MeshRenderer::new(&good, &[[0, 1, 2]]).expect("valid mesh");
        let collinear = [good[0], Point::new(8.0, 2.0), good[1]];
        let flat = MeshRenderer::new(&collinear, &[[0, 1, 2]]).expect("allowed");
        let mut out = canvas(16, 16);
        let id = Transform::identity();

        flat.draw(&mut out, texture.as_ref(), &collinear, id, 1.0);
        tri.draw(&mut out, texture.as_ref(), &good[..2], id, 1.0);
        tri.draw(
            &mut out,
            texture.as_ref(),
            &[good[0], good[1], Point::new(f64::NAN, 1.0)],
            id,
            1.0,
        );
        tri.draw(&mut out, texture.as_ref(), &good, id, f32::NAN);
        tri.draw(&mut out, texture.as_ref(), &good, id, 0.0);
        tri.draw(
            &mut out,
            texture.as_ref(),
            &good,
            Transform::from_scale(0.0, 0.0),
            1.0,
        );
        tri.draw(
            &mut out,
            texture.as_ref(),
            &good,
            Transform::from_translate(-100.0, 0.0),
            1.0,
        );
        assert!(out.data().iter().all(|&b| b == 0));

        // Absurd zoom: must not panic, whatever it draws.
        tri.draw(
            &mut out,
            texture.as_ref(),
            &good,
            Transform::from_scale(1e30, 1e30),
            1.0,
        );
    }

    #[test]
    fn flipped_triangle_still_draws() {
        let texture = colorful_texture(32, 32, |_, _| true);
        let uv = [
            Point::new(4.0, 4.0),
            Point::new(28.0, 4.0),
            Point::new(4.0, 28.0),
        ];
        let renderer = MeshRenderer::new(&uv, &[[0, 1, 2]]).expect("valid mesh");
        // Mirrored left-right: the triangle's orientation reverses.
        let positions = uv.map(|p| Point::new(32.0 - p.x, p.y));
        let mut out = canvas(32, 32);

        renderer.draw(
            &mut out,
            texture.as_ref(),
            &positions,
            Transform::identity(),
            1.0,
        );

        assert_eq!(alpha_at(&out, 22, 10), 255);
        assert_eq!(alpha_at(&out, 6, 10), 0);
        // The skirt and mask follow the flip: the mirrored hypotenuse is antialiased.
        let partial = (0..32)
            .filter(|&x| (1..255).contains(&alpha_at(&out, x, 16)))
            .count();
        assert!(partial >= 1);
    }

    /// Prints timing only; asserts nothing. Run with
    /// `cargo test --release --lib render -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn timing_512px_part_with_1000_triangles() {
        let center = Point::new(256.0, 256.0);
        let texture = colorful_texture(512, 512, |x, y| (Point::new(x, y) - center).norm() < 240.0);
        let (uv, triangles) = grid_mesh(&linspace(8.0, 504.0, 23), &linspace(8.0, 504.0, 23));
        let positions: Vec<Point> = uv
            .iter()
            .map(|&p| deform(p, center, 4.0, 0.97, 3.0))
            .collect();
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let mut out = canvas(512, 512);
        let runs = 20;
        let mut times = Vec::with_capacity(runs);
        for _ in 0..runs {
            let start = std::time::Instant::now();
            renderer.draw(
                &mut out,
                texture.as_ref(),
                &positions,
                Transform::identity(),
                1.0,
            );
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        let drawn = out.pixels().iter().filter(|p| p.alpha() > 0).count();
        println!(
            "draw 512×512 part, {} triangles, {drawn} px drawn: median {:.2} ms, min {:.2} ms \
             ({:.1} ns/px at the minimum)",
            triangles.len(),
            times[runs / 2],
            times[0],
            times[0] * 1e6 / drawn as f64
        );
    }
}
