//! One part's skinning weights, end to end.
//!
//! In: the part's [`EmbeddedMesh`] (its weight domain, containing the handles' geometry), the
//! [`Handles`], optional per-vertex colors for content-aware weights, and [`WeightOptions`].
//! Out: [`PartWeights`]: for each vertex of the drawn mesh ([`EmbeddedMesh::shape_mesh`]) its
//! non-zero weights as (column, weight), rows summing to one, at most `max_influences` each.
//!
//! Pieces of the domain that no handle touches (a part with no bone inside it, a stray island)
//! cannot be solved for; they follow the handle nearest to them rigidly, as cutout tools bind
//! an unweighted attachment to one bone.

use super::boundary::{bound_boundary_conditions, centroid, nearest_column};
use super::lift::{content_aware_domain, LiftError};
use super::monotone::{monotone_bounded_biharmonic_weights, MonotoneOptions};
use super::solve::{
    biharmonic_weights, bounded_biharmonic_weights, harmonic_weights, BbwOptions,
    BoundaryConditions, Domain, WeightMatrix,
};
use super::sparse::SolveError;
use crate::mesh::EmbeddedMesh;
use crate::rig::{handle_columns, Handles};
use serde::{Deserialize, Serialize};

/// Which energy the weights minimize.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum WeightMethod {
    /// Bounded biharmonic weights (Jacobson et al. 2011): smooth, local, in [0, 1].
    #[default]
    Bbw,
    /// Harmonic weights: fast, in [0, 1], but with a kink at point handles.
    Harmonic,
    /// Unconstrained biharmonic weights: smooth but not bounded nor local (for comparison).
    Biharmonic,
    /// Rigid cutout weights: the nearest handle inside the shape, blended over
    /// `rigid_blend_px` around joints (see [`super::rigid`]).
    Rigid,
}

/// How weights are computed. Shared by the command line, the editor and the rig document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct WeightOptions {
    /// Default: bounded biharmonic.
    pub method: WeightMethod,
    pub bbw: BbwOptions,
    /// Content-aware lift: measure the mesh in (x, y, s·r, s·g, s·b) with colors in [0, 1]
    /// (premultiplied), so that a full color change counts as `s` px. Default: off.
    pub content_aware: Option<f64>,
    /// Keep at most this many weights per vertex (the largest), renormalized. Default: all.
    pub max_influences: Option<usize>,
    /// Weights below this are dropped before renormalizing. Default 1e-6.
    pub min_weight: f64,
    /// With method `bbw`: monotone bounded biharmonic weights (Jacobson, Weinkauf & Sorkine
    /// 2012), whose per-handle weights have no spurious local extrema away from the handles
    /// (row normalization may add tiny ones), at the cost of an interior-point QP per handle
    /// (clarabel) with edge constraints per handle. Default: off.
    pub monotone: bool,
    /// With method `rigid`: width of the blend band around joints, px. Default 0 (no blend).
    pub rigid_blend_px: f64,
}

impl Default for WeightOptions {
    fn default() -> Self {
        WeightOptions {
            method: WeightMethod::Bbw,
            bbw: BbwOptions::default(),
            content_aware: None,
            max_influences: None,
            min_weight: 1e-6,
            monotone: false,
            rigid_blend_px: 0.0,
        }
    }
}

/// A part's weights over its drawn mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PartWeights {
    /// Per drawn vertex, its (column, weight) pairs, sorted by column.
    pub rows: Vec<Vec<(u32, f64)>>,
    /// Per weight column, how many domain vertices the handle fixes (0: it misses this part).
    pub touched: Vec<usize>,
    /// Columns that pieces without a handle were bound to rigidly.
    pub bound_to_nearest: Vec<usize>,
    /// Columns whose bounded solve stopped at its iteration limit before its tolerances.
    pub unconverged: Vec<usize>,
}

/// What went wrong computing weights.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum WeightError {
    #[error("no handles to compute weights for")]
    NoHandles,
    #[error("{0}")]
    Solve(#[from] SolveError),
    #[error("{0} colors for {1} mesh vertices")]
    ColorCount(usize, usize),
    #[error("invalid weight option: {0}")]
    InvalidOptions(String),
}

/// Connected pieces of a mesh: a piece index per vertex.
fn pieces(vertex_count: usize, triangles: &[[u32; 3]]) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..vertex_count).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (
                root(&mut parent, t[k] as usize),
                root(&mut parent, t[(k + 1) % 3] as usize),
            );
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    (0..vertex_count).map(|i| root(&mut parent, i)).collect()
}

/// Fixes every vertex of every piece that has no fixed vertex to the column nearest to the
/// piece's centroid; returns those columns.
fn bind_free_pieces(
    embedded: &EmbeddedMesh,
    handles: &Handles,
    binding: &[bool],
    bc: &mut BoundaryConditions,
) -> Vec<usize> {
    let vertices = &embedded.domain.vertices;
    let piece = pieces(vertices.len(), &embedded.domain.triangles);
    let mut has_fixed = vec![false; vertices.len()];
    for &v in &bc.vertices {
        has_fixed[piece[v]] = true;
    }
    let mut bound = Vec::new();
    let mut roots: Vec<usize> = piece.clone();
    roots.sort_unstable();
    roots.dedup();
    for r in roots {
        if has_fixed[r] {
            continue;
        }
        let members: Vec<usize> = (0..vertices.len()).filter(|&i| piece[i] == r).collect();
        let c = centroid(members.iter().map(|&i| vertices[i]));
        let nearest = nearest_column(c, handles, binding);
        for i in members {
            bc.fix_to_handle(i, nearest);
        }
        bound.push(nearest);
    }
    bound
}

/// Computes one part's weights. `colors` (premultiplied RGB in [0, 1], one per domain vertex)
/// is needed only for content-aware weights.
pub fn part_weights(
    embedded: &EmbeddedMesh,
    handles: &Handles,
    colors: Option<&[[f64; 3]]>,
    options: &WeightOptions,
) -> Result<PartWeights, WeightError> {
    let columns = handle_columns(handles).len();
    bound_part_weights(embedded, handles, &vec![true; columns], colors, options)
}

/// [`part_weights`] with only the columns marked in `binding` (one flag per column of
/// [`handle_columns`], see [`Handles::columns_binding`]) allowed to weigh the part; the others
/// get weight zero everywhere.
pub fn bound_part_weights(
    embedded: &EmbeddedMesh,
    handles: &Handles,
    binding: &[bool],
    colors: Option<&[[f64; 3]]>,
    options: &WeightOptions,
) -> Result<PartWeights, WeightError> {
    let columns = handle_columns(handles).len();
    if columns == 0 || !binding.iter().any(|&b| b) {
        return Err(WeightError::NoHandles);
    }
    if binding.len() != columns {
        return Err(WeightError::InvalidOptions(format!(
            "{} binding flags for {columns} weight columns",
            binding.len()
        )));
    }
    if !(options.min_weight.is_finite() && (0.0..1.0).contains(&options.min_weight)) {
        return Err(WeightError::InvalidOptions(
            "min_weight must lie in [0, 1)".into(),
        ));
    }
    if options.max_influences == Some(0) {
        return Err(WeightError::InvalidOptions(
            "max_influences must be at least 1".into(),
        ));
    }
    let mesh = &embedded.domain;
    let (mut bc, touched) = bound_boundary_conditions(&mesh.vertices, handles, binding);
    let bound_to_nearest = bind_free_pieces(embedded, handles, binding, &mut bc);
    let positions: Vec<[f64; 2]> = mesh.vertices.iter().map(|p| [p.x, p.y]).collect();
    let domain = match options.content_aware {
        None => Domain::new(&positions, &mesh.triangles),
        Some(scale) => {
            let colors = colors.ok_or(WeightError::ColorCount(0, mesh.vertices.len()))?;
            content_aware_domain(&positions, colors, scale, &mesh.triangles).map_err(
                |e| match e {
                    LiftError::InvalidScale(_) => WeightError::InvalidOptions(e.to_string()),
                    LiftError::ColorCount(c, n) => WeightError::ColorCount(c, n),
                },
            )?
        }
    };
    let mut unconverged = Vec::new();
    let mut w = match options.method {
        WeightMethod::Bbw if options.monotone => {
            monotone_bounded_biharmonic_weights(&domain, &bc, &MonotoneOptions::default())?.0
        }
        WeightMethod::Bbw => {
            let (w, report) = bounded_biharmonic_weights(&domain, &bc, &options.bbw)?;
            unconverged = report.unconverged;
            w
        }
        WeightMethod::Harmonic => harmonic_weights(&domain, &bc)?,
        WeightMethod::Biharmonic => biharmonic_weights(&domain, &bc)?,
        WeightMethod::Rigid => {
            if !(options.rigid_blend_px.is_finite() && options.rigid_blend_px >= 0.0) {
                return Err(WeightError::InvalidOptions(
                    "the rigid blend width must be finite and at least 0".into(),
                ));
            }
            super::rigid::rigid_weights(
                &mesh.vertices,
                &mesh.triangles,
                &bc,
                options.rigid_blend_px,
            )
        }
    };
    let empty = w.normalize_rows();
    fill_empty_rows(&mut w, &empty, mesh, handles, binding);
    let (_, domain_index) = embedded.shape_mesh();
    let rows = domain_index
        .iter()
        .map(|&i| sparse_row(w.row(i), options))
        .collect();
    Ok(PartWeights {
        rows,
        touched,
        bound_to_nearest,
        unconverged,
    })
}

/// Rows that every handle's bounds clamped to zero follow the nearest handle.
fn fill_empty_rows(
    w: &mut WeightMatrix,
    empty: &[usize],
    mesh: &crate::mesh::Mesh,
    handles: &Handles,
    binding: &[bool],
) {
    for &i in empty {
        let nearest = nearest_column(mesh.vertices[i], handles, binding);
        let m = w.handle_count;
        w.data[i * m..(i + 1) * m]
            .iter_mut()
            .enumerate()
            .for_each(|(j, x)| *x = if j == nearest { 1.0 } else { 0.0 });
    }
}

/// The row's weights above `min_weight`, the `max_influences` largest of them, renormalized,
/// sorted by column. Ties in size keep the lower column, so results are deterministic.
pub fn sparse_row(row: &[f64], options: &WeightOptions) -> Vec<(u32, f64)> {
    let mut entries: Vec<(u32, f64)> = row
        .iter()
        .enumerate()
        .filter(|(_, &w)| w > options.min_weight)
        .map(|(j, &w)| (j as u32, w))
        .collect();
    if entries.is_empty() {
        // Everything was tiny: keep the largest rather than nothing.
        let (j, _) =
            row.iter().enumerate().fold(
                (0, f64::MIN),
                |best, (j, &w)| if w > best.1 { (j, w) } else { best },
            );
        return vec![(j as u32, 1.0)];
    }
    if let Some(k) = options.max_influences {
        entries.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        entries.truncate(k);
        entries.sort_by_key(|e| e.0);
    }
    let sum: f64 = entries.iter().map(|e| e.1).sum();
    entries.iter_mut().for_each(|e| e.1 /= sum);
    entries
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sparse_rows_keep_the_largest_and_sum_to_one() {
        let options = WeightOptions {
            max_influences: Some(2),
            ..Default::default()
        };
        let row = sparse_row(&[0.1, 0.5, 0.0, 0.4], &options);
        assert_eq!(row.len(), 2);
        assert_eq!(row[0].0, 1);
        assert_eq!(row[1].0, 3);
        assert!((row[0].1 + row[1].1 - 1.0).abs() < 1e-15);
        let all = sparse_row(&[0.1, 0.5, 0.0, 0.4], &WeightOptions::default());
        assert_eq!(all.iter().map(|e| e.0).collect::<Vec<_>>(), vec![0, 1, 3]);
    }

    #[test]
    fn pieces_are_found() {
        let p = pieces(6, &[[0, 1, 2], [3, 4, 5]]);
        assert_eq!(p[0], p[2]);
        assert_ne!(p[0], p[3]);
    }
}
