//! Skinning weights: one function per handle column over a part's mesh.
//!
//! - [`laplacian`]: cotangent stiffness and mixed-Voronoi mass from edge lengths (flat or lifted).
//! - [`lift`]: the content-aware 5D lift (x, y, s·r, s·g, s·b), shared with `colorize`.
//! - [`sparse`]: principal sub-matrix Cholesky (faer) and products shared by the solvers.
//! - [`solve`]: harmonic, biharmonic and bounded biharmonic weights (interior point).
//! - [`active_set`]: the same bounded solve by active-set iterations from a close guess.
//! - [`support`]: the same bounded solve by one solve per handle on a close guess's support.
//! - [`bounds`]: the bounds on such a support, held by a Schur complement over its factor.
//! - [`inverse_entries`]: entries of H⁻¹ by forward solves along the elimination tree.
//! - [`monotone`]: bounded biharmonic weights without spurious extrema (Jacobson et al. 2012).
//! - [`reference`]: the same bounded QP by clarabel, the yardstick in tests.
//! - [`boundary`]: handles → fixed weights on the mesh vertices that carry their geometry.
//! - [`rigid`]: rigid cutout weights (nearest handle inside the shape, blend band at joints).
//! - [`part`]: one part end to end: boundary conditions, solve, normalize, sparsify.
//! - [`two_level`]: the same solved on a coarse mesh of the domain, carried to the fine mesh.
//! - [`paint`]: brush dabs (add, subtract, smooth) on a part's weights, locked columns kept.
//! - [`locked`]: locked columns kept through a recompute, rows carried over to a new mesh.
//! - [`rows`]: the checks of weight rows and meshes that `paint` and `locked` share.

pub mod active_set;
pub mod boundary;
pub mod bounds;
pub mod inverse_entries;
pub mod laplacian;
pub mod lift;
pub mod locked;
pub mod monotone;
pub mod paint;
pub mod part;
pub mod reference;
pub mod rigid;
pub mod rows;
pub mod solve;
pub mod sparse;
pub mod support;
pub mod two_level;

pub use locked::{keep_locked, transfer_rows, LockError};
pub use monotone::{
    count_spurious_extrema, monotone_bounded_biharmonic_weights, MonotoneOptions, MonotoneReport,
};
pub use paint::{
    dab_centres, paint_dab, paint_stroke, BrushMode, BrushOptions, Falloff, PaintError, PaintMesh,
    PaintTarget,
};
pub use part::{
    part_weights, PartWeights, TwoLevelOptions, TwoLevelPolish, WeightError, WeightMethod,
    WeightOptions,
};
pub use solve::{
    biharmonic_weights, bounded_biharmonic_weights, harmonic_weights, BbwOptions, BbwReport,
    BoundaryConditions, Domain, WeightMatrix,
};
pub use sparse::SolveError;
