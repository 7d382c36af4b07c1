//! Marching squares on an [`AlphaGrid`].
//!
//! In: the grid and the alpha threshold. Out: every closed contour of the iso level
//! `threshold − ISO_OFFSET`, as a ring of canvas-pixel points with sub-pixel positions
//! (linear interpolation along cell edges), oriented with the opaque side on the right on
//! screen (outer rings positive shoelace area, holes negative), in raster order of their first
//! point, and each with the ring immediately enclosing it.

use super::dilate::AlphaGrid;
use crate::geom::Point;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The iso level sits this far below the threshold. Alpha is an integer, so no sample ever
/// equals the level: contours never pass through a sample and never touch each other.
const ISO_OFFSET: f64 = 0.5;

/// Grid samples sit at pixel centers.
const PIXEL_CENTER: f64 = 0.5;

/// Runs of equal samples are skipped this many at a time when looking for crossings.
const SKIP_STRIDE: usize = 16;

/// A traced contour.
pub(super) struct Ring {
    /// Canvas pixels; closed implicitly. Starts at the ring's first crossing in raster order.
    pub points: Vec<Point>,
    /// The ring bounds a transparent region inside an opaque one.
    pub is_hole: bool,
    /// Index of the ring immediately enclosing this one; `None` for top-level outer rings.
    /// Always earlier in the list than the ring itself.
    pub container: Option<usize>,
}

// Cell edges, numbered clockwise on screen from the top. Corner k of a cell sits between edge
// k − 1 and edge k: corners are top-left, top-right, bottom-right, bottom-left.
const TOP: u8 = 0;
const RIGHT: u8 = 1;
const BOTTOM: u8 = 2;
const LEFT: u8 = 3;
const NO_EDGE: u8 = u8::MAX;

/// Table index bit set when a saddle cell's center is inside (its inside corners connect).
const SADDLE_JOINED: usize = 16;

/// `EXIT[case | joined][entry]` is the edge by which the contour leaves a cell it entered by
/// `entry`, or `NO_EDGE`. `case` has bit k set when corner k is inside.
const EXIT: [[u8; 4]; 32] = exit_table();

/// Builds [`EXIT`] with the opaque side on the right: a contour enters right after the last
/// corner of a run of inside corners (clockwise) and leaves right before the first one.
const fn exit_table() -> [[u8; 4]; 32] {
    let mut table = [[NO_EDGE; 4]; 32];
    let mut index = 0;
    while index < 32 {
        let case = index & 15;
        let joined = index & SADDLE_JOINED != 0;
        let saddle = is_saddle(case);
        let mut k = 0;
        while k < 4 {
            let inside = (case >> k) & 1 == 1;
            let next_inside = (case >> ((k + 1) % 4)) & 1 == 1;
            if inside && !next_inside {
                let exit = if saddle && joined {
                    // The outside corners are the isolated ones: cut off the next corner.
                    (k + 1) % 4
                } else {
                    let mut first = k;
                    while (case >> ((first + 3) % 4)) & 1 == 1 {
                        first = (first + 3) % 4;
                    }
                    (first + 3) % 4
                };
                table[index][k] = exit as u8;
            }
            k += 1;
        }
        index += 1;
    }
    table
}

/// Whether only diagonally opposite corners are inside.
const fn is_saddle(case: usize) -> bool {
    case == 0b0101 || case == 0b1010
}

/// Traces every contour of the grid at the level just below `threshold` (≥ 1).
pub(super) fn trace_rings(grid: &AlphaGrid, threshold: u8) -> Vec<Ring> {
    let mut rings: Vec<Ring> = Vec::new();
    let mut log = CrossingLog::new(grid.height);
    for gy in 1..grid.height.saturating_sub(1) {
        let row = &grid.values[gy * grid.width..(gy + 1) * grid.width];
        log.begin_row(gy);
        // The nearest crossing to the left tells which region a new ring starts in.
        let mut last_ring: Option<usize> = None;
        let mut gx = 0;
        while let Some(x) = next_crossing(row, gx, threshold) {
            let ring = match log.take(x) {
                Some(ring) => ring,
                None => {
                    let id = rings.len();
                    let is_hole = row[x] >= threshold;
                    let container = last_ring.and_then(|left| {
                        // A ring of the other kind to the left bounds the region we start in;
                        // one of the same kind is a sibling, sharing our container.
                        if rings[left].is_hole != is_hole {
                            Some(left)
                        } else {
                            rings[left].container
                        }
                    });
                    let points = walk_ring(grid, threshold, x, gy, id, &mut log);
                    rings.push(Ring {
                        points,
                        is_hole,
                        container,
                    });
                    id
                }
            };
            last_ring = Some(ring);
            gx = x + 1;
        }
    }
    rings
}

/// Which ring each horizontal crossing belongs to. A ring is found at its first crossing in
/// raster order; its other crossings must then be recognized as traced when the scan gets there.
struct CrossingLog {
    /// Per grid row below the scan line: (x, ring) of traced crossings, in no order.
    later_rows: Vec<Vec<(usize, usize)>>,
    /// The scan line's crossings from rings started on earlier rows, sorted, and how many the
    /// scan has passed.
    current: Vec<(usize, usize)>,
    passed: usize,
    /// The scan line's crossings from rings started on it (always right of their start).
    started_here: BinaryHeap<Reverse<(usize, usize)>>,
    row: usize,
}

impl CrossingLog {
    fn new(rows: usize) -> Self {
        CrossingLog {
            later_rows: vec![Vec::new(); rows],
            current: Vec::new(),
            passed: 0,
            started_here: BinaryHeap::new(),
            row: 0,
        }
    }

    fn begin_row(&mut self, y: usize) {
        self.row = y;
        self.current = std::mem::take(&mut self.later_rows[y]);
        self.current.sort_unstable();
        self.passed = 0;
        self.started_here.clear();
    }

    fn record(&mut self, x: usize, y: usize, ring: usize) {
        if y == self.row {
            self.started_here.push(Reverse((x, ring)));
        } else {
            self.later_rows[y].push((x, ring));
        }
    }

    /// The ring already traced through crossing x of the scan line, if any. Must be asked in
    /// increasing x, for every crossing.
    fn take(&mut self, x: usize) -> Option<usize> {
        if let Some(&(cx, ring)) = self.current.get(self.passed) {
            if cx == x {
                self.passed += 1;
                return Some(ring);
            }
        }
        match self.started_here.peek() {
            Some(&Reverse((hx, ring))) if hx == x => {
                self.started_here.pop();
                Some(ring)
            }
            _ => None,
        }
    }
}

/// First x ≥ `from` where samples x and x + 1 of `row` lie on different sides of the level.
fn next_crossing(row: &[u8], from: usize, threshold: u8) -> Option<usize> {
    let mut x = from;
    while x + 1 < row.len() {
        if x + SKIP_STRIDE < row.len() && row[x..x + SKIP_STRIDE] == row[x + 1..x + 1 + SKIP_STRIDE]
        {
            x += SKIP_STRIDE;
            continue;
        }
        if (row[x] >= threshold) != (row[x + 1] >= threshold) {
            return Some(x);
        }
        x += 1;
    }
    None
}

/// Follows the contour through horizontal edge (x, y)–(x + 1, y) until it closes, logging the
/// other horizontal edges it crosses as belonging to ring `id`.
fn walk_ring(
    grid: &AlphaGrid,
    threshold: u8,
    x: usize,
    y: usize,
    id: usize,
    log: &mut CrossingLog,
) -> Vec<Point> {
    let level = f64::from(threshold) - ISO_OFFSET;
    let mut points = vec![edge_point(grid, level, x, y, TOP)];
    // With the opaque side on the right, the contour runs down when the left sample is opaque.
    let (mut cx, mut cy, mut entry) = if grid.at(x, y) >= threshold {
        (x, y, TOP)
    } else {
        (x, y - 1, BOTTOM)
    };
    loop {
        let exit = cell_exit(grid, threshold, cx, cy, entry);
        if exit == NO_EDGE {
            debug_assert!(false, "contour lost in cell ({cx}, {cy})");
            break;
        }
        let horizontal_edge = match exit {
            TOP => Some((cx, cy)),
            BOTTOM => Some((cx, cy + 1)),
            _ => None,
        };
        if horizontal_edge == Some((x, y)) {
            break;
        }
        points.push(edge_point(grid, level, cx, cy, exit));
        if let Some((ex, ey)) = horizontal_edge {
            log.record(ex, ey, id);
        }
        // Crossing edges never lie on the all-zero frame, so the neighbor cell exists.
        (cx, cy, entry) = match exit {
            TOP => (cx, cy - 1, BOTTOM),
            RIGHT => (cx + 1, cy, LEFT),
            BOTTOM => (cx, cy + 1, TOP),
            _ => (cx - 1, cy, RIGHT),
        };
    }
    points
}

/// The edge by which the contour leaves cell (cx, cy) after entering by `entry`.
fn cell_exit(grid: &AlphaGrid, threshold: u8, cx: usize, cy: usize, entry: u8) -> u8 {
    let corners = [
        grid.at(cx, cy),
        grid.at(cx + 1, cy),
        grid.at(cx + 1, cy + 1),
        grid.at(cx, cy + 1),
    ];
    let case = corners
        .iter()
        .enumerate()
        .fold(0, |case, (k, &v)| case | (usize::from(v >= threshold) << k));
    let saddle = is_saddle(case);
    // Saddles follow the cell-center average: mean ≥ threshold − 1/2 ⇔ sum ≥ 4·threshold − 2.
    let joined = saddle && {
        let sum: u32 = corners.iter().map(|&v| u32::from(v)).sum();
        sum >= 4 * u32::from(threshold) - 2
    };
    let index = case | if joined { SADDLE_JOINED } else { 0 };
    EXIT[index][usize::from(entry)]
}

/// Where the level crosses edge `edge` of cell (cx, cy), in canvas pixels.
fn edge_point(grid: &AlphaGrid, level: f64, cx: usize, cy: usize, edge: u8) -> Point {
    // Always interpolate from the left/top sample so both cells sharing an edge agree exactly.
    let (from, to) = match edge {
        TOP => ((cx, cy), (cx + 1, cy)),
        RIGHT => ((cx + 1, cy), (cx + 1, cy + 1)),
        BOTTOM => ((cx, cy + 1), (cx + 1, cy + 1)),
        _ => ((cx, cy), (cx, cy + 1)),
    };
    let v_from = f64::from(grid.at(from.0, from.1));
    let v_to = f64::from(grid.at(to.0, to.1));
    let t = (level - v_from) / (v_to - v_from);
    let canvas = |g: usize| g as f64 - grid.margin as f64 + PIXEL_CENTER;
    Point::new(
        canvas(from.0) + t * (to.0 as f64 - from.0 as f64),
        canvas(from.1) + t * (to.1 as f64 - from.1 as f64),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_mixed_case_enters_and_leaves_consistently() {
        for (index, row) in EXIT.iter().enumerate() {
            let case = index & 15;
            let entries: Vec<usize> = (0..4).filter(|&e| row[e] != NO_EDGE).collect();
            let exits: Vec<u8> = entries.iter().map(|&e| row[e]).collect();
            // Each crossed edge is used exactly once, either as entry or as exit.
            let crossed = (0..4)
                .filter(|&e| ((case >> e) & 1) != ((case >> ((e + 1) % 4)) & 1))
                .count();
            assert_eq!(entries.len() * 2, crossed, "case {index}");
            for (&entry, &exit) in entries.iter().zip(&exits) {
                assert_ne!(usize::from(exit), entry);
                assert!(!entries.contains(&usize::from(exit)));
            }
        }
    }
}
