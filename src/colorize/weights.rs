//! One weight function per scribble color over the 5D-lifted image mesh.
//!
//! In: the [`ImageMesh`], the line art's colors (over white, [0, 1]) at its vertices, each
//! vertex's scribble label (0 = none, k + 1 = color k), the lift scale and the method.
//! Out: a [`WeightMatrix`] (vertices × colors), rows summing to one.
//!
//! Jacobson's thesis (2013, § 3.4): colorization is content-aware weights over the image. The
//! mesh is measured in (x, y, s·r, s·g, s·b) by [`crate::weights::lift`], the same lift
//! `sinew rig --content-aware` uses; every vertex of a scribble is a handle vertex (1 for its
//! color, 0 for the others) and [`crate::weights::solve`] does the rest.

use super::image_mesh::ImageMesh;
use crate::geom::{as_coordinate_arrays, Point};
use crate::weights::laplacian::{cotangent_stiffness, squared_edge_lengths, voronoi_mass};
use crate::weights::lift::{content_aware_domain, lift_points, LiftError};
use crate::weights::{
    bounded_biharmonic_weights, harmonic_weights, BbwOptions, BoundaryConditions, Domain,
    SolveError, WeightMatrix,
};
use serde::{Deserialize, Serialize};

/// Which energy the color weights minimize.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum ColorWeights {
    /// Harmonic weights: one Laplace solve per color over one factorization. Fast.
    #[default]
    Harmonic,
    /// Bounded biharmonic weights (Jacobson et al. 2011): smoother blends, far slower.
    Bbw,
}

/// How the lifted mesh is measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LiftedStiffness {
    /// The cotangent Laplacian of the mesh lifted to 5D (`Domain::new::<5>`), as `sinew rig
    /// --content-aware` uses it. Across an antialiased ramp the lifted triangles are needles
    /// whose large positive and negative cotangent weights cancel only approximately: thin
    /// (≤ 1.5 px) antialiased curved lines leak (the tests measure it).
    Cotangent,
    /// The flat mesh's cotangent weights, each divided by its edge's squared stretch
    /// |e|²₅D / |e|²₂D under the same lift: every weight stays non-negative (an M-matrix, so
    /// harmonic weights obey the maximum principle) and an edge across a line conducts
    /// (1 + 3·s²·Δc²)⁻¹ times less: a ramp is a wall whatever its triangles look like.
    #[default]
    EdgeStretch,
}

/// What went wrong solving for the color weights.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ColorWeightError {
    #[error("{0}")]
    Lift(#[from] LiftError),
    #[error("{0}")]
    Solve(#[from] SolveError),
}

/// How the color weights are solved for (the relevant part of `ColorizeOptions`).
#[derive(Clone, Debug, PartialEq)]
pub struct ColorWeightOptions {
    /// Lift scale, px per unit of color.
    pub scale: f64,
    pub stiffness: LiftedStiffness,
    pub method: ColorWeights,
    pub bbw: BbwOptions,
}

/// Solves for the weights. `colors[v]` and `labels[v]` belong to mesh vertex v; `color_count`
/// is the number of scribble colors (at least one vertex of each must be labeled).
pub fn color_weights(
    mesh: &ImageMesh,
    colors: &[[f64; 3]],
    labels: &[u16],
    color_count: usize,
    options: &ColorWeightOptions,
) -> Result<WeightMatrix, ColorWeightError> {
    let ColorWeightOptions {
        scale,
        stiffness,
        method,
        ref bbw,
    } = *options;
    let positions = mesh.positions();
    let domain = match stiffness {
        LiftedStiffness::Cotangent => {
            content_aware_domain(&positions, colors, scale, &mesh.triangles)?
        }
        LiftedStiffness::EdgeStretch => {
            edge_stretch_domain(&positions, colors, scale, &mesh.triangles)?
        }
    };
    let mut bc = BoundaryConditions {
        handle_count: color_count,
        ..Default::default()
    };
    for (v, &l) in labels.iter().enumerate() {
        if l > 0 {
            bc.fix_to_handle(v, l as usize - 1);
        }
    }
    let mut w = match method {
        ColorWeights::Harmonic => harmonic_weights(&domain, &bc)?,
        ColorWeights::Bbw => bounded_biharmonic_weights(&domain, &bc, bbw)?.0,
    };
    // Obtuse lifted triangles void the maximum principle: clamp tiny excursions, then make
    // rows sum to one. A row clamped to nothing keeps its (all-zero) values; callers take
    // the argmax, which is then the first color.
    for x in &mut w.data {
        *x = x.clamp(0.0, 1.0);
    }
    w.normalize_rows();
    Ok(w)
}

/// The [`LiftedStiffness::EdgeStretch`] domain: flat cotangent weights divided by each edge's
/// squared stretch under the lift (negative flat weights, on obtuse boundary triangles, are
/// dropped), and the lifted mesh's mixed-Voronoi mass.
pub fn edge_stretch_domain(
    positions: &[Point],
    colors: &[[f64; 3]],
    scale: f64,
    triangles: &[[u32; 3]],
) -> Result<Domain, LiftError> {
    let lifted = lift_points(positions, colors, scale)?;
    let n = positions.len();
    let mass = voronoi_mass(n, triangles, &squared_edge_lengths(&lifted, triangles));
    // The flat stiffness's pattern, values rewritten in place (no second assembly and sort).
    let mut stiffness = cotangent_stiffness(
        n,
        triangles,
        &squared_edge_lengths(as_coordinate_arrays(positions), triangles),
    );
    let d2 = |p: &[f64], q: &[f64]| p.iter().zip(q).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
    let indptr = stiffness.indptr().to_proper().into_owned();
    let indices = stiffness.indices().to_vec();
    let data = stiffness.data_mut();
    for i in 0..n {
        let mut diagonal = 0.0;
        let mut diagonal_at = None;
        for k in indptr[i]..indptr[i + 1] {
            let j = indices[k];
            if j == i {
                diagonal_at = Some(k);
            } else if data[k] < 0.0 {
                data[k] /=
                    d2(&lifted[i], &lifted[j]) / (positions[i] - positions[j]).norm_squared();
                diagonal -= data[k];
            } else {
                data[k] = 0.0;
            }
        }
        if let Some(k) = diagonal_at {
            data[k] = diagonal;
        }
    }
    Ok(Domain { stiffness, mass })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretched_edges_conduct_less_and_rows_sum_to_zero() {
        let positions = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(0.0, 1.0),
            Point::new(1.0, 1.0),
        ];
        let triangles = [[0, 1, 2], [1, 3, 2]];
        let colors = [[1.0; 3], [1.0; 3], [0.0; 3], [0.0; 3]];
        let d = edge_stretch_domain(&positions, &colors, 10.0, &triangles).unwrap();
        let k = d.stiffness.to_dense();
        // Edge 0–1 (same color) keeps its flat weight ½; edge 0–2 (a full change) is
        // divided by 1 + 3·10².
        assert!((k[[0, 1]] + 0.5).abs() < 1e-12);
        assert!((k[[0, 2]] + 0.5 / 301.0).abs() < 1e-12);
        for i in 0..4 {
            assert!(k.row(i).sum().abs() < 1e-12);
            for j in 0..4 {
                assert_eq!(k[[i, j]], k[[j, i]]);
                if i != j {
                    assert!(k[[i, j]] <= 0.0);
                }
            }
        }
    }
}
