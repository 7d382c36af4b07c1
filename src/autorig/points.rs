//! Point handles at extremities and spread over the shape: farthest-point sampling on the
//! geodesic distance inside the shape.
//!
//! In: a [`Shape`] (canvas px), a count and [`PointOptions`]. Out: that many points (canvas
//! px) at centers of inside pixels, in the order they were chosen.
//!
//! Distances are measured inside the shape on a grid of about `grid_side` cells across the
//! longer canvas side, by Dijkstra over 8-neighbours (a diagonal step only where both
//! orthogonal cells are inside, so paths never cut a corner of the outline). The first point is
//! the cell farthest from the cell nearest the shape's centroid (an extremity); each next one
//! is the cell farthest from all points chosen so far (Eldar et al. 1997, farthest point
//! strategy, with geodesic instead of Euclidean distance), so the first points land on the
//! tips of limbs and the rest spread evenly. Pieces of the shape not connected to the others
//! are at infinite distance and so get a point before any piece gets a second one.

use super::shape::Shape;
use crate::geom::Point;
use serde::{Deserialize, Serialize};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// How point handles are proposed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PointOptions {
    /// Grid cells across the longer side of the canvas for geodesic distances. Default 256.
    pub grid_side: u32,
}

impl Default for PointOptions {
    fn default() -> Self {
        PointOptions { grid_side: 256 }
    }
}

/// The grid that distances are measured on.
struct Grid {
    step: u32,
    columns: usize,
    rows: usize,
    inside: Vec<bool>,
}

impl Grid {
    fn new(shape: &Shape, grid_side: u32) -> Grid {
        let step = shape
            .width
            .max(shape.height)
            .div_ceil(grid_side.max(1))
            .max(1);
        let columns = shape.width.div_ceil(step) as usize;
        let rows = shape.height.div_ceil(step) as usize;
        let mut inside = vec![false; columns * rows];
        for r in 0..rows {
            for c in 0..columns {
                let (x, y) = (
                    (c as u32 * step + step / 2).min(shape.width - 1),
                    (r as u32 * step + step / 2).min(shape.height - 1),
                );
                inside[r * columns + c] = shape.inside[(y * shape.width + x) as usize];
            }
        }
        Grid {
            step,
            columns,
            rows,
            inside,
        }
    }

    /// The center of the pixel that represents cell `i`, canvas px.
    fn point(&self, i: usize, shape: &Shape) -> Point {
        let (c, r) = (i % self.columns, i / self.columns);
        let x = (c as u32 * self.step + self.step / 2).min(shape.width - 1);
        let y = (r as u32 * self.step + self.step / 2).min(shape.height - 1);
        Point::new(x as f64 + 0.5, y as f64 + 0.5)
    }

    /// Geodesic distances (px) from `source`, lowering `best` where shorter.
    fn dijkstra_min(&self, source: usize, best: &mut [f64]) {
        let mut dist = vec![f64::INFINITY; self.inside.len()];
        let mut heap = BinaryHeap::new();
        dist[source] = 0.0;
        heap.push(Reverse((0u64, source)));
        let step = self.step as f64;
        let diagonal = step * std::f64::consts::SQRT_2;
        while let Some(Reverse((d_bits, i))) = heap.pop() {
            let d = f64::from_bits(d_bits);
            if d > dist[i] {
                continue;
            }
            let (c, r) = ((i % self.columns) as i64, (i / self.columns) as i64);
            for (dc, dr) in [
                (-1, 0),
                (1, 0),
                (0, -1),
                (0, 1),
                (-1, -1),
                (1, -1),
                (-1, 1),
                (1, 1),
            ] {
                let (nc, nr) = (c + dc, r + dr);
                if nc < 0 || nr < 0 || nc >= self.columns as i64 || nr >= self.rows as i64 {
                    continue;
                }
                let j = nr as usize * self.columns + nc as usize;
                if !self.inside[j] {
                    continue;
                }
                let is_diagonal = dc != 0 && dr != 0;
                if is_diagonal
                    && !(self.inside[r as usize * self.columns + nc as usize]
                        && self.inside[nr as usize * self.columns + c as usize])
                {
                    continue;
                }
                let nd = d + if is_diagonal { diagonal } else { step };
                if nd < dist[j] {
                    dist[j] = nd;
                    // Non-negative floats order like their bit patterns.
                    heap.push(Reverse((nd.to_bits(), j)));
                }
            }
        }
        for (b, d) in best.iter_mut().zip(dist) {
            *b = b.min(d);
        }
    }
}

/// The inside cell with the largest value (infinite first), lowest index on ties.
fn farthest(inside: &[bool], distance: &[f64]) -> Option<usize> {
    (0..inside.len())
        .filter(|&i| inside[i])
        .fold(None, |best: Option<usize>, i| match best {
            Some(b) if distance[b] >= distance[i] => Some(b),
            _ => Some(i),
        })
}

/// `count` point handles by geodesic farthest-point sampling.
pub fn propose_points(shape: &Shape, count: usize, options: &PointOptions) -> Vec<Point> {
    if count == 0 {
        return Vec::new();
    }
    let grid = Grid::new(shape, options.grid_side);
    let cells: Vec<usize> = (0..grid.inside.len()).filter(|&i| grid.inside[i]).collect();
    if cells.is_empty() {
        return Vec::new();
    }
    let centroid = cells.iter().fold(crate::geom::Vec2::zeros(), |s, &i| {
        s + grid.point(i, shape).coords
    }) / cells.len() as f64;
    let seed = *cells
        .iter()
        .min_by(|&&a, &&b| {
            (grid.point(a, shape).coords - centroid)
                .norm()
                .total_cmp(&(grid.point(b, shape).coords - centroid).norm())
        })
        .unwrap_or(&cells[0]);
    let mut from_seed = vec![f64::INFINITY; grid.inside.len()];
    grid.dijkstra_min(seed, &mut from_seed);
    let mut chosen = Vec::new();
    let mut best = vec![f64::INFINITY; grid.inside.len()];
    let mut next = farthest(&grid.inside, &from_seed);
    while let Some(i) = next {
        if chosen.len() == count || chosen.contains(&i) {
            break;
        }
        chosen.push(i);
        grid.dijkstra_min(i, &mut best);
        next = farthest(&grid.inside, &best);
    }
    chosen.into_iter().map(|i| grid.point(i, shape)).collect()
}
