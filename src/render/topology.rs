//! What the renderer derives once from a mesh's connectivity and rest positions: the triangles
//! that can carry a texture map (with their texture-space edges), the boundary edges
//! (edges of exactly one such triangle) and the boundary loops they chain into.
//!
//! All positions here are texture pixels; nothing depends on the deformation.

use crate::geom::{triangle_area2, Point};
use nalgebra::Matrix2;

use super::RenderError;

/// Twice the area, in px², below which a triangle is treated as degenerate: it cannot define an
/// affine map, and it covers no pixel center worth drawing.
pub(super) const DEGENERATE_AREA2_PX2: f64 = 1e-9;

/// A triangle with a usable texture-space shape.
pub(super) struct TexturedTriangle {
    pub vertices: [u32; 3],
    /// Texture position of `vertices[0]`.
    pub uv_origin: Point,
    /// The matrix whose columns are the texture-space edges from `vertices[0]` to `vertices[1]`
    /// and `vertices[2]`: with the same matrix of a frame's edges it gives the triangle's
    /// texture-from-canvas map.
    pub uv_edges: Matrix2<f64>,
}

/// A boundary edge, directed so that its triangle lies on the same side of every boundary edge
/// (in texture space); chaining edges head to tail then walks each boundary loop in one
/// consistent direction, and holes run opposite to the outer boundary.
pub(super) struct BoundaryEdge {
    pub from: u32,
    pub to: u32,
    /// The triangle's third vertex, which tells the inside of the edge in any deformation.
    pub opposite: u32,
    /// Index into [`Topology::triangles`] of the edge's triangle.
    pub triangle: usize,
    /// Indices into [`Topology::boundary_vertices`] of `from` and `to`.
    pub from_slot: usize,
    pub to_slot: usize,
}

/// The precomputed connectivity of one mesh.
pub(super) struct Topology {
    pub vertex_count: usize,
    pub triangles: Vec<TexturedTriangle>,
    pub boundary_edges: Vec<BoundaryEdge>,
    /// The vertices on the boundary, each once.
    pub boundary_vertices: Vec<u32>,
    /// Boundary loops as vertex indices in walking order; each closes back to its start.
    pub loops: Vec<Vec<u32>>,
}

impl Topology {
    /// Validates the mesh and derives its connectivity.
    pub fn new(uv_px: &[Point], triangles: &[[u32; 3]]) -> Result<Self, RenderError> {
        validate(uv_px, triangles)?;
        let textured: Vec<TexturedTriangle> = triangles
            .iter()
            .filter_map(|&t| TexturedTriangle::new(uv_px, t))
            .collect();
        let (boundary_edges, boundary_vertices) = boundary_edges(uv_px.len(), &textured);
        let loops = chain_loops(&boundary_edges, boundary_vertices.len());
        Ok(Topology {
            vertex_count: uv_px.len(),
            triangles: textured,
            boundary_edges,
            boundary_vertices,
            loops,
        })
    }
}

/// Checks that the mesh is non-empty, finite and indexes only existing vertices.
fn validate(uv_px: &[Point], triangles: &[[u32; 3]]) -> Result<(), RenderError> {
    if uv_px.is_empty() || triangles.is_empty() {
        return Err(RenderError::EmptyMesh {
            vertices: uv_px.len(),
            triangles: triangles.len(),
        });
    }
    if let Some(vertex) = uv_px
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(RenderError::NonFiniteCoordinate { vertex });
    }
    for (triangle, t) in triangles.iter().enumerate() {
        if let Some(&index) = t.iter().find(|&&i| i as usize >= uv_px.len()) {
            return Err(RenderError::TriangleIndexOutOfRange {
                triangle,
                index,
                vertex_count: uv_px.len(),
            });
        }
    }
    Ok(())
}

impl TexturedTriangle {
    /// The triangle with its texture basis inverted, or `None` when it is degenerate in texture
    /// space. Indices must be valid.
    fn new(uv_px: &[Point], vertices: [u32; 3]) -> Option<Self> {
        let [a, b, c] = vertices.map(|i| uv_px[i as usize]);
        let det = triangle_area2(a, b, c);
        if det.abs() <= DEGENERATE_AREA2_PX2 {
            return None;
        }
        let (e1, e2) = (b - a, c - a);
        Some(TexturedTriangle {
            vertices,
            uv_origin: a,
            uv_edges: Matrix2::new(e1.x, e2.x, e1.y, e2.y),
        })
    }

    /// Whether the triangle runs clockwise on screen in texture space (see `triangle_area2`).
    fn is_clockwise(&self) -> bool {
        let m = &self.uv_edges;
        m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)] > 0.0
    }
}

/// The edges that belong to exactly one textured triangle, directed consistently, and the
/// distinct vertices they touch.
fn boundary_edges(
    vertex_count: usize,
    triangles: &[TexturedTriangle],
) -> (Vec<BoundaryEdge>, Vec<u32>) {
    // Every directed half-edge; sorting by undirected vertex pair brings the two halves of an
    // interior edge together.
    let mut halves: Vec<HalfEdge> = triangles
        .iter()
        .enumerate()
        .flat_map(|(triangle, t)| {
            let [a, b, c] = t.vertices;
            let directed = if t.is_clockwise() {
                [(a, b, c), (b, c, a), (c, a, b)]
            } else {
                [(b, a, c), (c, b, a), (a, c, b)]
            };
            directed.map(|(from, to, opposite)| HalfEdge {
                from,
                to,
                opposite,
                triangle,
            })
        })
        .collect();
    halves.sort_unstable_by_key(HalfEdge::undirected);

    let mut slot_of = vec![usize::MAX; vertex_count];
    let mut boundary_vertices = Vec::new();
    let mut slot = |v: u32| {
        let s = &mut slot_of[v as usize];
        if *s == usize::MAX {
            *s = boundary_vertices.len();
            boundary_vertices.push(v);
        }
        *s
    };
    let mut edges = Vec::new();
    for run in halves.chunk_by(|x, y| x.undirected() == y.undirected()) {
        if let [h] = run {
            edges.push(BoundaryEdge {
                from: h.from,
                to: h.to,
                opposite: h.opposite,
                triangle: h.triangle,
                from_slot: slot(h.from),
                to_slot: slot(h.to),
            });
        }
    }
    (edges, boundary_vertices)
}

/// One side of a triangle edge, directed like its (texture-space clockwise) triangle.
struct HalfEdge {
    from: u32,
    to: u32,
    opposite: u32,
    triangle: usize,
}

impl HalfEdge {
    /// The edge's vertex pair regardless of direction.
    fn undirected(&self) -> (u32, u32) {
        (self.from.min(self.to), self.from.max(self.to))
    }
}

/// Chains directed boundary edges head to tail into loops of vertex indices.
///
/// A vertex where several loops touch has several outgoing edges; any choice still yields
/// closed walks. A walk that gets stuck (possible only for inconsistently wound meshes) ends
/// there and is closed by a straight segment when filled.
fn chain_loops(edges: &[BoundaryEdge], slot_count: usize) -> Vec<Vec<u32>> {
    // Outgoing edges per slot, in compressed rows.
    let mut row_start = vec![0usize; slot_count + 1];
    for e in edges {
        row_start[e.from_slot + 1] += 1;
    }
    for s in 0..slot_count {
        row_start[s + 1] += row_start[s];
    }
    let mut next_free = row_start.clone();
    let mut outgoing = vec![0usize; edges.len()];
    for (i, e) in edges.iter().enumerate() {
        outgoing[next_free[e.from_slot]] = i;
        next_free[e.from_slot] += 1;
    }

    let mut used = vec![false; edges.len()];
    let mut cursor = row_start.clone();
    let mut take_outgoing = |slot: usize, used: &mut Vec<bool>| {
        while cursor[slot] < row_start[slot + 1] {
            let e = outgoing[cursor[slot]];
            cursor[slot] += 1;
            if !used[e] {
                used[e] = true;
                return Some(e);
            }
        }
        None
    };

    let mut loops = Vec::new();
    for first in 0..edges.len() {
        if used[first] {
            continue;
        }
        used[first] = true;
        let start = edges[first].from;
        let mut ring = vec![start];
        let mut edge = first;
        while edges[edge].to != start {
            ring.push(edges[edge].to);
            match take_outgoing(edges[edge].to_slot, &mut used) {
                Some(e) => edge = e,
                None => break,
            }
        }
        loops.push(ring);
    }
    loops
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64) -> Point {
        Point::new(x, y)
    }

    /// A 2×2 grid of unit squares: 9 vertices, 8 triangles, 8 boundary edges in one loop.
    fn grid_2x2() -> (Vec<Point>, Vec<[u32; 3]>) {
        let uv: Vec<Point> = (0..9)
            .map(|i| p(f64::from(i % 3), f64::from(i / 3)))
            .collect();
        let mut tris = Vec::new();
        for cy in 0..2u32 {
            for cx in 0..2u32 {
                let v = cy * 3 + cx;
                // Alternate winding to check that orientation comes from geometry.
                if (cx + cy) % 2 == 0 {
                    tris.push([v, v + 1, v + 4]);
                    tris.push([v, v + 4, v + 3]);
                } else {
                    tris.push([v + 1, v, v + 4]);
                    tris.push([v + 4, v, v + 3]);
                }
            }
        }
        (uv, tris)
    }

    #[test]
    fn grid_boundary_is_one_consistent_loop() {
        let (uv, tris) = grid_2x2();
        let topo = Topology::new(&uv, &tris).expect("valid mesh");
        assert_eq!(topo.triangles.len(), 8);
        assert_eq!(topo.boundary_edges.len(), 8);
        assert_eq!(topo.boundary_vertices.len(), 8);
        assert_eq!(topo.loops.len(), 1);
        let ring: Vec<Point> = topo.loops[0].iter().map(|&i| uv[i as usize]).collect();
        assert_eq!(ring.len(), 8);
        // Consistent direction: the walk encloses the full area with one sign.
        assert!((crate::geom::ring_signed_area(&ring).abs() - 4.0).abs() < 1e-12);
    }

    #[test]
    fn hole_runs_opposite_to_outer_boundary() {
        // A 3×3 grid of unit squares without the middle one.
        let uv: Vec<Point> = (0..16)
            .map(|i| p(f64::from(i % 4), f64::from(i / 4)))
            .collect();
        let mut tris = Vec::new();
        for cy in 0..3u32 {
            for cx in 0..3u32 {
                if (cx, cy) != (1, 1) {
                    let v = cy * 4 + cx;
                    tris.push([v, v + 1, v + 5]);
                    tris.push([v, v + 5, v + 4]);
                }
            }
        }
        let topo = Topology::new(&uv, &tris).expect("valid mesh");
        assert_eq!(topo.loops.len(), 2);
        let areas: Vec<f64> = topo
            .loops
            .iter()
            .map(|l| {
                let ring: Vec<Point> = l.iter().map(|&i| uv[i as usize]).collect();
                crate::geom::ring_signed_area(&ring)
            })
            .collect();
        assert!(areas[0] * areas[1] < 0.0, "areas {areas:?}");
        assert!(((areas[0] + areas[1]).abs() - 8.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_triangles_are_left_out() {
        let uv = vec![p(0.0, 0.0), p(1.0, 0.0), p(2.0, 0.0), p(0.0, 1.0)];
        let tris = [[0, 1, 2], [0, 2, 3], [1, 1, 3]];
        let topo = Topology::new(&uv, &tris).expect("valid mesh");
        assert_eq!(topo.triangles.len(), 1);
        assert_eq!(topo.boundary_edges.len(), 3);
        assert_eq!(topo.loops, vec![vec![0, 2, 3]]);
    }
}
