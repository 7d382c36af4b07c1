//! Handles → boundary conditions on a mesh that contains their geometry.
//!
//! In: mesh vertex positions (canvas px) and [`Handles`]. Out: [`BoundaryConditions`] over the
//! weight columns of [`handle_columns`]: a vertex on a bone or at a point handle gets weight 1
//! for it; a vertex on a cage edge gets the two cage corners' weights by linear interpolation
//! along the edge (barycentric); a vertex inside or on a region gets weight 1 for the region.
//! A vertex claimed by several handles (a joint shared by two bones) gets the mean of their
//! claims, which still sums to one.
//!
//! [`handle_columns`]: crate::rig::handle_columns

use super::solve::BoundaryConditions;
use crate::geom::{point_in_ring, segment_distance, Point, Vec2};
use crate::rig::Handles;

/// How far (px) a vertex may be from handle geometry and still lie on it: the mesher puts
/// handle vertices on the geometry up to floating-point rounding of edge splits.
pub const ON_HANDLE_TOLERANCE_PX: f64 = 1e-6;

/// Per vertex, each handle's claim: (column, weight) lists summing to one.
fn claims(vertices: &[Point], handles: &Handles, columns: usize) -> Vec<Vec<Vec<(usize, f64)>>> {
    let tol = ON_HANDLE_TOLERANCE_PX;
    let mut claims: Vec<Vec<Vec<(usize, f64)>>> = vec![Vec::new(); vertices.len()];
    let mut column = 0;
    for bone in &handles.bones {
        let (a, b) = (bone.head, bone.tail);
        for (i, &p) in vertices.iter().enumerate() {
            if segment_distance(p, a, b).0 <= tol {
                claims[i].push(vec![(column, 1.0)]);
            }
        }
        column += 1;
    }
    for point in &handles.points {
        for (i, &p) in vertices.iter().enumerate() {
            if (p - point.at).norm() <= tol {
                claims[i].push(vec![(column, 1.0)]);
            }
        }
        column += 1;
    }
    for cage in &handles.cages {
        let n = cage.polygon.len();
        for (i, &p) in vertices.iter().enumerate() {
            // A cage corner lies on two edges; take the first edge that holds the vertex.
            for k in 0..n {
                let (a, b) = (cage.polygon[k], cage.polygon[(k + 1) % n]);
                let (d, t) = segment_distance(p, a, b);
                if d <= tol {
                    claims[i].push(vec![(column + k, 1.0 - t), (column + (k + 1) % n, t)]);
                    break;
                }
            }
        }
        column += n;
    }
    for region in &handles.regions {
        let ring = &region.polygon;
        let n = ring.len();
        for (i, &p) in vertices.iter().enumerate() {
            let on_edge = (0..n).any(|k| segment_distance(p, ring[k], ring[(k + 1) % n]).0 <= tol);
            if on_edge || point_in_ring(p, ring) {
                claims[i].push(vec![(column, 1.0)]);
            }
        }
        column += 1;
    }
    debug_assert_eq!(column, columns);
    claims
}

/// The boundary conditions the handles impose on `vertices`, and per weight column how many
/// vertices it fixes (0: the handle does not touch this mesh).
pub fn boundary_conditions(
    vertices: &[Point],
    handles: &Handles,
) -> (BoundaryConditions, Vec<usize>) {
    let columns = crate::rig::handle_columns(handles).len();
    bound_boundary_conditions(vertices, handles, &vec![true; columns])
}

/// [`boundary_conditions`] from the columns marked in `binding` only (the others fix nothing
/// and so get zero weight).
pub fn bound_boundary_conditions(
    vertices: &[Point],
    handles: &Handles,
    binding: &[bool],
) -> (BoundaryConditions, Vec<usize>) {
    let columns = crate::rig::handle_columns(handles).len();
    let mut bc = BoundaryConditions {
        handle_count: columns,
        ..Default::default()
    };
    let mut touched = vec![0; columns];
    for (i, mut vertex_claims) in claims(vertices, handles, columns).into_iter().enumerate() {
        vertex_claims.retain(|claim| claim.iter().all(|&(c, _)| binding[c]));
        if vertex_claims.is_empty() {
            continue;
        }
        let share = 1.0 / vertex_claims.len() as f64;
        let mut merged: Vec<(usize, f64)> = Vec::new();
        for claim in &vertex_claims {
            for &(c, w) in claim {
                match merged.iter_mut().find(|(mc, _)| *mc == c) {
                    Some(entry) => entry.1 += share * w,
                    None => merged.push((c, share * w)),
                }
            }
        }
        for &(c, w) in &merged {
            if w > 0.0 {
                touched[c] += 1;
            }
        }
        bc.fix(i, &merged);
    }
    (bc, touched)
}

/// Of the columns marked in `binding`, the one whose geometry is nearest to `p` (the first on
/// ties; column 0 when none is marked).
pub fn nearest_column(p: Point, handles: &Handles, binding: &[bool]) -> usize {
    (0..binding.len())
        .filter(|&c| binding[c])
        .min_by(|&a, &b| {
            distance_to_column(p, handles, a).total_cmp(&distance_to_column(p, handles, b))
        })
        .unwrap_or(0)
}

/// Distance from `p` to the geometry of weight column `column` (bones and cage edges as
/// segments, points as points, regions as their outline or 0 inside).
pub fn distance_to_column(p: Point, handles: &Handles, column: usize) -> f64 {
    let mut c = column;
    if c < handles.bones.len() {
        let b = &handles.bones[c];
        return segment_distance(p, b.head, b.tail).0;
    }
    c -= handles.bones.len();
    if c < handles.points.len() {
        return (p - handles.points[c].at).norm();
    }
    c -= handles.points.len();
    for cage in &handles.cages {
        if c < cage.polygon.len() {
            return (p - cage.polygon[c]).norm();
        }
        c -= cage.polygon.len();
    }
    let region = &handles.regions[c];
    let ring = &region.polygon;
    if point_in_ring(p, ring) {
        return 0.0;
    }
    (0..ring.len())
        .map(|k| segment_distance(p, ring[k], ring[(k + 1) % ring.len()]).0)
        .fold(f64::INFINITY, f64::min)
}

/// The centroid of a set of points (for choosing the nearest handle of a piece).
pub fn centroid(points: impl Iterator<Item = Point>) -> Point {
    let (sum, n) = points.fold((Vec2::zeros(), 0usize), |(s, n), p| (s + p.coords, n + 1));
    Point::from(sum / n.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::{Bone, Cage, PointHandle, Region};

    #[test]
    fn bones_points_cages_and_regions_fix_their_vertices() {
        let handles = Handles {
            physics: Vec::new(),
            bones: vec![
                Bone {
                    name: "a".into(),
                    parent: None,
                    head: Point::new(0.0, 0.0),
                    tail: Point::new(10.0, 0.0),
                },
                Bone {
                    name: "b".into(),
                    parent: Some("a".into()),
                    head: Point::new(10.0, 0.0),
                    tail: Point::new(20.0, 0.0),
                },
            ],
            points: vec![PointHandle {
                name: "p".into(),
                at: Point::new(5.0, 5.0),
                parent: None,
            }],
            bind: Default::default(),
            ik: Vec::new(),
            cages: vec![Cage {
                name: "c".into(),
                polygon: vec![
                    Point::new(30.0, 0.0),
                    Point::new(40.0, 0.0),
                    Point::new(40.0, 10.0),
                ],
            }],
            regions: vec![Region {
                name: "r".into(),
                polygon: vec![
                    Point::new(0.0, 20.0),
                    Point::new(4.0, 20.0),
                    Point::new(4.0, 24.0),
                    Point::new(0.0, 24.0),
                ],
            }],
        };
        let vertices = [
            Point::new(5.0, 0.0),   // on bone a
            Point::new(10.0, 0.0),  // the joint: shared by a and b
            Point::new(5.0, 5.0),   // the point handle
            Point::new(35.0, 0.0),  // halfway along the first cage edge
            Point::new(2.0, 22.0),  // inside the region
            Point::new(50.0, 50.0), // free
        ];
        let (bc, touched) = boundary_conditions(&vertices, &handles);
        assert_eq!(bc.handle_count, 7);
        assert_eq!(bc.vertices, vec![0, 1, 2, 3, 4]);
        let row = |k: usize| &bc.values[k * 7..(k + 1) * 7];
        assert_eq!(row(0), &[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(row(1), &[0.5, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(row(2), &[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(row(3), &[0.0, 0.0, 0.0, 0.5, 0.5, 0.0, 0.0]);
        assert_eq!(row(4), &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(touched, vec![2, 1, 1, 1, 1, 0, 1]);
        assert_eq!(distance_to_column(Point::new(40.0, 13.0), &handles, 5), 3.0);
    }
}
