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
//!
//! What comes out: rings are simple and mutually disjoint, with at least 3 points and no
//! repeated consecutive points, each within `simplify_tolerance_px` of the traced contour.
//! Every ring vertex lies within `padding_px + 1` px of the center of a pixel with alpha ≥
//! `alpha_threshold`. The center of every such pixel (unless its region was dropped as a speck)
//! lies inside the outlines (even-odd over outer rings and holes), at least
//! `padding_px − simplify_tolerance_px − 1` px from every ring whenever that is ≥ 0; with less
//! padding it lies inside the traced contour, but simplification may cut it off. Outlines come
//! in raster order (top to bottom, then left to right) of the first point of their outer ring,
//! which is where the ring starts; holes likewise.

use crate::geom::{ring_signed_area, Point};
use serde::{Deserialize, Serialize};

mod dilate;
mod march;
mod simplify;

/// Largest accepted `padding_px`.
pub const MAX_PADDING_PX: f64 = 256.0;

/// How alpha becomes outlines. Defaults work on ordinary antialiased sprites.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct TraceOptions {
    /// A pixel is opaque when its alpha is at least this (1–255; 0 would make every pixel
    /// opaque). Default 1: every visible pixel, soft shadows and glows included, lies inside
    /// the mesh, so the rest pose draws the sprite back whole.
    pub alpha_threshold: u8,
    /// Outward padding in pixels, so the antialiased fringe lies inside the outline: the alpha is
    /// dilated by the pixel disk of this radius. At most [`MAX_PADDING_PX`]; the cost grows
    /// linearly with it. Default 2.
    pub padding_px: f64,
    /// Components and holes smaller than this area (px²) are dropped. Default 8.
    pub min_area_px2: f64,
    /// Largest distance (px) between a simplified ring and the traced one. Default 0.5.
    pub simplify_tolerance_px: f64,
}

impl Default for TraceOptions {
    fn default() -> Self {
        TraceOptions {
            alpha_threshold: 1,
            padding_px: 2.0,
            min_area_px2: 8.0,
            simplify_tolerance_px: 0.5,
        }
    }
}

impl TraceOptions {
    /// Few outline points, for meshes that game runtimes draw: a wider padding so that the
    /// coarser simplification (2 px) still keeps the antialiased fringe inside.
    pub fn coarse() -> Self {
        TraceOptions {
            padding_px: 3.0,
            simplify_tolerance_px: 2.0,
            ..TraceOptions::default()
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

/// `outlines` moved by a whole number of pixels (`offset_px`, y down): the outlines of an
/// image traced in its own pixels, placed where the image lies on a canvas.
pub fn translated(mut outlines: Vec<Outline>, offset_px: [i32; 2]) -> Vec<Outline> {
    if offset_px == [0, 0] {
        return outlines;
    }
    let shift = crate::geom::Vec2::new(f64::from(offset_px[0]), f64::from(offset_px[1]));
    for outline in &mut outlines {
        for p in outline
            .outer
            .iter_mut()
            .chain(outline.holes.iter_mut().flatten())
        {
            *p += shift;
        }
    }
    outlines
}

/// What the caller got wrong.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TraceError {
    #[error("the image has no pixel with alpha at or above {threshold}")]
    NoOpaquePixels { threshold: u8 },
    /// An option out of range: the field as files write it, and the rule with the value.
    #[error("invalid trace option: {field} {rule}")]
    InvalidOption { field: &'static str, rule: String },
}

/// Traces the opaque regions of `image`.
///
/// Returns one outline per connected opaque region (after padding) of at least
/// `min_area_px2`; the list is empty when every region is smaller than that.
pub fn trace(image: &image::RgbaImage, options: &TraceOptions) -> Result<Vec<Outline>, TraceError> {
    check_options(options)?;
    let threshold = options.alpha_threshold;
    if !image
        .pixels()
        .any(|px| px[dilate::ALPHA_CHANNEL] >= threshold)
    {
        return Err(TraceError::NoOpaquePixels { threshold });
    }
    let grid = dilate::dilate_alpha(image, options.padding_px);
    let rings = march::trace_rings(&grid, threshold);
    // The grid is by far the largest allocation; don't hold it through simplification.
    drop(grid);
    let (rings, owners) = drop_specks(rings, options.min_area_px2);
    let simplified = simplify::simplify_rings(&rings, options.simplify_tolerance_px);
    Ok(assemble(simplified, &owners))
}

/// Checks `options`: each out of range is refused naming the field as files write it
/// (`padding_px`; the command line maps it to its flag) and the rule with the value.
pub fn check_options(options: &TraceOptions) -> Result<(), TraceError> {
    if options.alpha_threshold == 0 {
        return Err(TraceError::InvalidOption {
            field: "alpha_threshold",
            rule: "must be at least 1 (at 0 every pixel, transparent ones included, would \
                   count as opaque)"
                .into(),
        });
    }
    check_non_negative("padding_px", options.padding_px)?;
    if options.padding_px > MAX_PADDING_PX {
        return Err(TraceError::InvalidOption {
            field: "padding_px",
            rule: format!(
                "must be at most {MAX_PADDING_PX}, not {}",
                crate::shown::Shown(options.padding_px)
            ),
        });
    }
    check_non_negative("min_area_px2", options.min_area_px2)?;
    check_non_negative("simplify_tolerance_px", options.simplify_tolerance_px)
}

fn check_non_negative(field: &'static str, value: f64) -> Result<(), TraceError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(TraceError::InvalidOption {
            field,
            rule: format!(
                "must be a number at least 0, not {}",
                crate::shown::Shown(value)
            ),
        })
    }
}

/// Which outline a kept ring belongs to.
enum Owner {
    /// The outer ring of a new outline (outlines are numbered in ring order).
    Outer,
    /// A hole of the outline whose outer ring is the kept ring with this index.
    HoleOf(usize),
}

/// Drops rings smaller than `min_area` px², with the holes of dropped outer rings; returns the
/// remaining rings, in order, and what each is.
fn drop_specks(rings: Vec<march::Ring>, min_area: f64) -> (Vec<Vec<Point>>, Vec<Owner>) {
    // Kept index of each traced ring, if kept. Containers come before what they contain.
    let mut kept_index: Vec<Option<usize>> = Vec::with_capacity(rings.len());
    let mut kept = Vec::new();
    let mut owners = Vec::new();
    for ring in rings {
        let large_enough = ring_signed_area(&ring.points).abs() >= min_area;
        let owner = match (ring.is_hole, ring.container) {
            (false, _) => Some(Owner::Outer),
            (true, Some(c)) => kept_index[c].map(Owner::HoleOf),
            (true, None) => None,
        };
        match owner {
            Some(owner) if large_enough => {
                kept_index.push(Some(kept.len()));
                kept.push(ring.points);
                owners.push(owner);
            }
            _ => kept_index.push(None),
        }
    }
    (kept, owners)
}

fn assemble(rings: Vec<Vec<Point>>, owners: &[Owner]) -> Vec<Outline> {
    let mut outlines: Vec<Outline> = Vec::new();
    // Outline number of each kept outer ring.
    let mut outline_of = vec![usize::MAX; rings.len()];
    for (i, (ring, owner)) in rings.into_iter().zip(owners).enumerate() {
        match *owner {
            Owner::Outer => {
                outline_of[i] = outlines.len();
                outlines.push(Outline {
                    outer: ring,
                    holes: Vec::new(),
                });
            }
            Owner::HoleOf(outer) => outlines[outline_of[outer]].holes.push(ring),
        }
    }
    outlines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{point_segment_distance, segments_touch, triangle_area2 as orient};

    /// The defaults with the threshold at mid alpha, which the exact geometric expectations
    /// below are computed for.
    fn mid_threshold() -> TraceOptions {
        TraceOptions {
            alpha_threshold: 128,
            ..TraceOptions::default()
        }
    }
    use crate::geom::point_in_ring;
    use image::RgbaImage;

    /// Subsamples per pixel side when painting antialiased shapes.
    const SUPERSAMPLE: u32 = 16;

    /// Paints the region `inside` into the alpha of `image` (max with what is there), with
    /// alpha proportional to pixel coverage.
    fn paint(image: &mut RgbaImage, inside: impl Fn(f64, f64) -> bool) {
        let n = SUPERSAMPLE;
        for (x, y, px) in image.enumerate_pixels_mut() {
            let mut hits = 0;
            for sy in 0..n {
                for sx in 0..n {
                    let fx = x as f64 + (sx as f64 + 0.5) / n as f64;
                    let fy = y as f64 + (sy as f64 + 0.5) / n as f64;
                    hits += u32::from(inside(fx, fy));
                }
            }
            let alpha = (255.0 * hits as f64 / (n * n) as f64).round() as u8;
            px[3] = px[3].max(alpha);
        }
    }

    fn disk(cx: f64, cy: f64, r: f64) -> impl Fn(f64, f64) -> bool {
        move |x, y| (x - cx).powi(2) + (y - cy).powi(2) <= r * r
    }

    fn rect(x0: u32, y0: u32, x1: u32, y1: u32) -> impl Fn(f64, f64) -> bool {
        move |x, y| x >= x0 as f64 && x < x1 as f64 && y >= y0 as f64 && y < y1 as f64
    }

    fn image_with(w: u32, h: u32, shapes: &[&dyn Fn(f64, f64) -> bool]) -> RgbaImage {
        let mut image = RgbaImage::new(w, h);
        for shape in shapes {
            paint(&mut image, shape);
        }
        image
    }

    fn options(padding: f64, min_area: f64, tolerance: f64) -> TraceOptions {
        TraceOptions {
            padding_px: padding,
            min_area_px2: min_area,
            simplify_tolerance_px: tolerance,
            ..mid_threshold()
        }
    }

    fn rings(outlines: &[Outline]) -> Vec<&Vec<Point>> {
        outlines
            .iter()
            .flat_map(|o| std::iter::once(&o.outer).chain(&o.holes))
            .collect()
    }

    /// Even-odd over every ring of every outline.
    fn covered(p: Point, outlines: &[Outline]) -> bool {
        rings(outlines)
            .iter()
            .filter(|r| point_in_ring(p, r))
            .count()
            % 2
            == 1
    }

    fn distance_to_rings(p: Point, outlines: &[Outline]) -> f64 {
        rings(outlines)
            .iter()
            .flat_map(|r| (0..r.len()).map(move |i| (r[i], r[(i + 1) % r.len()])))
            .map(|(a, b)| point_segment_distance(p, a, b))
            .fold(f64::INFINITY, f64::min)
    }

    /// Rings simple and mutually disjoint (brute force), ≥ 3 distinct consecutive points,
    /// orientations right, holes inside their outer ring.
    fn assert_valid_rings(outlines: &[Outline]) {
        for outline in outlines {
            assert!(
                ring_signed_area(&outline.outer) > 0.0,
                "outer ring not positive"
            );
            for hole in &outline.holes {
                assert!(ring_signed_area(hole) < 0.0, "hole not negative");
                assert!(hole.iter().all(|&p| point_in_ring(p, &outline.outer)));
            }
        }
        let all = rings(outlines);
        let mut segments = Vec::new();
        for (r, ring) in all.iter().enumerate() {
            assert!(ring.len() >= 3, "ring with {} points", ring.len());
            for i in 0..ring.len() {
                let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                assert_ne!(a, b, "repeated point");
                segments.push((r, i, ring.len(), a, b));
            }
        }
        for (k, &(r, i, n, a, b)) in segments.iter().enumerate() {
            for &(s, j, _, c, d) in &segments[k + 1..] {
                let next = r == s && (j == (i + 1) % n || i == (j + 1) % n);
                if next {
                    // Consecutive segments share one point: they must not overlap.
                    let (p, q, o) = if j == (i + 1) % n {
                        (a, b, d)
                    } else {
                        (c, d, b)
                    };
                    assert!(
                        orient(p, q, o) != 0.0 || (o - q).dot(&(p - q)) <= 0.0,
                        "ring {r} folds back at {i}"
                    );
                } else {
                    assert!(
                        !segments_touch(a, b, c, d),
                        "ring {r} segment {i} meets ring {s} segment {j}"
                    );
                }
            }
        }
    }

    /// What the mesh stage does with the rings: every ring edge must go into spade's
    /// constrained Delaunay triangulation without crossing another one (spade panics then).
    fn assert_spade_accepts(outlines: &[Outline]) {
        use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
        let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
        let mut handles = Vec::new();
        for ring in rings(outlines) {
            let ring_handles: Vec<_> = ring
                .iter()
                .map(|p| cdt.insert(Point2::new(p.x, p.y)).expect("finite point"))
                .collect();
            handles.push(ring_handles);
        }
        assert_eq!(
            cdt.num_vertices(),
            handles.iter().map(Vec::len).sum::<usize>(),
            "two ring points coincide"
        );
        for ring in &handles {
            for i in 0..ring.len() {
                let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                assert!(cdt.can_add_constraint(a, b), "constraint would cross");
                cdt.add_constraint(a, b);
            }
        }
    }

    fn pixel_centers(image: &RgbaImage, pick: impl Fn(u8) -> bool) -> Vec<Point> {
        image
            .enumerate_pixels()
            .filter(|(_, _, px)| pick(px[3]))
            .map(|(x, y, _)| Point::new(x as f64 + 0.5, y as f64 + 0.5))
            .collect()
    }

    /// The guarantees of the module doc, checked by brute force.
    fn assert_traces_well(image: &RgbaImage, options: &TraceOptions) -> Vec<Outline> {
        let outlines = trace(image, options).expect("trace");
        assert_valid_rings(&outlines);
        assert_spade_accepts(&outlines);
        let t = options.alpha_threshold;
        let opaque = pixel_centers(image, |a| a >= t);
        let clearance = options.padding_px - options.simplify_tolerance_px - 1.0;
        if clearance >= 0.0 && options.min_area_px2 == 0.0 {
            for &c in &opaque {
                assert!(covered(c, &outlines), "opaque center {c} not covered");
                assert!(
                    distance_to_rings(c, &outlines) >= clearance,
                    "{c} too close"
                );
            }
        }
        for ring in rings(&outlines) {
            for &v in ring {
                let nearest = opaque
                    .iter()
                    .map(|&c| (c - v).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    nearest <= options.padding_px + 1.0,
                    "vertex {v} far from opaque"
                );
            }
        }
        // Far from every opaque pixel is outside: the traced region reaches at most a cell
        // diagonal past the dilated samples, plus the simplification.
        let reach = options.padding_px + std::f64::consts::SQRT_2 + options.simplify_tolerance_px;
        for c in pixel_centers(image, |a| a < t) {
            let nearest = opaque
                .iter()
                .map(|&o| (o - c).norm())
                .fold(f64::INFINITY, f64::min);
            if nearest > reach {
                assert!(!covered(c, &outlines), "transparent center {c} covered");
            }
        }
        outlines
    }

    #[test]
    fn opaque_rectangle_grows_by_the_padding() {
        let image = image_with(40, 30, &[&rect(10, 8, 30, 20)]);
        let outlines = assert_traces_well(&image, &mid_threshold());
        assert_eq!(outlines.len(), 1);
        assert!(outlines[0].holes.is_empty());
        let outer = &outlines[0].outer;
        let (min_x, max_x) = outer.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
            (lo.min(p.x), hi.max(p.x))
        });
        let (min_y, max_y) = outer.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
            (lo.min(p.y), hi.max(p.y))
        });
        assert_eq!((min_x, max_x, min_y, max_y), (8.0, 32.0, 6.0, 22.0));
        // Continuous rectangle ⊕ disk: 24 × 16 less (4 − π) r². The pixel disk is coarser, and
        // the simplification cuts the corners by up to the tolerance.
        let round = 24.0 * 16.0 - (4.0 - std::f64::consts::PI) * 4.0;
        let area = ring_signed_area(outer);
        assert!(area > round - 16.0 && area < round, "area {area}");
    }

    #[test]
    fn rectangle_without_padding_is_exact() {
        let image = image_with(20, 20, &[&rect(3, 4, 15, 9)]);
        let outlines = assert_traces_well(&image, &options(0.0, 0.0, 0.0));
        assert_eq!(outlines.len(), 1);
        let outer = &outlines[0].outer;
        // Straight runs collapse; marching squares bevels each corner by 1/8 px².
        assert_eq!(outer.len(), 8);
        let area = ring_signed_area(outer);
        assert!((area - (60.0 - 4.0 * 0.125)).abs() < 1e-9, "area {area}");
    }

    #[test]
    fn opaque_image_border_is_padded_beyond_the_canvas() {
        let image = image_with(10, 6, &[&rect(0, 0, 10, 6)]);
        let outlines = assert_traces_well(&image, &options(2.0, 0.0, 0.0));
        assert_eq!(outlines.len(), 1);
        let outer = &outlines[0].outer;
        let min = outer.iter().fold(Point::new(f64::MAX, f64::MAX), |m, p| {
            Point::new(m.x.min(p.x), m.y.min(p.y))
        });
        let max = outer.iter().fold(Point::new(f64::MIN, f64::MIN), |m, p| {
            Point::new(m.x.max(p.x), m.y.max(p.y))
        });
        assert_eq!((min, max), (Point::new(-2.0, -2.0), Point::new(12.0, 8.0)));
        let tiny = image_with(1, 1, &[&rect(0, 0, 1, 1)]);
        let outlines = assert_traces_well(&tiny, &options(0.0, 0.0, 0.0));
        assert_eq!(ring_signed_area(&outlines[0].outer), 0.5);
    }

    #[test]
    fn antialiased_disk_is_traced_to_sub_pixel_accuracy() {
        let (cx, cy, r) = (32.3, 30.7, 12.4);
        let image = image_with(64, 64, &[&disk(cx, cy, r)]);
        for tolerance in [0.0, 0.5] {
            let outlines = assert_traces_well(&image, &options(0.0, 8.0, tolerance));
            assert_eq!(outlines.len(), 1);
            let outer = &outlines[0].outer;
            assert!(outer.len() >= 16, "only {} points", outer.len());
            for p in outer {
                let radius = (p - Point::new(cx, cy)).norm();
                assert!((radius - r).abs() < 0.1, "radius {radius}");
            }
        }
        let traced = trace(&image, &options(0.0, 8.0, 0.0)).expect("trace");
        let area = ring_signed_area(&traced[0].outer);
        let expected = std::f64::consts::PI * r * r;
        assert!((area - expected).abs() < 0.005 * expected, "area {area}");
    }

    #[test]
    fn donut_has_one_hole_with_the_right_orientations() {
        let (c, outer_r, inner_r) = (25.0, 18.0, 9.0);
        let image = image_with(
            50,
            50,
            &[&|x, y| {
                let d2 = (x - c).powi(2) + (y - c).powi(2);
                d2 <= outer_r * outer_r && d2 >= inner_r * inner_r
            }],
        );
        let outlines = assert_traces_well(&image, &mid_threshold());
        assert_eq!(outlines.len(), 1);
        assert_eq!(outlines[0].holes.len(), 1);
        assert!(ring_signed_area(&outlines[0].outer) > 0.0);
        assert!(ring_signed_area(&outlines[0].holes[0]) < 0.0);
        assert!(covered(
            Point::new(c, c - (outer_r + inner_r) / 2.0),
            &outlines
        ));
        assert!(!covered(Point::new(c, c), &outlines));
    }

    #[test]
    fn separate_blobs_give_separate_outlines_in_raster_order() {
        let image = image_with(60, 40, &[&disk(45.0, 10.0, 6.0), &disk(15.0, 28.0, 7.0)]);
        let outlines = assert_traces_well(&image, &mid_threshold());
        assert_eq!(outlines.len(), 2);
        assert!(outlines[0].outer[0].x > 30.0, "upper blob first");
        assert!(outlines[1].outer[0].x < 30.0);
    }

    #[test]
    fn single_pixel_padded_becomes_a_small_disk() {
        let image = image_with(9, 9, &[&rect(4, 4, 5, 5)]);
        let outlines = assert_traces_well(&image, &options(2.0, 0.0, 0.0));
        assert_eq!(outlines.len(), 1);
        let outer = &outlines[0].outer;
        // The 13-pixel disk of radius 2 traces as a diamond (its staircase edges are straight
        // through the edge midpoints) with tips 2.5 px from the pixel center, plus the ring's
        // start (its first crossing in raster order), which is always kept.
        let tips = [(4.0, 2.5), (4.5, 2.0), (7.0, 4.5), (4.5, 7.0), (2.0, 4.5)]
            .map(|(x, y)| Point::new(x, y));
        assert_eq!(outer.as_slice(), &tips[..]);
        assert_eq!(ring_signed_area(outer), 12.5);
    }

    #[test]
    fn single_pixel_unpadded_is_a_diamond() {
        let image = image_with(5, 5, &[&rect(2, 2, 3, 3)]);
        let outlines = assert_traces_well(&image, &options(0.0, 0.0, 0.1));
        assert_eq!(outlines.len(), 1);
        // Starting at the first crossing in raster order, clockwise on screen.
        let expected =
            [(2.0, 2.5), (2.5, 2.0), (3.0, 2.5), (2.5, 3.0)].map(|(x, y)| Point::new(x, y));
        assert_eq!(outlines[0].outer.as_slice(), &expected[..]);
        assert_eq!(ring_signed_area(&outlines[0].outer), 0.5);
        // At a coarse tolerance it still keeps an area.
        let coarse = assert_traces_well(&image, &options(0.0, 0.0, 0.5));
        assert_eq!(coarse[0].outer.len(), 3);
    }

    #[test]
    fn thin_line_stays_one_outline() {
        let image = image_with(
            64,
            32,
            &[&|x: f64, y: f64| {
                // A 1-px-wide diagonal line.
                (y - (4.0 + 0.4 * x)).abs() <= 0.5 && (2.0..60.0).contains(&x)
            }],
        );
        let outlines = assert_traces_well(&image, &mid_threshold());
        assert_eq!(outlines.len(), 1);
        let unpadded = assert_traces_well(&image, &options(0.0, 0.0, 0.2));
        assert!(!unpadded.is_empty());
    }

    #[test]
    fn soft_alpha_gradient_is_cut_at_the_threshold() {
        let mut image = RgbaImage::new(64, 16);
        for (x, _, px) in image.enumerate_pixels_mut() {
            px[3] = (x * 4).min(255) as u8;
        }
        // Alpha ≥ 128 from x = 32 on: the level 127.5 sits at the center of pixel 31 + 7/8.
        let outlines = assert_traces_well(&image, &options(0.0, 0.0, 0.1));
        assert_eq!(outlines.len(), 1);
        let min_x = outlines[0]
            .outer
            .iter()
            .map(|p| p.x)
            .fold(f64::MAX, f64::min);
        assert!((min_x - 32.375).abs() < 1e-9, "min x {min_x}");
        // The padding moves the cut outwards by exactly the padding along a row.
        let padded = assert_traces_well(&image, &mid_threshold());
        let min_x = padded[0].outer.iter().map(|p| p.x).fold(f64::MAX, f64::min);
        assert!((min_x - 30.375).abs() < 1e-9, "min x {min_x}");
    }

    #[test]
    fn specks_below_min_area_are_dropped() {
        let mut image = image_with(40, 40, &[&disk(20.0, 20.0, 10.0), &rect(2, 2, 3, 3)]);
        // A one-pixel hole in the middle of the disk.
        image.get_pixel_mut(20, 20)[3] = 0;
        let outlines = assert_traces_well(&image, &options(0.0, 8.0, 0.5));
        assert_eq!(outlines.len(), 1, "speck dropped");
        assert!(outlines[0].holes.is_empty(), "tiny hole dropped");
        let all = assert_traces_well(&image, &options(0.0, 0.0, 0.5));
        assert_eq!(all.len(), 2);
        assert_eq!(all[1].holes.len(), 1);
    }

    #[test]
    fn hole_of_a_dropped_component_goes_with_it() {
        // A 3 × 3 pixel ring: outer area 9 − 4/8, hole area 4/8.
        let mut image = image_with(9, 9, &[&rect(3, 3, 6, 6)]);
        image.get_pixel_mut(4, 4)[3] = 0;
        let count = |min_area| {
            let outlines = assert_traces_well(&image, &options(0.0, min_area, 0.0));
            (
                outlines.len(),
                outlines.iter().map(|o| o.holes.len()).sum::<usize>(),
            )
        };
        assert_eq!(count(0.4), (1, 1));
        assert_eq!(count(1.0), (1, 0));
        assert_eq!(count(8.6), (0, 0));
    }

    #[test]
    fn checkerboard_saddles_do_not_touch() {
        for (high, low) in [(255, 0), (200, 60), (130, 126), (255, 127)] {
            let mut image = RgbaImage::new(12, 12);
            for (x, y, px) in image.enumerate_pixels_mut() {
                let on = (2..10).contains(&x) && (2..10).contains(&y) && (x + y) % 2 == 0;
                px[3] = if on { high } else { low };
            }
            for o in [
                options(0.0, 0.0, 0.0),
                options(0.0, 0.0, 0.5),
                options(1.0, 0.0, 0.3),
            ] {
                let outlines = assert_traces_well(&image, &o);
                assert!(!outlines.is_empty());
            }
        }
    }

    #[test]
    fn no_opaque_pixel_is_an_error() {
        let mut image = RgbaImage::new(8, 8);
        image.get_pixel_mut(3, 3)[3] = 127;
        let options = TraceOptions {
            alpha_threshold: 128,
            ..mid_threshold()
        };
        assert_eq!(
            trace(&image, &options),
            Err(TraceError::NoOpaquePixels { threshold: 128 })
        );
        assert_eq!(
            trace(&RgbaImage::new(0, 0), &options),
            Err(TraceError::NoOpaquePixels { threshold: 128 })
        );
    }

    #[test]
    fn invalid_options_are_rejected() {
        let image = image_with(8, 8, &[&rect(2, 2, 6, 6)]);
        let bad = [
            TraceOptions {
                alpha_threshold: 0,
                ..mid_threshold()
            },
            options(-1.0, 8.0, 0.5),
            options(f64::NAN, 8.0, 0.5),
            options(MAX_PADDING_PX + 1.0, 8.0, 0.5),
            options(2.0, f64::INFINITY, 0.5),
            options(2.0, -0.1, 0.5),
            options(2.0, 8.0, f64::NAN),
            options(2.0, 8.0, -1.0),
        ];
        for o in bad {
            assert!(
                matches!(trace(&image, &o), Err(TraceError::InvalidOption { .. })),
                "{o:?} accepted"
            );
        }
    }

    /// A tiny deterministic generator for the synthetic shapes.
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn synthetic_shapes() -> Vec<RgbaImage> {
        let mut shapes = vec![
            image_with(48, 48, &[&rect(5, 5, 40, 12), &rect(5, 14, 40, 20)]),
            // Nested: disk, ring around it, ring around that.
            image_with(
                64,
                64,
                &[
                    &disk(32.0, 32.0, 5.0),
                    &|x, y| (11.0..15.0).contains(&(x - 32.0f64).hypot(y - 32.0)),
                    &|x, y| (21.0..26.0).contains(&(x - 32.0f64).hypot(y - 32.0)),
                ],
            ),
            // A comb: teeth one pixel apart, merged by the padding.
            image_with(
                48,
                32,
                &[&|x: f64, y: f64| {
                    (4.0..44.0).contains(&x)
                        && (4.0..28.0).contains(&y)
                        && ((x as u32).is_multiple_of(2) || y < 6.0)
                }],
            ),
            // A spiral-ish curve.
            image_with(
                64,
                64,
                &[&|x: f64, y: f64| {
                    let (dx, dy) = (x - 32.0, y - 32.0);
                    let r = dx.hypot(dy);
                    let a = dy.atan2(dx) + std::f64::consts::PI;
                    let phase = (r - 3.0 * a) / (6.0 * std::f64::consts::PI);
                    r < 28.0 && (phase - phase.floor()) < 0.45
                }],
            ),
        ];
        // Narrow wavy gaps: at coarse tolerances the chords on both sides of a gap cross.
        shapes.push(image_with(
            64,
            48,
            &[&|x: f64, y: f64| {
                let wave = |y0: f64| y0 + 3.0 * (x / 3.0).sin();
                (4.0..60.0).contains(&x)
                    && (4.0..44.0).contains(&y)
                    && (y - wave(16.0)).abs() > 0.7
                    && (y - wave(30.0)).abs() > 0.6
            }],
        ));
        // Tight concentric rings with wobbly edges, 1 px apart.
        shapes.push(image_with(
            64,
            64,
            &[&|x: f64, y: f64| {
                let (dx, dy) = (x - 32.0, y - 32.0);
                let r = dx.hypot(dy) + 0.8 * (5.0 * dy.atan2(dx)).sin();
                r < 28.0 && (r % 3.0) > 1.0
            }],
        ));
        // Pure noise: every pixel random, binary or soft: saddles everywhere.
        let mut rng = Lcg(3);
        for soft in [false, true] {
            let mut image = RgbaImage::new(24, 24);
            for px in image.pixels_mut() {
                let v = rng.next();
                px[3] = if soft {
                    (256.0 * v) as u8
                } else {
                    u8::from(v < 0.5) * 255
                };
            }
            shapes.push(image);
        }
        // Random blobs with random soft edges.
        let mut rng = Lcg(7);
        for _ in 0..4 {
            let mut image = RgbaImage::new(56, 56);
            for _ in 0..12 {
                let (cx, cy, r) = (56.0 * rng.next(), 56.0 * rng.next(), 0.5 + 5.0 * rng.next());
                paint(&mut image, disk(cx, cy, r));
            }
            for px in image.pixels_mut() {
                if rng.next() < 0.05 {
                    px[3] = (256.0 * rng.next()) as u8;
                }
            }
            shapes.push(image);
        }
        shapes
    }

    #[test]
    fn synthetic_shapes_keep_every_guarantee() {
        let variants = [
            TraceOptions {
                min_area_px2: 0.0,
                ..mid_threshold()
            },
            options(0.0, 0.0, 0.5),
            options(1.0, 0.0, 0.0),
            options(3.5, 0.0, 1.0),
            options(2.0, 0.0, 3.0),
            options(0.0, 0.0, 2.0),
            options(0.5, 0.0, 4.0),
            TraceOptions {
                alpha_threshold: 40,
                ..options(1.5, 0.0, 0.4)
            },
            mid_threshold(),
        ];
        for (s, image) in synthetic_shapes().iter().enumerate() {
            for o in &variants {
                let first = assert_traces_well(image, o);
                let again = trace(image, o).expect("trace");
                assert_eq!(first, again, "shape {s}: output not deterministic");
            }
        }
    }

    /// Prints timings only (run with `cargo test --release --lib trace -- --ignored
    /// --nocapture`): traces a character-like antialiased sprite at 1024² and 4096², clean and
    /// with speckle noise, with a per-stage breakdown.
    #[test]
    #[ignore]
    fn print_trace_timing() {
        let ms = |t: std::time::Instant| t.elapsed().as_secs_f64() * 1e3;
        for size in [1024u32, 4096] {
            let clean = character_sprite(size);
            let mut noisy = clean.clone();
            let mut rng = Lcg(size.into());
            for px in noisy.pixels_mut() {
                if rng.next() < 0.01 {
                    px[3] = (256.0 * rng.next()) as u8;
                }
            }
            for (name, image) in [("clean", clean), ("noisy", noisy)] {
                let o = mid_threshold();
                let start = std::time::Instant::now();
                let outlines = trace(&image, &o).expect("trace");
                let total = ms(start);
                let stage = std::time::Instant::now();
                let grid = dilate::dilate_alpha(&image, o.padding_px);
                let dilate_ms = ms(stage);
                let stage = std::time::Instant::now();
                let traced = march::trace_rings(&grid, o.alpha_threshold);
                let march_ms = ms(stage);
                let (kept, _) = drop_specks(traced, o.min_area_px2);
                let stage = std::time::Instant::now();
                simplify::simplify_rings(&kept, o.simplify_tolerance_px);
                let simplify_ms = ms(stage);
                let points: usize = rings(&outlines).iter().map(|r| r.len()).sum();
                println!(
                    "{size}² {name}: {total:.1} ms (dilate {dilate_ms:.1}, march \
                     {march_ms:.1}, simplify {simplify_ms:.1}); {} outlines, {} holes, \
                     {points} points",
                    outlines.len(),
                    outlines.iter().map(|o| o.holes.len()).sum::<usize>()
                );
            }
        }
    }

    /// Ellipses (head, body, arms, legs) and a thin staff, antialiased by signed distance.
    fn character_sprite(size: u32) -> RgbaImage {
        let s = size as f64;
        let ellipses = [
            (0.50, 0.18, 0.12, 0.13),
            (0.50, 0.45, 0.16, 0.22),
            (0.30, 0.42, 0.05, 0.17),
            (0.70, 0.42, 0.05, 0.17),
            (0.42, 0.78, 0.06, 0.18),
            (0.58, 0.78, 0.06, 0.18),
        ];
        let (a, b) = (
            nalgebra::Vector2::new(0.78 * s, 0.10 * s),
            nalgebra::Vector2::new(0.86 * s, 0.95 * s),
        );
        let mut image = RgbaImage::new(size, size);
        for (x, y, px) in image.enumerate_pixels_mut() {
            let p = nalgebra::Vector2::new(x as f64 + 0.5, y as f64 + 0.5);
            let mut distance = f64::INFINITY;
            for &(cx, cy, rx, ry) in &ellipses {
                let (dx, dy) = ((p.x - cx * s) / (rx * s), (p.y - cy * s) / (ry * s));
                distance = distance.min((dx.hypot(dy) - 1.0) * rx.min(ry) * s);
            }
            let t = ((p - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
            distance = distance.min((p - (a + (b - a) * t)).norm() - 0.6);
            px[3] = (255.0 * (0.5 - distance).clamp(0.0, 1.0)).round() as u8;
        }
        image
    }
}
