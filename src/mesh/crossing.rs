//! Cages that cross the drawing's outline.
//!
//! A cage's inside joins the weight domain (the domain is the union of the traced shape and
//! the cages' insides), so a cage may reach past the drawing on one side and cut into it on
//! another: that is what cages are for. The mesher takes every outline ring and every cage ring
//! as constraint edges, which must not cross; [`split_at_crossings`] splits a cage edge and an
//! outline edge that cross at their crossing point, one point shared by both rings, so that the
//! rings meet only at shared vertices. Splitting an edge at a point on it changes neither
//! ring's inside, so the shape's parity test and the cages' insides stay what they were.
//!
//! In: outline rings and cage rings, canvas px. Out: the same rings with the crossing points
//! inserted, or which cage edge runs along the outline or which two cages cross (refused).

use super::MeshError;
use crate::geom::{segments_touch, Point};

/// Outline rings and cage rings with every cage–outline crossing a vertex of both.
#[derive(Clone, Debug, PartialEq)]
pub struct SplitRings {
    pub rings: Vec<Vec<Point>>,
    pub extensions: Vec<Vec<Point>>,
}

/// Two edges whose directions' cross product is below this fraction of their lengths' product
/// are parallel: when they touch, a cage edge runs along the outline (no single crossing point).
pub const PARALLEL_SINE: f64 = 1e-9;

/// Splits each cage edge and outline edge that cross at the crossing point (see the module
/// doc). Touching at a shared vertex is no crossing. Refused: a cage edge that runs along an
/// outline edge ([`MeshError::CageAlongOutline`]), and two cages that touch
/// ([`MeshError::CagesCross`]).
pub fn split_at_crossings(
    rings: &[&[Point]],
    extensions: &[&[Point]],
) -> Result<SplitRings, MeshError> {
    if let Some(error) = crossing_cages(extensions) {
        return Err(error);
    }
    // Points to insert per ring edge, with their parameter along the edge.
    let mut on_ring: Vec<Vec<Vec<(f64, Point)>>> =
        rings.iter().map(|r| vec![Vec::new(); r.len()]).collect();
    let mut on_cage: Vec<Vec<Vec<(f64, Point)>>> = extensions
        .iter()
        .map(|r| vec![Vec::new(); r.len()])
        .collect();
    for (cage, cage_ring) in extensions.iter().enumerate() {
        for (edge, [a, b]) in edges(cage_ring).enumerate() {
            for (ring, outline) in rings.iter().enumerate() {
                for (j, [c, d]) in edges(outline).enumerate() {
                    let shared = a == c || a == d || b == c || b == d;
                    if shared || !segments_touch(a, b, c, d) {
                        continue;
                    }
                    let (u, v) = (b - a, d - c);
                    let cross = u.x * v.y - u.y * v.x;
                    if cross.abs() <= PARALLEL_SINE * u.norm() * v.norm() {
                        return Err(MeshError::CageAlongOutline { cage, edge });
                    }
                    let w = c - a;
                    let s = ((w.x * v.y - w.y * v.x) / cross).clamp(0.0, 1.0);
                    let t = ((w.x * u.y - w.y * u.x) / cross).clamp(0.0, 1.0);
                    // An end of either edge on the other is that end, exactly.
                    let p = match (s, t) {
                        (0.0, _) => a,
                        (1.0, _) => b,
                        (_, 0.0) => c,
                        (_, 1.0) => d,
                        _ => a + u * s,
                    };
                    if p != a && p != b {
                        on_cage[cage][edge].push((s, p));
                    }
                    if p != c && p != d {
                        on_ring[ring][j].push((t, p));
                    }
                }
            }
        }
    }
    Ok(SplitRings {
        rings: rings
            .iter()
            .zip(on_ring)
            .map(|(r, inserts)| with_inserted(r, inserts))
            .collect(),
        extensions: extensions
            .iter()
            .zip(on_cage)
            .map(|(r, inserts)| with_inserted(r, inserts))
            .collect(),
    })
}

/// The ring's closed edges, `[start, end]`.
fn edges(ring: &[Point]) -> impl Iterator<Item = [Point; 2]> + '_ {
    (0..ring.len()).map(move |i| [ring[i], ring[(i + 1) % ring.len()]])
}

/// `ring` with each edge's points inserted after its start, in order along the edge, once.
fn with_inserted(ring: &[Point], inserts: Vec<Vec<(f64, Point)>>) -> Vec<Point> {
    let mut out = Vec::with_capacity(ring.len());
    for (&start, mut points) in ring.iter().zip(inserts) {
        out.push(start);
        points.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (_, p) in points {
            if out.last() != Some(&p) {
                out.push(p);
            }
        }
    }
    out
}

/// The first two cages that touch (other than at a shared vertex), if any.
fn crossing_cages(extensions: &[&[Point]]) -> Option<MeshError> {
    for (first, ring) in extensions.iter().enumerate() {
        for (second, other) in extensions.iter().enumerate().skip(first + 1) {
            let touch = edges(ring).any(|[a, b]| {
                edges(other).any(|[c, d]| {
                    let shared = a == c || a == d || b == c || b == d;
                    !shared && segments_touch(a, b, c, d)
                })
            });
            if touch {
                return Some(MeshError::CagesCross { first, second });
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(points: &[[f64; 2]]) -> Vec<Point> {
        points.iter().map(|p| Point::new(p[0], p[1])).collect()
    }

    #[test]
    fn a_cage_across_a_square_splits_both_at_the_crossings() {
        let square = ring(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
        // A band from x = 5 to x = 20 across the square's right edge.
        let cage = ring(&[[5.0, 2.0], [20.0, 2.0], [20.0, 4.0], [5.0, 4.0]]);
        let split = split_at_crossings(&[&square], &[&cage]).unwrap();
        let (p, q) = (Point::new(10.0, 2.0), Point::new(10.0, 4.0));
        assert_eq!(
            split.rings[0],
            vec![square[0], square[1], p, q, square[2], square[3]]
        );
        assert_eq!(
            split.extensions[0],
            vec![cage[0], p, cage[1], cage[2], q, cage[3]]
        );
    }

    #[test]
    fn an_enclosing_cage_and_shared_vertices_are_left_alone() {
        let square = ring(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
        let around = ring(&[[-5.0, -5.0], [15.0, -5.0], [15.0, 15.0], [-5.0, 15.0]]);
        let sharing = ring(&[[10.0, 10.0], [20.0, 10.0], [20.0, 20.0]]);
        let split = split_at_crossings(&[&square], &[&around]).unwrap();
        assert_eq!(split.rings[0], square);
        assert_eq!(split.extensions[0], around);
        let split = split_at_crossings(&[&square], &[&sharing]).unwrap();
        assert_eq!(split.rings[0], square);
    }

    #[test]
    fn a_cage_vertex_on_the_outline_becomes_an_outline_vertex() {
        let square = ring(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
        let cage = ring(&[[10.0, 5.0], [20.0, 2.0], [20.0, 8.0]]);
        let split = split_at_crossings(&[&square], &[&cage]).unwrap();
        assert_eq!(split.rings[0][2], Point::new(10.0, 5.0));
        assert_eq!(split.extensions[0], cage);
    }

    #[test]
    fn an_edge_along_the_outline_and_touching_cages_are_refused() {
        let square = ring(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
        let along = ring(&[[2.0, 0.0], [8.0, 0.0], [5.0, -5.0]]);
        assert_eq!(
            split_at_crossings(&[&square], &[&along]),
            Err(MeshError::CageAlongOutline { cage: 0, edge: 0 })
        );
        let a = ring(&[[-5.0, -5.0], [15.0, -5.0], [15.0, 15.0], [-5.0, 15.0]]);
        let b = ring(&[[-6.0, 3.0], [16.0, 3.0], [16.0, 4.0], [-6.0, 4.0]]);
        assert_eq!(
            split_at_crossings(&[&square], &[&a, &b]),
            Err(MeshError::CagesCross {
                first: 0,
                second: 1
            })
        );
    }
}
