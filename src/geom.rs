//! Plain 2D geometry shared by every stage.
//!
//! Coordinates are canvas pixels: x to the right, y down, origin at the top-left corner of the
//! canvas. Pixel (i, j) covers [i, i+1) × [j, j+1), so its center is (i + 0.5, j + 0.5).

pub mod pack;

/// A position on the canvas, in pixels.
pub type Point = nalgebra::Point2<f64>;
/// A displacement on the canvas, in pixels.
pub type Vec2 = nalgebra::Vector2<f64>;

/// The coordinates of a run of points, x0 y0 x1 y1 …, without copying.
pub fn point_numbers(points: &[Point]) -> &[f64] {
    bytemuck::cast_slice(points)
}

/// The points as coordinate arrays, without copying: for code generic over the dimension
/// (`[f64; D]`: the weight metric measures 2D positions and 5D content-aware lifts alike).
pub fn as_coordinate_arrays(points: &[Point]) -> &[[f64; 2]] {
    bytemuck::cast_slice(points)
}

/// [`point_numbers`], mutable.
pub fn point_numbers_mut(points: &mut [Point]) -> &mut [f64] {
    bytemuck::cast_slice_mut(points)
}

/// Twice the signed area of a closed ring by the shoelace formula, in px².
///
/// With y pointing down, a ring that runs clockwise on screen has a positive value.
pub fn ring_signed_area2(ring: &[Point]) -> f64 {
    let n = ring.len();
    (0..n)
        .map(|i| {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum()
}

/// Signed area of a closed ring in px² (see [`ring_signed_area2`] for the sign).
pub fn ring_signed_area(ring: &[Point]) -> f64 {
    0.5 * ring_signed_area2(ring)
}

/// Whether `p` lies inside the closed ring, by the even-odd rule.
pub fn point_in_ring(p: Point, ring: &[Point]) -> bool {
    let n = ring.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (ring[i], ring[j]);
        if (a.y > p.y) != (b.y > p.y) {
            let x_cross = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x_cross {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Barycentric coordinates of `p` in triangle abc (weights of a, b, c), or `None` for a
/// degenerate triangle (|det| below [`DEGENERATE_DET`]).
pub fn barycentric(p: Point, a: Point, b: Point, c: Point) -> Option<[f64; 3]> {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let det = v0.x * v1.y - v0.y * v1.x;
    if det.abs() < DEGENERATE_DET {
        return None;
    }
    let u = (v2.x * v1.y - v2.y * v1.x) / det;
    let v = (v0.x * v2.y - v0.y * v2.x) / det;
    Some([1.0 - u - v, u, v])
}

/// Twice a triangle's area (px²) below which [`barycentric`] calls it degenerate.
pub const DEGENERATE_DET: f64 = 1e-12;

/// Distance (px) from `p` to the closed segment a–b, and the parameter of the closest point on
/// it (0 at a, 1 at b; 0 for a segment of zero length, whose distance is to a).
pub fn segment_distance(p: Point, a: Point, b: Point) -> (f64, f64) {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p - (a + ab * t)).norm(), t)
}

/// Distance (px) from `p` to the closed segment a–b (see [`segment_distance`]).
pub fn point_segment_distance(p: Point, a: Point, b: Point) -> f64 {
    segment_distance(p, a, b).0
}

/// Twice the signed area of triangle (a, b, c), in px²; positive when a → b → c turns clockwise
/// on screen (y down).
pub fn triangle_area2(a: Point, b: Point, c: Point) -> f64 {
    (b - a).perp(&(c - a))
}

/// Whether closed segments `a`–`b` and `c`–`d` share a point.
pub fn segments_touch(a: Point, b: Point, c: Point, d: Point) -> bool {
    let orient = triangle_area2;
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: Point, q: Point, r: Point| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_square_area_and_inside() {
        let sq = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(1.0, 1.0),
            Point::new(0.0, 1.0),
        ];
        assert_eq!(ring_signed_area(&sq), 1.0);
        assert!(point_in_ring(Point::new(0.5, 0.5), &sq));
        assert!(!point_in_ring(Point::new(1.5, 0.5), &sq));
    }
}
