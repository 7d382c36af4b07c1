//! Simplification of closed rings that keeps them simple, disjoint and nested as they were.
//!
//! In: rings in canvas pixels that are simple, mutually disjoint (further apart than
//! [`CONTACT_MARGIN_PX`]) and have at least 3 points, and a tolerance in pixels. Out: for each
//! ring, a subsequence of its points that starts at the same point, stays within the tolerance
//! of the ring (and the ring within the tolerance of it), has at least 3 points and the
//! orientation of the ring; the simplified rings are again simple and mutually disjoint, and
//! each lies inside exactly the rings it was inside before.
//!
//! Douglas–Peucker first; then, while a simplified segment (a chord) touches another chord or
//! sweeps over a point of another ring, the farthest point of its span is put back (and
//! Douglas–Peucker rerun on both halves). Conflicts are found with a spatial hash of the chords,
//! so each round costs about linear time.

use crate::geom::{point_segment_distance, ring_signed_area2, triangle_area2 as orient, Point};

/// Chords closer than this are treated as touching. Traced rings are far further apart than
/// this (interpolated crossings are at least 1/510 px from any sample), so only conflicts the
/// simplification created are caught, with room for rounding.
const CONTACT_MARGIN_PX: f64 = 1e-7;

/// Smallest side of a spatial-hash cell, so a dense cluster of tiny chords can't blow up the
/// number of cells.
const MIN_CELL_PX: f64 = 1.0;

/// Fewest points a ring can keep and still enclose an area.
const MIN_RING_POINTS: usize = 3;

/// A straight segment of a simplified ring, from one kept point to the next.
struct Chord {
    ring: usize,
    /// Index of the first point in the ring.
    start: usize,
    /// How many steps along the ring the chord spans (≥ 1).
    steps: usize,
    a: Point,
    b: Point,
    /// The dropped point farthest from the chord, and its distance; `None` when nothing is
    /// dropped (the chord is a traced segment).
    farthest: Option<(usize, f64)>,
}

impl Chord {
    fn deviation(&self) -> f64 {
        self.farthest.map_or(0.0, |(_, d)| d)
    }
}

/// Simplifies `rings` to `tolerance` (see the module doc for what is guaranteed).
pub(super) fn simplify_rings(rings: &[Vec<Point>], tolerance: f64) -> Vec<Vec<Point>> {
    let mut keep: Vec<Vec<bool>> = rings
        .iter()
        .map(|ring| douglas_peucker_ring(ring, tolerance))
        .collect();
    let area_signs: Vec<bool> = rings.iter().map(|r| ring_signed_area2(r) > 0.0).collect();
    loop {
        let (chords, first_chord) = chords_of(rings, &keep);
        let mut flagged = find_conflicts(rings, &chords, &first_chord);
        flag_flipped_rings(&chords, &first_chord, &area_signs, &mut flagged);
        let mut refined = false;
        for (chord, _) in chords.iter().zip(&flagged).filter(|(_, &f)| f) {
            if let Some((far, _)) = chord.farthest {
                let ring = &rings[chord.ring];
                let mid = chord.start + (far + ring.len() - chord.start) % ring.len();
                keep[chord.ring][far] = true;
                refine_span(ring, &mut keep[chord.ring], chord.start, mid, tolerance);
                refine_span(
                    ring,
                    &mut keep[chord.ring],
                    mid,
                    chord.start + chord.steps,
                    tolerance,
                );
                refined = true;
            }
        }
        // Traced segments never conflict, so some flagged chord always has a point to put back;
        // stopping otherwise only guards against looping forever.
        if !refined {
            debug_assert!(!flagged.contains(&true), "unresolvable conflict");
            break;
        }
    }
    rings
        .iter()
        .zip(&keep)
        .map(|(ring, keep)| {
            ring.iter()
                .zip(keep)
                .filter(|(_, &k)| k)
                .map(|(p, _)| *p)
                .collect()
        })
        .collect()
}

/// Which points of a closed ring Douglas–Peucker keeps: anchored at point 0 and the point
/// farthest from it, topped up to [`MIN_RING_POINTS`].
fn douglas_peucker_ring(ring: &[Point], tolerance: f64) -> Vec<bool> {
    let n = ring.len();
    if n <= MIN_RING_POINTS {
        return vec![true; n];
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    let opposite = (1..n)
        .map(|i| (i, (ring[i] - ring[0]).norm_squared()))
        .fold(
            (1, f64::NEG_INFINITY),
            |best, c| if c.1 > best.1 { c } else { best },
        );
    let m = opposite.0;
    keep[m] = true;
    refine_span(ring, &mut keep, 0, m, tolerance);
    refine_span(ring, &mut keep, m, n, tolerance);
    if keep.iter().filter(|&&k| k).count() < MIN_RING_POINTS {
        // Both halves are within tolerance of the same chord: keep the farthest point anyway.
        let candidates = [farthest_in_span(ring, 0, m), farthest_in_span(ring, m, n)];
        if let Some((far, _)) = candidates.into_iter().flatten().fold(None, farther) {
            keep[far] = true;
        }
    }
    keep
}

/// Douglas–Peucker on the span of the ring from index `from` to index `to` (which may run past
/// the end and wrap), marking in `keep` every point needed to stay within `tolerance`.
fn refine_span(ring: &[Point], keep: &mut [bool], from: usize, to: usize, tolerance: f64) {
    // An explicit stack: traced rings can be long enough to overflow a recursive one.
    let mut pending = vec![(from, to)];
    while let Some((i, j)) = pending.pop() {
        if let Some((far, distance)) = farthest_in_span(ring, i, j) {
            if distance > tolerance {
                keep[far] = true;
                let mid = i + (far + ring.len() - i % ring.len()) % ring.len();
                pending.push((i, mid));
                pending.push((mid, j));
            }
        }
    }
}

/// The point strictly between ring indices `i` and `j` (j may exceed the length and wrap)
/// farthest from segment i–j, as (index, distance); the first one on ties.
fn farthest_in_span(ring: &[Point], i: usize, j: usize) -> Option<(usize, f64)> {
    let n = ring.len();
    let (a, b) = (ring[i % n], ring[j % n]);
    ((i + 1)..j)
        .map(|s| (s % n, point_segment_distance(ring[s % n], a, b)))
        .fold(None, farther)
}

/// Fold step keeping the (index, distance) with the larger distance, the earlier one on ties.
fn farther(best: Option<(usize, f64)>, candidate: (usize, f64)) -> Option<(usize, f64)> {
    match best {
        Some((_, d)) if d >= candidate.1 => best,
        _ => Some(candidate),
    }
}

/// The chords of every ring, ring after ring, and the index of each ring's first chord (plus
/// one past the last).
fn chords_of(rings: &[Vec<Point>], keep: &[Vec<bool>]) -> (Vec<Chord>, Vec<usize>) {
    let mut chords = Vec::new();
    let mut first_chord = Vec::with_capacity(rings.len() + 1);
    for (r, (ring, keep)) in rings.iter().zip(keep).enumerate() {
        first_chord.push(chords.len());
        let n = ring.len();
        let kept: Vec<usize> = (0..n).filter(|&i| keep[i]).collect();
        for (k, &start) in kept.iter().enumerate() {
            let end = kept.get(k + 1).copied().unwrap_or(kept[0] + n);
            chords.push(Chord {
                ring: r,
                start,
                steps: end - start,
                a: ring[start],
                b: ring[end % n],
                farthest: farthest_in_span(ring, start, end),
            });
        }
    }
    first_chord.push(chords.len());
    (chords, first_chord)
}

/// Chords that touch another chord, or sweep over a point of another ring, flagged by index.
fn find_conflicts(rings: &[Vec<Point>], chords: &[Chord], first_chord: &[usize]) -> Vec<bool> {
    let mut flagged = vec![false; chords.len()];
    let rules = ConflictRules {
        rings,
        chords,
        first_chord,
    };
    let (mut segments, mut vertices) = (Vec::new(), Vec::new());
    for cell in SpatialHash::new(chords).cells() {
        segments.clear();
        vertices.clear();
        for &code in cell {
            let chord = (code / 2) as usize;
            if code % 2 == SEGMENT_ITEM {
                segments.push(chord);
            } else {
                vertices.push(chord);
            }
        }
        for (k, &c) in segments.iter().enumerate() {
            for &d in &segments[k + 1..] {
                if rules.touch(c, d) {
                    flagged[c] = true;
                    flagged[d] = true;
                }
            }
        }
        for &v in &vertices {
            for &c in &segments {
                if rules.sweeps_over(c, v) {
                    flagged[c] = true;
                }
            }
        }
    }
    flagged
}

/// What counts as a conflict between chords.
struct ConflictRules<'a> {
    rings: &'a [Vec<Point>],
    chords: &'a [Chord],
    first_chord: &'a [usize],
}

impl ConflictRules<'_> {
    fn next_in_ring(&self, c: usize) -> usize {
        let ring = self.chords[c].ring;
        if c + 1 == self.first_chord[ring + 1] {
            self.first_chord[ring]
        } else {
            c + 1
        }
    }

    /// Whether chords c and d meet anywhere but at a point they share as neighbors.
    fn touch(&self, c: usize, d: usize) -> bool {
        let (c_chord, d_chord) = (&self.chords[c], &self.chords[d]);
        if self.next_in_ring(c) == d {
            folds_back(c_chord.a, c_chord.b, d_chord.b)
        } else if self.next_in_ring(d) == c {
            folds_back(d_chord.a, d_chord.b, c_chord.b)
        } else {
            segments_touch(c_chord.a, c_chord.b, d_chord.a, d_chord.b)
        }
    }

    /// Whether chord c, with the span it replaces, encloses the first point of chord v of
    /// another ring: that point's side of ring c would change.
    fn sweeps_over(&self, c: usize, v: usize) -> bool {
        let (chord, p) = (&self.chords[c], self.chords[v].a);
        chord.ring != self.chords[v].ring
            && chord.farthest.is_some()
            // The loop lies within the chord's deviation of it: a cheap test first.
            && point_segment_distance(p, chord.a, chord.b) <= chord.deviation() + CONTACT_MARGIN_PX
            && point_in_span_loop(p, &self.rings[chord.ring], chord.start, chord.steps)
    }
}

/// A simplified ring whose orientation flipped gets its widest chord refined.
fn flag_flipped_rings(
    chords: &[Chord],
    first_chord: &[usize],
    area_signs: &[bool],
    flagged: &mut [bool],
) {
    for (r, &positive) in area_signs.iter().enumerate() {
        let range = first_chord[r]..first_chord[r + 1];
        let area2: f64 = chords[range.clone()]
            .iter()
            .map(|c| c.a.x * c.b.y - c.b.x * c.a.y)
            .sum();
        if (area2 > 0.0) != positive || area2 == 0.0 {
            let widest =
                range.max_by(|&i, &j| chords[i].deviation().total_cmp(&chords[j].deviation()));
            if let Some(c) = widest {
                flagged[c] = true;
            }
        }
    }
}

/// Item kinds in the spatial hash: a chord (fattened by its deviation) or its first point.
const SEGMENT_ITEM: u32 = 0;
const VERTEX_ITEM: u32 = 1;

/// Cells of a uniform grid per chord, relative to the mean chord length: big enough that most
/// chords fall in one or two cells per axis, small enough that cells hold few chords.
const CELL_PER_CHORD_LENGTH: f64 = 2.0;

/// At most this many grid cells per chord, so a few chords spread over a big canvas don't make
/// an enormous, empty grid.
const MAX_CELLS_PER_CHORD: usize = 4;

/// Every chord (fattened by its deviation, so a point inside its swept loop shares a cell
/// with it) and every chord's first point, bucketed by grid cell. Items are
/// 2 × chord + kind, grouped by cell (a counting sort).
struct SpatialHash {
    layout: GridLayout,
    /// Items of cell c are `items[first[c]..first[c + 1]]`.
    first: Vec<u32>,
    items: Vec<u32>,
}

impl SpatialHash {
    fn new(chords: &[Chord]) -> Self {
        let layout = GridLayout::fit(chords);
        let mut first = vec![0u32; layout.cols * layout.rows + 1];
        let mut cells = Vec::new();
        for chord in chords {
            layout.chord_cells(chord, &mut cells);
            for &cell in &cells {
                first[cell + 1] += 1;
            }
            first[layout.cell_of(chord.a) + 1] += 1;
        }
        for c in 1..first.len() {
            first[c] += first[c - 1];
        }
        let mut fill = first.clone();
        let mut items = vec![0; first[first.len() - 1] as usize];
        let mut put = |cell: usize, item: u32| {
            items[fill[cell] as usize] = item;
            fill[cell] += 1;
        };
        for (c, chord) in chords.iter().enumerate() {
            let code = 2 * c as u32;
            layout.chord_cells(chord, &mut cells);
            for &cell in &cells {
                put(cell, code + SEGMENT_ITEM);
            }
            put(layout.cell_of(chord.a), code + VERTEX_ITEM);
        }
        SpatialHash {
            layout,
            first,
            items,
        }
    }

    /// The items of every non-empty cell.
    fn cells(&self) -> impl Iterator<Item = &[u32]> {
        (0..self.layout.cols * self.layout.rows)
            .map(|c| &self.items[self.first[c] as usize..self.first[c + 1] as usize])
            .filter(|items| !items.is_empty())
    }
}

/// A uniform grid covering every chord with room for its fattening.
struct GridLayout {
    origin: Point,
    cell: f64,
    cols: usize,
    rows: usize,
}

impl GridLayout {
    fn fit(chords: &[Chord]) -> Self {
        let pad = chords.iter().map(Chord::deviation).fold(0.0, f64::max) + CONTACT_MARGIN_PX;
        let (mut lo, mut hi) = (
            Point::new(f64::MAX, f64::MAX),
            Point::new(f64::MIN, f64::MIN),
        );
        let mut total_length = 0.0;
        for chord in chords {
            for p in [chord.a, chord.b] {
                lo = Point::new(lo.x.min(p.x), lo.y.min(p.y));
                hi = Point::new(hi.x.max(p.x), hi.y.max(p.y));
            }
            total_length += (chord.b - chord.a).norm();
        }
        if chords.is_empty() {
            (lo, hi) = (Point::origin(), Point::origin());
        }
        let (width, height) = (hi.x - lo.x + 2.0 * pad, hi.y - lo.y + 2.0 * pad);
        let mean_length = total_length / chords.len().max(1) as f64;
        let mut cell = (CELL_PER_CHORD_LENGTH * mean_length).max(MIN_CELL_PX);
        let max_cells = (MAX_CELLS_PER_CHORD * chords.len()).max(1) as f64;
        let cells = (width / cell).ceil().max(1.0) * (height / cell).ceil().max(1.0);
        if cells > max_cells {
            cell *= (cells / max_cells).sqrt();
        }
        GridLayout {
            origin: Point::new(lo.x - pad, lo.y - pad),
            cell,
            cols: ((width / cell).ceil() as usize).max(1),
            rows: ((height / cell).ceil() as usize).max(1),
        }
    }

    /// Column and row of the cell holding (x, y), clamped to the grid (which only merges
    /// outside points into border cells: never a missed pair).
    fn col_row(&self, x: f64, y: f64) -> (usize, usize) {
        let index = |v: f64, origin: f64, count: usize| {
            (((v - origin) / self.cell).floor().max(0.0) as usize).min(count - 1)
        };
        (
            index(x, self.origin.x, self.cols),
            index(y, self.origin.y, self.rows),
        )
    }

    fn cell_of(&self, p: Point) -> usize {
        let (col, row) = self.col_row(p.x, p.y);
        row * self.cols + col
    }

    /// The cells `chord`, fattened by its deviation, overlaps (a superset), each once.
    fn chord_cells(&self, chord: &Chord, out: &mut Vec<usize>) {
        out.clear();
        let pad = chord.deviation() + CONTACT_MARGIN_PX;
        // Pieces at most a cell long: each piece's box covers a few cells, so a long diagonal
        // chord doesn't claim its whole bounding box.
        let pieces = ((chord.b - chord.a).norm() / self.cell).ceil().max(1.0) as usize;
        for piece in 0..pieces {
            let p = chord.a + (chord.b - chord.a) * (piece as f64 / pieces as f64);
            let q = chord.a + (chord.b - chord.a) * ((piece + 1) as f64 / pieces as f64);
            let (c0, r0) = self.col_row(p.x.min(q.x) - pad, p.y.min(q.y) - pad);
            let (c1, r1) = self.col_row(p.x.max(q.x) + pad, p.y.max(q.y) + pad);
            for row in r0..=r1 {
                out.extend((c0..=c1).map(|col| row * self.cols + col));
            }
        }
        if pieces > 1 {
            out.sort_unstable();
            out.dedup();
        }
    }
}

/// Whether consecutive chords a–b and b–c overlap beyond their shared point.
fn folds_back(a: Point, b: Point, c: Point) -> bool {
    point_segment_distance(c, a, b) < CONTACT_MARGIN_PX
        || point_segment_distance(a, b, c) < CONTACT_MARGIN_PX
}

/// Whether segments a–b and c–d cross or come within [`CONTACT_MARGIN_PX`] of each other.
fn segments_touch(a: Point, b: Point, c: Point, d: Point) -> bool {
    let m = CONTACT_MARGIN_PX;
    if a.x.max(b.x) + m < c.x.min(d.x)
        || c.x.max(d.x) + m < a.x.min(b.x)
        || a.y.max(b.y) + m < c.y.min(d.y)
        || c.y.max(d.y) + m < a.y.min(b.y)
    {
        return false;
    }
    let opposite = |s: f64, t: f64| (s > 0.0 && t < 0.0) || (s < 0.0 && t > 0.0);
    let crossing =
        opposite(orient(a, b, c), orient(a, b, d)) && opposite(orient(c, d, a), orient(c, d, b));
    crossing
        || point_segment_distance(a, c, d) < m
        || point_segment_distance(b, c, d) < m
        || point_segment_distance(c, a, b) < m
        || point_segment_distance(d, a, b) < m
}

/// Even-odd test of `p` against the loop formed by `steps` steps of the ring from `start` and
/// the chord back.
fn point_in_span_loop(p: Point, ring: &[Point], start: usize, steps: usize) -> bool {
    let n = ring.len();
    let mut inside = false;
    for s in 0..=steps {
        let a = ring[(start + s) % n];
        let b = if s == steps {
            ring[start % n]
        } else {
            ring[(start + s + 1) % n]
        };
        if (a.y > p.y) != (b.y > p.y) {
            let x_cross = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x_cross {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::point_in_ring;

    fn pts(coords: &[(f64, f64)]) -> Vec<Point> {
        coords.iter().map(|&(x, y)| Point::new(x, y)).collect()
    }

    #[test]
    fn straight_runs_collapse_to_corners() {
        let mut square = Vec::new();
        for i in 0..10 {
            square.push((i as f64, 0.0));
        }
        for i in 0..10 {
            square.push((10.0, i as f64));
        }
        for i in 0..10 {
            square.push((10.0 - i as f64, 10.0));
        }
        for i in 0..10 {
            square.push((0.0, 10.0 - i as f64));
        }
        let out = simplify_rings(&[pts(&square)], 0.1);
        assert_eq!(
            out[0],
            pts(&[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)])
        );
    }

    #[test]
    fn flat_ring_keeps_three_points() {
        let sliver = pts(&[(0.0, 0.0), (5.0, -0.1), (10.0, 0.0), (5.0, 0.1)]);
        let out = simplify_rings(std::slice::from_ref(&sliver), 1.0);
        assert_eq!(out[0].len(), 3);
        assert_eq!(
            ring_signed_area2(&out[0]) > 0.0,
            ring_signed_area2(&sliver) > 0.0
        );
    }

    #[test]
    fn chord_does_not_swallow_a_ring_in_a_notch() {
        // A bar with a shallow notch in its top edge, and a small separate ring in the notch.
        // Plain Douglas–Peucker at tolerance 3 would cut the notch off, putting the small ring
        // inside the bar without any crossing.
        let bar = pts(&[
            (0.0, 0.0),
            (40.0, 0.0),
            (40.0, 2.0),
            (45.0, 2.0),
            (45.0, 0.0),
            (100.0, 0.0),
            (100.0, 10.0),
            (0.0, 10.0),
        ]);
        let speck = pts(&[(41.0, 0.5), (44.0, 0.5), (44.0, 1.5), (41.0, 1.5)]);
        let out = simplify_rings(&[bar, speck], 3.0);
        assert!(out[1].iter().all(|&p| !point_in_ring(p, &out[0])));
    }

    #[test]
    fn close_rings_do_not_cross_after_simplification() {
        // Two interleaved zigzags 0.2 px apart: dropping points of either makes them cross.
        let teeth = 20;
        let mut upper = Vec::new();
        let mut lower = Vec::new();
        for i in 0..=teeth {
            let x = i as f64 * 2.0;
            let y = if i % 2 == 0 { 0.0 } else { 1.0 };
            upper.push((x, y));
            lower.push((x, y + 0.2));
        }
        let mut top = upper.clone();
        top.push((40.0, -5.0));
        top.push((0.0, -5.0));
        let mut bottom: Vec<(f64, f64)> = lower.into_iter().rev().collect();
        bottom.push((0.0, 6.0));
        bottom.push((40.0, 6.0));
        let out = simplify_rings(&[pts(&top), pts(&bottom)], 2.0);
        for (i, p) in out[0].iter().enumerate() {
            let q = out[0][(i + 1) % out[0].len()];
            for (j, r) in out[1].iter().enumerate() {
                let s = out[1][(j + 1) % out[1].len()];
                assert!(!segments_touch(*p, q, *r, s));
            }
        }
    }
}
