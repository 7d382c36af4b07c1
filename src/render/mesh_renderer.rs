//! One part's textured, deformed mesh → the canvas (see the module doc of [`super`] for the
//! approach).
//!
//! Spaces: texture pixels (the mesh's rest positions), world pixels (the deformed positions),
//! canvas pixels (world through `canvas_from_world`) and region pixels (canvas pixels relative
//! to the corner of the part's clipped bounding box, where its coverage lives).

use tiny_skia::{Pixmap, Transform};

use crate::geom::Point;
use nalgebra::Matrix2;

use super::blend::{source_over, tinted, Tint, TintFactors};
use super::coverage::CoverageMask;
use super::raster::{floor_i64, for_each_run, to_fixed, FixedPoint, PixelRect, MAX_COORD_PX};
use super::skirt::skirt_offsets;
use super::texture::{sampler_coord, sampler_step, Texture};
use super::topology::{TexturedTriangle, Topology, DEGENERATE_AREA2_PX2};
use super::RenderError;

/// Whole pixels kept around the part's bounding box in its coverage region, so that rounding can
/// never push coverage off the region.
const REGION_MARGIN_PX: f64 = 1.0;

/// The per-mesh state rendering needs that does not change between frames.
pub struct MeshRenderer {
    topology: Topology,
}

/// Buffers one draw needs, kept between parts and frames to save allocations.
#[derive(Default)]
pub(super) struct DrawScratch {
    coverage: CoverageMask,
    points: Vec<Point>,
    fixed: Vec<FixedPoint>,
    maps: Vec<Option<TextureMap>>,
}

impl MeshRenderer {
    /// Precomputes what drawing needs from the mesh's connectivity and rest positions
    /// (`uv_px`: texture pixels): the texture-space edges of each triangle, the boundary edges
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

    /// Draws the mesh textured with `texture` (sampled in texture pixels) source-over onto
    /// `canvas`, with its vertices at `positions_px` (world pixels, one per vertex, in the order
    /// of `uv_px`) mapped through `canvas_from_world`, its colours multiplied by `tint`.
    ///
    /// Draws nothing when the positions do not match the mesh (wrong count, NaN or infinite, or
    /// beyond ±2²⁰ canvas px), when the tint's alpha is not positive, or when the part lies off
    /// the canvas. Triangles flipped by the deformation are drawn; triangles collapsed to (near)
    /// zero area are skipped. Where triangles overlap (a fold), the one listed last shows.
    pub fn draw(
        &self,
        canvas: &mut Pixmap,
        texture: &Texture,
        positions_px: &[Point],
        canvas_from_world: Transform,
        tint: Tint,
    ) {
        let mut scratch = DrawScratch::default();
        self.draw_with(
            canvas,
            texture,
            positions_px,
            canvas_from_world,
            tint,
            &mut scratch,
        );
    }

    /// [`MeshRenderer::draw`] with caller-kept buffers.
    pub(super) fn draw_with(
        &self,
        canvas: &mut Pixmap,
        texture: &Texture,
        positions_px: &[Point],
        canvas_from_world: Transform,
        tint: Tint,
        scratch: &mut DrawScratch,
    ) {
        let tint = TintFactors::new(tint);
        if tint.is_invisible() || self.topology.triangles.is_empty() {
            return;
        }
        if !canvas_positions(
            positions_px,
            self.topology.vertex_count,
            canvas_from_world,
            &mut scratch.points,
        ) {
            return;
        }
        let points = &scratch.points;
        let Some(region) = region_around(points, canvas.width(), canvas.height()) else {
            return;
        };
        self.cover(points, region, &mut scratch.coverage);

        scratch.fixed.clear();
        scratch
            .fixed
            .extend(points.iter().filter_map(|&p| to_fixed(p)));
        scratch.maps.clear();
        scratch.maps.extend(
            self.topology
                .triangles
                .iter()
                .map(|t| TextureMap::new(t, points)),
        );
        let canvas_width = canvas.width() as usize;
        let mut target = Target {
            canvas: canvas.data_mut(),
            canvas_width,
            region,
            coverage: scratch.coverage.coverage_mut(),
            texture,
            tint,
        };
        // Each pixel is drawn once, by the first shape that owns its center: the target clears
        // its coverage on drawing. Last-listed triangles go first so that they show in a fold,
        // and triangles before skirts so that a skirt reaching over the mesh (at a concave
        // corner) never hides the mesh's own texture.
        for (triangle, map) in self.topology.triangles.iter().zip(&scratch.maps).rev() {
            if let Some(map) = map {
                let corners = triangle.vertices.map(|v| scratch.fixed[v as usize]);
                target.fill_triangle(corners, map);
            }
        }
        let offsets = skirt_offsets(&self.topology, points);
        for edge in &self.topology.boundary_edges {
            let Some(map) = &scratch.maps[edge.triangle] else {
                continue;
            };
            let (a, b) = (points[edge.from as usize], points[edge.to as usize]);
            let outward = (
                to_fixed(a + offsets[edge.from_slot]),
                to_fixed(b + offsets[edge.to_slot]),
            );
            let (Some(a_out), Some(b_out)) = outward else {
                continue;
            };
            let (a, b) = (
                scratch.fixed[edge.from as usize],
                scratch.fixed[edge.to as usize],
            );
            for corners in [[a, b, b_out], [a, b_out, a_out]] {
                target.fill_triangle(corners, map);
            }
        }
    }

    /// The exact area coverage of the part's boundary loops over `region`.
    fn cover(&self, points: &[Point], region: PixelRect, coverage: &mut CoverageMask) {
        let (width, height) = (
            (region.x1 - region.x0) as usize,
            (region.y1 - region.y0) as usize,
        );
        coverage.start(width, height);
        if self.topology.loops.is_empty() {
            // No boundary (every edge shared twice): nothing to antialias against.
            coverage.cover_everything();
            return;
        }
        let origin = nalgebra::Vector2::new(region.x0 as f64, region.y0 as f64);
        let local = |v: u32| points[v as usize] - origin;
        for ring in &self.topology.loops {
            for (k, &v) in ring.iter().enumerate() {
                let next = ring[(k + 1) % ring.len()];
                coverage.add_edge(local(v), local(next));
            }
        }
        coverage.finish();
    }
}

/// Fills `points` with the world positions mapped to canvas pixels; `false` unless there is
/// exactly one position per vertex and every mapped one is finite and within
/// [`MAX_COORD_PX`].
fn canvas_positions(
    positions_px: &[Point],
    vertex_count: usize,
    canvas_from_world: Transform,
    points: &mut Vec<Point>,
) -> bool {
    if positions_px.len() != vertex_count {
        return false;
    }
    let t = canvas_from_world;
    let [sx, kx, tx, ky, sy, ty] = [t.sx, t.kx, t.tx, t.ky, t.sy, t.ty].map(f64::from);
    points.clear();
    points.extend(
        positions_px
            .iter()
            .map(|p| Point::new(sx * p.x + kx * p.y + tx, ky * p.x + sy * p.y + ty)),
    );
    // The comparison is false for NaN.
    let usable = |v: f64| v.abs() <= MAX_COORD_PX;
    points.iter().all(|p| usable(p.x) && usable(p.y))
}

/// The canvas pixels the part can cover: its bounding box with a margin, clipped to the canvas;
/// `None` if that misses the canvas.
fn region_around(points: &[Point], canvas_width: u32, canvas_height: u32) -> Option<PixelRect> {
    let (min, max) = points.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(min, max), p| {
            (
                [min[0].min(p.x), min[1].min(p.y)],
                [max[0].max(p.x), max[1].max(p.y)],
            )
        },
    );
    let (x0, x1) = clipped_span(min[0], max[0], canvas_width)?;
    let (y0, y1) = clipped_span(min[1], max[1], canvas_height)?;
    Some(PixelRect { x0, y0, x1, y1 })
}

/// The whole pixels touched by [lo, hi] plus the margin, clipped to 0..limit, as a half-open
/// range; `None` if empty.
fn clipped_span(lo: f64, hi: f64, limit: u32) -> Option<(i64, i64)> {
    let limit = f64::from(limit);
    let start = (lo.floor() - REGION_MARGIN_PX).clamp(0.0, limit);
    let end = (hi.ceil() + REGION_MARGIN_PX).clamp(0.0, limit);
    (end > start).then_some((start as i64, end as i64))
}

/// A triangle's affine map from canvas pixels to sampler coordinates, in fixed point so that
/// each run of pixels starts with a few integer operations.
struct TextureMap {
    /// A pixel near the triangle (the one holding its first corner) and the sampler coordinates
    /// of its center. Steps are rounded to 1/2¹⁶ texel, so measuring from nearby keeps the
    /// accumulated error far below the 1/256 texel the sampler resolves.
    reference_px: [i64; 2],
    at_reference: [i64; 2],
    /// Sampler steps of (u, v) per pixel to the right and per pixel down.
    step_x: [i64; 2],
    step_y: [i64; 2],
}

impl TextureMap {
    /// The map taking the triangle's corners at `points` (canvas px) back onto its rest corners,
    /// or `None` when the triangle has (near) zero area on the canvas.
    fn new(triangle: &TexturedTriangle, points: &[Point]) -> Option<Self> {
        let [p0, p1, p2] = triangle.vertices.map(|v| points[v as usize]);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let det = e1.x * e2.y - e1.y * e2.x;
        if det.abs() <= DEGENERATE_AREA2_PX2 {
            return None;
        }
        let inverse_det = 1.0 / det;
        let canvas_edges_inverse = Matrix2::new(
            e2.y * inverse_det,
            -e2.x * inverse_det,
            -e1.y * inverse_det,
            e1.x * inverse_det,
        );
        let linear = triangle.uv_edges * canvas_edges_inverse;
        let reference_px = [floor_i64(p0.x), floor_i64(p0.y)];
        let center = Point::new(reference_px[0] as f64 + 0.5, reference_px[1] as f64 + 0.5);
        let uv = triangle.uv_origin + linear * (center - p0);
        Some(TextureMap {
            reference_px,
            at_reference: [sampler_coord(uv.x), sampler_coord(uv.y)],
            step_x: [sampler_step(linear[(0, 0)]), sampler_step(linear[(1, 0)])],
            step_y: [sampler_step(linear[(0, 1)]), sampler_step(linear[(1, 1)])],
        })
    }

    /// The sampler coordinates of the center of canvas pixel (`x`, `y`).
    fn at_pixel(&self, x: i64, y: i64) -> [i64; 2] {
        let (dx, dy) = (x - self.reference_px[0], y - self.reference_px[1]);
        [0, 1].map(|k| self.at_reference[k] + dx * self.step_x[k] + dy * self.step_y[k])
    }
}

/// Where and how runs of pixels are drawn for one part.
struct Target<'a> {
    /// Premultiplied RGBA8, row-major.
    canvas: &'a mut [u8],
    canvas_width: usize,
    region: PixelRect,
    /// The region's coverage; a drawn pixel's is set to 0 so nothing draws it again.
    coverage: &'a mut [u8],
    texture: &'a Texture,
    tint: TintFactors,
}

impl Target<'_> {
    /// Draws the pixels the triangle `corners` owns that are not drawn yet, each with the
    /// texture sampled at its center through `map`.
    fn fill_triangle(&mut self, corners: [FixedPoint; 3], map: &TextureMap) {
        for_each_run(corners, self.region, |row, start, end| {
            self.fill_run(row, start, end, map)
        });
    }

    /// Draws the pixels `start..end` of `row` (canvas pixels, inside the region) not drawn yet.
    #[inline(always)]
    fn fill_run(&mut self, row: i64, start: i64, end: i64, map: &TextureMap) {
        let region_width = (self.region.x1 - self.region.x0) as usize;
        let mask_row = (row - self.region.y0) as usize * region_width;
        let mask = &mut self.coverage[mask_row + (start - self.region.x0) as usize
            ..mask_row + (end - self.region.x0) as usize];
        let canvas_row = row as usize * self.canvas_width;
        let pixels =
            &mut self.canvas[(canvas_row + start as usize) * 4..(canvas_row + end as usize) * 4];
        let at = map.at_pixel(start, row);
        if self.texture.holds_run(at, map.step_x, end - start) {
            shade_run::<false>(mask, pixels, self.texture, self.tint, at, map.step_x);
        } else {
            shade_run::<true>(mask, pixels, self.texture, self.tint, at, map.step_x);
        }
    }
}

/// Samples, scales and blends each pixel of a run whose coverage is not zero yet, then clears
/// its coverage; `CLAMP` as for [`Texture::sample`].
#[inline(always)]
fn shade_run<const CLAMP: bool>(
    coverage: &mut [u8],
    pixels: &mut [u8],
    texture: &Texture,
    tint: TintFactors,
    [mut u, mut v]: [i64; 2],
    [du, dv]: [i64; 2],
) {
    let untinted = tint.is_identity();
    for (cover, px) in coverage.iter_mut().zip(pixels.chunks_exact_mut(4)) {
        let amount = *cover;
        if amount != 0 {
            *cover = 0;
            let src = texture.sample::<CLAMP>(u, v);
            if src != 0 {
                let src = if untinted && amount == u8::MAX {
                    src
                } else {
                    tinted(src, u32::from(amount), tint)
                };
                if let Ok(px) = <&mut [u8; 4]>::try_from(px) {
                    let out = if src >> 24 == 0xFF {
                        src
                    } else {
                        source_over(u32::from_le_bytes(*px), src)
                    };
                    *px = out.to_le_bytes();
                }
            }
        }
        u += du;
        v += dv;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::point_in_ring;
    use crate::render::test_support::{
        canvas, colorful_image, colorful_texture, distance_to_ring, fan_mesh, grid_mesh, linspace,
    };
    use crate::render::{max_channel_diff_where, psnr_rgba, rgba_from_pixmap};

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

    fn draw_rest_pose(uv: &[Point], triangles: &[[u32; 3]], texture: &Texture) -> Pixmap {
        let renderer = MeshRenderer::new(uv, triangles).expect("valid mesh");
        let mut out = canvas(texture.width(), texture.height());
        renderer.draw(&mut out, texture, uv, Transform::identity(), Tint::WHITE);
        out
    }

    #[test]
    fn rest_pose_grid_reproduces_texture() {
        let inside = |x: f64, y: f64| (8.0..56.0).contains(&x) && (8.0..56.0).contains(&y);
        let expected = colorful_image(64, 64, inside);
        let texture = Texture::from_rgba(&expected).expect("non-empty");
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
        let texture = Texture::from_rgba(&expected).expect("non-empty");
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
        let texture = Texture::from_rgba(&expected).expect("non-empty");
        let (uv, triangles) = grid_mesh(&linspace(2.0, 30.0, 5), &linspace(2.0, 30.0, 5));
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let mut out = canvas(48, 48);
        let shift = Transform::from_translate(10.0, 5.0);

        renderer.draw(&mut out, &texture, &uv, shift, Tint::WHITE);

        let got = rgba_from_pixmap(&out);
        let moved = image::imageops::crop_imm(&got, 10, 5, 32, 32).to_image();
        assert_eq!(max_channel_diff_where(&expected, &moved, |_, _| true), 0);
    }

    #[test]
    fn deformed_mesh_with_slivers_has_no_seams() {
        for zoom in [1.0, 4.0] {
            slivers_have_no_seams_at(zoom);
        }
    }

    /// The sliver mesh drawn through a view scaling by `zoom`: every pixel well inside is
    /// opaque.
    fn slivers_have_no_seams_at(zoom: f64) {
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
        let side = (128.0 * zoom) as u32;
        let mut out = canvas(side, side);
        let view = Transform::from_scale(zoom as f32, zoom as f32);

        renderer.draw(&mut out, &texture, &positions, view, Tint::WHITE);

        let positions: Vec<Point> = positions
            .iter()
            .map(|p| Point::from(p.coords * zoom))
            .collect();
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
                    assert_eq!(alpha_at(&out, x, y), 255, "seam at ({x}, {y}), zoom {zoom}");
                    checked += 1;
                }
            }
        }
        let expected = 8000.0 * zoom * zoom;
        assert!(checked as f64 > expected, "only {checked} pixels checked");
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
            &texture,
            &positions,
            Transform::identity(),
            Tint::WHITE,
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
    fn black_white_texture() -> Texture {
        let img = image::RgbaImage::from_fn(8, 8, |x, _| {
            let v = if x < 4 { 0 } else { 255 };
            image::Rgba([v, v, v, 255])
        });
        Texture::from_rgba(&img).expect("non-empty")
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
            &texture,
            &positions,
            Transform::identity(),
            Tint::WHITE,
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
            &texture,
            &positions,
            Transform::identity(),
            Tint::WHITE,
        );

        // Pixel 8's center maps to texture x = 4.0, halfway between black and white.
        let row: Vec<i32> = (0..16).map(|x| red_at(&out, x, 4)).collect();
        assert_eq!(row[7], 0, "{row:?}");
        assert!((row[8] - 128).abs() <= 1, "{row:?}");
        assert_eq!(row[9], 255, "{row:?}");
    }

    #[test]
    fn a_part_moved_by_a_fraction_of_a_pixel_moves_by_that_fraction() {
        let texture = black_white_texture();
        let (uv, triangles) = grid_mesh(&linspace(0.0, 8.0, 3), &linspace(0.0, 8.0, 3));
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let red_row = |shift_px: f64| {
            let moved: Vec<Point> = uv
                .iter()
                .map(|p| p + nalgebra::Vector2::new(shift_px, 0.0))
                .collect();
            let mut out = canvas(12, 8);
            renderer.draw(
                &mut out,
                &texture,
                &moved,
                Transform::identity(),
                Tint::WHITE,
            );
            (0..12).map(|x| red_at(&out, x, 4)).collect::<Vec<i32>>()
        };
        // Unmoved, pixel 4 is the first white texel. Moved right by d, its center samples
        // texture x = 4.5 − d, a fraction 1 − d of the way from the black texel center (3.5) to
        // the white one (4.5).
        assert_eq!(red_row(0.0)[4], 255);
        for shift_px in [0.1, 0.3, 0.6] {
            let row = red_row(shift_px);
            let expected = 255.0 * (1.0 - shift_px);
            assert!(
                (f64::from(row[4]) - expected).abs() <= 2.0,
                "moved {shift_px} px: {row:?}"
            );
            assert_eq!(row[3], 0, "moved {shift_px} px: {row:?}");
        }
    }

    #[test]
    fn translucent_texture_blends_source_over_at_opacity() {
        let straight = image::RgbaImage::from_pixel(16, 16, image::Rgba([200, 0, 0, 128]));
        let texture = Texture::from_rgba(&straight).expect("non-empty");
        let (uv, triangles) = grid_mesh(&linspace(0.0, 16.0, 3), &linspace(0.0, 16.0, 3));
        let renderer = MeshRenderer::new(&uv, &triangles).expect("valid mesh");
        let mut out = canvas(16, 16);
        out.fill(tiny_skia::Color::from_rgba8(100, 100, 100, 255));
        let opacity = 0.5;

        renderer.draw(
            &mut out,
            &texture,
            &uv,
            Transform::identity(),
            Tint::opacity(opacity),
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
            &texture,
            &positions,
            Transform::identity(),
            Tint::WHITE,
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

        flat.draw(&mut out, &texture, &collinear, id, Tint::WHITE);
        tri.draw(&mut out, &texture, &good[..2], id, Tint::WHITE);
        tri.draw(
            &mut out,
            &texture,
            &[good[0], good[1], Point::new(f64::NAN, 1.0)],
            id,
            Tint::WHITE,
        );
        tri.draw(&mut out, &texture, &good, id, Tint::opacity(f32::NAN));
        tri.draw(&mut out, &texture, &good, id, Tint::opacity(0.0));
        tri.draw(
            &mut out,
            &texture,
            &good,
            Transform::from_scale(0.0, 0.0),
            Tint::WHITE,
        );
        tri.draw(
            &mut out,
            &texture,
            &good,
            Transform::from_translate(-100.0, 0.0),
            Tint::WHITE,
        );
        assert!(out.data().iter().all(|&b| b == 0));

        // Absurd zoom: must not panic, whatever it draws.
        tri.draw(
            &mut out,
            &texture,
            &good,
            Transform::from_scale(1e30, 1e30),
            Tint::WHITE,
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
            &texture,
            &positions,
            Transform::identity(),
            Tint::WHITE,
        );

        assert_eq!(alpha_at(&out, 22, 10), 255);
        assert_eq!(alpha_at(&out, 6, 10), 0);
        // The skirt and mask follow the flip: the mirrored hypotenuse is antialiased.
        let partial = (0..32)
            .filter(|&x| (1..255).contains(&alpha_at(&out, x, 16)))
            .count();
        assert!(partial >= 1);
    }
}
