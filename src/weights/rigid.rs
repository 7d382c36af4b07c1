//! Rigid cutout weights: each vertex follows its nearest handle, measured inside the shape,
//! with a smooth blend band around the places where two handles are equally near (the joints,
//! for bones).
//!
//! In: the weight domain's vertices (canvas px) and triangles, the [`BoundaryConditions`] the
//! handles impose (their fixed vertices), and `blend_px` (the band's full width, px). Out: a
//! dense [`WeightMatrix`] with at most two non-zero weights per row, summing to one.
//!
//! Distances are geodesic: Dijkstra over the mesh edges (Euclidean edge lengths) from each
//! column's fixed vertices (those where the column's fixed weight is at least one half, so a
//! joint vertex shared by two bones is a source of both), so that a hand near a hip follows
//! the arm it belongs to, not the leg across the gap. With d₁ ≤ d₂ the distances to the two
//! nearest columns, the nearer gets 1/2 + s/2 and the other 1/2 − s/2, where
//! s = smoothstep(min(1, (d₂ − d₁) / (blend_px / 2))): one half on the equidistant line,
//! exactly rigid beyond `blend_px / 2` of it. With `blend_px` = 0 every vertex follows one
//! handle. This is the cheap one-or-two-influence rig mobile runtimes like, next to BBW; where
//! three handles meet (a triple point) the weights jump between pairs.

use super::solve::{BoundaryConditions, WeightMatrix};
use crate::geom::Point;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Fixed weights at least this large make a vertex a distance source of its column.
const SOURCE_WEIGHT: f64 = 0.5;

/// Rigid weights with a blend band of `blend_px` (full width, px; finite, ≥ 0).
pub fn rigid_weights(
    vertices: &[Point],
    triangles: &[[u32; 3]],
    bc: &BoundaryConditions,
    blend_px: f64,
) -> WeightMatrix {
    let n = vertices.len();
    let m = bc.handle_count;
    let neighbors = crate::mesh::vertex_neighbours(n, triangles);
    let distances: Vec<Vec<f64>> = (0..m)
        .map(|j| {
            let sources: Vec<usize> = bc
                .vertices
                .iter()
                .enumerate()
                .filter(|&(k, _)| bc.values[k * m + j] >= SOURCE_WEIGHT)
                .map(|(_, &v)| v)
                .collect();
            geodesic_distances(vertices, &neighbors, &sources)
        })
        .collect();
    let mut data = vec![0.0; n * m];
    let half_band = 0.5 * blend_px;
    for i in 0..n {
        // The two nearest columns (lowest index on ties).
        let (mut first, mut second) = (None::<(f64, usize)>, None::<(f64, usize)>);
        for (j, d) in distances.iter().enumerate() {
            let d = d[i];
            if !d.is_finite() {
                continue;
            }
            if first.is_none_or(|f| d < f.0) {
                second = first;
                first = Some((d, j));
            } else if second.is_none_or(|s| d < s.0) {
                second = Some((d, j));
            }
        }
        let Some((d1, j1)) = first else { continue };
        let row = &mut data[i * m..(i + 1) * m];
        match second {
            Some((d2, j2)) if half_band > 0.0 && d2 - d1 < half_band => {
                let t = (d2 - d1) / half_band;
                let s = t * t * (3.0 - 2.0 * t);
                row[j1] = 0.5 + 0.5 * s;
                row[j2] = 0.5 - 0.5 * s;
            }
            _ => row[j1] = 1.0,
        }
    }
    WeightMatrix {
        vertex_count: n,
        handle_count: m,
        data,
    }
}

/// Shortest distances (px) along mesh edges from any of `sources`; infinite where unreached.
fn geodesic_distances(vertices: &[Point], neighbors: &[Vec<u32>], sources: &[usize]) -> Vec<f64> {
    let mut dist = vec![f64::INFINITY; vertices.len()];
    let mut heap = BinaryHeap::new();
    for &s in sources {
        dist[s] = 0.0;
        heap.push(Reverse((0u64, s)));
    }
    while let Some(Reverse((bits, i))) = heap.pop() {
        let d = f64::from_bits(bits);
        if d > dist[i] {
            continue;
        }
        for &j in &neighbors[i] {
            let j = j as usize;
            let nd = d + (vertices[j] - vertices[i]).norm();
            if nd < dist[j] {
                dist[j] = nd;
                // Non-negative floats order like their bit patterns.
                heap.push(Reverse((nd.to_bits(), j)));
            }
        }
    }
    dist
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of unit squares along x from 0 to `len`, two triangles each.
    fn strip(len: usize) -> (Vec<Point>, Vec<[u32; 3]>) {
        let mut vertices = Vec::new();
        for x in 0..=len {
            vertices.push(Point::new(x as f64, 0.0));
            vertices.push(Point::new(x as f64, 1.0));
        }
        let triangles = (0..len as u32)
            .flat_map(|x| {
                let (a, b, c, d) = (2 * x, 2 * x + 1, 2 * x + 2, 2 * x + 3);
                [[a, c, b], [b, c, d]]
            })
            .collect();
        (vertices, triangles)
    }

    #[test]
    fn two_handles_on_a_strip_blend_only_in_the_band() {
        let (vertices, triangles) = strip(40);
        let mut bc = BoundaryConditions {
            handle_count: 2,
            ..Default::default()
        };
        // Handle 0 fixes the left end, handle 1 the right end.
        bc.fix_to_handle(0, 0);
        bc.fix_to_handle(1, 0);
        bc.fix_to_handle(80, 1);
        bc.fix_to_handle(81, 1);
        let w = rigid_weights(&vertices, &triangles, &bc, 10.0);
        for (i, p) in vertices.iter().enumerate() {
            let row = w.row(i);
            assert!((row[0] + row[1] - 1.0).abs() < 1e-12);
            if p.x < 15.0 {
                assert_eq!(row[0], 1.0, "x = {}", p.x);
            } else if p.x > 25.0 {
                assert_eq!(row[1], 1.0, "x = {}", p.x);
            } else if p.y == 0.0 && p.x == 20.0 {
                assert!((row[0] - 0.5).abs() < 1e-12);
            }
        }
        // Monotone across the band.
        let along: Vec<f64> = (0..=40).map(|x| w.get(2 * x, 0)).collect();
        assert!(along.windows(2).all(|p| p[1] <= p[0] + 1e-12));
        // No band: a hard switch.
        let hard = rigid_weights(&vertices, &triangles, &bc, 0.0);
        assert!((0..vertices.len()).all(|i| hard.row(i).contains(&1.0)));
    }
}
