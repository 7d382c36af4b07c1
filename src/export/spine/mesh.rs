//! A part's mesh as a Spine weighted mesh attachment.
//!
//! In: the part's mesh (canvas px) and weight rows, the weight columns' bones
//! ([`Skeleton::column_bone`]), the atlas region's rectangle on the canvas and the most
//! influences a vertex may keep. Out: a [`MeshAttachment`]: vertices reordered so that the hull
//! (the longest boundary loop) comes first, as Spine's `hull` count expects; uvs in 0..1 over
//! the region with v down; triangles; boundary edges (indices × 2, Spine's layout); and per
//! vertex its influences as (bone, bind position, weight), the bind position being the rest
//! vertex in that bone's setup-pose frame (Spine world, y up), so the runtime's setup pose
//! reproduces the rest mesh.

use super::frame::SpineFrame;
use super::skeleton::Skeleton;
use super::SpineError;
use crate::geom::Point;
use std::collections::HashMap;

/// One bone's pull on a vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Influence {
    /// Index into the skeleton's bones.
    pub bone: usize,
    /// The rest vertex in the bone's setup-pose frame (Spine units, y up).
    pub bind: Point,
    pub weight: f64,
}

/// A weighted mesh attachment, ready to write.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshAttachment {
    /// For each exported vertex, its index in the part's mesh.
    pub vertex_source: Vec<usize>,
    /// Per vertex, 0..1 over the region, v down.
    pub uvs: Vec<Point>,
    /// Vertex indices, 3 per triangle (into the exported order).
    pub triangles: Vec<u32>,
    /// The first `hull` vertices are the hull loop, in order.
    pub hull: usize,
    /// Boundary edges as pairs of vertex indices × 2 (Spine's nonessential `edges`).
    pub edges: Vec<u32>,
    pub influences: Vec<Vec<Influence>>,
}

/// An axis-aligned rectangle of the canvas in whole px: the part's atlas region.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegionRect {
    pub x: i64,
    pub y: i64,
    pub width: u32,
    pub height: u32,
}

impl RegionRect {
    /// The whole-pixel box around `vertices`, grown by `margin_px` so that bilinear sampling at
    /// the mesh's edge reads pixels of this region only.
    pub fn around(vertices: &[Point], margin_px: u32) -> RegionRect {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in vertices {
            lo = [lo[0].min(p.x), lo[1].min(p.y)];
            hi = [hi[0].max(p.x), hi[1].max(p.y)];
        }
        if vertices.is_empty() {
            return RegionRect {
                x: 0,
                y: 0,
                width: 1,
                height: 1,
            };
        }
        let m = i64::from(margin_px);
        let (x0, y0) = (lo[0].floor() as i64 - m, lo[1].floor() as i64 - m);
        let (x1, y1) = (hi[0].ceil() as i64 + m, hi[1].ceil() as i64 + m);
        RegionRect {
            x: x0,
            y: y0,
            width: (x1 - x0).max(1) as u32,
            height: (y1 - y0).max(1) as u32,
        }
    }

    pub fn uv(&self, p: Point) -> Point {
        Point::new(
            (p.x - self.x as f64) / f64::from(self.width),
            (p.y - self.y as f64) / f64::from(self.height),
        )
    }
}

/// Boundary loops of a triangle mesh (edges used by one triangle), each in walking order.
fn boundary_loops(triangles: &[[u32; 3]]) -> Vec<Vec<usize>> {
    let mut count: HashMap<(u32, u32), usize> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    // Directed boundary edges keep the triangles' orientation, so loops walk consistently.
    let mut next: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if count[&(a.min(b), a.max(b))] == 1 {
                next.entry(a).or_default().push(b);
            }
        }
    }
    let mut loops = Vec::new();
    while let Some((&start, _)) = next.iter().find(|(_, v)| !v.is_empty()) {
        let mut ring = vec![start as usize];
        let mut at = start;
        while let Some(b) = next.get_mut(&at).and_then(|v| v.pop()) {
            if b == start {
                break;
            }
            ring.push(b as usize);
            at = b;
        }
        loops.push(ring);
    }
    loops
}

/// A part's mesh with its weights: canvas px, and `rows[i]` = vertex i's (column, weight) pairs.
#[derive(Clone, Copy, Debug)]
pub struct WeightedMesh<'a> {
    pub vertices: &'a [Point],
    pub triangles: &'a [[u32; 3]],
    pub rows: &'a [Vec<(usize, f64)>],
}

/// Builds the attachment of one part.
pub fn mesh_attachment(
    part: &str,
    mesh: WeightedMesh,
    skeleton: &Skeleton,
    frame: &SpineFrame,
    region: &RegionRect,
    max_influences: Option<usize>,
) -> Result<MeshAttachment, SpineError> {
    let WeightedMesh {
        vertices,
        triangles,
        rows,
    } = mesh;
    let loops = boundary_loops(triangles);
    let hull_loop = loops
        .iter()
        .max_by_key(|l| l.len())
        .cloned()
        .unwrap_or_default();
    let mut order = hull_loop.clone();
    let mut placed = vec![false; vertices.len()];
    for &v in &order {
        placed[v] = true;
    }
    order.extend((0..vertices.len()).filter(|&v| !placed[v]));
    let mut new_index = vec![0u32; vertices.len()];
    for (k, &v) in order.iter().enumerate() {
        new_index[v] = k as u32;
    }
    let mut edges = Vec::new();
    for ring in &loops {
        for k in 0..ring.len() {
            let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
            edges.extend([new_index[a] * 2, new_index[b] * 2]);
        }
    }
    let mut influences = Vec::with_capacity(order.len());
    for &v in &order {
        let row = crate::skin::strongest_influences(&rows[v], max_influences);
        if row.is_empty() {
            return Err(SpineError::UnweightedVertex {
                part: part.to_string(),
                vertex: v,
            });
        }
        let rest = frame.spine_from_canvas(vertices[v]);
        let mut out = Vec::with_capacity(row.len());
        for (column, w) in row {
            let bone = skeleton.column_bone[column];
            let inverse = skeleton.bones[bone]
                .setup_world
                .inverse()
                .ok_or_else(|| SpineError::Singular(skeleton.bones[bone].name.clone()))?;
            let bind = inverse.apply(rest);
            out.push(Influence {
                bone,
                bind,
                weight: w,
            });
        }
        // Spine lists a vertex's bones in any order; by bone index reads best.
        out.sort_by_key(|i| i.bone);
        influences.push(out);
    }
    Ok(MeshAttachment {
        uvs: order.iter().map(|&v| region.uv(vertices[v])).collect(),
        triangles: triangles
            .iter()
            .flat_map(|t| t.map(|v| new_index[v as usize]))
            .collect(),
        hull: hull_loop.len(),
        edges,
        influences,
        vertex_source: order,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hull_comes_first_and_edges_are_doubled() {
        // A square split by a diagonal, with an interior vertex listed first.
        let tris = vec![[1, 2, 0], [1, 0, 3], [1, 3, 4], [1, 4, 2]];
        let loops = boundary_loops(&tris);
        assert_eq!(loops.len(), 1);
        let mut ring = loops[0].clone();
        ring.sort();
        assert_eq!(ring, vec![0, 2, 3, 4]);
    }

    #[test]
    fn region_rect_holds_the_mesh_with_a_margin() {
        let r = RegionRect::around(&[Point::new(-1.5, 2.2), Point::new(10.1, 7.0)], 2);
        assert_eq!(
            r,
            RegionRect {
                x: -4,
                y: 0,
                width: 17,
                height: 9
            }
        );
        assert_eq!(r.uv(Point::new(-4.0, 9.0)), Point::new(0.0, 1.0));
    }
}
