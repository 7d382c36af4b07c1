//! One part's skinning weights, end to end.
//!
//! In: the part's [`EmbeddedMesh`] (its weight domain, containing the handles' geometry), the
//! [`Handles`], optional per-vertex colors for content-aware weights, and [`WeightOptions`].
//! Out: [`PartWeights`]: for each vertex of the drawn mesh ([`EmbeddedMesh::shape_mesh`]) its
//! non-zero weights as (column, weight), rows summing to one, at most `max_influences` each.
//!
//! Pieces of the domain that no handle touches (a part with no bone inside it, a stray island,
//! a detached head) cannot be solved for; they follow the handle nearest to them (measured
//! across the gap: the smallest distance from any of their vertices) rigidly, as cutout tools
//! bind an unweighted attachment to one bone. Pieces are those the solve sees: vertices joined
//! by non-degenerate triangles only (a degenerate triangle adds nothing to the stiffness, so a
//! piece hanging on by slivers, or a vertex of slivers only, is a piece of its own).

use super::boundary::{bound_boundary_conditions, distance_to_column, nearest_column};
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
use std::collections::BTreeMap;

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
    /// Two-level weights ([`super::two_level`]): solved on a coarse mesh of the same weight
    /// domain and carried to the fine mesh. `None` solves on the fine mesh itself (the exact
    /// solve). Default: None.
    pub two_level: Option<TwoLevelOptions>,
}

/// How two-level weights are solved ([`super::two_level`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct TwoLevelOptions {
    /// About how many vertices the coarse mesh has. Two-level weights are used only where the
    /// fine mesh has more than [`TWO_LEVEL_MIN_RATIO`] times as many. Default 500.
    pub coarse_vertices: usize,
    /// With bounded biharmonic weights: how the carried weights are brought to the fine mesh's
    /// solution. Default `support`.
    pub polish: TwoLevelPolish,
    /// With polish `support`: free vertices whose carried weight exceeds this are solved for,
    /// the others held at zero. Default [`super::support::SUPPORT_FLOOR`] (1e-3).
    pub support_floor: f64,
    /// With polish `active_set`: iterations on the fine mesh, each one numeric factorization
    /// of the whole mesh per handle. Default 4.
    pub polish_iterations: usize,
}

/// The fine-mesh step of two-level bounded biharmonic weights.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum TwoLevelPolish {
    /// The carried weights as they are.
    None,
    /// One solve per handle on the carried weights' support ([`super::support`]).
    #[default]
    Support,
    /// Primal–dual active-set iterations from the carried weights' bound sets
    /// ([`super::active_set`]); slower and further from the exact solve than `support`
    /// (docs/two-level-weights.md).
    ActiveSet,
}

impl Default for TwoLevelOptions {
    fn default() -> Self {
        TwoLevelOptions {
            coarse_vertices: 500,
            polish: TwoLevelPolish::Support,
            support_floor: super::support::SUPPORT_FLOOR,
            polish_iterations: 4,
        }
    }
}

/// Two-level weights are used only where the fine mesh has more than this many times the
/// coarse mesh's target vertex count (below it the exact solve costs about as much).
pub const TWO_LEVEL_MIN_RATIO: usize = 2;

/// The fewest coarse vertices two-level weights accept: fewer cannot carry several handles.
pub const MIN_COARSE_VERTICES: usize = 50;

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
            two_level: None,
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
    /// How many domain vertices those pieces have.
    pub bound_vertices: usize,
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

/// The pieces the solve sees: a piece index per vertex, vertices joined by the triangles that
/// are not degenerate ([`super::laplacian::is_degenerate`]) in `vertices` (canvas px).
fn solved_pieces(vertices: &[crate::geom::Point], triangles: &[[u32; 3]]) -> Vec<usize> {
    let points = crate::geom::as_coordinate_arrays(vertices);
    let l2 = super::laplacian::squared_edge_lengths(points, triangles);
    let solid: Vec<[u32; 3]> = triangles
        .iter()
        .zip(&l2)
        .filter(|(_, l)| !super::laplacian::is_degenerate(**l))
        .map(|(t, _)| *t)
        .collect();
    pieces(vertices.len(), &solid)
}

/// Fixes every vertex of every piece that has no fixed vertex to the column nearest to the
/// piece (the smallest distance from any of its vertices); returns those columns and how
/// many vertices they took.
fn bind_free_pieces(
    embedded: &EmbeddedMesh,
    handles: &Handles,
    binding: &[bool],
    bc: &mut BoundaryConditions,
) -> (Vec<usize>, usize) {
    let vertices = &embedded.domain.vertices;
    let piece = solved_pieces(vertices, &embedded.domain.triangles);
    let mut has_fixed = vec![false; vertices.len()];
    for &v in &bc.vertices {
        has_fixed[piece[v]] = true;
    }
    let mut members: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (i, &r) in piece.iter().enumerate() {
        if !has_fixed[r] {
            members.entry(r).or_default().push(i);
        }
    }
    let mut bound = Vec::new();
    let mut count = 0;
    for members in members.values() {
        let nearest = (0..binding.len())
            .filter(|&c| binding[c])
            .map(|c| {
                let d = members
                    .iter()
                    .map(|&i| distance_to_column(vertices[i], handles, c))
                    .fold(f64::INFINITY, f64::min);
                (c, d)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
            .map_or(0, |(c, _)| c);
        for &i in members {
            bc.fix_to_handle(i, nearest);
        }
        count += members.len();
        if !bound.contains(&nearest) {
            bound.push(nearest);
        }
    }
    (bound, count)
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
    check_options(handles, binding, options)?;
    let solved = domain_weights(embedded, handles, binding, colors, options)?;
    Ok(shape_rows(embedded, solved, options))
}

/// Weights over the whole weight domain of `embedded` (every domain vertex, rows summing to
/// one), before they are sparsified for the drawn mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct DomainWeights {
    pub matrix: WeightMatrix,
    /// As [`PartWeights::touched`].
    pub touched: Vec<usize>,
    /// As [`PartWeights::bound_to_nearest`].
    pub bound_to_nearest: Vec<usize>,
    /// As [`PartWeights::bound_vertices`].
    pub bound_vertices: usize,
    /// As [`PartWeights::unconverged`].
    pub unconverged: Vec<usize>,
}

/// The drawn mesh's sparse rows of `solved` (see [`sparse_row`]).
pub fn shape_rows(
    embedded: &EmbeddedMesh,
    solved: DomainWeights,
    options: &WeightOptions,
) -> PartWeights {
    let (_, domain_index) = embedded.shape_mesh();
    let rows = domain_index
        .iter()
        .map(|&i| sparse_row(solved.matrix.row(i), options))
        .collect();
    PartWeights {
        rows,
        touched: solved.touched,
        bound_to_nearest: solved.bound_to_nearest,
        bound_vertices: solved.bound_vertices,
        unconverged: solved.unconverged,
    }
}

/// The checks of handles, binding flags and options shared by every weight solve.
pub fn check_options(
    handles: &Handles,
    binding: &[bool],
    options: &WeightOptions,
) -> Result<(), WeightError> {
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
    if options
        .two_level
        .as_ref()
        .is_some_and(|t| t.coarse_vertices < MIN_COARSE_VERTICES)
    {
        return Err(WeightError::InvalidOptions(format!(
            "coarse_vertices must be at least {MIN_COARSE_VERTICES}"
        )));
    }
    if options
        .two_level
        .as_ref()
        .is_some_and(|t| !(t.support_floor.is_finite() && (0.0..1.0).contains(&t.support_floor)))
    {
        return Err(WeightError::InvalidOptions(
            "support_floor must lie in [0, 1)".into(),
        ));
    }
    if options.max_influences == Some(0) {
        return Err(WeightError::InvalidOptions(
            "max_influences must be at least 1".into(),
        ));
    }
    Ok(())
}

/// Solves the weights over every vertex of `embedded`'s domain: boundary conditions from the
/// handles (only the columns in `binding`), pieces without a handle bound to the nearest one,
/// the method's solve, rows normalized (rows every bound clamped to zero follow the nearest
/// handle). `colors` as in [`part_weights`].
pub fn domain_weights(
    embedded: &EmbeddedMesh,
    handles: &Handles,
    binding: &[bool],
    colors: Option<&[[f64; 3]]>,
    options: &WeightOptions,
) -> Result<DomainWeights, WeightError> {
    let mesh = &embedded.domain;
    let (bc, touched, (bound_to_nearest, bound_vertices)) =
        boundary_conditions(embedded, handles, binding);
    let domain = weight_domain(mesh, colors, options)?;
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
    normalize_rows(&mut w, mesh, handles, binding);
    Ok(DomainWeights {
        matrix: w,
        touched,
        bound_to_nearest,
        bound_vertices,
        unconverged,
    })
}

/// The handles' boundary conditions on `embedded`'s domain vertices (only the columns in
/// `binding`), with every piece no handle reaches bound to the nearest handle; also how many
/// vertices each column fixes, and the columns pieces were bound to with how many vertices.
pub fn boundary_conditions(
    embedded: &EmbeddedMesh,
    handles: &Handles,
    binding: &[bool],
) -> (BoundaryConditions, Vec<usize>, (Vec<usize>, usize)) {
    let (mut bc, touched) = bound_boundary_conditions(&embedded.domain.vertices, handles, binding);
    let bound_to_nearest = bind_free_pieces(embedded, handles, binding, &mut bc);
    (bc, touched, bound_to_nearest)
}

/// The domain the weights are measured in: `mesh` in canvas px, or lifted by its vertices'
/// `colors` with content-aware weights.
pub fn weight_domain(
    mesh: &crate::mesh::Mesh,
    colors: Option<&[[f64; 3]]>,
    options: &WeightOptions,
) -> Result<Domain, WeightError> {
    let positions = &mesh.vertices;
    match options.content_aware {
        None => Ok(Domain::planar(positions, &mesh.triangles)),
        Some(scale) => {
            let colors = colors.ok_or(WeightError::ColorCount(0, mesh.vertices.len()))?;
            content_aware_domain(positions, colors, scale, &mesh.triangles).map_err(|e| match e {
                LiftError::InvalidScale(_) => WeightError::InvalidOptions(e.to_string()),
                LiftError::ColorCount(c, n) => WeightError::ColorCount(c, n),
            })
        }
    }
}

/// Rows scaled to sum to one; rows that every bound clamped to zero follow the nearest handle.
pub fn normalize_rows(
    w: &mut WeightMatrix,
    mesh: &crate::mesh::Mesh,
    handles: &Handles,
    binding: &[bool],
) {
    let empty = w.normalize_rows();
    fill_empty_rows(w, &empty, mesh, handles, binding);
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

    /// Two triangles joined only by a degenerate (flat) one, a bone on the first: the second
    /// is a piece the solve cannot reach (a flat triangle adds no stiffness), so it follows
    /// the bone rigidly instead of failing the solve as unreachable.
    #[test]
    fn a_piece_joined_by_a_flat_triangle_follows_the_nearest_handle() {
        use crate::geom::Point;
        use crate::mesh::Mesh;
        use crate::rig::Bone;
        let p = |x: f64, y: f64| Point::new(x, y);
        let domain = Mesh {
            vertices: vec![
                p(0.0, 0.0),
                p(10.0, 0.0),
                p(0.0, 10.0),
                p(20.0, 0.0),
                p(30.0, 0.0),
                p(20.0, 10.0),
                p(15.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5], [1, 6, 3]],
        };
        let embedded = EmbeddedMesh {
            in_shape: vec![true; 3],
            domain,
        };
        let handles = Handles {
            bones: vec![Bone {
                name: "a".into(),
                parent: None,
                head: Point::new(0.0, 0.0),
                tail: Point::new(0.0, 10.0),
            }],
            ..Default::default()
        };
        for method in [WeightMethod::Harmonic, WeightMethod::Bbw] {
            let options = WeightOptions {
                method,
                ..Default::default()
            };
            let w = part_weights(&embedded, &handles, None, &options).expect("weights");
            assert_eq!(w.bound_to_nearest, vec![0]);
            // The far triangle and the flat triangle's middle vertex.
            assert_eq!(w.bound_vertices, 4);
            assert!(w.rows.iter().all(|r| r == &vec![(0, 1.0)]));
        }
    }

    #[test]
    fn pieces_are_found() {
        let p = pieces(6, &[[0, 1, 2], [3, 4, 5]]);
        assert_eq!(p[0], p[2]);
        assert_ne!(p[0], p[3]);
    }
}
