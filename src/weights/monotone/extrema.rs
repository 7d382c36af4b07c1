//! Strict local extrema of weight columns over mesh 1-rings: the measure monotone weights are
//! judged by ([`count_spurious_extrema`]), and what the repair rounds look for.
//!
//! In: triangles (or a stiffness pattern) and a weight column. Out: the free vertices whose
//! weight beats every neighbour's by more than a tolerance, and which way.

use crate::weights::solve::WeightMatrix;
use sprs::CsMat;

/// The default tolerance of [`count_spurious_extrema`] and [`MonotoneOptions::extremum_tolerance`]:
/// a vertex is an extremum only when it beats every neighbour by more than this. Well above the
/// interior-point solver's accuracy, far below any bump a deformation would show.
pub const EXTREMUM_TOLERANCE: f64 = 1e-8;

/// Which way a vertex is a strict local extremum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Extremum {
    Maximum,
    Minimum,
}

/// Vertex 1-rings, compressed: the neighbours of i are `neighbors[start[i]..start[i + 1]]`.
pub(super) struct Rings {
    start: Vec<usize>,
    neighbors: Vec<usize>,
}

impl Rings {
    /// From undirected edges (either orientation, repeats and loops allowed).
    fn from_edges(n: usize, edges: impl Iterator<Item = (usize, usize)>) -> Self {
        let mut directed: Vec<(usize, usize)> = edges
            .filter(|&(a, b)| a != b)
            .flat_map(|(a, b)| [(a, b), (b, a)])
            .collect();
        directed.sort_unstable();
        directed.dedup();
        let mut start = vec![0; n + 1];
        for &(a, _) in &directed {
            start[a + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        Rings {
            start,
            neighbors: directed.into_iter().map(|(_, b)| b).collect(),
        }
    }

    /// The triangles' edges; corners outside `0..n` are ignored.
    fn from_triangles(n: usize, triangles: &[[u32; 3]]) -> Self {
        Rings::from_edges(
            n,
            triangles
                .iter()
                .flat_map(|t| (0..3).map(move |k| (t[k] as usize, t[(k + 1) % 3] as usize)))
                .filter(|&(a, b)| a < n && b < n),
        )
    }

    /// The off-diagonal pattern of a square sparse matrix.
    pub(super) fn from_pattern(a: &CsMat<f64>) -> Self {
        Rings::from_edges(
            a.rows(),
            a.outer_iterator().enumerate().flat_map(|(i, row)| {
                row.indices()
                    .iter()
                    .map(move |&k| (i, k))
                    .collect::<Vec<_>>()
            }),
        )
    }

    pub(super) fn of(&self, i: usize) -> &[usize] {
        &self.neighbors[self.start[i]..self.start[i + 1]]
    }
}

/// Whether `w[i]` beats every neighbour by more than `tolerance`, and which way. A vertex
/// without neighbours is no extremum; neither is one level with some neighbour (a plateau, such
/// as a region clamped to 0).
fn strict_extremum(rings: &Rings, w: &[f64], i: usize, tolerance: f64) -> Option<Extremum> {
    let ring = rings.of(i);
    if ring.is_empty() {
        None
    } else if ring.iter().all(|&k| w[i] > w[k] + tolerance) {
        Some(Extremum::Maximum)
    } else if ring.iter().all(|&k| w[i] < w[k] - tolerance) {
        Some(Extremum::Minimum)
    } else {
        None
    }
}

/// Strict local extrema of `w` at vertices not fixed, in ascending vertex order.
pub(super) fn spurious_extrema(
    rings: &Rings,
    w: &[f64],
    is_fixed: &[bool],
    tolerance: f64,
) -> Vec<(usize, Extremum)> {
    (0..w.len())
        .filter(|&i| !is_fixed[i])
        .filter_map(|i| strict_extremum(rings, w, i, tolerance).map(|e| (i, e)))
        .collect()
}

/// Per handle, the number of spurious extrema of its weight column: vertices not in `fixed`
/// whose weight is above every 1-ring neighbour's (a local maximum) or below every one's (a
/// local minimum) by more than `tolerance`. Mesh-boundary vertices count like any other;
/// plateaus (a vertex level with some neighbour, such as a region clamped to exactly 0) do not.
/// Triangle corners and fixed indices outside the matrix are ignored.
pub fn spurious_extrema_per_handle(
    mesh_triangles: &[[u32; 3]],
    w: &WeightMatrix,
    fixed: &[usize],
    tolerance: f64,
) -> Vec<usize> {
    let n = w.vertex_count;
    let rings = Rings::from_triangles(n, mesh_triangles);
    let mut is_fixed = vec![false; n];
    for &v in fixed.iter().filter(|&&v| v < n) {
        is_fixed[v] = true;
    }
    (0..w.handle_count)
        .map(|j| spurious_extrema(&rings, &w.column(j), &is_fixed, tolerance).len())
        .collect()
}

/// The spurious extrema of all handles' weights together (see [`spurious_extrema_per_handle`]),
/// at [`EXTREMUM_TOLERANCE`].
pub fn count_spurious_extrema(
    mesh_triangles: &[[u32; 3]],
    w: &WeightMatrix,
    fixed: &[usize],
) -> usize {
    spurious_extrema_per_handle(mesh_triangles, w, fixed, EXTREMUM_TOLERANCE)
        .iter()
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weights::solve::tests::grid;

    #[test]
    fn spurious_extrema_are_strict_free_and_beyond_the_tolerance() {
        let (_, t) = grid(4, 1.0);
        let id = |i: usize, j: usize| j * 5 + i;
        let column = |values: &[(usize, f64)]| {
            let mut data = vec![0.0; 25];
            for &(v, x) in values {
                data[v] = x;
            }
            WeightMatrix {
                vertex_count: 25,
                handle_count: 1,
                data,
            }
        };
        // All zero: one plateau, no extremum.
        assert_eq!(count_spurious_extrema(&t, &column(&[]), &[]), 0);
        // An interior bump is a maximum, unless it is fixed.
        let bump = column(&[(id(2, 2), 0.5)]);
        assert_eq!(count_spurious_extrema(&t, &bump, &[]), 1);
        assert_eq!(count_spurious_extrema(&t, &bump, &[id(2, 2)]), 0);
        // Below the tolerance it is noise.
        let noise = column(&[(id(2, 2), 0.1 * EXTREMUM_TOLERANCE)]);
        assert_eq!(count_spurious_extrema(&t, &noise, &[]), 0);
        // A bump two vertices wide is a plateau on top: not strict.
        let wide = column(&[(id(2, 2), 0.5), (id(3, 2), 0.5)]);
        assert_eq!(count_spurious_extrema(&t, &wide, &[]), 0);
        // Boundary vertices count; a dip is a minimum.
        let mut corner = column(&[(id(0, 0), 1.0)]);
        assert_eq!(count_spurious_extrema(&t, &corner, &[]), 1);
        corner.data.iter_mut().for_each(|x| *x = 1.0 - *x);
        assert_eq!(count_spurious_extrema(&t, &corner, &[]), 1);
        // Indices outside the matrix are ignored, not a panic.
        assert_eq!(count_spurious_extrema(&[[0, 1, 99]], &bump, &[1000]), 0);
    }
}
