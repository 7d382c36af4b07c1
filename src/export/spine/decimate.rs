//! Coarser runtime meshes that carry the fine mesh's weights.
//!
//! In: a part's fine [`Mesh`] (canvas px), its weight rows and the most vertices to keep. Out:
//! the kept vertices (indices into the fine mesh, ascending) and triangles over them (indices
//! into that kept list). Every kept vertex keeps its position, uv and weights exactly — the
//! coarse mesh is a subset of the fine one — so its rest shape and the skinning of its vertices
//! are the fine mesh's; only what lies between them is interpolated more coarsely.
//!
//! Method: greedy half-edge collapses (Hoppe 1996, "Progressive Meshes", with the half-edge
//! restriction so no new vertex is made), cheapest first. A collapse u → v removes u and gives
//! its triangles to v. Cost, in px: how far the outline moves (an outline vertex may only slide
//! along the outline, costing its distance to the chord that replaces it), plus the edge length
//! times the weight-space distance of u and v (how much the deformation of the area around u
//! changes when it is interpolated from v's weights), plus a small multiple of the edge length so
//! that ties favour short edges. A collapse is refused if it would flip or flatten a triangle or
//! break the mesh's topology (the link condition), so holes and separate pieces survive.
//!
//! Speed: each vertex's one-ring (neighbours, outline edges) is cached and recomputed only for
//! the vertices a collapse touches, triangle lists are small vectors, weight rows are sorted
//! once and merged, and each edge around a collapse is re-costed once, not once per endpoint.
//! None of this changes which collapses happen (`benches/spine.rs` measures it).

use crate::geom::Point;
use crate::mesh::Mesh;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Edge length (px) weight that breaks ties towards short edges.
pub const SHORT_EDGE_PREFERENCE: f64 = 0.01;

/// A triangle whose doubled area (px²) falls below this is flattened; such a collapse is refused.
pub const MIN_DOUBLE_AREA_PX2: f64 = 1e-6;

fn double_area(a: Point, b: Point, c: Point) -> f64 {
    (b - a).perp(&(c - a))
}

/// A weight row sorted by column (stably: repeated columns keep their order).
fn sorted_row(row: &[(usize, f64)]) -> Vec<(usize, f64)> {
    let mut sorted = row.to_vec();
    sorted.sort_by_key(|&(j, _)| j);
    sorted
}

/// Distance between two sparse weight rows sorted by column (Euclidean over columns): per
/// column, `a`'s weights added and `b`'s subtracted, the squares summed in column order, so
/// that it is the same number on every run.
fn weight_distance(a: &[(usize, f64)], b: &[(usize, f64)]) -> f64 {
    let (mut i, mut k) = (0, 0);
    let mut sum = 0.0;
    while i < a.len() || k < b.len() {
        let j = match (a.get(i), b.get(k)) {
            (Some(&(ja, _)), Some(&(jb, _))) => ja.min(jb),
            (Some(&(ja, _)), None) => ja,
            (None, Some(&(jb, _))) => jb,
            (None, None) => break,
        };
        let mut d = 0.0;
        while let Some(&(_, w)) = a.get(i).filter(|e| e.0 == j) {
            d += w;
            i += 1;
        }
        while let Some(&(_, w)) = b.get(k).filter(|e| e.0 == j) {
            d -= w;
            k += 1;
        }
        sum += d * d;
    }
    sum.sqrt()
}

#[derive(PartialEq)]
struct Candidate {
    cost: f64,
    u: usize,
    v: usize,
    stamp: (u64, u64),
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        // Min-heap on cost, then on (u, v) for determinism.
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| other.u.cmp(&self.u))
            .then_with(|| other.v.cmp(&self.v))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// A vertex's one-ring: its neighbours in ascending order, each with whether the edge to it is
/// on the outline (used by one triangle only).
struct Ring {
    neighbours: Vec<usize>,
    boundary: Vec<bool>,
}

impl Ring {
    fn boundary_neighbours(&self) -> impl Iterator<Item = usize> + '_ {
        self.neighbours
            .iter()
            .zip(&self.boundary)
            .filter(|(_, &b)| b)
            .map(|(&w, _)| w)
    }

    fn on_outline(&self) -> bool {
        self.boundary.iter().any(|&b| b)
    }
}

struct State<'a> {
    points: &'a [Point],
    /// Weight rows sorted by column.
    rows: Vec<Vec<(usize, f64)>>,
    triangles: Vec<[usize; 3]>,
    alive: Vec<bool>,
    /// Per vertex, the triangles using it (a handful: plain vectors beat sets here).
    around: Vec<Vec<usize>>,
    /// Per vertex, its [`Ring`], kept up to date as triangles change.
    rings: Vec<Ring>,
    stamp: Vec<u64>,
}

impl State<'_> {
    /// u's neighbours and outline edges, from the two other corners of each of its triangles:
    /// an edge seen in exactly one triangle is on the outline.
    fn ring(&self, u: usize) -> Ring {
        let mut corners: Vec<usize> = self.around[u]
            .iter()
            .flat_map(|&t| self.triangles[t])
            .filter(|&w| w != u)
            .collect();
        corners.sort_unstable();
        let mut ring = Ring {
            neighbours: Vec::with_capacity(corners.len() / 2 + 1),
            boundary: Vec::with_capacity(corners.len() / 2 + 1),
        };
        let mut k = 0;
        while k < corners.len() {
            let w = corners[k];
            let mut count = 0;
            while k < corners.len() && corners[k] == w {
                count += 1;
                k += 1;
            }
            ring.neighbours.push(w);
            ring.boundary.push(count == 1);
        }
        ring
    }

    fn neighbours(&self, u: usize) -> &[usize] {
        &self.rings[u].neighbours
    }

    /// Triangles using both u and v.
    fn shared(&self, u: usize, v: usize) -> Vec<usize> {
        self.around[u]
            .iter()
            .copied()
            .filter(|&t| self.triangles[t].contains(&v))
            .collect()
    }

    /// The cost of collapsing u into v, or `None` when the collapse is not allowed.
    fn cost(&self, u: usize, v: usize) -> Option<f64> {
        let shared = self.shared(u, v);
        if shared.is_empty() {
            return None;
        }
        let (ring_u, ring_v) = (&self.rings[u], &self.rings[v]);
        let mut shape_px = 0.0;
        if ring_u.on_outline() {
            // An outline vertex slides along the outline only, and only where the outline is a
            // simple curve through it.
            let boundary_u: Vec<usize> = ring_u.boundary_neighbours().collect();
            if boundary_u.len() != 2 || !boundary_u.contains(&v) || shared.len() != 1 {
                return None;
            }
            let w = if boundary_u[0] == v {
                boundary_u[1]
            } else {
                boundary_u[0]
            };
            let (pu, pv, pw) = (self.points[u], self.points[v], self.points[w]);
            let chord = pw - pv;
            let len = chord.norm();
            shape_px = if len > 0.0 {
                (double_area(pv, pw, pu) / len).abs()
            } else {
                (pu - pv).norm()
            };
        } else if ring_v.on_outline() && shared.len() != 2 {
            return None;
        }
        // Link condition: u and v share exactly the neighbours across their shared triangles.
        let mut opposite: Vec<usize> = shared
            .iter()
            .flat_map(|&t| self.triangles[t])
            .filter(|&w| w != u && w != v)
            .collect();
        opposite.sort_unstable();
        opposite.dedup();
        let common = ring_u
            .neighbours
            .iter()
            .filter(|w| ring_v.neighbours.binary_search(w).is_ok());
        if !common.eq(opposite.iter()) {
            return None;
        }
        // No flipped or flattened triangle.
        for &t in &self.around[u] {
            if shared.contains(&t) {
                continue;
            }
            let tri = self.triangles[t];
            let before = double_area(
                self.points[tri[0]],
                self.points[tri[1]],
                self.points[tri[2]],
            );
            let moved = tri.map(|w| if w == u { v } else { w });
            let after = double_area(
                self.points[moved[0]],
                self.points[moved[1]],
                self.points[moved[2]],
            );
            if after.abs() < MIN_DOUBLE_AREA_PX2 || after.signum() != before.signum() {
                return None;
            }
        }
        let length = (self.points[u] - self.points[v]).norm();
        Some(
            shape_px
                + length * weight_distance(&self.rows[u], &self.rows[v])
                + SHORT_EDGE_PREFERENCE * length,
        )
    }

    /// Both directions of the edge u–v, at the current stamps, when allowed.
    fn push_edge(&self, u: usize, v: usize, heap: &mut BinaryHeap<Candidate>) {
        for (a, b) in [(u, v), (v, u)] {
            if let Some(cost) = self.cost(a, b) {
                heap.push(Candidate {
                    cost,
                    u: a,
                    v: b,
                    stamp: (self.stamp[a], self.stamp[b]),
                });
            }
        }
    }
}

/// Decimates `mesh` to at most `max_vertices` vertices (fewer collapses happen when none is
/// allowed any more). Returns the kept fine-mesh vertex indices and the triangles over them.
pub fn decimate(
    mesh: &Mesh,
    rows: &[Vec<(usize, f64)>],
    max_vertices: usize,
) -> (Vec<usize>, Vec<[u32; 3]>) {
    let n = mesh.vertices.len();
    let triangles: Vec<[usize; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| v as usize))
        .collect();
    let mut around = vec![Vec::new(); n];
    for (i, t) in triangles.iter().enumerate() {
        for &v in t {
            if !around[v].contains(&i) {
                around[v].push(i);
            }
        }
    }
    let mut state = State {
        points: &mesh.vertices,
        rows: rows.iter().map(|r| sorted_row(r)).collect(),
        alive: vec![true; triangles.len()],
        triangles,
        around,
        rings: Vec::new(),
        stamp: vec![0; n],
    };
    state.rings = (0..n).map(|u| state.ring(u)).collect();
    let mut heap = BinaryHeap::new();
    for u in 0..n {
        for &v in state.neighbours(u) {
            if let Some(cost) = state.cost(u, v) {
                heap.push(Candidate {
                    cost,
                    u,
                    v,
                    stamp: (0, 0),
                });
            }
        }
    }
    let mut removed = vec![false; n];
    let mut remaining = (0..n).filter(|&v| !state.around[v].is_empty()).count();
    let mut edges: Vec<(usize, usize)> = Vec::new();
    while remaining > max_vertices {
        let Some(c) = heap.pop() else { break };
        if removed[c.u] || removed[c.v] || c.stamp != (state.stamp[c.u], state.stamp[c.v]) {
            continue;
        }
        // Neighbourhoods may have changed without touching these stamps' vertices: recheck.
        if state.cost(c.u, c.v).is_none() {
            continue;
        }
        let (u, v) = (c.u, c.v);
        let touched = state.neighbours(u).to_vec();
        for t in std::mem::take(&mut state.around[u]) {
            let tri = state.triangles[t];
            if tri.contains(&v) {
                state.alive[t] = false;
                for w in tri {
                    state.around[w].retain(|&x| x != t);
                }
            } else {
                state.triangles[t] = tri.map(|w| if w == u { v } else { w });
                state.around[v].push(t);
            }
        }
        removed[u] = true;
        remaining -= 1;
        // Only the triangles around u changed: their corners are u's neighbours and v.
        state.rings[u] = state.ring(u);
        for &w in touched.iter().chain([&v]) {
            state.rings[w] = state.ring(w);
        }
        for &w in touched.iter().chain([&v]) {
            state.stamp[w] += 1;
        }
        // Every edge at a touched vertex, once: a candidate pushed twice at the same stamps
        // is the same candidate, and popping its copy would change nothing.
        edges.clear();
        for &w in touched.iter().chain([&v]) {
            for &x in state.neighbours(w) {
                edges.push((w.min(x), w.max(x)));
            }
        }
        edges.sort_unstable();
        edges.dedup();
        for &(a, b) in &edges {
            state.push_edge(a, b, &mut heap);
        }
    }
    let kept: Vec<usize> = (0..n)
        .filter(|&v| !removed[v] && !state.around[v].is_empty())
        .collect();
    let mut index = vec![u32::MAX; n];
    for (k, &v) in kept.iter().enumerate() {
        index[v] = k as u32;
    }
    let triangles = state
        .triangles
        .iter()
        .zip(&state.alive)
        .filter(|(_, &alive)| alive)
        .map(|(t, _)| t.map(|v| index[v]))
        .collect();
    (kept, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A (k+1)² grid over [0, k]², two triangles per cell, counter-clockwise on screen.
    fn grid(k: usize) -> Mesh {
        let mut vertices = Vec::new();
        for y in 0..=k {
            for x in 0..=k {
                vertices.push(Point::new(x as f64, y as f64));
            }
        }
        let at = |x: usize, y: usize| (y * (k + 1) + x) as u32;
        let mut triangles = Vec::new();
        for y in 0..k {
            for x in 0..k {
                triangles.push([at(x, y), at(x + 1, y), at(x + 1, y + 1)]);
                triangles.push([at(x, y), at(x + 1, y + 1), at(x, y + 1)]);
            }
        }
        Mesh {
            vertices,
            triangles,
        }
    }

    #[test]
    fn a_flat_grid_keeps_its_square_and_no_triangle_flips() {
        let mesh = grid(8);
        let rows: Vec<Vec<(usize, f64)>> = mesh.vertices.iter().map(|_| vec![(0, 1.0)]).collect();
        let (kept, tris) = decimate(&mesh, &rows, 12);
        assert!(kept.len() <= 12, "{}", kept.len());
        // The four corners survive (removing one would cut the square), so the area does too.
        for corner in [0, 8, 72, 80] {
            assert!(kept.contains(&corner), "{kept:?}");
        }
        let area: f64 = tris
            .iter()
            .map(|t| {
                let p = t.map(|v| mesh.vertices[kept[v as usize]]);
                double_area(p[0], p[1], p[2]) / 2.0
            })
            .sum();
        assert!((area - 64.0).abs() < 1e-9, "{area}");
        for t in &tris {
            let p = t.map(|v| mesh.vertices[kept[v as usize]]);
            assert!(double_area(p[0], p[1], p[2]) > 0.0);
        }
    }

    #[test]
    fn weights_steer_which_vertices_stay() {
        // Left half on handle 0, right half on handle 1: the seam column (x = 4) between the
        // two keeps its vertices longer than the uniform regions do.
        let mesh = grid(8);
        let rows: Vec<Vec<(usize, f64)>> = mesh
            .vertices
            .iter()
            .map(|p| {
                if p.x < 4.0 {
                    vec![(0, 1.0)]
                } else if p.x > 4.0 {
                    vec![(1, 1.0)]
                } else {
                    vec![(0, 0.5), (1, 0.5)]
                }
            })
            .collect();
        let (kept, _) = decimate(&mesh, &rows, 30);
        let seam = kept.iter().filter(|&&v| mesh.vertices[v].x == 4.0).count();
        let left_inner = kept
            .iter()
            .filter(|&&v| {
                let p = mesh.vertices[v];
                p.x > 0.0 && p.x < 4.0 && p.y > 0.0 && p.y < 8.0
            })
            .count();
        assert!(
            seam >= left_inner,
            "seam {seam}, left interior {left_inner}"
        );
        // Same input, same output.
        assert_eq!(decimate(&mesh, &rows, 30).0, kept);
    }
}
