//! The global step when some handle columns are rigid: rotation and translation only, so a bone
//! keeps its length as in Spine (optionally with a uniform scale, like Spine's IK `stretch`).
//!
//! In: the T-space quadratic form Q (3m × 3m) and hard-constraint rows E (r × 3m) of
//! [`super::fast`], the columns' degrees of freedom, and per iteration the right-hand side F
//! (3m × 2), the constraint targets (r × 2) and the current T. Out: the next T, minimizing
//! tr(Tᵀ Q T) − 2 tr(Tᵀ F) subject to E T = targets over the columns' degrees of freedom.
//!
//! A rotation couples T's two output columns, so the step works on vec(T) (6m entries). Every
//! free column is parametrized linearly by a vector w: an affine column by its six entries, a
//! translation by two, a rigid column by a similarity (a, b, tₓ, t_y) about its pivot c:
//! L = [[a, −b], [b, a]], translation t + c − L c. A rigid column without scale keeps (a, b) on
//! the unit circle by a Gauss–Newton step: the step moves its angle θ along the circle's tangent
//! (−b, a), and the new (a, b) is the old one turned by exactly that angle (a retraction), so the
//! column is a rotation after every step, never approximately. Keyed children of a rigid bone
//! follow it through their fixed local transform.
//!
//! A joint at a rigid column's pivot is met by the parametrization itself: the column's
//! translation keeps its pivot where its parent puts it, so a skeleton's joints never leave the
//! solution. The other hard rows (drags) enter as a stiff least-squares term ([`HARD_WEIGHT`]):
//! drags the limbs can reach are met, drags beyond their reach are met in the least-squares
//! sense (the pins and the dragged point share the miss), and a step turns no column by more
//! than [`MAX_TURN_RAD`].

use super::fast::{ColumnDofs, Joint};
use super::IkError;
use crate::geom::Point;
use nalgebra::{DMatrix, DVector};

/// Largest turn of a rigid column in one step, rad: steps that would turn a column further are
/// shortened as a whole.
pub const MAX_TURN_RAD: f64 = 0.5;

/// Weight of the hard rows the parametrization does not meet itself (drags), relative to the
/// stiffness of moving one handle (the mean translation diagonal of A): a drag within reach is
/// met to within the energy's pull over this weight (well under 0.01 px).
pub const HARD_WEIGHT: f64 = 1e6;

/// How one column's entries of T depend on the parameters w.
#[derive(Clone, Debug, PartialEq)]
enum Param {
    /// No parameter (fixed, or following another column).
    None,
    /// Six entries (rows 3j..3j+2 of output coordinate 0, then of coordinate 1) from `offset`.
    Affine { offset: usize },
    /// Two translation entries from `offset`.
    Translation { offset: usize },
    /// (a, b, tₓ, t_y) from `offset`, about `pivot`; `scale`: (a, b) may leave the unit circle.
    /// With `joined`, only (a, b): the pivot is a joint on column `joined`, so the translation
    /// keeps the pivot where that column puts it.
    Similarity {
        offset: usize,
        pivot: Point,
        scale: bool,
        joined: Option<usize>,
    },
}

/// The precomputed coupled step of one problem structure.
#[derive(Clone, Debug)]
pub struct CoupledStep {
    params: Vec<Param>,
    /// Per column that follows another: (column, parent, the 3 × 3 map of the parent's rows).
    follows: Vec<(usize, usize, [[f64; 3]; 3])>,
    /// The columns with parameters or parents, each after the column it depends on.
    order: Vec<usize>,
    /// vec(T) = P w + (constant entries); P is 6m × n_w, row c·3m + k for T[k, c].
    p: DMatrix<f64>,
    /// Σ_c P_cᵀ Q P_c.
    h_w: DMatrix<f64>,
    /// (I₂ ⊗ E′) P, E′ the hard rows left after the joints the parametrization meets: row
    /// c·r′ + k for kept constraint k's coordinate c.
    e_w: DMatrix<f64>,
    /// The rows of E kept in E′.
    kept: Vec<usize>,
    /// [`HARD_WEIGHT`] in energy units.
    hard_weight: f64,
}

impl CoupledStep {
    /// Whether a problem needs the coupled step: it has a rigid column.
    pub fn needed(columns: &[ColumnDofs]) -> bool {
        columns
            .iter()
            .any(|c| matches!(c, ColumnDofs::Rigid { .. }))
    }

    /// Prepares the step for `columns` with the quadratic form `q_t` and hard rows `e_t`, whose
    /// first rows are `joints`. A joint at a rigid column's pivot is met by the parametrization
    /// itself (the column's translation follows its parent) and leaves the constraints.
    pub fn new(
        columns: &[ColumnDofs],
        joints: &[Joint],
        q_t: &DMatrix<f64>,
        e_t: &DMatrix<f64>,
        handle_stiffness: f64,
    ) -> Result<Self, IkError> {
        let m = columns.len();
        let dim = 3 * m;
        let mut params = Vec::with_capacity(m);
        let mut eliminated = vec![false; e_t.nrows()];
        let mut n_w = 0;
        for (j, c) in columns.iter().enumerate() {
            params.push(match c {
                ColumnDofs::Affine { .. } => {
                    n_w += 6;
                    Param::Affine { offset: n_w - 6 }
                }
                ColumnDofs::Translation { .. } => {
                    n_w += 2;
                    Param::Translation { offset: n_w - 2 }
                }
                ColumnDofs::Rigid { pivot, scale } => {
                    let joint = joints.iter().position(|k| {
                        k.child == j && k.at == *pivot && k.parent != j && k.parent < m
                    });
                    let joined = joint.map(|k| {
                        eliminated[k] = true;
                        joints[k].parent
                    });
                    let offset = n_w;
                    n_w += if joined.is_some() { 2 } else { 4 };
                    Param::Similarity {
                        offset,
                        pivot: *pivot,
                        scale: *scale,
                        joined,
                    }
                }
                ColumnDofs::Fixed(_) | ColumnDofs::Follows { .. } => Param::None,
            });
        }
        let mut follows = Vec::new();
        for (j, c) in columns.iter().enumerate() {
            if let ColumnDofs::Follows { parent, local } = c {
                if !matches!(
                    columns.get(*parent),
                    Some(ColumnDofs::Affine { .. } | ColumnDofs::Rigid { .. })
                ) {
                    return Err(IkError::BadFollow {
                        column: j,
                        parent: *parent,
                    });
                }
                // Row k of T_j (per coordinate) = Σ_l map[k][l] · row l of T_parent.
                let (g, gt) = (local.linear, local.translation);
                let map = [
                    [g[(0, 0)], g[(1, 0)], 0.0],
                    [g[(0, 1)], g[(1, 1)], 0.0],
                    [gt[0], gt[1], 1.0],
                ];
                follows.push((j, *parent, map));
            }
        }
        let order = dependency_order(&params, &follows)?;
        let mut p = DMatrix::<f64>::zeros(2 * dim, n_w);
        for &j in &order {
            fill_column(
                &mut p,
                dim,
                j,
                &params[j],
                follows.iter().find(|f| f.0 == j),
            );
        }
        let kept: Vec<usize> = (0..e_t.nrows()).filter(|&k| !eliminated[k]).collect();
        let e_kept = e_t.select_rows(&kept);
        let (p0, p1) = (p.rows(0, dim), p.rows(dim, dim));
        let h_w = p0.tr_mul(&(q_t * p0)) + p1.tr_mul(&(q_t * p1));
        let r = kept.len();
        let mut e_w = DMatrix::<f64>::zeros(2 * r, n_w);
        e_w.rows_mut(0, r).copy_from(&(&e_kept * p0));
        e_w.rows_mut(r, r).copy_from(&(&e_kept * p1));
        Ok(CoupledStep {
            params,
            follows,
            order,
            p,
            h_w,
            e_w,
            kept,
            hard_weight: HARD_WEIGHT * handle_stiffness,
        })
    }

    /// Adds the constant entries of the parametrization to `q` (3m × 2, the fixed entries of
    /// T): a rigid column's pivot, a joined column's joint where its parent puts it, carried to
    /// the columns that follow them.
    pub fn add_constants(&self, q: &mut DMatrix<f64>) {
        for &j in &self.order {
            match (&self.params[j], self.follows.iter().find(|f| f.0 == j)) {
                (
                    Param::Similarity {
                        pivot,
                        joined: Some(parent),
                        ..
                    },
                    _,
                ) => {
                    // Where the parent puts the joint, the pivot's own offset cancelling.
                    for c in 0..2 {
                        q[(3 * j + 2, c)] += pivot.x * q[(3 * parent, c)]
                            + pivot.y * q[(3 * parent + 1, c)]
                            + q[(3 * parent + 2, c)];
                    }
                }
                (Param::Similarity { pivot, .. }, _) => {
                    q[(3 * j + 2, 0)] += pivot.x;
                    q[(3 * j + 2, 1)] += pivot.y;
                }
                (_, Some(&(_, parent, map))) => {
                    for c in 0..2 {
                        let from = [0, 1, 2].map(|l| q[(3 * parent + l, c)]);
                        for (k, row) in map.iter().enumerate() {
                            q[(3 * j + k, c)] = (0..3).map(|l| row[l] * from[l]).sum();
                        }
                    }
                }
                _ => {}
            }
        }
    }

    /// How much the parameters move `u · T` (u: k × 3m, applied per output coordinate), for
    /// telling a fold the free columns can undo from one the fixed ones make.
    pub fn free_part(&self, u: &DMatrix<f64>) -> f64 {
        let dim = u.ncols();
        (u * self.p.rows(0, dim)).norm() + (u * self.p.rows(dim, dim)).norm()
    }

    /// The parameters of `t` (3m × 2), a rigid column's (a, b) put back on the unit circle.
    fn parameters(&self, t: &DMatrix<f64>) -> DVector<f64> {
        let mut w = DVector::zeros(self.p.ncols());
        for (j, param) in self.params.iter().enumerate() {
            match *param {
                Param::None => {}
                Param::Affine { offset } => {
                    for c in 0..2 {
                        for k in 0..3 {
                            w[offset + 3 * c + k] = t[(3 * j + k, c)];
                        }
                    }
                }
                Param::Translation { offset } => {
                    for c in 0..2 {
                        w[offset + c] = t[(3 * j + 2, c)];
                    }
                }
                Param::Similarity {
                    offset: o,
                    pivot,
                    scale,
                    joined,
                } => {
                    let (cx, cy) = (pivot.x, pivot.y);
                    let (l00, l01, l10, l11) = (
                        t[(3 * j, 0)],
                        t[(3 * j + 1, 0)],
                        t[(3 * j, 1)],
                        t[(3 * j + 1, 1)],
                    );
                    let (mut a, mut b) = (0.5 * (l00 + l11), 0.5 * (l10 - l01));
                    if !scale {
                        let r = a.hypot(b);
                        (a, b) = if r > 0.0 && r.is_finite() {
                            (a / r, b / r)
                        } else {
                            (1.0, 0.0)
                        };
                    }
                    // Keep the column's pivot where T puts it.
                    let (px, py) = (
                        l00 * cx + l01 * cy + t[(3 * j + 2, 0)],
                        l10 * cx + l11 * cy + t[(3 * j + 2, 1)],
                    );
                    w[o] = a;
                    w[o + 1] = b;
                    if joined.is_none() {
                        w[o + 2] = px - cx;
                        w[o + 3] = py - cy;
                    }
                }
            }
        }
        w
    }

    /// One step from `t`: minimizes tr(Tᵀ Q T) − 2 tr(Tᵀ F) over the step's parameters with
    /// E T = targets, where `g_w` = Σ_c P_cᵀ (F − Q q)_c and `e` = targets − E q (stacked by
    /// coordinate) are the linear terms `rhs` makes. `q` holds T's constant entries
    /// ([`CoupledStep::add_constants`] applied).
    pub fn step(
        &self,
        t: &DMatrix<f64>,
        f_minus_q: &DMatrix<f64>,
        e: &DMatrix<f64>,
        q: &DMatrix<f64>,
    ) -> Result<DMatrix<f64>, IkError> {
        let dim = t.nrows();
        let n_w = self.p.ncols();
        let (p0, p1) = (self.p.rows(0, dim), self.p.rows(dim, dim));
        let g_w = p0.tr_mul(&f_minus_q.column(0)) + p1.tr_mul(&f_minus_q.column(1));
        let e = e.select_rows(&self.kept);
        let r = e.nrows();
        let mut e_vec = DVector::zeros(2 * r);
        e_vec.rows_mut(0, r).copy_from(&e.column(0));
        e_vec.rows_mut(r, r).copy_from(&e.column(1));
        let w0 = self.parameters(t);

        // u: the step's unknowns; each maps to at most two entries of w.
        let mut map: Vec<[(usize, f64); 2]> = Vec::with_capacity(n_w);
        let mut turns = Vec::new();
        for param in &self.params {
            match *param {
                Param::None => {}
                Param::Affine { offset } => {
                    map.extend((0..6).map(|k| [(offset + k, 1.0), (offset + k, 0.0)]))
                }
                Param::Translation { offset } => {
                    map.extend((0..2).map(|k| [(offset + k, 1.0), (offset + k, 0.0)]))
                }
                Param::Similarity {
                    offset: o,
                    scale,
                    joined,
                    ..
                } => {
                    if scale {
                        map.extend((0..2).map(|k| [(o + k, 1.0), (o + k, 0.0)]));
                    } else {
                        turns.push((map.len(), o));
                        map.push([(o, -w0[o + 1]), (o + 1, w0[o])]);
                    }
                    if joined.is_none() {
                        map.push([(o + 2, 1.0), (o + 2, 0.0)]);
                        map.push([(o + 3, 1.0), (o + 3, 0.0)]);
                    }
                }
            }
        }
        let n_u = map.len();
        // The reduced gradient and Hessian: g_u = Cᵀ (g_w − H_w w₀), H_u = Cᵀ H_w C.
        let residual = &g_w - &self.h_w * &w0;
        let g_u: DVector<f64> = DVector::from_fn(n_u, |i, _| {
            map[i].iter().map(|&(a, ca)| ca * residual[a]).sum()
        });
        let h_u: DMatrix<f64> = DMatrix::from_fn(n_u, n_u, |i, k| {
            let mut s = 0.0;
            for &(a, ca) in &map[i] {
                for &(b, cb) in &map[k] {
                    s += ca * cb * self.h_w[(a, b)];
                }
            }
            s
        });
        let mut h_u = h_u;
        let mut g_u = g_u;
        if r > 0 {
            // The hard rows as a stiff least-squares term: met (to within the energy's pull over
            // `self.hard_weight`) when the limbs reach, met in the least-squares sense when not.
            let e_u = DMatrix::from_fn(2 * r, n_u, |row, i| {
                map[i].iter().map(|&(a, ca)| ca * self.e_w[(row, a)]).sum()
            });
            let e_u0 = &e_vec - &self.e_w * &w0;
            h_u += e_u.tr_mul(&e_u) * self.hard_weight;
            g_u += e_u.tr_mul(&e_u0) * self.hard_weight;
        }
        let ridge = 1e-12
            * (0..n_u)
                .map(|i| h_u[(i, i)].abs())
                .fold(0.0, f64::max)
                .max(1e-300);
        for i in 0..n_u {
            h_u[(i, i)] += ridge;
        }
        let cholesky = h_u.cholesky().ok_or(IkError::Singular)?;
        let mut delta = cholesky.solve(&g_u);
        let largest_turn = turns
            .iter()
            .map(|&(i, _)| delta[i].abs())
            .fold(0.0, f64::max);
        if !largest_turn.is_finite() || delta.iter().any(|v| !v.is_finite()) {
            return Err(IkError::NonFinite);
        }
        if largest_turn > MAX_TURN_RAD {
            delta *= MAX_TURN_RAD / largest_turn;
        }
        let mut w = w0.clone();
        for (i, entries) in map.iter().enumerate() {
            for &(a, ca) in entries {
                w[a] += ca * delta[i];
            }
        }
        // Retraction: a rigid column's (a, b) turned by exactly its angle.
        for &(i, o) in &turns {
            let (sin, cos) = delta[i].sin_cos();
            let (a, b) = (w0[o], w0[o + 1]);
            w[o] = a * cos - b * sin;
            w[o + 1] = a * sin + b * cos;
        }
        let flat = &self.p * &w;
        Ok(DMatrix::from_fn(dim, 2, |k, c| {
            flat[c * dim + k] + q[(k, c)]
        }))
    }
}

/// The columns that have parameters or follow another, each after the column it depends on
/// (a joined rigid column after its parent, a follower after the column it follows).
fn dependency_order(
    params: &[Param],
    follows: &[(usize, usize, [[f64; 3]; 3])],
) -> Result<Vec<usize>, IkError> {
    let depends_on = |j: usize| match params[j] {
        Param::Similarity {
            joined: Some(parent),
            ..
        } => Some(parent),
        Param::None => follows.iter().find(|f| f.0 == j).map(|f| f.1),
        _ => None,
    };
    let needed: Vec<bool> = (0..params.len())
        .map(|j| !matches!(params[j], Param::None) || depends_on(j).is_some())
        .collect();
    let mut placed = vec![false; params.len()];
    let mut order = Vec::new();
    while order.len() < needed.iter().filter(|n| **n).count() {
        let before = order.len();
        for j in 0..params.len() {
            if placed[j] || !needed[j] {
                continue;
            }
            if depends_on(j).is_some_and(|parent| needed[parent] && !placed[parent]) {
                continue;
            }
            placed[j] = true;
            order.push(j);
        }
        if order.len() == before {
            // Parents are validated acyclic; a cycle here is a malformed problem.
            return Err(IkError::Singular);
        }
    }
    Ok(order)
}

/// Writes column `j`'s rows of P (both output coordinates) from its parametrization; a follower
/// or a joined column reads its parent's rows, which must be written already.
fn fill_column(
    p: &mut DMatrix<f64>,
    dim: usize,
    j: usize,
    param: &Param,
    follow: Option<&(usize, usize, [[f64; 3]; 3])>,
) {
    match *param {
        Param::None => {
            if let Some(&(_, parent, map)) = follow {
                for c in 0..2 {
                    for (k, row) in map.iter().enumerate() {
                        for (l, &coefficient) in row.iter().enumerate() {
                            if coefficient != 0.0 {
                                let from = p.row(c * dim + 3 * parent + l) * coefficient;
                                let mut to = p.row_mut(c * dim + 3 * j + k);
                                to += from;
                            }
                        }
                    }
                }
            }
        }
        Param::Affine { offset } => {
            for c in 0..2 {
                for k in 0..3 {
                    p[(c * dim + 3 * j + k, offset + 3 * c + k)] = 1.0;
                }
            }
        }
        Param::Translation { offset } => {
            for c in 0..2 {
                p[(c * dim + 3 * j + 2, offset + c)] = 1.0;
            }
        }
        Param::Similarity {
            offset: o,
            pivot,
            joined,
            ..
        } => {
            let (cx, cy) = (pivot.x, pivot.y);
            // L = [[a, −b], [b, a]]; the translation's −L c part.
            p[(3 * j, o)] = 1.0;
            p[(3 * j + 1, o + 1)] = -1.0;
            p[(dim + 3 * j, o + 1)] = 1.0;
            p[(dim + 3 * j + 1, o)] = 1.0;
            p[(3 * j + 2, o)] = -cx;
            p[(3 * j + 2, o + 1)] = cy;
            p[(dim + 3 * j + 2, o)] = -cy;
            p[(dim + 3 * j + 2, o + 1)] = -cx;
            match joined {
                // c + t: t free (c is a constant entry).
                None => {
                    p[(3 * j + 2, o + 2)] = 1.0;
                    p[(dim + 3 * j + 2, o + 3)] = 1.0;
                }
                // The parent's image of c.
                Some(parent) => {
                    for c in 0..2 {
                        let from = p.row(c * dim + 3 * parent) * cx
                            + p.row(c * dim + 3 * parent + 1) * cy
                            + p.row(c * dim + 3 * parent + 2);
                        let mut to = p.row_mut(c * dim + 3 * j + 2);
                        to += from;
                    }
                }
            }
        }
    }
}
