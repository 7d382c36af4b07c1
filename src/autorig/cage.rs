//! Cages: a simplified outline with at most N vertices that contains every opaque pixel, does
//! not intersect itself and hugs the shape.
//!
//! In: the layers' union alpha (straight RGBA, canvas px), the alpha threshold, the largest
//! vertex count and [`CageOptions`]. Out: a simple polygon (canvas px, positive shoelace area)
//! containing every pixel square with alpha ≥ the threshold, at least `margin_px` from it
//! where the polygon was not simplified.
//!
//! Steps: the alpha is max-pooled to at most `working_side_px` per side (so the pooled shape
//! contains the drawing) and traced with padding `margin_px` plus two pooled pixels and no
//! simplification (the tracer guarantees every opaque pixel center lies at least padding − 1
//! from the ring; the extra pixel covers the pixel's corners). Drawings in several pieces are
//! wrapped in their convex hull. Then vertices are removed, cheapest first, only by moves that
//! *grow* the polygon, so containment holds by construction: a reflex vertex is cut off (the
//! shortcut runs outside), or an edge between two convex vertices is collapsed into the
//! meeting point of its neighboring edges' extensions (Aggarwal et al.'s edge flush, as in
//! minimum-area enclosing polygon heuristics). The cost of a move is the area it adds; a move
//! whose new edges would cross the polygon is skipped, so the polygon stays simple.

use crate::geom::{ring_signed_area, Point};
use crate::trace::{self, TraceOptions};
use image::RgbaImage;
use serde::{Deserialize, Serialize};

/// How cages are proposed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CageOptions {
    /// Smallest distance kept between the cage and the opaque pixels before simplification,
    /// px. It keeps the cage clear of the outline `sinew rig` traces (padded 2 px by
    /// default). Default 3.
    pub margin_px: f64,
    /// The alpha is max-pooled to at most this many pixels per side before tracing (larger
    /// drawings get a coarser, slightly looser cage). Default 512.
    pub working_side_px: u32,
}

impl Default for CageOptions {
    fn default() -> Self {
        CageOptions {
            margin_px: 3.0,
            working_side_px: 512,
        }
    }
}

/// What went wrong proposing a cage.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CageError {
    #[error("a cage needs at least 3 vertices, got {0}")]
    TooFewAllowed(usize),
    #[error("the drawing has no pixel with alpha at or above {0}")]
    Empty(u8),
    #[error("no containing cage with at most {allowed} vertices was found (best: {reached})")]
    CannotReach { allowed: usize, reached: usize },
    #[error("invalid cage option: {0}")]
    InvalidOptions(String),
}

/// A containing cage of at most `max_vertices` vertices around the pixels of `image` with
/// alpha ≥ `alpha_threshold`.
pub fn propose_cage(
    image: &RgbaImage,
    alpha_threshold: u8,
    max_vertices: usize,
    options: &CageOptions,
) -> Result<Vec<Point>, CageError> {
    if max_vertices < 3 {
        return Err(CageError::TooFewAllowed(max_vertices));
    }
    if !(options.margin_px.is_finite() && options.margin_px >= 0.0) || options.working_side_px < 8 {
        return Err(CageError::InvalidOptions(
            "margin_px must be finite and ≥ 0, working_side_px at least 8".into(),
        ));
    }
    let threshold = alpha_threshold.max(1);
    let (w, h) = image.dimensions();
    let k = w.max(h).div_ceil(options.working_side_px).max(1);
    let (pw, ph) = (w.div_ceil(k), h.div_ceil(k));
    let mut pooled = RgbaImage::new(pw, ph);
    let mut any = false;
    for (x, y, px) in image.enumerate_pixels() {
        if px[3] >= threshold {
            pooled.get_pixel_mut(x / k, y / k)[3] = 255;
            any = true;
        }
    }
    if !any {
        return Err(CageError::Empty(threshold));
    }
    let padding = options.margin_px / k as f64 + 2.0;
    let traced = trace::trace(
        &pooled,
        &TraceOptions {
            alpha_threshold: 255,
            padding_px: padding.min(trace::MAX_PADDING_PX),
            min_area_px2: 0.0,
            simplify_tolerance_px: 0.0,
        },
    )
    .map_err(|e| CageError::InvalidOptions(e.to_string()))?;
    let scale = |p: &Point| Point::new(p.x * k as f64, p.y * k as f64);
    let mut ring: Vec<Point> = if traced.len() == 1 {
        traced[0].outer.iter().map(scale).collect()
    } else {
        convex_hull(
            traced
                .iter()
                .flat_map(|o| o.outer.iter().map(scale))
                .collect(),
        )
    };
    if ring_signed_area(&ring) < 0.0 {
        ring.reverse();
    }
    // Simplify the outline itself, and its convex hull (which always simplifies, and with few
    // vertices can enclose less than a concave polygon forced around every limb): keep the
    // smaller of those that reach the budget.
    let concave = grow_simplify(ring.clone(), max_vertices, true);
    let convex = grow_simplify(convex_hull(ring), max_vertices, false);
    let fits = |c: &Vec<Point>| c.len() <= max_vertices && c.len() >= 3;
    match (fits(&concave), fits(&convex)) {
        (true, true) if ring_signed_area(&convex) < ring_signed_area(&concave) => Ok(convex),
        (true, _) => Ok(concave),
        (false, true) => Ok(convex),
        (false, false) => Err(CageError::CannotReach {
            allowed: max_vertices,
            reached: concave.len().min(convex.len()),
        }),
    }
}

/// The convex hull (Andrew's monotone chain), positive shoelace area, no collinear points.
pub fn convex_hull(mut points: Vec<Point>) -> Vec<Point> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let cross = |o: Point, a: Point, b: Point| (a - o).perp(&(b - o));
    let mut hull: Vec<Point> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Point>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// One growing move.
#[derive(Clone, Copy, Debug)]
enum Move {
    /// Drop the vertex (reflex or collinear).
    Cut(usize),
    /// Replace the vertex and its successor by this point.
    Collapse(usize, Point),
}

/// Removes vertices of the (positive-area, simple) `ring` by growing moves until at most
/// `max` remain or no move is possible. With `allow_cuts` false only collapses are tried.
fn grow_simplify(ring: Vec<Point>, max: usize, allow_cuts: bool) -> Vec<Point> {
    let mut pts = ring;
    loop {
        let n = pts.len();
        if n <= max || n < 4 {
            return pts;
        }
        let cross = |a: Point, b: Point, c: Point| (b - a).perp(&(c - b));
        let mut moves: Vec<(f64, usize, Move)> = Vec::new();
        for i in 0..n {
            let (a, b, c, d) = (
                pts[(i + n - 1) % n],
                pts[i],
                pts[(i + 1) % n],
                pts[(i + 2) % n],
            );
            let turn_b = cross(a, b, c);
            if allow_cuts && turn_b <= 0.0 {
                moves.push((-0.5 * turn_b, i, Move::Cut(i)));
            }
            if turn_b > 0.0 && cross(b, c, d) > 0.0 {
                if let Some(x) = line_meet(a, b, d, c) {
                    moves.push((0.5 * (x - b).perp(&(c - b)).abs(), i, Move::Collapse(i, x)));
                }
            }
        }
        moves.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        // Apply the cheapest moves that touch disjoint stretches, a bounded number per pass.
        let quota = ((n - max).div_ceil(3)).max(1);
        let mut touched = vec![false; n];
        let mut removed = vec![false; n];
        let mut replaced: Vec<Option<Point>> = vec![None; n];
        let mut applied = 0;
        for &(_, i, mv) in &moves {
            if applied >= quota {
                break;
            }
            let span = [
                (i + n - 2) % n,
                (i + n - 1) % n,
                i,
                (i + 1) % n,
                (i + 2) % n,
            ];
            if span.iter().any(|&v| touched[v]) {
                continue;
            }
            let current = current_ring(&pts, &removed, &replaced);
            let ok = match mv {
                Move::Cut(i) => {
                    let (a, c) = (pts[(i + n - 1) % n], pts[(i + 1) % n]);
                    !crosses(&current, a, c, &[(i + n - 1) % n, i, (i + 1) % n], &pts)
                }
                Move::Collapse(i, x) => {
                    let (a, d) = (pts[(i + n - 1) % n], pts[(i + 2) % n]);
                    let skip = [(i + n - 1) % n, i, (i + 1) % n, (i + 2) % n];
                    !crosses(&current, a, x, &skip, &pts) && !crosses(&current, x, d, &skip, &pts)
                }
            };
            if !ok {
                continue;
            }
            match mv {
                Move::Cut(i) => removed[i] = true,
                Move::Collapse(i, x) => {
                    replaced[i] = Some(x);
                    removed[(i + 1) % n] = true;
                }
            }
            span.iter().for_each(|&v| touched[v] = true);
            applied += 1;
        }
        if applied == 0 {
            return pts;
        }
        pts = (0..n)
            .filter(|&v| !removed[v])
            .map(|v| replaced[v].unwrap_or(pts[v]))
            .collect();
    }
}

/// The ring with this pass's moves applied so far, as (original index, point) pairs.
fn current_ring(
    pts: &[Point],
    removed: &[bool],
    replaced: &[Option<Point>],
) -> Vec<(usize, Point)> {
    (0..pts.len())
        .filter(|&v| !removed[v])
        .map(|v| (v, replaced[v].unwrap_or(pts[v])))
        .collect()
}

/// Whether segment p–q touches an edge of `ring` other than those starting or ending at the
/// original vertices in `skip`.
fn crosses(ring: &[(usize, Point)], p: Point, q: Point, skip: &[usize], _pts: &[Point]) -> bool {
    let m = ring.len();
    (0..m).any(|k| {
        let (u, a) = ring[k];
        let (v, b) = ring[(k + 1) % m];
        if skip.contains(&u) || skip.contains(&v) {
            return false;
        }
        crate::geom::segments_touch(p, q, a, b)
    })
}

/// Where the ray from `a` through `b` (beyond `b`) meets the ray from `d` through `c` (beyond
/// `c`), if it does.
fn line_meet(a: Point, b: Point, d: Point, c: Point) -> Option<Point> {
    let (r, s) = (b - a, c - d);
    let denom = r.perp(&s);
    if denom.abs() < 1e-12 {
        return None;
    }
    let t = (d - a).perp(&s) / denom;
    let u = (d - a).perp(&r) / denom;
    (t > 1.0 && u > 1.0).then(|| a + r * t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::point_in_ring;

    #[test]
    fn an_l_shape_cage_contains_every_pixel_with_few_vertices() {
        let image = RgbaImage::from_fn(80, 80, |x, y| {
            let inside = (10..30).contains(&x) && (10..70).contains(&y)
                || (10..70).contains(&x) && (50..70).contains(&y);
            image::Rgba([0, 0, 0, if inside { 255 } else { 0 }])
        });
        for max in [4, 6, 12] {
            let cage = propose_cage(&image, 1, max, &CageOptions::default()).unwrap();
            assert!(cage.len() <= max, "{} > {max}", cage.len());
            for (x, y, px) in image.enumerate_pixels() {
                if px[3] > 0 {
                    for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                        let p = Point::new(x as f64 + dx, y as f64 + dy);
                        assert!(point_in_ring(p, &cage), "{p:?} outside the {max}-cage");
                    }
                }
            }
        }
        // With 6 vertices the L is hugged: far less than its bounding box grown by the margin.
        let six = propose_cage(&image, 1, 6, &CageOptions::default()).unwrap();
        assert!(ring_signed_area(&six) < 0.8 * 70.0 * 70.0);
    }
}
