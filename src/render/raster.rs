//! Triangles → the pixels whose centers they own, row by row, decided in exact integers.
//!
//! In: three corners in canvas pixels, already in fixed point ([`to_fixed`]: 1/[`SUBPIXEL`] px),
//! and a clip rectangle of whole pixels. Out: for each pixel row, the half-open run of columns
//! whose centers (i + 0.5, j + 0.5) lie inside the triangle.
//!
//! Why integers: two triangles sharing an edge must split the pixel centers on that edge between
//! them exactly, or a seam (a center nobody owns) or a double blend (a center both own) appears.
//! With integer corners, the edge function of the shared edge in one triangle is exactly the
//! negation of the other's, so a single tie rule decides every center on it once.
//!
//! The tie rule: a center exactly on an edge belongs to the triangle that the center would enter
//! if nudged by an infinitesimal step in the direction (1, ε), ε ≪ 1 (right, then a hair down).
//! Such a nudged point lies on no edge, so it is inside exactly one triangle of any edge-connected
//! triangulation around it, even at a vertex shared by a whole fan.
//!
//! Orientation does not matter: a triangle flipped by the deformation owns the same centers as
//! its mirror image, and a triangle of zero area owns none.

/// Fixed-point fraction bits of a corner coordinate.
pub(super) const SUBPIXEL_BITS: u32 = 8;
/// Fixed-point units per pixel.
pub(super) const SUBPIXEL: i64 = 1 << SUBPIXEL_BITS;
/// Largest canvas coordinate magnitude, px, that corners may have. Beyond it the products of the
/// edge functions could leave `i64`; 2²⁰ px is far past any view (a 2048 px canvas at 500 %).
pub(super) const MAX_COORD_PX: f64 = (1u64 << 20) as f64;

/// A point in fixed-point canvas coordinates.
pub(super) type FixedPoint = [i64; 2];

/// `p` (canvas px) rounded to the nearest fixed-point position, or `None` if it is not finite or
/// lies beyond [`MAX_COORD_PX`].
pub(super) fn to_fixed(p: crate::geom::Point) -> Option<FixedPoint> {
    let inside = |v: f64| v.abs() <= MAX_COORD_PX;
    (inside(p.x) && inside(p.y)).then(|| [p.x, p.y].map(|v| round_i64(v * SUBPIXEL as f64)))
}

/// Magnitude beyond which the float → integer helpers clamp, far inside `i64`.
const MAX_ROUNDED: f64 = (1u64 << 62) as f64;

/// `v` rounded half away from zero, as `f64::round` (which on baseline x86-64 is a call into
/// libm, too slow per triangle); clamped to ±2⁶², NaN gives 0.
pub(super) fn round_i64(v: f64) -> i64 {
    round_within_range(v.clamp(-MAX_ROUNDED, MAX_ROUNDED))
}

/// [`round_i64`] for a `v` the caller knows to lie within ±2⁶² (NaN still gives 0).
#[inline(always)]
pub(super) fn round_within_range(v: f64) -> i64 {
    let t = v as i64;
    // Exact: below 2⁵² the integer part converts back exactly; above it `v` is an integer.
    let rest = v - t as f64;
    t + i64::from(rest >= 0.5) - i64::from(rest <= -0.5)
}

/// ⌊v⌋ (clamped like [`round_i64`]).
pub(super) fn floor_i64(v: f64) -> i64 {
    let v = v.clamp(-MAX_ROUNDED, MAX_ROUNDED);
    let t = v as i64;
    t - i64::from(t as f64 > v)
}

/// A rectangle of whole pixels, half-open: columns `x0..x1`, rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct PixelRect {
    pub x0: i64,
    pub y0: i64,
    pub x1: i64,
    pub y1: i64,
}

/// Distance, in columns, within which a float estimate of an edge's crossing is checked exactly.
/// The estimate is two roundings off the exact ratio, a relative error of 2⁻⁵², so for crossings
/// within 2³⁰ columns (any clip) it is off by less than 10⁻⁶ columns, and farther from a whole
/// column its rounding is the exact one; crossings farther out fall outside the clip either way.
const TIE_WINDOW_COLUMNS: f64 = 1e-6;
/// Crossings farther out than this many columns are not checked exactly: they lie outside any
/// clip (so either rounding gives the same run), and the exact margin there could leave `i64`.
const MAX_EXACT_COLUMNS: f64 = (1u64 << 30) as f64;

/// One edge of a positively oriented triangle, as a linear function of the pixel grid: its
/// margin at the center of pixel (column, row) is `margin_on_row + column·per_column` on the
/// current row, the edge function minus the threshold a center must reach (0 where centers on
/// the edge belong to this triangle, 1 where they belong to the neighbour). A center is inside
/// the edge exactly when its margin is not negative.
struct Edge {
    margin_on_row: i64,
    per_row: i64,
    per_column: i64,
    /// −1 / `per_column` (0 for a horizontal edge): turns the margin into the column distance
    /// to the crossing.
    crossing_per_margin: f64,
    /// Whether the inside lies right of the crossing (the edge runs up); otherwise left of it,
    /// or, for a horizontal edge, on whole rows.
    bounds_start: bool,
    horizontal: bool,
}

impl Edge {
    /// The edge `from → to` with its margin at the center of column 0 of `row`.
    #[inline(always)]
    fn new(from: FixedPoint, to: FixedPoint, row: i64) -> Self {
        let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
        let center_y = row * SUBPIXEL + SUBPIXEL / 2;
        let margin_on_row = dx * (center_y - from[1])
            - dy * (SUBPIXEL / 2 - from[0])
            - i64::from(!owns_ties(dx, dy));
        let per_column = -SUBPIXEL * dy;
        Edge {
            margin_on_row,
            per_row: SUBPIXEL * dx,
            per_column,
            crossing_per_margin: if per_column == 0 {
                0.0
            } else {
                -1.0 / per_column as f64
            },
            bounds_start: per_column > 0,
            horizontal: per_column == 0,
        }
    }

    fn inside(&self, column: i64) -> bool {
        self.margin_on_row + self.per_column * column >= 0
    }

    /// The column where this edge's inside starts ([`Edge::bounds_start`]) or one past where it
    /// ends (otherwise) on the current row; meaningless for a horizontal edge.
    ///
    /// Branch-free but for the rare exact check, since an edge's direction varies from triangle
    /// to triangle and a branch on it would be mispredicted about as often as not.
    #[inline(always)]
    fn bound(&self) -> i64 {
        // The column position where the margin crosses zero. Away from a whole column, the
        // first column inside (start edge) and one past the last (end edge) are both
        // ⌊crossing⌋ + 1.
        // |margin| < 2⁶⁰ and |1/per_column| ≤ 1/S, so |crossing| < 2⁵²: it converts to and
        // from an integer exactly after truncation, with no need to clamp.
        let crossing = self.margin_on_row as f64 * self.crossing_per_margin;
        let toward_zero = crossing as i64;
        let below = toward_zero - i64::from(toward_zero as f64 > crossing);
        let fraction = crossing - below as f64;
        if (TIE_WINDOW_COLUMNS..=1.0 - TIE_WINDOW_COLUMNS).contains(&fraction)
            || crossing.abs() > MAX_EXACT_COLUMNS
        {
            return below + 1;
        }
        // Within the window of a whole column n: decide n exactly. A start edge begins at n if
        // n is inside, else at n + 1; an end edge stops after n if n is inside.
        let n = below + i64::from(fraction > 0.5);
        n + i64::from(self.inside(n) != self.bounds_start)
    }

    /// Narrows the columns `lo..hi` of the current row to this edge's inside, whatever its
    /// direction.
    #[inline(always)]
    fn narrow(&self, lo: &mut i64, hi: &mut i64) {
        if self.horizontal {
            if self.margin_on_row < 0 {
                *hi = i64::MIN;
            }
        } else if self.bounds_start {
            *lo = (*lo).max(self.bound());
        } else {
            *hi = (*hi).min(self.bound());
        }
    }

    fn next_row(&mut self) {
        self.margin_on_row += self.per_row;
    }
}

/// Whether centers exactly on an edge running (dx, dy) belong to the triangle on its positive
/// side: nudging such a center by (1, ε) changes the edge function by −dy + ε·dx, and the
/// center belongs where the nudge takes it.
fn owns_ties(dx: i64, dy: i64) -> bool {
    dy < 0 || (dy == 0 && dx > 0)
}

/// Calls `run(row, start, end)` for every pixel row of `clip` that the triangle's centers reach,
/// with `start..end` (non-empty, inside `clip`) the columns whose centers it owns.
pub(super) fn for_each_run(
    [a, b, c]: [FixedPoint; 3],
    clip: PixelRect,
    mut run: impl FnMut(i64, i64, i64),
) {
    let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    let (b, c) = match area2.signum() {
        1 => (b, c),
        -1 => (c, b),
        _ => return,
    };
    // Pixels whose centers (i·S + S/2) lie within [lo, hi], clipped, half-open.
    let centers_within = |lo: i64, hi: i64, clip_lo: i64, clip_hi: i64| {
        let first = (lo - SUBPIXEL / 2 + SUBPIXEL - 1).div_euclid(SUBPIXEL);
        let end = (hi - SUBPIXEL / 2).div_euclid(SUBPIXEL) + 1;
        (first.max(clip_lo), end.min(clip_hi))
    };
    let (first_row, end_row) = centers_within(
        a[1].min(b[1]).min(c[1]),
        a[1].max(b[1]).max(c[1]),
        clip.y0,
        clip.y1,
    );
    let (first_column, end_column) = centers_within(
        a[0].min(b[0]).min(c[0]),
        a[0].max(b[0]).max(c[0]),
        clip.x0,
        clip.x1,
    );
    if first_row >= end_row || first_column >= end_column {
        return;
    }
    let mut edges = [
        Edge::new(a, b, first_row),
        Edge::new(b, c, first_row),
        Edge::new(c, a, first_row),
    ];
    // A row line strictly between two corner heights crosses exactly two edges, a start and an
    // end edge: those at the top corner above the middle height, those at the bottom corner
    // below it. Rows exactly at a corner's height (where a horizontal edge or a corner decides
    // ties) test all three.
    let heights = [a[1], b[1], c[1]];
    let (top, bottom) = (argmin(heights), argmin(heights.map(|y| -y)));
    let middle = 3 - top - bottom;
    let pair_at = |corner: usize| {
        // Corner k starts edge k and ends edge k + 2 (mod 3).
        let (out, back) = (corner, (corner + 2) % 3);
        if edges[out].bounds_start {
            (out, back)
        } else {
            (back, out)
        }
    };
    let (upper, lower) = (pair_at(top), pair_at(bottom));
    let middle_y = heights[middle];
    for row in first_row..end_row {
        let center_y = row * SUBPIXEL + SUBPIXEL / 2;
        let (mut lo, mut hi) = (first_column, end_column);
        if heights.contains(&center_y) {
            for edge in &edges {
                edge.narrow(&mut lo, &mut hi);
            }
        } else {
            let (start, end) = if center_y < middle_y { upper } else { lower };
            lo = lo.max(edges[start].bound());
            hi = hi.min(edges[end].bound());
        }
        if lo < hi {
            run(row, lo, hi);
        }
        for edge in &mut edges {
            edge.next_row();
        }
    }
}

/// Index of the smallest of three values (the first on ties).
fn argmin(v: [i64; 3]) -> usize {
    if v[0] <= v[1] && v[0] <= v[2] {
        0
    } else if v[1] <= v[2] {
        1
    } else {
        2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CLIP: PixelRect = PixelRect {
        x0: -4,
        y0: -4,
        x1: 40,
        y1: 40,
    };

    fn fixed(x: f64, y: f64) -> FixedPoint {
        to_fixed(crate::geom::Point::new(x, y)).expect("in range")
    }

    /// How many times each pixel of `CLIP` is owned by the given triangles.
    fn ownership(triangles: &[[FixedPoint; 3]]) -> Vec<u32> {
        let width = (CLIP.x1 - CLIP.x0) as usize;
        let mut count = vec![0u32; width * (CLIP.y1 - CLIP.y0) as usize];
        for &t in triangles {
            for_each_run(t, CLIP, |row, start, end| {
                assert!(start < end && start >= CLIP.x0 && end <= CLIP.x1);
                assert!((CLIP.y0..CLIP.y1).contains(&row));
                for x in start..end {
                    count[(row - CLIP.y0) as usize * width + (x - CLIP.x0) as usize] += 1;
                }
            });
        }
        count
    }

    /// Brute force: whether the center of pixel (x, y) is strictly inside the triangle.
    fn strictly_inside(t: [FixedPoint; 3], x: i64, y: i64) -> bool {
        let p = [x * SUBPIXEL + SUBPIXEL / 2, y * SUBPIXEL + SUBPIXEL / 2];
        let side = |a: FixedPoint, b: FixedPoint| {
            ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])).signum()
        };
        let s = [side(t[0], t[1]), side(t[1], t[2]), side(t[2], t[0])];
        s.iter().all(|&v| v > 0) || s.iter().all(|&v| v < 0)
    }

    #[test]
    fn a_shared_edge_through_pixel_centers_is_owned_exactly_once() {
        // The diagonal from (0.5, 0.5) to (20.5, 20.5) passes through 21 pixel centers.
        let (p, q) = (fixed(0.5, 0.5), fixed(20.5, 20.5));
        let upper = [p, q, fixed(20.5, 0.5)];
        let lower = [p, fixed(0.5, 20.5), q];
        let counts = ownership(&[upper, lower]);
        let alone = ownership(&[upper]);
        let width = (CLIP.x1 - CLIP.x0) as usize;
        for i in 1..20 {
            let idx = (i + 4) * width + (i + 4);
            assert_eq!(counts[idx], 1, "center ({i}.5, {i}.5)");
        }
        assert!(counts.iter().all(|&c| c <= 1));
        // Both triangles own some of the centers on their other edges and the vertices
        // consistently; what one owns the other does not.
        assert!(alone.iter().sum::<u32>() > 0);
    }

    #[test]
    fn a_quad_split_in_two_covers_every_center_inside_once() {
        // Corners off the pixel grid, a skewed quad, split along either diagonal.
        let [a, b, c, d] = [
            fixed(2.3, 3.1),
            fixed(30.7, 1.9),
            fixed(33.2, 28.4),
            fixed(4.9, 31.6),
        ];
        for split in [[[a, b, c], [a, c, d]], [[a, b, d], [b, c, d]]] {
            let counts = ownership(&split);
            let width = (CLIP.x1 - CLIP.x0) as usize;
            for (i, &n) in counts.iter().enumerate() {
                let (x, y) = ((i % width) as i64 + CLIP.x0, (i / width) as i64 + CLIP.y0);
                let inside_quad = strictly_inside([a, b, c], x, y)
                    || strictly_inside([a, c, d], x, y)
                    || strictly_inside([a, b, d], x, y)
                    || strictly_inside([b, c, d], x, y);
                assert!(n <= 1, "({x}, {y}) owned {n} times");
                if inside_quad {
                    assert_eq!(n, 1, "({x}, {y}) inside but not owned");
                }
            }
        }
    }

    #[test]
    fn a_fan_around_a_pixel_center_owns_it_once() {
        // Eight triangles meeting at the center of pixel (10, 10), their edges running through
        // other centers too (horizontal, vertical, diagonal).
        let hub = fixed(10.5, 10.5);
        let ring = [
            (15.5, 10.5),
            (15.5, 15.5),
            (10.5, 15.5),
            (5.5, 15.5),
            (5.5, 10.5),
            (5.5, 5.5),
            (10.5, 5.5),
            (15.5, 5.5),
        ]
        .map(|(x, y)| fixed(x, y));
        let fan: Vec<[FixedPoint; 3]> = (0..8).map(|k| [hub, ring[k], ring[(k + 1) % 8]]).collect();
        let counts = ownership(&fan);
        let width = (CLIP.x1 - CLIP.x0) as usize;
        for y in 6..15 {
            for x in 6..15 {
                let n = counts[(y + 4) * width + (x + 4)];
                assert_eq!(n, 1, "center of ({x}, {y}) owned {n} times");
            }
        }
    }

    #[test]
    fn runs_match_the_brute_force_center_test_off_the_edges() {
        let t = [fixed(1.37, 2.91), fixed(27.03, 11.6), fixed(8.25, 33.8)];
        let counts = ownership(&[t]);
        let width = (CLIP.x1 - CLIP.x0) as usize;
        for (i, &n) in counts.iter().enumerate() {
            let (x, y) = ((i % width) as i64 + CLIP.x0, (i / width) as i64 + CLIP.y0);
            // No center lies exactly on these edges, so owning is being strictly inside.
            assert_eq!(n == 1, strictly_inside(t, x, y), "({x}, {y})");
        }
    }

    #[test]
    fn runs_agree_with_brute_force_and_neighbours_on_many_triangles() {
        // Corners on a 1/8 px grid put many centers exactly on edges.
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = |range: f64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            ((seed % 1_000_000) as f64 / 1_000_000.0 * range * 8.0).round() / 8.0
        };
        for k in 0..300 {
            let size = if k % 2 == 0 { 12.0 } else { 44.0 };
            let t = [(); 3].map(|_| fixed(next(size) - 2.0, next(size) - 2.0));
            let counts = ownership(&[t]);
            // Its neighbour across each edge, mirrored through the edge's midpoint: together
            // they own every center on the shared edge exactly once.
            let width = (CLIP.x1 - CLIP.x0) as usize;
            for (i, &n) in counts.iter().enumerate() {
                let (x, y) = ((i % width) as i64 + CLIP.x0, (i / width) as i64 + CLIP.y0);
                if strictly_inside(t, x, y) {
                    assert_eq!(n, 1, "triangle {k} {t:?}: ({x}, {y})");
                }
            }
            for e in 0..3 {
                let (p, q, r) = (t[e], t[(e + 1) % 3], t[(e + 2) % 3]);
                let mirrored = [p[0] + q[0] - r[0], p[1] + q[1] - r[1]];
                let pair = ownership(&[t, [q, p, mirrored]]);
                for (i, &n) in pair.iter().enumerate() {
                    let (x, y) = ((i % width) as i64 + CLIP.x0, (i / width) as i64 + CLIP.y0);
                    assert!(n <= 1, "triangle {k} edge {e}: ({x}, {y}) owned {n} times");
                    let on_edge = {
                        let c = [x * SUBPIXEL + SUBPIXEL / 2, y * SUBPIXEL + SUBPIXEL / 2];
                        let cross = (q[0] - p[0]) * (c[1] - p[1]) - (q[1] - p[1]) * (c[0] - p[0]);
                        let within =
                            (c[0] - p[0]) * (c[0] - q[0]) + (c[1] - p[1]) * (c[1] - q[1]) < 0;
                        cross == 0 && within
                    };
                    if on_edge {
                        assert_eq!(n, 1, "triangle {k} edge {e}: ({x}, {y}) on the edge");
                    }
                }
            }
        }
    }

    #[test]
    fn huge_triangles_split_their_shared_edge_exactly_too() {
        // A diagonal through every center (i + 0.5, i + 0.5), from corners near the coordinate
        // limit: the edge functions reach 2⁵⁷, far beyond what a float holds exactly.
        let far = 900_000.5;
        let (p, q) = (fixed(-far, -far), fixed(far, far));
        let upper = [p, q, fixed(far, -far)];
        let lower = [p, fixed(-far, far), q];
        let counts = ownership(&[upper, lower]);
        assert!(counts.iter().all(|&n| n == 1), "every center exactly once");
        let alone = ownership(&[upper]);
        let width = (CLIP.x1 - CLIP.x0) as usize;
        let diagonal: Vec<u32> = (0..width).map(|i| alone[i * width + i]).collect();
        // The diagonal's centers all go to the same side.
        assert!(diagonal.iter().all(|&n| n == diagonal[0]), "{diagonal:?}");
    }

    #[test]
    fn a_flipped_triangle_owns_the_same_centers() {
        let t = [fixed(3.5, 2.0), fixed(25.0, 9.5), fixed(6.0, 30.5)];
        assert_eq!(ownership(&[t]), ownership(&[[t[0], t[2], t[1]]]));
    }

    #[test]
    fn runs_stay_inside_the_clip_and_degenerate_triangles_own_nothing() {
        let big = [
            fixed(-100.0, -100.0),
            fixed(300.0, -90.0),
            fixed(-50.0, 400.0),
        ];
        let clip = PixelRect {
            x0: 5,
            y0: 7,
            x1: 9,
            y1: 10,
        };
        let mut owned = 0;
        for_each_run(big, clip, |row, start, end| {
            assert!((7..10).contains(&row));
            assert_eq!((start, end), (5, 9));
            owned += end - start;
        });
        assert_eq!(owned, 12);
        let flat = [fixed(0.0, 0.0), fixed(10.0, 10.0), fixed(20.0, 20.0)];
        assert!(ownership(&[flat]).iter().all(|&n| n == 0));
    }

    #[test]
    fn coordinates_out_of_range_are_refused() {
        assert!(to_fixed(crate::geom::Point::new(MAX_COORD_PX, -MAX_COORD_PX)).is_some());
        assert!(to_fixed(crate::geom::Point::new(MAX_COORD_PX * 2.0, 0.0)).is_none());
        assert!(to_fixed(crate::geom::Point::new(f64::NAN, 0.0)).is_none());
        assert_eq!(
            to_fixed(crate::geom::Point::new(0.3, -0.3)),
            Some([77, -77])
        );
    }

    #[test]
    fn float_to_integer_helpers_match_the_standard_ones() {
        let values = [
            0.0,
            0.49999999999999994,
            0.5,
            1.5,
            2.5,
            -0.5,
            -1.5,
            -2.4,
            7.0,
            -7.0,
            1e15 + 0.5,
            -3.7e17,
            123.456,
            -0.0001,
        ];
        for v in values {
            assert_eq!(round_i64(v), v.round() as i64, "round {v}");
            assert_eq!(floor_i64(v), v.floor() as i64, "floor {v}");
        }
        assert_eq!(round_i64(f64::NAN), 0);
        assert_eq!(floor_i64(1e300), MAX_ROUNDED as i64);
    }

    #[test]
    fn near_horizontal_and_long_edges_are_decided_exactly() {
        // Edges with tiny dy across a wide clip: the column estimate is huge or far off.
        let wide = PixelRect {
            x0: -2000,
            y0: -3,
            x1: 2000,
            y1: 5,
        };
        let t = [fixed(-1900.3, 0.2), fixed(1900.9, 0.9), fixed(3.1, 3.7)];
        let mut owned = Vec::new();
        for_each_run(t, wide, |row, start, end| owned.push((row, start, end)));
        for y in wide.y0..wide.y1 {
            let expected: Vec<i64> = (wide.x0..wide.x1)
                .filter(|&x| strictly_inside(t, x, y))
                .collect();
            let got: Vec<i64> = owned
                .iter()
                .filter(|r| r.0 == y)
                .flat_map(|r| r.1..r.2)
                .collect();
            assert_eq!(got, expected, "row {y}");
        }
    }
}
