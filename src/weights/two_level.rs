//! Two-level weights: solve on a coarse mesh of the same domain, carry the weights to the fine
//! mesh.
//!
//! The bounded biharmonic weights are smooth at the scale of the handles, not of the drawing's
//! mesh, so most of a fine solve's cost buys nothing visible. As Jacobson et al. 2011 solve
//! images, and as Unity's 2D Animation does for sprites (it re-tessellates coarsely before its
//! BBW solve), the weights are solved exactly on a coarse triangulation of the same weight
//! domain (the same outline rings, cages and handle geometry, so every handle is there) and
//! read back at each fine vertex by linear interpolation in the coarse triangle that holds it.
//! A convex combination of rows in [0, 1] that sum to one is in [0, 1] and sums to one: bounds
//! and partition of unity stay exact. Fine vertices a handle fixes keep the handle's own
//! values exactly.
//!
//! In: the fine and coarse [`EmbeddedMesh`]es of one part (canvas px), the handles, the binding
//! flags, the coarse vertices' colors for content-aware weights, [`WeightOptions`]. Out: the
//! fine mesh's [`PartWeights`].

use super::active_set::active_set_bbw;
use super::part::{
    boundary_conditions, check_options, domain_weights, normalize_rows, shape_rows, weight_domain,
    DomainWeights, PartWeights, TwoLevelOptions, TwoLevelPolish, WeightMethod,
};
use super::solve::{BoundaryConditions, Domain, WeightMatrix};
use super::sparse::SolveError;
use super::support::{support_bbw, SupportSolver};
use super::{WeightError, WeightOptions};
use crate::geom::Point;
use crate::mesh::{EmbeddedMesh, Mesh};
use crate::rig::Handles;

/// A point whose barycentric coordinates in a triangle are all above this is inside it (the
/// slack covers rounding on shared edges and on the domain's boundary).
pub const INSIDE_BARYCENTRIC: f64 = -1e-9;

/// Solves `coarse` and carries the weights to `fine` (see the module doc), then, with bounded
/// biharmonic weights, polishes them on `fine` ([`TwoLevelOptions::polish`]).
/// `fine_colors` and `coarse_colors`: one premultiplied RGB per domain vertex of each mesh,
/// needed only with content-aware weights.
pub fn two_level_weights(
    fine: &EmbeddedMesh,
    coarse: &EmbeddedMesh,
    handles: &Handles,
    binding: &[bool],
    fine_colors: Option<&[[f64; 3]]>,
    coarse_colors: Option<&[[f64; 3]]>,
    options: &WeightOptions,
) -> Result<PartWeights, WeightError> {
    check_options(handles, binding, options)?;
    let two_level = options.two_level.clone().unwrap_or_default();
    let (bc, touched, _) = boundary_conditions(fine, handles, binding);
    let polished = two_level.polish != TwoLevelPolish::None
        && options.method == WeightMethod::Bbw
        && !options.monotone;
    // The fine mesh's support solver does not need the coarse weights: it is prepared while
    // the coarse mesh solves.
    let prepare = || -> Result<Option<(Domain, Option<SupportSolver>)>, WeightError> {
        if !polished {
            return Ok(None);
        }
        let domain = weight_domain(&fine.domain, fine_colors, options)?;
        let solver = match two_level.polish {
            TwoLevelPolish::Support => Some(SupportSolver::new(&domain, &bc)?),
            _ => None,
        };
        Ok(Some((domain, solver)))
    };
    let (solved, prepared) = rayon::join(
        || domain_weights(coarse, handles, binding, coarse_colors, options),
        prepare,
    );
    let solved = solved?;
    let mut matrix = carry_to(&coarse.domain, &solved.matrix, &fine.domain.vertices);
    if let Some((domain, solver)) = prepared? {
        matrix = match solver {
            Some(solver) => solver.solve(&matrix, two_level.support_floor)?,
            None => polish(&domain, &bc, &matrix, &two_level)?,
        };
        normalize_rows(&mut matrix, &fine.domain, handles, binding);
    }
    // The handles' own vertices keep exactly what the handles give them.
    let m = matrix.handle_count;
    for (k, &v) in bc.vertices.iter().enumerate() {
        matrix.data[v * m..(v + 1) * m].copy_from_slice(&bc.values[k * m..(k + 1) * m]);
    }
    Ok(shape_rows(
        fine,
        DomainWeights {
            matrix,
            touched,
            bound_to_nearest: solved.bound_to_nearest,
            bound_vertices: solved.bound_vertices,
            unconverged: solved.unconverged,
        },
        options,
    ))
}

/// The fine mesh's bounded biharmonic weights from `carried` (weights carried from a coarse
/// solve, one row per vertex of `domain`) by the polish `options.polish` names, clamped to
/// [0, 1], rows not normalized; `carried` itself with [`TwoLevelPolish::None`].
pub fn polish(
    domain: &Domain,
    bc: &BoundaryConditions,
    carried: &WeightMatrix,
    options: &TwoLevelOptions,
) -> Result<WeightMatrix, SolveError> {
    match options.polish {
        TwoLevelPolish::None => Ok(carried.clone()),
        TwoLevelPolish::Support => support_bbw(domain, bc, carried, options.support_floor),
        // The polish is a fixed number of steps toward the fine solution: sets that have not
        // settled by then are expected, not a failure (only the coarse solve's are reported).
        TwoLevelPolish::ActiveSet => {
            active_set_bbw(domain, bc, carried, options.polish_iterations).map(|(w, _)| w)
        }
    }
}

/// The weights `w` (one row per vertex of `mesh`) at `points`, interpolated linearly in the
/// triangle of `mesh` that holds each point; a point outside every triangle (rounding at the
/// boundary, or a fine vertex a hair outside the coarse domain) takes the nearest triangle's
/// values with its barycentric coordinates clamped to the triangle.
pub fn carry_to(mesh: &Mesh, w: &WeightMatrix, points: &[Point]) -> WeightMatrix {
    let m = w.handle_count;
    let grid = TriangleGrid::new(mesh);
    let mut data = vec![0.0; points.len() * m];
    for (p, out) in points.iter().zip(data.chunks_mut(m.max(1))) {
        let Some((t, b)) = grid.locate(mesh, *p) else {
            continue;
        };
        for (corner, &weight) in mesh.triangles[t].iter().zip(&b) {
            if weight > 0.0 {
                for (o, x) in out.iter_mut().zip(w.row(*corner as usize)) {
                    *o += weight * x;
                }
            }
        }
    }
    WeightMatrix {
        vertex_count: points.len(),
        handle_count: m,
        data,
    }
}

/// Barycentric coordinates of `p` in triangle `abc` (NaN for a degenerate triangle).
fn barycentric(p: Point, [a, b, c]: [Point; 3]) -> [f64; 3] {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let det = v0.x * v1.y - v1.x * v0.y;
    let u = (v2.x * v1.y - v1.x * v2.y) / det;
    let v = (v0.x * v2.y - v2.x * v0.y) / det;
    [1.0 - u - v, u, v]
}

/// Triangles bucketed by the grid cells their bounding boxes overlap, for point location.
struct TriangleGrid {
    min: Point,
    cell_px: f64,
    columns: usize,
    rows: usize,
    cells: Vec<Vec<u32>>,
}

impl TriangleGrid {
    fn new(mesh: &Mesh) -> Self {
        let (mut min, mut max) = (
            Point::new(f64::INFINITY, f64::INFINITY),
            Point::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for p in &mesh.vertices {
            min = Point::new(min.x.min(p.x), min.y.min(p.y));
            max = Point::new(max.x.max(p.x), max.y.max(p.y));
        }
        let n = mesh.triangles.len().max(1) as f64;
        let (width, height) = ((max.x - min.x).max(1e-9), (max.y - min.y).max(1e-9));
        // About one triangle per cell.
        let cell_px = (width * height / n).sqrt().max(1e-9);
        let columns = ((width / cell_px).ceil() as usize).clamp(1, 4096);
        let rows = ((height / cell_px).ceil() as usize).clamp(1, 4096);
        let cell_px = (width / columns as f64).max(height / rows as f64);
        let mut grid = TriangleGrid {
            min,
            cell_px,
            columns,
            rows,
            cells: vec![Vec::new(); columns * rows],
        };
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let corners = tri.map(|v| mesh.vertices[v as usize]);
            let (lo, hi) = corners.iter().fold(
                (
                    Point::new(f64::INFINITY, f64::INFINITY),
                    Point::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
                ),
                |(lo, hi), p| {
                    (
                        Point::new(lo.x.min(p.x), lo.y.min(p.y)),
                        Point::new(hi.x.max(p.x), hi.y.max(p.y)),
                    )
                },
            );
            let (c0, r0) = grid.cell_of(lo);
            let (c1, r1) = grid.cell_of(hi);
            for r in r0..=r1 {
                for c in c0..=c1 {
                    grid.cells[r * columns + c].push(t as u32);
                }
            }
        }
        grid
    }

    fn cell_of(&self, p: Point) -> (usize, usize) {
        let c = ((p.x - self.min.x) / self.cell_px).floor();
        let r = ((p.y - self.min.y) / self.cell_px).floor();
        (
            (c.max(0.0) as usize).min(self.columns - 1),
            (r.max(0.0) as usize).min(self.rows - 1),
        )
    }

    /// The triangle holding `p` and `p`'s barycentric coordinates in it, clamped to [0, 1] and
    /// summing to one; the nearest triangle (searched in growing rings of cells) if none holds
    /// it. `None` only for a mesh without a proper triangle.
    fn locate(&self, mesh: &Mesh, p: Point) -> Option<(usize, [f64; 3])> {
        let (c, r) = self.cell_of(p);
        let mut best: Option<(f64, usize, [f64; 3])> = None;
        let reach = self.columns.max(self.rows);
        for ring in 0..=reach {
            let (c0, c1) = (c.saturating_sub(ring), (c + ring).min(self.columns - 1));
            let (r0, r1) = (r.saturating_sub(ring), (r + ring).min(self.rows - 1));
            for rr in r0..=r1 {
                for cc in c0..=c1 {
                    let on_ring = rr == r0 || rr == r1 || cc == c0 || cc == c1;
                    if !on_ring {
                        continue;
                    }
                    for &t in &self.cells[rr * self.columns + cc] {
                        let tri = mesh.triangles[t as usize];
                        let b = barycentric(p, tri.map(|v| mesh.vertices[v as usize]));
                        let worst = b[0].min(b[1]).min(b[2]);
                        if !worst.is_finite() {
                            continue;
                        }
                        let better = best.is_none_or(|(w, bt, _)| {
                            worst > w || (worst == w && (t as usize) < bt)
                        });
                        if better {
                            best = Some((worst, t as usize, b));
                        }
                    }
                }
            }
            match best {
                Some((worst, _, _)) if worst >= INSIDE_BARYCENTRIC => break,
                // Outside every triangle met so far: one more ring may hold a nearer one (the
                // cells are about a triangle wide), then the nearest found is taken.
                Some(_) if ring >= 1 => break,
                _ => {}
            }
        }
        best.map(|(_, t, b)| {
            let clamped = b.map(|x| x.max(0.0));
            let sum: f64 = clamped.iter().sum();
            (t, clamped.map(|x| x / sum))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_mesh() -> Mesh {
        Mesh {
            vertices: vec![
                Point::new(0.0, 0.0),
                Point::new(10.0, 0.0),
                Point::new(10.0, 10.0),
                Point::new(0.0, 10.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    #[test]
    fn linear_functions_are_carried_exactly_and_rows_stay_partitions() {
        let mesh = square_mesh();
        // Two columns: x / 10 and 1 − x / 10.
        let w = WeightMatrix {
            vertex_count: 4,
            handle_count: 2,
            data: vec![0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0],
        };
        let points = [
            Point::new(2.5, 7.0),
            Point::new(9.0, 1.0),
            Point::new(5.0, 5.0),
            // Outside the square: clamped to its edge.
            Point::new(12.0, 5.0),
            Point::new(-1e-12, 3.0),
        ];
        let carried = carry_to(&mesh, &w, &points);
        for (i, p) in points.iter().enumerate() {
            let x = p.x.clamp(0.0, 10.0) / 10.0;
            let row = carried.row(i);
            assert!((row[0] - x).abs() < 1e-12, "{p:?}: {row:?}");
            assert!((row[0] + row[1] - 1.0).abs() < 1e-12);
            assert!(row.iter().all(|&v| (0.0..=1.0).contains(&v)));
        }
    }
}
