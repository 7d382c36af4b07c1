//! Locked weight columns kept through a recompute.
//!
//! In: a part's freshly computed rows, its previous rows on the same vertices with the same
//! columns ([`transfer_rows`] carries rows over from the mesh the part had before a re-trace),
//! and one locked flag per column. Out ([`keep_locked`]): rows whose locked columns hold their
//! previous values bit for bit and whose unlocked columns are the fresh ones rescaled to fill
//! 1 − Σ locked, so the rows still sum to one. This is how an animator keeps painted weights
//! of some handles while the others are recomputed after an edit.
//!
//! Rows are sparse: per vertex its non-zero `(column, weight)` pairs, sorted by column.

use super::rows::{check_columns, check_row_count, check_triangles, RowsError};
use crate::geom::{barycentric, Point};

/// What does not fit. Nothing was changed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LockError {
    #[error("{fresh} fresh weight rows but {previous} previous ones")]
    RowCount { fresh: usize, previous: usize },
    #[error(transparent)]
    Rows(#[from] RowsError),
    #[error("the previous mesh has no vertices to carry weights from")]
    EmptyMesh,
}

/// How far a kept row's sum may stray from one by rounding.
const ROW_SUM_TOLERANCE: f64 = 1e-9;

/// Replaces the locked columns of `fresh` by those of `previous`, vertex by vertex, and
/// rescales the fresh unlocked columns to fill the rest of one. Where the fresh unlocked
/// columns are all zero, the previous unlocked ones are rescaled instead; where those are zero
/// too, the vertex keeps its previous row, or, when that row no longer sums to one (its weight
/// went with a deleted handle), takes its fresh row: every row still sums to one. `locked` has
/// one flag per column.
///
/// With `max_influences` K, a row keeps only the largest unlocked weights that fit beside its
/// non-zero locked ones (K minus their count), rescaled to fill the rest; where the locked
/// weights alone already take K or more influences but leave room, the largest unlocked one
/// still fills it, so that rows sum to one (that row has one more than its locked count). A
/// vertex that keeps its previous row (no unlocked weight anywhere) keeps its count too.
pub fn keep_locked(
    fresh: &mut [Vec<(u32, f64)>],
    previous: &[Vec<(u32, f64)>],
    locked: &[bool],
    max_influences: Option<usize>,
) -> Result<(), LockError> {
    if fresh.len() != previous.len() {
        return Err(LockError::RowCount {
            fresh: fresh.len(),
            previous: previous.len(),
        });
    }
    let columns = locked.len();
    check_columns(fresh, columns)?;
    check_columns(previous, columns)?;
    if !locked.iter().any(|&l| l) {
        return Ok(());
    }
    for (row, before) in fresh.iter_mut().zip(previous) {
        let locked_sum: f64 = before
            .iter()
            .filter(|(c, _)| locked[*c as usize])
            .map(|e| e.1)
            .sum();
        let room = (1.0 - locked_sum).max(0.0);
        let unlocked = |r: &[(u32, f64)]| -> Vec<(u32, f64)> {
            r.iter()
                .filter(|(c, _)| !locked[*c as usize])
                .copied()
                .collect()
        };
        let sum = |r: &[(u32, f64)]| -> f64 { r.iter().map(|e| e.1).sum() };
        let (fresh_free, old_free) = (unlocked(row), unlocked(before));
        let mut source = if sum(&fresh_free) > 0.0 {
            fresh_free
        } else if sum(&old_free) > 0.0 {
            old_free
        } else {
            if (sum(before) - 1.0).abs() <= ROW_SUM_TOLERANCE {
                *row = before.clone();
            }
            // Otherwise nothing unlocked can fill what a deleted handle took: the fresh row,
            // which sums to one, is the only whole row there is.
            continue;
        };
        if let Some(k) = max_influences {
            let locked_count = before
                .iter()
                .filter(|(c, w)| locked[*c as usize] && *w > 0.0)
                .count();
            let fits = k.saturating_sub(locked_count).max(1);
            if source.len() > fits {
                // Largest first; ties by column, so the choice is deterministic.
                source.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
                source.truncate(fits);
            }
        }
        let scale = room / sum(&source);
        let mut merged: Vec<(u32, f64)> = before
            .iter()
            .filter(|(c, _)| locked[*c as usize])
            .copied()
            .chain(
                source
                    .iter()
                    .map(|&(c, w)| (c, (w * scale).clamp(0.0, 1.0)))
                    .filter(|e| e.1 > 0.0),
            )
            .collect();
        merged.sort_by_key(|e| e.0);
        *row = merged;
    }
    Ok(())
}

/// The rows of a mesh's vertices `to_px` carried over from another mesh of the same part
/// (`from_vertices`, `from_triangles`, `from_rows`): a vertex inside a triangle of the old mesh
/// gets the barycentric blend of its corners' rows; a vertex outside every old triangle (the
/// outline grew) gets the row of the nearest old vertex. Rows that sum to one blend to rows
/// that sum to one.
pub fn transfer_rows(
    from_vertices: &[Point],
    from_triangles: &[[u32; 3]],
    from_rows: &[Vec<(u32, f64)>],
    to_px: &[Point],
) -> Result<Vec<Vec<(u32, f64)>>, LockError> {
    let n = from_vertices.len();
    check_row_count(from_rows, n)?;
    if n == 0 {
        return Err(LockError::EmptyMesh);
    }
    check_triangles(from_triangles, n)?;
    let grid = TriangleGrid::new(from_vertices, from_triangles);
    Ok(to_px
        .iter()
        .map(|&p| {
            let inside = grid.candidates(p).find_map(|t| {
                let [a, b, c] = from_triangles[t].map(|v| from_vertices[v as usize]);
                let w = barycentric(p, a, b, c)?;
                // A hair of slack so points on shared edges are not lost between triangles.
                w.iter()
                    .all(|&x| x >= -1e-9)
                    .then(|| (from_triangles[t], w.map(|x| x.max(0.0))))
            });
            match inside {
                Some((t, w)) => {
                    let total: f64 = w.iter().sum();
                    let mut dense: Vec<(u32, f64)> = Vec::new();
                    for (k, &v) in t.iter().enumerate() {
                        for &(c, x) in &from_rows[v as usize] {
                            match dense.iter_mut().find(|e| e.0 == c) {
                                Some(e) => e.1 += x * w[k] / total,
                                None => dense.push((c, x * w[k] / total)),
                            }
                        }
                    }
                    // Rounding can lift a blend of ones a hair above one.
                    dense.iter_mut().for_each(|e| e.1 = e.1.min(1.0));
                    dense.retain(|e| e.1 > 0.0);
                    dense.sort_by_key(|e| e.0);
                    dense
                }
                None => {
                    let nearest = (0..n)
                        .min_by(|&i, &j| {
                            let d = |k: usize| (from_vertices[k] - p).norm_squared();
                            d(i).total_cmp(&d(j))
                        })
                        .unwrap_or(0);
                    from_rows[nearest].clone()
                }
            }
        })
        .collect())
}

/// Triangles bucketed by the grid cells their bounding boxes overlap, for point location.
struct TriangleGrid {
    origin: Point,
    cell_px: f64,
    size: [usize; 2],
    cells: Vec<Vec<usize>>,
}

impl TriangleGrid {
    fn new(vertices: &[Point], triangles: &[[u32; 3]]) -> Self {
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for v in vertices {
            for k in 0..2 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        let extent = [(hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9)];
        // About one triangle per cell.
        let cells_wanted = triangles.len().clamp(1, 1 << 20) as f64;
        let cell_px = ((extent[0] * extent[1]) / cells_wanted).sqrt().max(1e-6);
        let size = [
            ((extent[0] / cell_px).ceil() as usize).clamp(1, 1024),
            ((extent[1] / cell_px).ceil() as usize).clamp(1, 1024),
        ];
        let cell_px = (extent[0] / size[0] as f64).max(extent[1] / size[1] as f64);
        let mut grid = TriangleGrid {
            origin: lo.into(),
            cell_px,
            size,
            cells: vec![Vec::new(); size[0] * size[1]],
        };
        for (t, tri) in triangles.iter().enumerate() {
            let ps = tri.map(|v| vertices[v as usize]);
            let min = [0, 1].map(|k| ps.iter().map(|p| p[k]).fold(f64::MAX, f64::min));
            let max = [0, 1].map(|k| ps.iter().map(|p| p[k]).fold(f64::MIN, f64::max));
            let (c0, c1) = (grid.cell(min.into()), grid.cell(max.into()));
            for y in c0[1]..=c1[1] {
                for x in c0[0]..=c1[0] {
                    grid.cells[y * size[0] + x].push(t);
                }
            }
        }
        grid
    }

    /// The cell holding `p`, clamped to the grid.
    fn cell(&self, p: Point) -> [usize; 2] {
        [0, 1].map(|k| {
            let i = ((p[k] - self.origin[k]) / self.cell_px).floor();
            if i.is_nan() {
                0
            } else {
                (i.max(0.0) as usize).min(self.size[k] - 1)
            }
        })
    }

    /// Triangles whose bounding box may contain `p`.
    fn candidates(&self, p: Point) -> impl Iterator<Item = usize> + '_ {
        let c = self.cell(p);
        self.cells[c[1] * self.size[0] + c[0]].iter().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sums_to_one(rows: &[Vec<(u32, f64)>]) {
        for row in rows {
            let s: f64 = row.iter().map(|e| e.1).sum();
            assert!((s - 1.0).abs() < 1e-9, "{row:?}");
            assert!(row.iter().all(|e| (0.0..=1.0).contains(&e.1)));
        }
    }

    #[test]
    fn locked_columns_keep_their_values_and_the_rest_is_rescaled() {
        let previous = vec![
            vec![(0, 0.2), (1, 0.3), (2, 0.5)],
            vec![(1, 1.0)],
            vec![(0, 0.6), (2, 0.4)],
        ];
        let mut fresh = vec![
            vec![(0, 0.5), (1, 0.5)],
            vec![(0, 0.25), (2, 0.75)],
            vec![(1, 1.0)],
        ];
        keep_locked(&mut fresh, &previous, &[false, true, false], None).unwrap();
        sums_to_one(&fresh);
        // Vertex 0: column 1 stays 0.3, the fresh column 0 fills 0.7 (the fresh 1 was locked).
        assert_eq!(fresh[0], vec![(0, 0.7), (1, 0.3)]);
        // Vertex 1: column 1 was everything, so the fresh others vanish.
        assert_eq!(fresh[1], vec![(1, 1.0)]);
        // Vertex 2: the locked column was zero; only it was fresh, so the previous unlocked
        // columns come back.
        assert_eq!(fresh[2], vec![(0, 0.6), (2, 0.4)]);
        // Bit-identical locked values.
        assert_eq!(fresh[0][1].1.to_bits(), 0.3f64.to_bits());
        // Nothing locked: nothing changes.
        let mut untouched = vec![vec![(0, 1.0)]; 3];
        keep_locked(&mut untouched, &previous, &[false; 3], None).unwrap();
        assert_eq!(untouched, vec![vec![(0, 1.0)]; 3]);
        assert!(keep_locked(&mut untouched, &previous[..2], &[true; 3], None).is_err());
        assert!(keep_locked(&mut untouched, &previous, &[true; 2], None).is_err());
    }

    #[test]
    fn kept_rows_respect_the_influence_limit() {
        // Column 0 locked at 0.4; the fresh unlocked weights spread over three columns.
        let previous = vec![vec![(0, 0.4), (1, 0.6)], vec![(0, 0.5), (3, 0.5)]];
        let mut fresh = vec![
            vec![(1, 0.5), (2, 0.3), (3, 0.2)],
            vec![(1, 0.5), (2, 0.25), (3, 0.25)],
        ];
        let locked = [true, false, false, false];
        keep_locked(&mut fresh, &previous, &locked, Some(2)).unwrap();
        sums_to_one(&fresh);
        // K = 2: the locked weight and the largest fresh one, which fills the rest.
        assert_eq!(fresh[0], vec![(0, 0.4), (1, 0.6)]);
        assert_eq!(fresh[1], vec![(0, 0.5), (1, 0.5)]);
        assert_eq!(fresh[0][0].1.to_bits(), 0.4f64.to_bits());
        // K = 1 with a locked weight below one: the largest fresh weight still fills the rest.
        let mut one = vec![vec![(1, 0.5), (2, 0.3), (3, 0.2)]];
        keep_locked(&mut one, &previous[..1], &locked, Some(1)).unwrap();
        assert_eq!(one[0], vec![(0, 0.4), (1, 0.6)]);
        // K = 3 leaves two places beside the lock: ties go to the lower column.
        let mut three = vec![vec![(1, 0.5), (2, 0.25), (3, 0.25)]];
        keep_locked(&mut three, &previous[1..], &locked, Some(3)).unwrap();
        sums_to_one(&three);
        assert_eq!(
            three[0].iter().map(|e| e.0).collect::<Vec<_>>(),
            vec![0, 1, 2]
        );
    }

    #[test]
    fn rows_that_lost_weight_with_a_deleted_handle_take_their_fresh_row() {
        // Column 0 locked. The previous rows lost a deleted handle's weight (0.25, and all of
        // it), and the fresh rows weigh only the locked column: nothing unlocked can fill them.
        let previous = vec![vec![(0, 0.75)], vec![], vec![(0, 1.0)]];
        let mut fresh = vec![vec![(0, 1.0)], vec![(0, 1.0)], vec![(0, 1.0)]];
        keep_locked(&mut fresh, &previous, &[true, false], None).unwrap();
        sums_to_one(&fresh);
        assert_eq!(fresh, vec![vec![(0, 1.0)]; 3]);
        // A whole previous row is kept as it was.
        let previous = vec![vec![(0, 0.5), (1, 0.5)]];
        let mut fresh = vec![vec![(0, 1.0)]];
        keep_locked(&mut fresh, &previous, &[true, true], None).unwrap();
        assert_eq!(fresh, previous);
    }

    #[test]
    fn rows_carry_over_to_a_new_mesh() {
        // Old mesh: the unit square (10 px) as two triangles, column 0 at x = 0, 1 at x = 10.
        let from = [
            Point::new(0.0, 0.0),
            Point::new(10.0, 0.0),
            Point::new(10.0, 10.0),
            Point::new(0.0, 10.0),
        ];
        let tris = [[0, 1, 2], [0, 2, 3]];
        let rows = vec![
            vec![(0, 1.0)],
            vec![(1, 1.0)],
            vec![(1, 1.0)],
            vec![(0, 1.0)],
        ];
        let to = [
            Point::new(2.5, 5.0),
            Point::new(10.0, 10.0),
            Point::new(5.0, 5.0),
            Point::new(14.0, 3.0),
        ];
        let carried = transfer_rows(&from, &tris, &rows, &to).unwrap();
        sums_to_one(&carried);
        let w1 = |r: &Vec<(u32, f64)>| r.iter().find(|e| e.0 == 1).map_or(0.0, |e| e.1);
        assert!((w1(&carried[0]) - 0.25).abs() < 1e-12, "{:?}", carried[0]);
        assert!((w1(&carried[1]) - 1.0).abs() < 1e-12);
        assert!((w1(&carried[2]) - 0.5).abs() < 1e-12);
        // Outside: the nearest old vertex, (10, 0).
        assert_eq!(carried[3], vec![(1, 1.0)]);
        assert_eq!(
            transfer_rows(&from, &[[0, 1, 9]], &rows, &to),
            Err(LockError::Rows(RowsError::Triangle {
                triangle: 0,
                vertex: 9,
                vertices: 4
            }))
        );
    }
}
