//! One brush dab's kernel: per vertex within the radius, the painted column's target (add,
//! subtract, or toward the neighbours' average, scaled by the falloff and strength), then the
//! row update that keeps the row summing to one, locked columns bit-identical, and the
//! influence limit (see the parent module's documentation).
//!
//! In: a [`PaintMesh`], sparse weight rows, a [`PaintTarget`], a [`BrushMode`], the dab's
//! centre in canvas px and [`BrushOptions`], all checked by the caller. Out: the rows changed in
//! place and a [`StrokeReport`] for the one dab.

use super::{BrushMode, BrushOptions, DabOutcome, PaintMesh, PaintTarget, StrokeReport};
use crate::geom::Point;

/// The weight of `column` in a sparse row.
pub fn weight_in(row: &[(u32, f64)], column: usize) -> f64 {
    row.iter()
        .find(|(c, _)| *c as usize == column)
        .map_or(0.0, |(_, w)| *w)
}

/// One dab, inputs checked.
pub(super) fn apply_dab(
    mesh: &PaintMesh,
    rows: &mut [Vec<(u32, f64)>],
    target: &PaintTarget,
    mode: BrushMode,
    centre: Point,
    options: &BrushOptions,
) -> StrokeReport {
    let PaintTarget {
        column,
        locked,
        max_influences,
    } = *target;
    let r = options.radius_px;
    // Targets first, all read from the rows before the dab, then the writes: smoothing must
    // not see half a dab, and the fallback spread reads the neighbours as they were.
    let mut changes: Vec<(usize, f64, Vec<f64>)> = Vec::new();
    for (i, p) in mesh.vertices.iter().enumerate() {
        let d = (p - centre).norm();
        let a = options.strength * options.falloff.factor(d, r);
        if a <= 0.0 {
            continue;
        }
        let w = weight_in(&rows[i], column);
        let target = match mode {
            BrushMode::Add => w + a,
            BrushMode::Subtract => w - a,
            BrushMode::Smooth => {
                let around = &mesh.neighbours[i];
                if around.is_empty() {
                    continue;
                }
                let mean = around
                    .iter()
                    .map(|&k| weight_in(&rows[k as usize], column))
                    .sum::<f64>()
                    / around.len() as f64;
                w + a * (mean - w)
            }
        };
        // Where the weight goes when the vertex's own free columns are all zero.
        let mut spread = vec![0.0; locked.len()];
        for &k in &mesh.neighbours[i] {
            for &(c, x) in &rows[k as usize] {
                spread[c as usize] += x;
            }
        }
        changes.push((i, target, spread));
    }
    let mut report = StrokeReport {
        dabs: 1,
        ..Default::default()
    };
    for (i, target, spread) in changes {
        match set_weight(
            &mut rows[i],
            column,
            target,
            locked,
            &spread,
            max_influences,
        ) {
            DabOutcome::Changed => report.vertex_changes += 1,
            DabOutcome::AtLimit => report.at_limit += 1,
            DabOutcome::Unchanged => {}
        }
    }
    report
}

/// Sets `column` of `row` to `target` (clamped to what the locked columns leave) and rescales
/// the unlocked other columns so the row sums to one; locked columns are copied bit for bit.
/// When the unlocked others all weigh zero, weight taken from `column` goes to them in the
/// proportions of `spread` (one value per column; the neighbours' weights). With
/// `max_influences`, the row then keeps that limit as the module doc says. The row is written
/// only when the outcome is [`DabOutcome::Changed`].
pub fn set_weight(
    row: &mut Vec<(u32, f64)>,
    column: usize,
    target: f64,
    locked: &[bool],
    spread: &[f64],
    max_influences: Option<usize>,
) -> DabOutcome {
    let columns = locked.len();
    let free = |k: usize| k != column && !locked[k];
    if !(0..columns).any(free) || !target.is_finite() {
        return DabOutcome::Unchanged;
    }
    let mut dense = vec![0.0; columns];
    for &(c, w) in row.iter() {
        dense[c as usize] = w;
    }
    let locked_sum: f64 = (0..columns).filter(|&k| locked[k]).map(|k| dense[k]).sum();
    let room = (1.0 - locked_sum).clamp(0.0, 1.0);
    let t = target.clamp(0.0, room);
    let rest = room - t;
    let free_sum: f64 = (0..columns).filter(|&k| free(k)).map(|k| dense[k]).sum();
    if free_sum > 0.0 {
        let scale = rest / free_sum;
        for k in (0..columns).filter(|&k| free(k)) {
            dense[k] = (dense[k] * scale).clamp(0.0, 1.0);
        }
    } else if rest > 0.0 {
        let spread_sum: f64 = (0..columns)
            .filter(|&k| free(k))
            .map(|k| spread.get(k).copied().unwrap_or(0.0).max(0.0))
            .sum();
        if spread_sum.is_nan() || spread_sum <= 0.0 {
            return DabOutcome::Unchanged;
        }
        for k in (0..columns).filter(|&k| free(k)) {
            let share = spread.get(k).copied().unwrap_or(0.0).max(0.0) / spread_sum;
            dense[k] = (rest * share).clamp(0.0, 1.0);
        }
    }
    let raising = t > dense[column];
    dense[column] = t;
    let mut limited = false;
    if let Some(k) = max_influences {
        match limit_influences(&mut dense, column, raising, locked, k) {
            Some(cut) => limited = cut,
            None => return DabOutcome::AtLimit,
        }
    }
    // Locked entries go back exactly as they were (a locked zero stays absent).
    let next: Vec<(u32, f64)> = dense
        .iter()
        .enumerate()
        .filter(|&(k, &w)| if locked[k] { w != 0.0 } else { w > 0.0 })
        .map(|(k, &w)| (k as u32, w))
        .collect();
    if next == *row {
        // The limit may have cut the change back to the row as it was.
        return if limited {
            DabOutcome::AtLimit
        } else {
            DabOutcome::Unchanged
        };
    }
    *row = next;
    DabOutcome::Changed
}

/// Cuts a dense row, its painted `column` just set (up when `raising`), back to at most
/// `max_influences` non-zero weights, or to its locked ones plus one unlocked where those
/// already reach the limit. The smallest unlocked weights go first; on a tie the painted column
/// stays when raised and goes when lowered, then the higher column goes first. The weight cut
/// goes to the unlocked others that stay, in proportion, or to the painted column when no
/// other stays. Returns whether anything was cut, or `None` (the row unusable) when a raised
/// painted column would be.
fn limit_influences(
    dense: &mut [f64],
    column: usize,
    raising: bool,
    locked: &[bool],
    max_influences: usize,
) -> Option<bool> {
    let locked_count = (0..dense.len())
        .filter(|&k| locked[k] && dense[k] != 0.0)
        .count();
    let mut unlocked: Vec<usize> = (0..dense.len())
        .filter(|&k| !locked[k] && dense[k] > 0.0)
        .collect();
    let limit = max_influences.max(locked_count + 1);
    if locked_count + unlocked.len() <= limit {
        return Some(false);
    }
    // Ascending weight; ties: the column to keep sorts last.
    let keep_rank = |k: usize| match (k == column, raising) {
        (true, true) => 2,
        (true, false) => 0,
        (false, _) => 1,
    };
    unlocked.sort_by(|&a, &b| {
        dense[a]
            .total_cmp(&dense[b])
            .then(keep_rank(a).cmp(&keep_rank(b)))
            .then(b.cmp(&a))
    });
    let (cut, kept) = unlocked.split_at(locked_count + unlocked.len() - limit);
    if raising && cut.contains(&column) {
        return None;
    }
    let dropped: f64 = cut.iter().map(|&k| dense[k]).sum();
    for &k in cut {
        dense[k] = 0.0;
    }
    let takers: Vec<usize> = match kept
        .iter()
        .copied()
        .filter(|&k| k != column)
        .collect::<Vec<_>>()
    {
        others if !others.is_empty() => others,
        _ => kept.to_vec(),
    };
    let takers_sum: f64 = takers.iter().map(|&k| dense[k]).sum();
    for &k in &takers {
        dense[k] = (dense[k] * (takers_sum + dropped) / takers_sum).clamp(0.0, 1.0);
    }
    Some(true)
}

#[cfg(test)]
mod tests {
    use super::super::{paint_dab, Falloff};
    use super::*;

    #[test]
    fn subtracting_a_sole_influence_spreads_to_the_neighbours_columns() {
        // A strip: vertices 0..3 weigh column 0 only, the last column 1 only.
        let v = [
            Point::new(0.0, 0.0),
            Point::new(10.0, 0.0),
            Point::new(20.0, 0.0),
            Point::new(0.0, 10.0),
            Point::new(10.0, 10.0),
            Point::new(20.0, 10.0),
        ];
        let t = [[0, 1, 3], [1, 4, 3], [1, 2, 4], [2, 5, 4]];
        let mesh = PaintMesh::new(&v, &t).unwrap();
        let mut rows = vec![
            vec![(0, 1.0)],
            vec![(0, 1.0)],
            vec![(1, 1.0)],
            vec![(0, 1.0)],
            vec![(0, 1.0)],
            vec![(1, 1.0)],
        ];
        let options = BrushOptions {
            radius_px: 3.0,
            strength: 0.5,
            falloff: Falloff::Constant,
            ..Default::default()
        };
        // Vertex 3's neighbours weigh only column 0: nowhere to go, it stays.
        paint_dab(
            &mesh,
            &mut rows,
            &PaintTarget {
                column: 0,
                locked: &[false; 3],
                max_influences: None,
            },
            BrushMode::Subtract,
            Point::new(0.0, 10.0),
            &options,
        )
        .unwrap();
        assert_eq!(rows[3], vec![(0, 1.0)]);
        // Vertex 1 has a neighbour weighing column 1: it gets the weight.
        paint_dab(
            &mesh,
            &mut rows,
            &PaintTarget {
                column: 0,
                locked: &[false; 3],
                max_influences: None,
            },
            BrushMode::Subtract,
            Point::new(10.0, 0.0),
            &options,
        )
        .unwrap();
        assert_eq!(rows[1], vec![(0, 0.5), (1, 0.5)]);
    }

    #[test]
    fn a_new_handle_at_the_influence_limit_replaces_the_weakest_once_it_outweighs_it() {
        use DabOutcome::{AtLimit, Changed, Unchanged};
        let free = [false; 3];
        let set = |row: &mut Vec<(u32, f64)>, column, target, limit| {
            set_weight(row, column, target, &free, &[0.0; 3], limit)
        };
        // A light dab (a brush's rim) cannot push out a handle weighing far more.
        let mut row = vec![(0, 0.5), (1, 0.5)];
        assert_eq!(set(&mut row, 2, 1e-4, Some(2)), AtLimit);
        assert_eq!(row, vec![(0, 0.5), (1, 0.5)]);
        // Without a limit the same dab gives three influences.
        assert_eq!(set(&mut row.clone(), 2, 1e-4, None), Changed);
        // Outweighing the weakest replaces it; its weight goes to the one that stays.
        let mut row = vec![(0, 0.2), (1, 0.8)];
        assert_eq!(set(&mut row, 2, 0.3, Some(2)), Changed);
        assert_eq!(row.iter().map(|e| e.0).collect::<Vec<_>>(), vec![1, 2]);
        assert!((row[1].1 - 0.3).abs() < 1e-15);
        assert!((row[0].1 + row[1].1 - 1.0).abs() < 1e-12);
        // A handle already on the vertex is painted as without a limit.
        let mut row = vec![(0, 0.2), (1, 0.8)];
        assert_eq!(set(&mut row, 0, 0.5, Some(2)), Changed);
        assert_eq!(row, vec![(0, 0.5), (1, 0.5)]);
        assert_eq!(set(&mut row, 0, 0.5, Some(2)), Unchanged);
    }

    #[test]
    fn one_influence_per_vertex_flips_at_half_and_locked_rows_keep_one_unlocked() {
        use DabOutcome::{AtLimit, Changed};
        // K = 1: the painted handle takes the vertex once it would weigh at least half.
        let mut row = vec![(0, 1.0)];
        assert_eq!(
            set_weight(&mut row, 1, 0.4, &[false; 2], &[0.0; 2], Some(1)),
            AtLimit
        );
        assert_eq!(
            set_weight(&mut row, 1, 0.5, &[false; 2], &[0.0; 2], Some(1)),
            Changed
        );
        assert_eq!(row, vec![(1, 1.0)]);
        // Lowering it below half hands the vertex to the neighbours' handle.
        assert_eq!(
            set_weight(&mut row, 1, 0.6, &[false; 2], &[1.0, 0.0], Some(1)),
            AtLimit
        );
        assert_eq!(row, vec![(1, 1.0)]);
        assert_eq!(
            set_weight(&mut row, 1, 0.4, &[false; 2], &[1.0, 0.0], Some(1)),
            Changed
        );
        assert_eq!(row, vec![(0, 1.0)]);
        // Locked weights that reach K alone keep one unlocked weight beside them, which a
        // painted handle replaces once it outweighs it; the locked ones stay bit for bit.
        let locked = [true, true, false, false];
        let mut row = vec![(0, 0.3), (1, 0.3), (2, 0.4)];
        assert_eq!(
            set_weight(&mut row, 3, 0.1, &locked, &[0.0; 4], Some(2)),
            AtLimit
        );
        assert_eq!(
            set_weight(&mut row, 3, 0.25, &locked, &[0.0; 4], Some(2)),
            Changed
        );
        assert_eq!(row, vec![(0, 0.3), (1, 0.3), (3, 0.4)]);
    }
}
