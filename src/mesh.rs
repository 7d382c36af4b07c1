//! Outlines → quality triangle mesh.
//!
//! In: the [`Outline`]s of one part (canvas pixels, from [`crate::trace`]), the canvas size and
//! [`MeshOptions`]. Out: a [`Mesh`] whose vertices are canvas pixels (which are also the texture
//! coordinates of the part's image, since all layers share the canvas) and whose triangles all
//! have positive [`triangle_area2`] (clockwise on screen, y down).
//!
//! The outline rings become constraint edges of spade's constrained Delaunay triangulation;
//! Delaunay refinement (Ruppert/Chew style, spade's `refine`) then adds Steiner points until
//! every triangle meets the angle and area limits. Faces outside the outer rings or inside holes
//! are dropped (spade decides inside by the winding parity of the constraint rings).

use crate::geom::{ring_signed_area, triangle_area2, Point};
use crate::trace::Outline;
use serde::{Deserialize, Serialize};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};
use std::collections::HashMap;

/// How outlines become triangles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MeshOptions {
    /// Whether to add interior (Steiner) points for quality. Default true.
    pub refine: bool,
    /// Smallest interior angle refinement aims for, degrees. Default 28. Corners of the outline
    /// sharper than this stay sharp; spade's refinement degrades above 30°.
    pub min_angle_deg: f64,
    /// Largest triangle area as a fraction of the canvas area. Default 1/1600 (a 512² canvas
    /// gives triangles of at most ~164 px²).
    pub max_area_fraction: f64,
    /// Triangles smaller than this (px²) are never split further; it stops refinement from
    /// chasing tiny features of the outline. Default 0.25.
    pub min_refine_area_px2: f64,
    /// Whether refinement may split outline edges. Off keeps the hull exactly the traced
    /// outline (fewer vertices for game runtimes) at some cost in angle quality. Default true.
    pub split_outline: bool,
    /// A safety budget: refinement stops after adding this many times the points that the area
    /// limit and the outline call for (outline points + region area / largest area). Default 8.
    pub steiner_budget_factor: f64,
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions {
            refine: true,
            min_angle_deg: 28.0,
            max_area_fraction: 1.0 / 1600.0,
            min_refine_area_px2: 0.25,
            split_outline: true,
            steiner_budget_factor: 8.0,
        }
    }
}

impl MeshOptions {
    /// Few vertices, for meshes that game runtimes draw: the outline is kept as traced (trace it
    /// coarsely too, see [`crate::trace::TraceOptions::coarse`]) and only large triangles are
    /// split.
    pub fn coarse() -> Self {
        MeshOptions {
            refine: true,
            min_angle_deg: 15.0,
            max_area_fraction: 1.0 / 100.0,
            split_outline: false,
            ..MeshOptions::default()
        }
    }

    fn validate(&self) -> Result<(), MeshError> {
        let bad = |what: &str| Err(MeshError::InvalidOptions(what.to_string()));
        if !(self.min_angle_deg.is_finite()
            && (0.0..=MAX_ANGLE_LIMIT_DEG).contains(&self.min_angle_deg))
        {
            return bad("min_angle_deg must lie in [0, 33]");
        }
        if !(self.max_area_fraction.is_finite() && self.max_area_fraction > 0.0) {
            return bad("max_area_fraction must be positive");
        }
        if !(self.steiner_budget_factor.is_finite() && self.steiner_budget_factor >= 1.0) {
            return bad("steiner_budget_factor must be at least 1");
        }
        if !(self.min_refine_area_px2.is_finite() && self.min_refine_area_px2 >= 0.0) {
            return bad("min_refine_area_px2 must be non-negative");
        }
        Ok(())
    }
}

/// Above this, Delaunay refinement is not guaranteed to terminate.
const MAX_ANGLE_LIMIT_DEG: f64 = 33.0;

/// A triangle mesh in canvas pixels.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Rest positions, canvas px; also the texture coordinates in the part's image, px.
    pub vertices: Vec<Point>,
    /// Vertex indices, each triangle with positive [`triangle_area2`].
    pub triangles: Vec<[u32; 3]>,
}

/// Counts and quality of a mesh, for reports.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MeshStats {
    pub vertices: usize,
    pub triangles: usize,
    /// Smallest interior angle over all triangles, degrees.
    pub min_angle_deg: f64,
}

/// What the caller got wrong.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MeshError {
    #[error("nothing to triangulate: no outline")]
    Empty,
    #[error("outline coordinates are not finite")]
    NonFinite,
    #[error("outline edges cross each other")]
    CrossingOutlines,
    #[error("invalid mesh option: {0}")]
    InvalidOptions(String),
}

impl Mesh {
    /// Vertex and triangle counts and the smallest angle.
    pub fn stats(&self) -> MeshStats {
        let min_angle_deg = self
            .triangles
            .iter()
            .map(|t| triangle_min_angle_deg(t.map(|i| self.vertices[i as usize])))
            .fold(f64::INFINITY, f64::min);
        MeshStats {
            vertices: self.vertices.len(),
            triangles: self.triangles.len(),
            min_angle_deg: if self.triangles.is_empty() {
                0.0
            } else {
                min_angle_deg
            },
        }
    }

    /// Each undirected edge once, as (smaller index, larger index), sorted.
    pub fn edges(&self) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = self
            .triangles
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .map(|[a, b]| [a.min(b), a.max(b)])
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }
}

/// The smallest interior angle of a triangle, degrees (0 for a degenerate one).
pub fn triangle_min_angle_deg(p: [Point; 3]) -> f64 {
    (0..3)
        .map(|i| {
            let (a, b, c) = (p[i], p[(i + 1) % 3], p[(i + 2) % 3]);
            let (u, v) = (b - a, c - a);
            let denom = u.norm() * v.norm();
            if denom == 0.0 {
                0.0
            } else {
                (u.dot(&v) / denom).clamp(-1.0, 1.0).acos().to_degrees()
            }
        })
        .fold(f64::INFINITY, f64::min)
}

/// Triangulates the region inside `outlines` (outer rings minus holes).
///
/// `canvas_area_px2` scales [`MeshOptions::max_area_fraction`].
pub fn triangulate(
    outlines: &[Outline],
    canvas_area_px2: f64,
    options: &MeshOptions,
) -> Result<Mesh, MeshError> {
    options.validate()?;
    if !(canvas_area_px2.is_finite() && canvas_area_px2 > 0.0) {
        return Err(MeshError::InvalidOptions(
            "the canvas area must be positive".into(),
        ));
    }
    let rings: Vec<&[Point]> = outlines
        .iter()
        .flat_map(|o| std::iter::once(o.outer.as_slice()).chain(o.holes.iter().map(Vec::as_slice)))
        .filter(|r| r.len() >= 3)
        .collect();
    if rings.is_empty() {
        return Err(MeshError::Empty);
    }
    let (points, edges) = constraint_graph(&rings)?;
    let outline_points = points.len();
    let mut conflict = false;
    let mut cdt =
        ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(points, edges, |_| {
            conflict = true
        })
        .map_err(|_| MeshError::NonFinite)?;
    if conflict {
        return Err(MeshError::CrossingOutlines);
    }

    let max_area_px2 = options.max_area_fraction * canvas_area_px2;
    let mut params = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .with_angle_limit(AngleLimit::from_deg(if options.refine {
            options.min_angle_deg
        } else {
            0.0
        }))
        .with_min_required_area(options.min_refine_area_px2)
        .with_max_additional_vertices(if options.refine {
            let region_area: f64 = rings.iter().map(|r| ring_signed_area(r)).sum();
            let expected = outline_points as f64 + region_area.abs() / max_area_px2;
            (options.steiner_budget_factor * expected).ceil() as usize
        } else {
            0
        });
    if options.refine {
        params = params.with_max_allowed_area(max_area_px2);
    }
    if !options.split_outline {
        params = params.keep_constraint_edges();
    }
    let result = cdt.refine(params);
    let excluded: std::collections::HashSet<_> = result.excluded_faces.into_iter().collect();

    // Keep inner faces only, renumbering the vertices they use in spade's (deterministic) order.
    let mut index_of: HashMap<usize, u32> = HashMap::new();
    let mut used = vec![false; cdt.num_vertices()];
    let inner: Vec<[usize; 3]> = cdt
        .inner_faces()
        .filter(|f| !excluded.contains(&f.fix()))
        .map(|f| f.vertices().map(|v| v.fix().index()))
        .collect();
    for t in &inner {
        for &v in t {
            used[v] = true;
        }
    }
    let mut vertices = Vec::new();
    for (i, v) in cdt.vertices().enumerate() {
        if used[i] {
            index_of.insert(i, vertices.len() as u32);
            let p = v.position();
            vertices.push(Point::new(p.x, p.y));
        }
    }
    let triangles = inner
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|v| index_of[&v]);
            let area2 = triangle_area2(
                vertices[a as usize],
                vertices[b as usize],
                vertices[c as usize],
            );
            // Spade's faces are counter-clockwise in y-up terms, i.e. negative here; flip them.
            if area2 < 0.0 {
                Some([a, c, b])
            } else if area2 > 0.0 {
                Some([a, b, c])
            } else {
                None
            }
        })
        .collect();
    Ok(Mesh {
        vertices,
        triangles,
    })
}

/// The rings' points (deduplicated exactly) and the constraint edges between them.
fn constraint_graph(rings: &[&[Point]]) -> Result<(Vec<Point2<f64>>, Vec<[usize; 2]>), MeshError> {
    let mut points = Vec::new();
    let mut index_of: HashMap<(u64, u64), usize> = HashMap::new();
    let mut edges = Vec::new();
    for ring in rings {
        let ids: Vec<usize> = ring
            .iter()
            .map(|p| {
                if !(p.x.is_finite() && p.y.is_finite()) {
                    return Err(MeshError::NonFinite);
                }
                Ok(*index_of
                    .entry((p.x.to_bits(), p.y.to_bits()))
                    .or_insert_with(|| {
                        points.push(Point2::new(p.x, p.y));
                        points.len() - 1
                    }))
            })
            .collect::<Result<_, _>>()?;
        for i in 0..ids.len() {
            let (a, b) = (ids[i], ids[(i + 1) % ids.len()]);
            if a != b {
                edges.push([a, b]);
            }
        }
    }
    Ok((points, edges))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, side: f64) -> Vec<Point> {
        vec![
            Point::new(x0, y0),
            Point::new(x0 + side, y0),
            Point::new(x0 + side, y0 + side),
            Point::new(x0, y0 + side),
        ]
    }

    fn area(mesh: &Mesh) -> f64 {
        mesh.triangles
            .iter()
            .map(|t| {
                0.5 * triangle_area2(
                    t.map(|i| mesh.vertices[i as usize])[0],
                    mesh.vertices[t[1] as usize],
                    mesh.vertices[t[2] as usize],
                )
            })
            .sum()
    }

    #[test]
    fn square_with_hole_keeps_the_hole() {
        let mut hole = square(40.0, 40.0, 20.0);
        hole.reverse();
        let outline = Outline {
            outer: square(0.0, 0.0, 100.0),
            holes: vec![hole],
        };
        let mesh = triangulate(&[outline], 100.0 * 100.0, &MeshOptions::default()).unwrap();
        assert!(
            (area(&mesh) - (10000.0 - 400.0)).abs() < 1e-6,
            "area {}",
            area(&mesh)
        );
        let stats = mesh.stats();
        assert!(stats.min_angle_deg >= 20.0, "{stats:?}");
        // Every triangle is positively oriented and none lies in the hole.
        for t in &mesh.triangles {
            let p = t.map(|i| mesh.vertices[i as usize]);
            assert!(triangle_area2(p[0], p[1], p[2]) > 0.0);
            let c = Point::new(
                (p[0].x + p[1].x + p[2].x) / 3.0,
                (p[0].y + p[1].y + p[2].y) / 3.0,
            );
            assert!(!(c.x > 40.0 && c.x < 60.0 && c.y > 40.0 && c.y < 60.0));
        }
        // Area limit: 1/1600 of the canvas.
        for t in &mesh.triangles {
            let p = t.map(|i| mesh.vertices[i as usize]);
            assert!(0.5 * triangle_area2(p[0], p[1], p[2]) <= 10000.0 / 1600.0 + 1e-9);
        }
    }

    #[test]
    fn two_components_and_coarse_setting() {
        let outlines = [
            Outline {
                outer: square(0.0, 0.0, 50.0),
                holes: vec![],
            },
            Outline {
                outer: square(100.0, 0.0, 50.0),
                holes: vec![],
            },
        ];
        let fine = triangulate(&outlines, 200.0 * 200.0, &MeshOptions::default()).unwrap();
        let coarse = triangulate(&outlines, 200.0 * 200.0, &MeshOptions::coarse()).unwrap();
        assert!((area(&fine) - 5000.0).abs() < 1e-6);
        assert!((area(&coarse) - 5000.0).abs() < 1e-6);
        assert!(
            coarse.vertices.len() * 4 < fine.vertices.len(),
            "{} vs {}",
            coarse.vertices.len(),
            fine.vertices.len()
        );
    }

    #[test]
    fn crossing_outline_is_an_error_not_a_panic() {
        let bow = vec![
            Point::new(0.0, 0.0),
            Point::new(10.0, 10.0),
            Point::new(10.0, 0.0),
            Point::new(0.0, 10.0),
        ];
        let r = triangulate(
            &[Outline {
                outer: bow,
                holes: vec![],
            }],
            100.0,
            &MeshOptions::default(),
        );
        assert_eq!(r, Err(MeshError::CrossingOutlines));
    }

    #[test]
    fn bad_options_and_empty_input() {
        assert_eq!(
            triangulate(&[], 1.0, &MeshOptions::default()),
            Err(MeshError::Empty)
        );
        let o = MeshOptions {
            min_angle_deg: 45.0,
            ..MeshOptions::default()
        };
        let sq = [Outline {
            outer: square(0.0, 0.0, 1.0),
            holes: vec![],
        }];
        assert!(matches!(
            triangulate(&sq, 1.0, &o),
            Err(MeshError::InvalidOptions(_))
        ));
        let nan = [Outline {
            outer: vec![
                Point::new(f64::NAN, 0.0),
                Point::new(1.0, 0.0),
                Point::new(0.0, 1.0),
            ],
            holes: vec![],
        }];
        assert_eq!(
            triangulate(&nan, 1.0, &MeshOptions::default()),
            Err(MeshError::NonFinite)
        );
    }
}
