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
//! along the outline, costing its distance to the chord that replaces it), plus how much the
//! deformation around u changes — the edge length times the weight-space distance of u and v,
//! and [`INTERPOLATION_LEVER_PX`] times the weight-space distance between u's weights and those
//! the runtime interpolates at u's rest position from the triangle it then falls in (where the
//! weights vary nonlinearly, a coarse triangle bends the texture away from the fine mesh) —
//! scaled up by the texture detail under u's triangles ([`TextureDetail`],
//! [`TEXTURE_DETAIL_GAIN`]: a warp shows on edges, not on flat colour), plus a small multiple of
//! the edge length so that ties favour short edges. A collapse is refused if it would flip or
//! flatten a triangle or break the mesh's topology (the link condition), so holes and separate
//! pieces survive.
//!
//! Measured (`tests/spine_runtime.rs`, the demo under `--preset game`, spine-core's vertices
//! drawn textured against the full export's): without the interpolation and detail terms the
//! torso's belt buckle warped (walk 42.2 dB, wave 45.1, hop 45.4, lift 50.1 min PSNR); with
//! them 58.9, 48.3, 57.2 and 61.6 dB, the JSON 0.3% larger.
//!
//! Speed: each vertex's one-ring (neighbours, outline edges) is cached and recomputed only for
//! the vertices a collapse touches, triangle lists are small vectors, weight rows are sorted
//! once and merged, and each edge around a collapse is re-costed once, not once per endpoint.
//! None of this changes which collapses happen (`benches/spine.rs` measures it).

use crate::geom::Point;
use crate::mesh::Mesh;
use image::RgbaImage;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Edge length (px) weight that breaks ties towards short edges.
pub const SHORT_EDGE_PREFERENCE: f64 = 0.01;

/// A triangle whose doubled area (px²) falls below this is flattened; such a collapse is refused.
pub const MIN_DOUBLE_AREA_PX2: f64 = 1e-6;

/// How much texture detail multiplies the weight term of a collapse: the term is scaled by
/// `1 + TEXTURE_DETAIL_GAIN · d`, where `d` is the root mean square texture gradient (largest
/// premultiplied channel, 0..1 per px) over the box of the triangles the collapse changes. A
/// region of flat colour (d ≈ 0) costs as before; where the texture has edges (a belt buckle)
/// interpolating the deformation more coarsely shows, so the collapse costs more. 20 measured
/// best of 0, 20 and 100 on the demo's `--preset game` (tests/spine_runtime.rs).
pub const TEXTURE_DETAIL_GAIN: f64 = 20.0;

/// Px per unit of weight-space error where u's weights are interpolated from the triangle it
/// falls in once collapsed: a weight error δ moves u by about δ × (the other bones' motion
/// relative to its own at u), which grows with u's distance from the joints. 20 measured better
/// than 100 on the demo's `--preset game` (tests/spine_runtime.rs).
pub const INTERPOLATION_LEVER_PX: f64 = 20.0;

/// A part's texture detail on the canvas: per pixel the squared gradient of its premultiplied
/// image (largest channel, central differences, 0..1 per px), summed into a table so that the
/// mean over any box is four lookups.
pub struct TextureDetail {
    /// Canvas px of the image's top-left corner.
    origin: [i64; 2],
    width: usize,
    height: usize,
    /// `(width + 1) × (height + 1)` prefix sums of the squared gradient.
    sums: Vec<f64>,
}

impl TextureDetail {
    /// The detail of `image` (straight alpha) placed on the canvas at `offset_px`.
    pub fn new(image: &RgbaImage, offset_px: [i32; 2]) -> Self {
        let (width, height) = (image.width() as usize, image.height() as usize);
        let texel = |x: usize, y: usize, c: usize| -> f64 {
            let p = image.get_pixel(x as u32, y as u32).0;
            let a = f64::from(p[3]) / 255.0;
            if c == 3 {
                a
            } else {
                f64::from(p[c]) / 255.0 * a
            }
        };
        let mut sums = vec![0.0; (width + 1) * (height + 1)];
        for y in 0..height {
            let mut row = 0.0;
            for x in 0..width {
                let (x0, x1) = (x.saturating_sub(1), (x + 1).min(width - 1));
                let (y0, y1) = (y.saturating_sub(1), (y + 1).min(height - 1));
                let mut g2: f64 = 0.0;
                for c in 0..4 {
                    let gx = (texel(x1, y, c) - texel(x0, y, c)) / (x1 - x0).max(1) as f64;
                    let gy = (texel(x, y1, c) - texel(x, y0, c)) / (y1 - y0).max(1) as f64;
                    g2 = g2.max(gx * gx + gy * gy);
                }
                row += g2;
                sums[(y + 1) * (width + 1) + x + 1] = sums[y * (width + 1) + x + 1] + row;
            }
        }
        TextureDetail {
            origin: [i64::from(offset_px[0]), i64::from(offset_px[1])],
            width,
            height,
            sums,
        }
    }

    /// Root mean square gradient over the pixels of the canvas box `lo`..`hi` (0 outside the
    /// image).
    fn rms_gradient(&self, lo: Point, hi: Point) -> f64 {
        let clamp_x = |x: f64| (x.floor() as i64 - self.origin[0]).clamp(0, self.width as i64);
        let clamp_y = |y: f64| (y.floor() as i64 - self.origin[1]).clamp(0, self.height as i64);
        let (x0, x1) = (clamp_x(lo.x) as usize, clamp_x(hi.x + 1.0) as usize);
        let (y0, y1) = (clamp_y(lo.y) as usize, clamp_y(hi.y + 1.0) as usize);
        let area = ((hi.x - lo.x + 1.0) * (hi.y - lo.y + 1.0)).max(1.0);
        if x1 <= x0 || y1 <= y0 {
            return 0.0;
        }
        let w = self.width + 1;
        let sum = self.sums[y1 * w + x1] - self.sums[y0 * w + x1] - self.sums[y1 * w + x0]
            + self.sums[y0 * w + x0];
        (sum.max(0.0) / area).sqrt()
    }
}

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
    detail: Option<&'a TextureDetail>,
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
        let interpolation = self.interpolation_error(u, v, &shared);
        let detail = self.detail.map_or(0.0, |d| {
            let (mut lo, mut hi) = (self.points[u], self.points[u]);
            for &t in &self.around[u] {
                for w in self.triangles[t] {
                    let p = self.points[w];
                    lo = Point::new(lo.x.min(p.x), lo.y.min(p.y));
                    hi = Point::new(hi.x.max(p.x), hi.y.max(p.y));
                }
            }
            d.rms_gradient(lo, hi)
        });
        Some(
            shape_px
                + (length * weight_distance(&self.rows[u], &self.rows[v])
                    + INTERPOLATION_LEVER_PX * interpolation)
                    * (1.0 + TEXTURE_DETAIL_GAIN * detail)
                + SHORT_EDGE_PREFERENCE * length,
        )
    }

    /// How far u's weights are from those the runtime interpolates at u's rest position once u
    /// is collapsed into v (weight space): barycentric over the new triangle nearest to u.
    fn interpolation_error(&self, u: usize, v: usize, shared: &[usize]) -> f64 {
        let p = self.points[u];
        let mut best: Option<(f64, [usize; 3], [f64; 3])> = None;
        for &t in &self.around[u] {
            if shared.contains(&t) {
                continue;
            }
            let c = self.triangles[t].map(|w| if w == u { v } else { w });
            let [a, b, d] = c.map(|w| self.points[w]);
            let area = double_area(a, b, d);
            if area.abs() < MIN_DOUBLE_AREA_PX2 {
                continue;
            }
            let bary = [
                double_area(p, b, d) / area,
                double_area(a, p, d) / area,
                double_area(a, b, p) / area,
            ];
            let inside = bary[0].min(bary[1]).min(bary[2]);
            if best.as_ref().is_none_or(|(m, _, _)| inside > *m) {
                best = Some((inside, c, bary));
            }
        }
        let Some((_, corners, bary)) = best else {
            return 0.0;
        };
        // Clamped to the triangle (u past the outline reads its nearest edge, roughly).
        let bary = bary.map(|b| b.max(0.0));
        let total: f64 = bary.iter().sum();
        let mut mixed: Vec<(usize, f64)> = Vec::new();
        for (w, b) in corners.iter().zip(bary) {
            for &(j, x) in &self.rows[*w] {
                mixed.push((j, x * b / total));
            }
        }
        mixed.sort_by_key(|&(j, _)| j);
        weight_distance(&self.rows[u], &mixed)
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
    decimate_textured(mesh, rows, max_vertices, None)
}

/// [`decimate`], with collapses over texture detail ([`TextureDetail`] of the part's image)
/// costing more ([`TEXTURE_DETAIL_GAIN`]).
pub fn decimate_textured(
    mesh: &Mesh,
    rows: &[Vec<(usize, f64)>],
    max_vertices: usize,
    detail: Option<&TextureDetail>,
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
        detail,

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
