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
use crate::weights::lift::{content_aware_domain, LiftError};
use crate::weights::{
    bounded_biharmonic_weights, harmonic_weights, BbwOptions, BoundaryConditions, SolveError,
    WeightMatrix,
};
use serde::{Deserialize, Serialize};

/// Which energy the color weights minimize.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum ColorWeights {
    /// Harmonic weights: one Laplace solve per color over one factorization. Fast.
    #[default]
    Harmonic,
    /// Bounded biharmonic weights (Jacobson et al. 2011): smoother blends, far slower.
    Bbw,
}

/// What went wrong solving for the color weights.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ColorWeightError {
    #[error("{0}")]
    Lift(#[from] LiftError),
    #[error("{0}")]
    Solve(#[from] SolveError),
}

/// Solves for the weights. `colors[v]` and `labels[v]` belong to mesh vertex v; `color_count`
/// is the number of scribble colors (at least one vertex of each must be labeled).
pub fn color_weights(
    mesh: &ImageMesh,
    colors: &[[f64; 3]],
    labels: &[u16],
    color_count: usize,
    scale: f64,
    method: ColorWeights,
    bbw: &BbwOptions,
) -> Result<WeightMatrix, ColorWeightError> {
    let domain = content_aware_domain(&mesh.positions(), colors, scale, &mesh.triangles)?;
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
