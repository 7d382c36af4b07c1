//! Weight painting: brush dabs on one part's skinning weights, with locked columns.
//!
//! In: a part's rest mesh ([`PaintMesh`]: vertices in canvas px and their mesh neighbours), its
//! sparse weight rows (per vertex its non-zero `(column, weight)` pairs, summing to one), a
//! [`PaintTarget`] (the column painted, one locked flag per weight column, the influence
//! limit), a [`BrushMode`], the stroke's samples in canvas px and [`BrushOptions`]. Out: the
//! rows changed in place, still summing to one (to 1e-9), every weight in [0, 1], locked
//! columns bit-identical, and a [`StrokeReport`].
//!
//! A dab sets the painted column `j` of each vertex within the radius to a target (add,
//! subtract, or move toward the neighbours' average), and then rescales the *unlocked other*
//! columns so that the row sums to one again. Locked columns never change, so the painted
//! column can take at most 1 − Σ locked. Where every other column is locked, the vertex cannot
//! change. Where the unlocked others all weigh zero at a vertex (say, in the middle of a bone's
//! rigid zone), the weight taken from `j` goes to the unlocked columns the vertex's mesh
//! neighbours use, in their proportions; with none there either, the vertex stays as it is.
//!
//! With an influence limit K (the document's `max_influences`), a row the dab would leave with
//! more than K weights drops its smallest unlocked ones, and their weight goes to the unlocked
//! others it keeps (to the painted column when it is the only one). So a handle painted onto a
//! vertex at the limit enters only once the dab gives it at least the weight of the vertex's
//! weakest unlocked handle, which it then replaces; a weaker dab (a brush's rim, a light
//! stroke, smoothing) leaves the vertex as it is and is counted in [`StrokeReport::at_limit`],
//! and a dab that lowers the painted column below the weakest hands it over likewise. The
//! changes thus stay as large as the brush's effect. Locked weights are never dropped; a row
//! whose locked weights alone reach K keeps one unlocked weight beside them (as recomputes do,
//! [`crate::weights::keep_locked`]).
//!
//! A stroke is resampled into dabs at a fixed spacing along its polyline, starting at its first
//! sample, so the dabs of a stroke's prefix are a prefix of its dabs: an editor can preview a
//! stroke dab by dab and commit the whole stroke once, getting the same weights.//!
//! The pieces: this module holds the brush's options, the target, and the stroke (its dab
//! centres, checks and the loop over dabs); [`dab`] holds one dab's kernel: the targets within
//! the radius and the row update that keeps sums, locks and the influence limit.

mod dab;

pub use dab::{set_weight, weight_in};

use super::rows::{check_columns, check_row_count, check_triangles, RowsError};
use crate::geom::Point;
use dab::apply_dab;
use serde::{Deserialize, Serialize};

/// What a dab does to the painted column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BrushMode {
    /// Raises the weight by strength × falloff.
    #[default]
    Add,
    /// Lowers the weight by strength × falloff.
    Subtract,
    /// Moves the weight toward the average of its mesh neighbours' weights by strength × falloff
    /// of the difference (a Jacobi step: every vertex reads the weights from before the dab).
    Smooth,
}

/// How a dab's effect fades from its centre (distance d) to its rim (radius r).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Falloff {
    /// Full effect everywhere inside the radius.
    Constant,
    /// 1 − d/r.
    Linear,
    /// (1 − (d/r)²)²: full at the centre, fading with zero slope at the rim, so strokes leave
    /// no visible edge.
    #[default]
    Smooth,
}

impl Falloff {
    /// The factor in [0, 1] at distance `d_px` from the centre of a brush of radius `r_px`
    /// (zero outside).
    pub fn factor(self, d_px: f64, r_px: f64) -> f64 {
        // NaN distances paint nothing.
        if d_px.is_nan() || d_px >= r_px {
            return 0.0;
        }
        let x = d_px / r_px;
        match self {
            Falloff::Constant => 1.0,
            Falloff::Linear => 1.0 - x,
            Falloff::Smooth => (1.0 - x * x).powi(2),
        }
    }
}

/// How a brush paints. Shared by the editor and the document's paint command.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BrushOptions {
    /// Brush radius, canvas px. Default 24.
    pub radius_px: f64,
    /// Effect of one dab at the centre, in [0, 1]: the weight added or subtracted, or the
    /// fraction of the way to the neighbours' average. Default 0.1.
    pub strength: f64,
    /// Default [`Falloff::Smooth`].
    pub falloff: Falloff,
    /// Dabs along a stroke lie this fraction of the radius apart, in (0, 1]. Default 0.25
    /// (a point crossed by a stroke's middle gets about eight dabs).
    pub spacing: f64,
}

impl Default for BrushOptions {
    fn default() -> Self {
        BrushOptions {
            radius_px: 24.0,
            strength: 0.1,
            falloff: Falloff::Smooth,
            spacing: 0.25,
        }
    }
}

/// What is wrong with a paint request. Nothing was changed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PaintError {
    #[error("invalid brush option: {0}")]
    InvalidOptions(String),
    #[error("a brush position is not finite: {0:?}")]
    NotFinite(Point),
    #[error("column {column} is painted, but the weights have {columns} columns")]
    UnknownColumn { column: usize, columns: usize },
    #[error("column {0} is locked")]
    LockedColumn(usize),
    #[error("the influence limit must be at least 1")]
    NoInfluences,
    #[error(transparent)]
    Rows(#[from] RowsError),
}

/// A part's rest mesh prepared for painting: positions and, per vertex, its mesh neighbours.
#[derive(Clone, Debug, PartialEq)]
pub struct PaintMesh {
    /// Rest positions, canvas px.
    pub vertices: Vec<Point>,
    /// Per vertex, the vertices sharing an edge with it, sorted.
    pub neighbours: Vec<Vec<u32>>,
}

impl PaintMesh {
    pub fn new(vertices: &[Point], triangles: &[[u32; 3]]) -> Result<Self, PaintError> {
        let n = vertices.len();
        check_triangles(triangles, n)?;
        Ok(PaintMesh {
            vertices: vertices.to_vec(),
            neighbours: crate::mesh::vertex_neighbours(n, triangles),
        })
    }
}

/// What a stroke (or one dab) did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StrokeReport {
    pub dabs: usize,
    /// Vertex changes summed over the dabs (a vertex changed by two dabs counts twice).
    pub vertex_changes: usize,
    /// Vertex dabs the influence limit refused, summed the same way.
    pub at_limit: usize,
}

/// What a dab did to one vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DabOutcome {
    Changed,
    /// Nothing changed: the target was the weight already, every other column is locked, or
    /// the weight taken from the painted column had nowhere to go.
    Unchanged,
    /// The influence limit refused the change (see the module doc).
    AtLimit,
}

/// Checks `options` (radius, strength and spacing in range, finite).
pub fn check_options(options: &BrushOptions) -> Result<(), PaintError> {
    if !(options.radius_px.is_finite() && options.radius_px > 0.0) {
        return Err(PaintError::InvalidOptions(format!(
            "the radius must be a positive number of px, not {}",
            options.radius_px
        )));
    }
    if !(0.0..=1.0).contains(&options.strength) {
        return Err(PaintError::InvalidOptions(format!(
            "the strength must lie in [0, 1], not {}",
            options.strength
        )));
    }
    if !(options.spacing > 0.0 && options.spacing <= 1.0) {
        return Err(PaintError::InvalidOptions(format!(
            "the spacing must lie in (0, 1], not {}",
            options.spacing
        )));
    }
    Ok(())
}

/// The dab centres of a stroke through `samples_px`: its first sample, then every
/// `spacing × radius` px of arc length along the polyline (the last partial step gets no dab,
/// so a longer stroke only appends dabs). No samples: no dabs.
pub fn dab_centres(samples_px: &[Point], options: &BrushOptions) -> Result<Vec<Point>, PaintError> {
    check_options(options)?;
    if let Some(bad) = samples_px
        .iter()
        .find(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(PaintError::NotFinite(*bad));
    }
    let step_px = options.spacing * options.radius_px;
    let Some(&first) = samples_px.first() else {
        return Ok(Vec::new());
    };
    let mut dabs = vec![first];
    // Arc length still to go from the current position to the next dab.
    let mut to_next = step_px;
    for pair in samples_px.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let length = (b - a).norm();
        let mut at = 0.0;
        while length - at >= to_next {
            at += to_next;
            let t = at / length;
            dabs.push(a + t * (b - a));
            to_next = step_px;
        }
        to_next -= length - at;
    }
    Ok(dabs)
}

/// Which column a brush paints, and what it must leave as it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaintTarget<'a> {
    /// The column painted; it must not be locked.
    pub column: usize,
    /// One flag per weight column: locked columns never change.
    pub locked: &'a [bool],
    /// The most non-zero weights a row may have (see the module doc); `None`: no limit.
    pub max_influences: Option<usize>,
}

/// Checks that `rows` and the target's locks fit `mesh` and that its column can be painted;
/// returns the number of columns.
fn check_target(
    mesh: &PaintMesh,
    rows: &[Vec<(u32, f64)>],
    target: &PaintTarget,
) -> Result<usize, PaintError> {
    let PaintTarget {
        column,
        locked,
        max_influences,
    } = *target;
    if max_influences == Some(0) {
        return Err(PaintError::NoInfluences);
    }
    let columns = locked.len();
    if column >= columns {
        return Err(PaintError::UnknownColumn { column, columns });
    }
    if locked[column] {
        return Err(PaintError::LockedColumn(column));
    }
    check_row_count(rows, mesh.vertices.len())?;
    check_columns(rows, columns)?;
    Ok(columns)
}

/// Paints one stroke on `target`: every dab of [`dab_centres`] in order. On error nothing is
/// changed.
pub fn paint_stroke(
    mesh: &PaintMesh,
    rows: &mut [Vec<(u32, f64)>],
    target: &PaintTarget,
    mode: BrushMode,
    samples_px: &[Point],
    options: &BrushOptions,
) -> Result<StrokeReport, PaintError> {
    check_target(mesh, rows, target)?;
    let dabs = dab_centres(samples_px, options)?;
    let mut report = StrokeReport::default();
    for centre in dabs {
        report += apply_dab(mesh, rows, target, mode, centre, options);
    }
    Ok(report)
}

/// Paints one dab at `centre_px` (arguments as for [`paint_stroke`]); returns what it did. On
/// error nothing is changed.
pub fn paint_dab(
    mesh: &PaintMesh,
    rows: &mut [Vec<(u32, f64)>],
    target: &PaintTarget,
    mode: BrushMode,
    centre_px: Point,
    options: &BrushOptions,
) -> Result<StrokeReport, PaintError> {
    check_target(mesh, rows, target)?;
    check_options(options)?;
    if !(centre_px.x.is_finite() && centre_px.y.is_finite()) {
        return Err(PaintError::NotFinite(centre_px));
    }
    Ok(apply_dab(mesh, rows, target, mode, centre_px, options))
}

impl std::ops::AddAssign for StrokeReport {
    fn add_assign(&mut self, other: StrokeReport) {
        self.dabs += other.dabs;
        self.vertex_changes += other.vertex_changes;
        self.at_limit += other.at_limit;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of `n × n` vertices, `step` px apart, two triangles per cell.
    fn grid(n: usize, step: f64) -> (Vec<Point>, Vec<[u32; 3]>) {
        let mut vertices = Vec::new();
        for y in 0..n {
            for x in 0..n {
                vertices.push(Point::new(x as f64 * step, y as f64 * step));
            }
        }
        let mut triangles = Vec::new();
        for y in 0..n - 1 {
            for x in 0..n - 1 {
                let i = (y * n + x) as u32;
                let n = n as u32;
                triangles.push([i, i + 1, i + n]);
                triangles.push([i + 1, i + n + 1, i + n]);
            }
        }
        (vertices, triangles)
    }

    /// Three columns varying smoothly over the grid: left, right, and a bump in the middle.
    fn rows_for(vertices: &[Point], width: f64) -> Vec<Vec<(u32, f64)>> {
        vertices
            .iter()
            .map(|p| {
                let u = p[0] / width;
                let bump = 0.3 * (-((p[1] / width - 0.5).powi(2)) * 8.0).exp();
                let raw = [(1.0 - u) * (1.0 - bump), u * (1.0 - bump), bump];
                raw.iter()
                    .enumerate()
                    .filter(|(_, &w)| w > 0.0)
                    .map(|(k, &w)| (k as u32, w))
                    .collect()
            })
            .collect()
    }

    fn check_rows(rows: &[Vec<(u32, f64)>]) {
        for (i, row) in rows.iter().enumerate() {
            let sum: f64 = row.iter().map(|e| e.1).sum();
            assert!(
                (sum - 1.0).abs() < 1e-9,
                "vertex {i} sums to {sum}: {row:?}"
            );
            for &(_, w) in row {
                assert!((0.0..=1.0).contains(&w), "vertex {i}: {row:?}");
            }
            assert!(row.windows(2).all(|p| p[0].0 < p[1].0), "sorted {row:?}");
        }
    }

    fn column(rows: &[Vec<(u32, f64)>], c: usize) -> Vec<f64> {
        rows.iter().map(|r| weight_in(r, c)).collect()
    }

    #[test]
    fn add_and_subtract_keep_rows_summing_to_one_and_locked_columns_exact() {
        let (v, t) = grid(21, 5.0);
        let mesh = PaintMesh::new(&v, &t).unwrap();
        let before = rows_for(&v, 100.0);
        let locked = [false, false, true];
        let options = BrushOptions {
            radius_px: 30.0,
            strength: 0.4,
            ..Default::default()
        };
        let stroke = [Point::new(20.0, 50.0), Point::new(80.0, 50.0)];
        let mut rows = before.clone();
        let report = paint_stroke(
            &mesh,
            &mut rows,
            &PaintTarget {
                column: 1,
                locked: &locked,
                max_influences: None,
            },
            BrushMode::Add,
            &stroke,
            &options,
        )
        .unwrap();
        assert!(report.dabs > 5 && report.vertex_changes > 0, "{report:?}");
        check_rows(&rows);
        // The locked column is bit-identical everywhere.
        let (old, new) = (column(&before, 2), column(&rows, 2));
        assert!(old
            .iter()
            .zip(&new)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
        // Column 1 rose under the stroke, never fell, and did not move far away from it.
        let (b1, a1) = (column(&before, 1), column(&rows, 1));
        let centre = 10 * 21 + 3; // (15, 50)-ish: under the stroke's start
        assert!(
            a1[centre] > b1[centre] + 0.1,
            "{} → {}",
            b1[centre],
            a1[centre]
        );
        for (i, p) in v.iter().enumerate() {
            assert!(a1[i] >= b1[i] - 1e-12);
            if (p[1] - 50.0).abs() > 31.0 {
                assert_eq!(a1[i].to_bits(), b1[i].to_bits(), "outside the brush");
            }
        }
        // Saturates at what the lock leaves: 1 − locked.
        let mut full = before.clone();
        let strong = BrushOptions {
            strength: 1.0,
            falloff: Falloff::Constant,
            ..options
        };
        paint_stroke(
            &mesh,
            &mut full,
            &PaintTarget {
                column: 1,
                locked: &locked,
                max_influences: None,
            },
            BrushMode::Add,
            &stroke,
            &strong,
        )
        .unwrap();
        check_rows(&full);
        let i = 10 * 21 + 10;
        assert!((weight_in(&full[i], 1) + weight_in(&full[i], 2) - 1.0).abs() < 1e-12);
        assert_eq!(weight_in(&full[i], 0), 0.0);

        // Subtracting gives the weight to the unlocked other column only.
        let mut less = before.clone();
        paint_stroke(
            &mesh,
            &mut less,
            &PaintTarget {
                column: 0,
                locked: &locked,
                max_influences: None,
            },
            BrushMode::Subtract,
            &stroke,
            &strong,
        )
        .unwrap();
        check_rows(&less);
        let i = 10 * 21 + 6;
        assert_eq!(weight_in(&less[i], 0), 0.0);
        assert_eq!(
            weight_in(&less[i], 2).to_bits(),
            weight_in(&before[i], 2).to_bits()
        );
        assert!((weight_in(&less[i], 1) - (1.0 - weight_in(&before[i], 2))).abs() < 1e-12);
    }

    #[test]
    fn smoothing_reduces_variation() {
        let (v, t) = grid(21, 5.0);
        let mesh = PaintMesh::new(&v, &t).unwrap();
        // A sharp step in column 0 down the middle.
        let before: Vec<Vec<(u32, f64)>> = v
            .iter()
            .map(|p| {
                if p[0] < 50.0 {
                    vec![(0, 1.0)]
                } else {
                    vec![(1, 1.0)]
                }
            })
            .collect();
        let mut rows = before.clone();
        let options = BrushOptions {
            radius_px: 40.0,
            strength: 0.8,
            ..Default::default()
        };
        let stroke = [Point::new(50.0, 20.0), Point::new(50.0, 80.0)];
        paint_stroke(
            &mesh,
            &mut rows,
            &PaintTarget {
                column: 0,
                locked: &[false, false],
                max_influences: None,
            },
            BrushMode::Smooth,
            &stroke,
            &options,
        )
        .unwrap();
        check_rows(&rows);
        // Total variation of column 0 over the mesh's edges.
        let variation = |rows: &[Vec<(u32, f64)>]| -> f64 {
            let c = column(rows, 0);
            mesh.neighbours
                .iter()
                .enumerate()
                .flat_map(|(i, n)| n.iter().map(move |&k| (i, k as usize)))
                .map(|(i, k)| (c[i] - c[k]).powi(2))
                .sum()
        };
        let (b, a) = (variation(&before), variation(&rows));
        assert!(a < 0.8 * b, "variation {b} → {a}");
        // Near the step, weights are now strictly between 0 and 1.
        let i = 10 * 21 + 9;
        let w = weight_in(&rows[i], 0);
        assert!(w > 0.05 && w < 0.95, "{w}");
    }

    #[test]
    fn fully_locked_vertices_and_locked_columns_are_refused_or_kept() {
        let (v, t) = grid(5, 10.0);
        let mesh = PaintMesh::new(&v, &t).unwrap();
        let rows: Vec<Vec<(u32, f64)>> = vec![vec![(0, 0.25), (1, 0.5), (2, 0.25)]; v.len()];
        let options = BrushOptions {
            radius_px: 100.0,
            strength: 0.5,
            ..Default::default()
        };
        // Every other column locked: nothing can change.
        let mut same = rows.clone();
        let report = paint_stroke(
            &mesh,
            &mut same,
            &PaintTarget {
                column: 0,
                locked: &[false, true, true],
                max_influences: None,
            },
            BrushMode::Add,
            &[Point::new(20.0, 20.0)],
            &options,
        )
        .unwrap();
        assert_eq!(report.vertex_changes, 0);
        assert_eq!(same, rows);
        // Painting a locked column is refused, as are bad options and rows.
        let mut copy = rows.clone();
        let mut add_at = |locked: &[bool], column: usize, at: Point, options: &BrushOptions| {
            paint_stroke(
                &mesh,
                &mut copy,
                &PaintTarget {
                    column,
                    locked,
                    max_influences: None,
                },
                BrushMode::Add,
                &[at],
                options,
            )
        };
        assert_eq!(
            add_at(&[true, false, false], 0, Point::new(0.0, 0.0), &options),
            Err(PaintError::LockedColumn(0))
        );
        let bad = BrushOptions {
            strength: 1.5,
            ..options
        };
        assert!(matches!(
            add_at(&[false; 3], 0, Point::new(0.0, 0.0), &bad),
            Err(PaintError::InvalidOptions(_))
        ));
        assert!(matches!(
            add_at(&[false; 3], 3, Point::new(0.0, 0.0), &options),
            Err(PaintError::UnknownColumn { .. })
        ));
        assert!(matches!(
            add_at(&[false; 2], 0, Point::new(0.0, 0.0), &options),
            Err(PaintError::Rows(RowsError::Column { .. }))
        ));
        assert!(matches!(
            add_at(&[false; 3], 0, Point::new(f64::NAN, 0.0), &options),
            Err(PaintError::NotFinite(_))
        ));
        assert_eq!(copy, rows);
    }

    #[test]
    fn dabs_are_evenly_spaced_and_prefix_stable() {
        let options = BrushOptions {
            radius_px: 8.0,
            spacing: 0.5,
            ..Default::default()
        };
        let stroke = [
            Point::new(0.0, 0.0),
            Point::new(3.0, 0.0),
            Point::new(10.0, 0.0),
            Point::new(10.0, 9.0),
        ];
        let dabs = dab_centres(&stroke, &options).unwrap();
        // Length 19, a dab every 4 px from 0: 0, 4, 8, 12, 16.
        assert_eq!(dabs.len(), 5, "{dabs:?}");
        assert_eq!(dabs[2], Point::new(8.0, 0.0));
        assert!((dabs[3][0] - 10.0).abs() < 1e-12 && (dabs[3][1] - 2.0).abs() < 1e-12);
        for k in 1..stroke.len() {
            let prefix = dab_centres(&stroke[..k], &options).unwrap();
            assert_eq!(prefix[..], dabs[..prefix.len()]);
        }
        assert!(dab_centres(&[], &options).unwrap().is_empty());
        assert_eq!(
            dab_centres(&[Point::new(1.0, 2.0)], &options).unwrap(),
            vec![Point::new(1.0, 2.0)]
        );
    }

    #[test]
    fn falloffs_fade_to_zero_at_the_rim() {
        for f in [Falloff::Constant, Falloff::Linear, Falloff::Smooth] {
            assert_eq!(f.factor(0.0, 10.0), 1.0);
            assert_eq!(f.factor(10.0, 10.0), 0.0);
            assert_eq!(f.factor(f64::NAN, 10.0), 0.0);
        }
        assert!((Falloff::Smooth.factor(5.0, 10.0) - 0.5625).abs() < 1e-15);
        assert!((Falloff::Linear.factor(5.0, 10.0) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn strokes_respect_the_influence_limit_everywhere() {
        let (v, t) = grid(21, 5.0);
        let mesh = PaintMesh::new(&v, &t).unwrap();
        // Rows with at most two influences; then paint the bump column across them.
        let mut rows: Vec<Vec<(u32, f64)>> = rows_for(&v, 100.0)
            .into_iter()
            .map(|row| {
                let dense: Vec<f64> = (0..3).map(|c| weight_in(&row, c)).collect();
                crate::weights::part::sparse_row(
                    &dense,
                    &crate::weights::WeightOptions {
                        max_influences: Some(2),
                        ..Default::default()
                    },
                )
            })
            .collect();
        let options = BrushOptions {
            radius_px: 30.0,
            strength: 0.3,
            ..Default::default()
        };
        let stroke = [Point::new(10.0, 20.0), Point::new(90.0, 80.0)];
        let paint = |rows: &mut Vec<Vec<(u32, f64)>>, limit| {
            paint_stroke(
                &mesh,
                rows,
                &PaintTarget {
                    column: 2,
                    locked: &[false; 3],
                    max_influences: limit,
                },
                BrushMode::Add,
                &stroke,
                &options,
            )
        };
        let report = paint(&mut rows, Some(2)).unwrap();
        assert!(
            report.vertex_changes > 0 && report.at_limit > 0,
            "{report:?}"
        );
        check_rows(&rows);
        assert!(rows.iter().all(|r| r.len() <= 2));
        // The painted column did arrive under the stroke.
        assert!(
            weight_in(&rows[4 * 21 + 2], 2) > 0.3,
            "{:?}",
            rows[4 * 21 + 2]
        );
        assert_eq!(paint(&mut rows, Some(0)), Err(PaintError::NoInfluences));
    }
}
