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

pub mod crossing;

use crate::geom::{point_in_ring, ring_signed_area, triangle_area2, Point};
use crate::trace::Outline;
use serde::{Deserialize, Serialize};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};
use std::collections::{HashMap, HashSet};

/// How outlines become triangles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
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
    /// chasing tiny features of the outline. Default 0.02.
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
            min_refine_area_px2: 0.02,
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

    /// Checks the options: each out of range is refused naming the field as files write it
    /// (`min_angle_deg`; the command line maps it to its flag) and the rule with the value.
    pub fn check(&self) -> Result<(), MeshError> {
        let shown = crate::shown::Shown;
        let bad = |field: &'static str, rule: String| Err(MeshError::InvalidOption { field, rule });
        if !(self.min_angle_deg.is_finite()
            && (0.0..=MAX_ANGLE_LIMIT_DEG).contains(&self.min_angle_deg))
        {
            return bad(
                "min_angle_deg",
                format!(
                    "must lie in [0, {MAX_ANGLE_LIMIT_DEG}] degrees, not {}",
                    shown(self.min_angle_deg)
                ),
            );
        }
        if !(self.max_area_fraction.is_finite() && self.max_area_fraction > 0.0) {
            return bad(
                "max_area_fraction",
                format!("must be positive, not {}", shown(self.max_area_fraction)),
            );
        }
        if !(self.steiner_budget_factor.is_finite() && self.steiner_budget_factor >= 1.0) {
            return bad(
                "steiner_budget_factor",
                format!(
                    "must be at least 1, not {}",
                    shown(self.steiner_budget_factor)
                ),
            );
        }
        if !(self.min_refine_area_px2.is_finite() && self.min_refine_area_px2 >= 0.0) {
            return bad(
                "min_refine_area_px2",
                format!(
                    "must be at least 0, not {}",
                    shown(self.min_refine_area_px2)
                ),
            );
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
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
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
    #[error(
        "cage {cage}: its edge {edge} runs along the drawing's outline; move that edge's \
         vertices off the outline"
    )]
    CageAlongOutline { cage: usize, edge: usize },
    #[error("cage {first} and cage {second} cross each other: cages must not overlap")]
    CagesCross { first: usize, second: usize },
    #[error("the canvas has no area to mesh")]
    EmptyCanvas,
    /// An option out of range: the field as files write it, and the rule with the value.
    #[error("invalid mesh option: {field} {rule}")]
    InvalidOption { field: &'static str, rule: String },
    #[error(
        "the area limit asks for about {expected:.3e} mesh vertices, more than {MAX_MESH_VERTICES}: \
         raise max_area_fraction"
    )]
    TooFine { expected: f64 },
}

/// The most vertices a mesh may be asked for (outline points plus region area over the largest
/// triangle area): a sprite's mesh is far smaller, and a tiny area limit would otherwise refine
/// for minutes and fill the memory.
pub const MAX_MESH_VERTICES: f64 = 2_000_000.0;

/// The refinement budget for a mesh of about `expected` vertices, or why it is too fine to
/// refine.
fn steiner_budget(expected: f64, options: &MeshOptions) -> Result<usize, MeshError> {
    if options.refine && (expected.is_nan() || expected > MAX_MESH_VERTICES) {
        return Err(MeshError::TooFine { expected });
    }
    Ok((options.steiner_budget_factor * expected).ceil() as usize)
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

/// Per vertex of a mesh of `vertex_count` vertices, its neighbours along triangle edges
/// (sorted, no duplicates). Every triangle index must be below `vertex_count`.
pub fn vertex_neighbours(vertex_count: usize, triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut neighbours = vec![Vec::new(); vertex_count];
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    neighbours
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
    let rings = checked_rings(outlines, canvas_area_px2, options)?;
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
    let region_area: f64 = rings.iter().map(|r| ring_signed_area(r)).sum();
    let expected = outline_points as f64 + region_area.abs() / max_area_px2;
    let budget = steiner_budget(expected, options)?;
    let params = refinement_parameters(options, max_area_px2, budget, true);
    let result = cdt.refine(params);
    let excluded: HashSet<_> = result.excluded_faces.into_iter().collect();
    let (mesh, _) = extract_faces(&cdt, |f| !excluded.contains(&f));
    Ok(mesh)
}

/// Handle geometry a mesh must contain, canvas px.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HandleGeometry {
    /// Each becomes a mesh vertex (point handles).
    pub points: Vec<Point>,
    /// Each becomes a chain of mesh edges (bones).
    pub segments: Vec<[Point; 2]>,
    /// Closed polygons whose edges become mesh edges (cage and region outlines).
    pub polygons: Vec<Vec<Point>>,
    /// Closed polygons whose inside joins the weight domain (cages reaching past the shape).
    pub domain_extensions: Vec<Vec<Point>>,
}

/// A mesh of the weight domain (the shape plus any cage insides) that contains handle geometry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EmbeddedMesh {
    /// The weight domain's mesh.
    pub domain: Mesh,
    /// Per domain triangle: whether it lies inside the traced shape (and so is drawn).
    pub in_shape: Vec<bool>,
}

impl EmbeddedMesh {
    /// The drawn mesh (the triangles inside the shape, with only the vertices they use) and,
    /// per drawn vertex, its index in the domain mesh.
    pub fn shape_mesh(&self) -> (Mesh, Vec<usize>) {
        let mut new_index = vec![u32::MAX; self.domain.vertices.len()];
        let mut domain_index = Vec::new();
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for (t, &inside) in self.domain.triangles.iter().zip(&self.in_shape) {
            if !inside {
                continue;
            }
            triangles.push(t.map(|v| {
                if new_index[v as usize] == u32::MAX {
                    new_index[v as usize] = vertices.len() as u32;
                    vertices.push(self.domain.vertices[v as usize]);
                    domain_index.push(v as usize);
                }
                new_index[v as usize]
            }));
        }
        (
            Mesh {
                vertices,
                triangles,
            },
            domain_index,
        )
    }
}

/// Triangulates the shape inside `outlines` together with handle geometry, so that handles'
/// points and edges are mesh vertices and edges. The domain is the shape plus the insides of
/// `geometry.domain_extensions`; geometry outside the domain is dropped.
pub fn triangulate_with_handles(
    outlines: &[Outline],
    geometry: &HandleGeometry,
    canvas_area_px2: f64,
    options: &MeshOptions,
) -> Result<EmbeddedMesh, MeshError> {
    let rings = checked_rings(outlines, canvas_area_px2, options)?;
    let all_finite = geometry
        .points
        .iter()
        .chain(geometry.segments.iter().flatten())
        .chain(geometry.polygons.iter().flatten())
        .chain(geometry.domain_extensions.iter().flatten())
        .all(|p| p.x.is_finite() && p.y.is_finite());
    if !all_finite {
        return Err(MeshError::NonFinite);
    }
    let extensions: Vec<&[Point]> = geometry
        .domain_extensions
        .iter()
        .map(Vec::as_slice)
        .collect();
    // Where a cage crosses the outline, both rings get the crossing point: the domain is the
    // union of the shape and the cages' insides.
    let split = crossing::split_at_crossings(&rings, &extensions)?;
    let rings: Vec<&[Point]> = split.rings.iter().map(Vec::as_slice).collect();
    let extensions: Vec<&[Point]> = split.extensions.iter().map(Vec::as_slice).collect();
    let (points, edges) =
        constraint_graph(&rings.iter().chain(&extensions).copied().collect::<Vec<_>>())?;
    let mut conflict = false;
    let mut cdt =
        ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(points, edges, |_| {
            conflict = true
        })
        .map_err(|_| MeshError::NonFinite)?;
    if conflict {
        return Err(MeshError::CrossingOutlines);
    }

    // Geometry far outside the domain only costs refinement work: clip it to the domain's box.
    let bounds = Bounds::of(rings.iter().chain(&extensions).flat_map(|r| r.iter())).expanded(1.0);
    for p in &geometry.points {
        if bounds.contains(*p) {
            cdt.insert(Point2::new(p.x, p.y))
                .map_err(|_| MeshError::NonFinite)?;
        }
    }
    // A cage's outline is already constrained, split where it crosses the drawing's outline:
    // its split ring replaces it (the whole edge again would cross the outline a hair away).
    let polygons = geometry.polygons.iter().map(|poly| {
        geometry
            .domain_extensions
            .iter()
            .position(|e| e == poly)
            .map_or(poly.as_slice(), |k| extensions[k])
    });
    let polygon_edges = polygons
        .flat_map(|poly| (0..poly.len()).map(move |i| [poly[i], poly[(i + 1) % poly.len()]]));
    for [a, b] in geometry.segments.iter().copied().chain(polygon_edges) {
        let Some((a, b)) = bounds.clip_segment(a, b) else {
            continue;
        };
        let from = cdt
            .insert(Point2::new(a.x, a.y))
            .map_err(|_| MeshError::NonFinite)?;
        let to = cdt
            .insert(Point2::new(b.x, b.y))
            .map_err(|_| MeshError::NonFinite)?;
        if from != to {
            cdt.add_constraint_and_split(from, to, |p| p);
        }
    }

    // Handle polygons would flip spade's inside/outside parity, so refine everywhere in the
    // hull and classify faces by their centroids afterwards.
    let max_area_px2 = options.max_area_fraction * canvas_area_px2;
    let expected = cdt.num_vertices() as f64 + bounds.area() / max_area_px2;
    let budget = steiner_budget(expected, options)?;
    cdt.refine(refinement_parameters(options, max_area_px2, budget, false));

    let in_shape = |c: Point| rings.iter().filter(|r| point_in_ring(c, r)).count() % 2 == 1;
    let in_extension = |c: Point| extensions.iter().any(|r| point_in_ring(c, r));
    let (domain, centroids) = extract_faces(&cdt, |_| true);
    let mut keep = Vec::with_capacity(domain.triangles.len());
    let mut shape = Vec::with_capacity(domain.triangles.len());
    for c in &centroids {
        let inside = in_shape(*c);
        keep.push(inside || in_extension(*c));
        shape.push(inside);
    }
    let triangles: Vec<[u32; 3]> = domain
        .triangles
        .iter()
        .zip(&keep)
        .filter(|(_, &k)| k)
        .map(|(t, _)| *t)
        .collect();
    let in_shape: Vec<bool> = shape
        .iter()
        .zip(&keep)
        .filter(|(_, &k)| k)
        .map(|(s, _)| *s)
        .collect();
    let domain = drop_unused_vertices(Mesh {
        vertices: domain.vertices,
        triangles,
    });
    Ok(EmbeddedMesh { domain, in_shape })
}

/// Checks the options and the canvas area, and returns the outline rings (at least one).
fn checked_rings<'a>(
    outlines: &'a [Outline],
    canvas_area_px2: f64,
    options: &MeshOptions,
) -> Result<Vec<&'a [Point]>, MeshError> {
    options.check()?;
    if !(canvas_area_px2.is_finite() && canvas_area_px2 > 0.0) {
        return Err(MeshError::EmptyCanvas);
    }
    let rings = outline_rings(outlines);
    if rings.is_empty() {
        return Err(MeshError::Empty);
    }
    Ok(rings)
}

/// Every outer ring and hole of the outlines, in order.
fn outline_rings(outlines: &[Outline]) -> Vec<&[Point]> {
    outlines
        .iter()
        .flat_map(|o| std::iter::once(o.outer.as_slice()).chain(o.holes.iter().map(Vec::as_slice)))
        .filter(|r| r.len() >= 3)
        .collect()
}

fn refinement_parameters(
    options: &MeshOptions,
    max_area_px2: f64,
    budget: usize,
    exclude_outer: bool,
) -> RefinementParameters<f64> {
    let mut params = RefinementParameters::<f64>::new()
        .exclude_outer_faces(exclude_outer)
        .with_angle_limit(AngleLimit::from_deg(if options.refine {
            options.min_angle_deg
        } else {
            0.0
        }))
        .with_min_required_area(options.min_refine_area_px2)
        .with_max_additional_vertices(if options.refine { budget } else { 0 });
    if options.refine {
        params = params.with_max_allowed_area(max_area_px2);
    }
    if !options.split_outline {
        params = params.keep_constraint_edges();
    }
    params
}

/// An axis-aligned box, canvas px.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    min: Point,
    max: Point,
}

impl Bounds {
    fn of<'a>(points: impl Iterator<Item = &'a Point>) -> Self {
        let mut b = Bounds {
            min: Point::new(f64::INFINITY, f64::INFINITY),
            max: Point::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        };
        for p in points {
            b.min = Point::new(b.min.x.min(p.x), b.min.y.min(p.y));
            b.max = Point::new(b.max.x.max(p.x), b.max.y.max(p.y));
        }
        b
    }

    fn expanded(self, margin: f64) -> Self {
        Bounds {
            min: self.min - crate::geom::Vec2::new(margin, margin),
            max: self.max + crate::geom::Vec2::new(margin, margin),
        }
    }

    fn area(&self) -> f64 {
        (self.max.x - self.min.x).max(0.0) * (self.max.y - self.min.y).max(0.0)
    }

    fn contains(&self, p: Point) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }

    /// The part of segment a–b inside the box (Liang–Barsky), if any.
    fn clip_segment(&self, a: Point, b: Point) -> Option<(Point, Point)> {
        let d = b - a;
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (p, q) in [
            (-d.x, a.x - self.min.x),
            (d.x, self.max.x - a.x),
            (-d.y, a.y - self.min.y),
            (d.y, self.max.y - a.y),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
            }
        }
        (t0 <= t1).then(|| (a + d * t0, a + d * t1))
    }
}

/// The faces `keep` accepts, with vertices renumbered in spade's (deterministic) order, each
/// triangle oriented positively; also each kept triangle's centroid.
fn extract_faces<F>(
    cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>,
    keep: F,
) -> (Mesh, Vec<Point>)
where
    F: Fn(spade::handles::FixedFaceHandle<spade::handles::InnerTag>) -> bool,
{
    let inner: Vec<[usize; 3]> = cdt
        .inner_faces()
        .filter(|f| keep(f.fix()))
        .map(|f| f.vertices().map(|v| v.fix().index()))
        .collect();
    let positions: Vec<Point> = cdt
        .vertices()
        .map(|v| Point::new(v.position().x, v.position().y))
        .collect();
    let mut triangles = Vec::with_capacity(inner.len());
    let mut centroids = Vec::with_capacity(inner.len());
    for t in &inner {
        let [a, b, c] = t.map(|v| positions[v]);
        let area2 = triangle_area2(a, b, c);
        // Spade's faces are counter-clockwise in y-up terms, i.e. negative here; flip them.
        let tri = if area2 < 0.0 {
            [t[0], t[2], t[1]]
        } else if area2 > 0.0 {
            *t
        } else {
            continue;
        };
        triangles.push(tri.map(|v| v as u32));
        centroids.push(Point::from((a.coords + b.coords + c.coords) / 3.0));
    }
    (
        drop_unused_vertices(Mesh {
            vertices: positions,
            triangles,
        }),
        centroids,
    )
}

/// Removes vertices no triangle uses, keeping the others' order.
fn drop_unused_vertices(mesh: Mesh) -> Mesh {
    let mut new_index = vec![u32::MAX; mesh.vertices.len()];
    for t in &mesh.triangles {
        for &v in t {
            new_index[v as usize] = 0;
        }
    }
    let mut vertices = Vec::new();
    for (i, p) in mesh.vertices.iter().enumerate() {
        if new_index[i] == 0 {
            new_index[i] = vertices.len() as u32;
            vertices.push(*p);
        }
    }
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| new_index[v as usize]))
        .collect();
    Mesh {
        vertices,
        triangles,
    }
}

/// Points and the constraint edges between them (pairs of point indices).
type ConstraintGraph = (Vec<Point2<f64>>, Vec<[usize; 2]>);

/// The rings' points (deduplicated exactly) and the constraint edges between them.
fn constraint_graph(rings: &[&[Point]]) -> Result<ConstraintGraph, MeshError> {
    let mut points = Vec::new();
    let mut index_of: HashMap<(u64, u64), usize> = HashMap::new();
    let mut edges = Vec::new();
    let mut uses: HashMap<(u64, u64), usize> = HashMap::new();
    for p in rings.iter().flat_map(|r| r.iter()) {
        *uses.entry((p.x.to_bits(), p.y.to_bits())).or_default() += 1;
    }
    for ring in rings {
        let ring = drop_straight_vertices(ring, |p| uses[&(p.x.to_bits(), p.y.to_bits())] > 1);
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

/// A ring vertex whose two edges turn by less than this (the sine of the turn) is dropped.
///
/// Tracing can leave a vertex where the outline runs straight on. Refinement then splits the
/// two collinear constraint edges at midpoints that rounding puts a hair off the line, and the
/// triangles between those points have areas of 1e-16 px² and cotangents that break the
/// weight solve.
pub const STRAIGHT_TURN_SINE: f64 = 1e-9;

/// `ring` without the vertices where it runs straight on (see [`STRAIGHT_TURN_SINE`]), except
/// vertices that `keep` asks to keep (shared with another ring). Rings that would fall below
/// three vertices are returned as they are.
fn drop_straight_vertices(ring: &[Point], keep: impl Fn(Point) -> bool) -> Vec<Point> {
    let n = ring.len();
    if n <= 3 {
        return ring.to_vec();
    }
    let straight = |a: Point, b: Point, c: Point| {
        let (u, v) = (b - a, c - b);
        let cross = u.x * v.y - u.y * v.x;
        u.dot(&v) > 0.0 && cross.abs() <= STRAIGHT_TURN_SINE * u.norm() * v.norm()
    };
    // Start from a vertex that stays, so the wrap-around needs no special case.
    let Some(start) = (0..n)
        .find(|&i| keep(ring[i]) || !straight(ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]))
    else {
        return ring.to_vec();
    };
    let mut kept = vec![ring[start]];
    for k in 1..n {
        let b = ring[(start + k) % n];
        let c = ring[(start + k + 1) % n];
        let a = *kept.last().unwrap_or(&ring[start]);
        if keep(b) || !straight(a, b, c) {
            kept.push(b);
        }
    }
    if kept.len() < 3 {
        return ring.to_vec();
    }
    kept
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
    fn straight_ring_vertices_are_dropped_unless_shared() {
        let p = |x: f64, y: f64| Point::new(x, y);
        // A square with a vertex halfway along two sides, one of them shared with another ring.
        let ring = [
            p(0.0, 0.0),
            p(1.0, 0.0),
            p(2.0, 0.0),
            p(2.0 - 1e-12, 1.0),
            p(2.0, 2.0),
            p(0.0, 2.0),
        ];
        let kept = drop_straight_vertices(&ring, |q| q == p(1.0, 0.0));
        assert_eq!(
            kept,
            vec![
                p(0.0, 0.0),
                p(1.0, 0.0),
                p(2.0, 0.0),
                p(2.0, 2.0),
                p(0.0, 2.0)
            ]
        );
        // A turn back (a spike) is not straight, however thin.
        let spike = [p(0.0, 0.0), p(2.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)];
        assert_eq!(drop_straight_vertices(&spike, |_| false).len(), 4);
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
            Err(MeshError::InvalidOption { .. })
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
        // A tiny area limit is refused up front instead of refining for minutes.
        let tiny = MeshOptions {
            max_area_fraction: 1e-30,
            ..MeshOptions::default()
        };
        assert!(matches!(
            triangulate(&sq, 1.0, &tiny),
            Err(MeshError::TooFine { .. })
        ));
        let geometry = HandleGeometry {
            points: vec![Point::new(0.5, 0.5)],
            ..Default::default()
        };
        assert!(matches!(
            triangulate_with_handles(&sq, &geometry, 1.0, &tiny),
            Err(MeshError::TooFine { .. })
        ));
    }
}
