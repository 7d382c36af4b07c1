//! Where a part's skirt reaches: per boundary vertex, the offset from the vertex to its skirt
//! corner, in output pixels.
//!
//! The skirt is a band [`SKIRT_PX`] wide outside every boundary edge, drawn with the map of the
//! edge's triangle extended past the edge: a pixel whose center lies just outside the mesh but
//! whose area is partly inside it (so the antialiased coverage is not zero) still gets texture
//! colour. Corners are mitred, so the skirts of adjacent edges share their outer corner and meet
//! without a gap.

use super::topology::{BoundaryEdge, Topology, DEGENERATE_AREA2_PX2};
use crate::geom::{Point, Vec2};

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

/// Per boundary vertex (indexed like `Topology::boundary_vertices`), the displacement from the
/// vertex at `points_px` to its skirt corner: along the bisector of the outward normals of its
/// boundary edges, long enough that every edge's skirt is [`SKIRT_PX`] wide (a mitre), capped at
/// [`MAX_MITER_RATIO`].
pub(super) fn skirt_offsets(topology: &Topology, points_px: &[Point]) -> Vec<Vec2> {
    let edges = &topology.boundary_edges;
    let normals: Vec<Option<Vec2>> = edges.iter().map(|e| outward_normal(e, points_px)).collect();

    let slots = topology.boundary_vertices.len();
    let mut sums = vec![Vec2::zeros(); slots];
    for (e, n) in edges.iter().zip(&normals) {
        if let Some(n) = *n {
            sums[e.from_slot] += n;
            sums[e.to_slot] += n;
        }
    }
    // Opposite normals cancel at a needle tip or a vertex with no usable edge; such a vertex
    // gets no skirt corner, which only thins the skirt next to it.
    let bisectors: Vec<Option<Vec2>> = sums
        .into_iter()
        .map(|s| {
            let length = s.dot(&s).sqrt();
            (length >= MIN_DIRECTION_PX).then(|| s * (1.0 / length))
        })
        .collect();

    let mut min_cos = vec![1.0f64; slots];
    for (e, n) in edges.iter().zip(&normals) {
        if let Some(n) = *n {
            for slot in [e.from_slot, e.to_slot] {
                if let Some(b) = bisectors[slot] {
                    min_cos[slot] = min_cos[slot].min(b.dot(&n));
                }
            }
        }
    }
    bisectors
        .iter()
        .zip(&min_cos)
        .map(|(b, &cos)| match b {
            Some(b) => b * (SKIRT_PX / cos.max(1.0 / MAX_MITER_RATIO)),
            None => Vec2::zeros(),
        })
        .collect()
}

/// The unit normal of a boundary edge pointing away from its triangle in the current
/// deformation (so it follows flips and mirroring), or `None` when the edge or the triangle has
/// collapsed.
fn outward_normal(edge: &BoundaryEdge, points_px: &[Point]) -> Option<Vec2> {
    let [a, b, c] = [edge.from, edge.to, edge.opposite].map(|v| points_px[v as usize]);
    let along = b - a;
    let length = along.dot(&along).sqrt();
    if length < MIN_DIRECTION_PX {
        return None;
    }
    let normal = Vec2::new(along.y / length, -along.x / length);
    let inward_reach = normal.dot(&(c - a));
    if (inward_reach * length).abs() <= DEGENERATE_AREA2_PX2 {
        return None;
    }
    Some(if inward_reach > 0.0 { -normal } else { normal })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_gets_mitred_corners_pointing_outward() {
        let uv =
            [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)].map(|(x, y)| Point::new(x, y));
        let topology = Topology::new(&uv, &[[0, 1, 2], [0, 2, 3]]).expect("valid mesh");
        let points = uv.to_vec();
        let offsets = skirt_offsets(&topology, &points);
        for (slot, &v) in topology.boundary_vertices.iter().enumerate() {
            let p = points[v as usize];
            let away = p - Point::new(5.0, 5.0);
            let o = offsets[slot];
            // Diagonal, outward, and √2 long: a 1 px band along both edges.
            assert!((o[0].abs() - 1.0).abs() < 1e-12 && (o[1].abs() - 1.0).abs() < 1e-12);
            assert!(o.dot(&away) > 0.0, "vertex {v}: {o:?}");
        }
    }

    #[test]
    fn sharp_corners_are_capped() {
        // A needle-like triangle: the tip's mitre would be ~19 px long uncapped.
        let uv = [(0.0, 0.0), (40.0, 2.0), (0.0, 4.0)].map(|(x, y)| Point::new(x, y));
        let topology = Topology::new(&uv, &[[0, 1, 2]]).expect("valid mesh");
        let offsets = skirt_offsets(&topology, &uv);
        for o in offsets {
            assert!(o.norm() <= SKIRT_PX * MAX_MITER_RATIO + 1e-9);
        }
    }
}
