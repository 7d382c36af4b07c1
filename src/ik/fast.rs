//! Fast automatic skinning transformations: the local/global solver over the reduced energy.
//!
//! In: a [`Subspace`] (precomputed once per rig) and a [`Problem`] (which handle columns are
//! free and how, joint and drag constraints, targets). Out: one affine map per handle column,
//! rest canvas → posed canvas ([`IkSolution`]).
//!
//! Following Jacobson, Baran, Kavan, Popović & Sorkine 2012, each solve alternates
//! - a local step: the best rotation per cluster (closed-form 2×2 fit), and the nearest
//!   rotation (or scaled rotation) to each rigid handle's linear part;
//! - a global step: the energy is quadratic in the free handle parameters z, with T = P z + q
//!   (P selects free entries and expresses keyed children through their free ancestor), and the
//!   hard constraints E z = e are linear, so the step is one product with matrices prepared by
//!   a null-space factorization of the KKT system.
//!
//! The factorization depends only on the problem's structure (which columns are free, the
//! keyed children's local transforms, which drags exist and where they grip), not on the
//! targets: [`FastIk`] keeps it while only targets change, so a drag in the editor costs a few
//! small dense products per iteration. The last solution warm-starts the next.
//!
//! Rigid columns ([`ColumnDofs::Rigid`]: bones by default) are rotations exactly: a problem
//! with one is solved by the coupled Gauss–Newton global step of [`super::rigid`] instead of the
//! factorized one. Near-rigid handles (regions always, affine bones when
//! [`IkOptions::rigidity`] asks) are held near rotations by a penalty λ‖L − R‖² (R the nearest rotation, refreshed in every local step); λ is
//! the column's rigidity times its own stiffness in A, so the term is unit-free. Hard constraints
//! are met exactly whenever they are feasible; infeasible ones are met in the least-squares sense.
//! (In the coupled step, joints are met by the parametrization and drags by a stiff
//! least-squares term.) A cold solve of a problem with rigid columns runs from two starts and
//! keeps the result that misses the hard drags least, then has the least energy, so the answer
//! depends on the problem alone.
//!
//! After the iterations, the [`super::fold`] guard checks the skinned triangles' orientation; a
//! triangle (nearly) folded over gets a rigidity term of its own, the system is factored again
//! and the iterations resume, up to [`IkOptions::fold_rounds`] times per solve. The guarded
//! triangles are kept for the following warm-started solves of the same structure.

use super::arap::{best_rotation, nearest_rotation};
use super::fold::FoldCheck;
use super::rigid::CoupledStep;
use super::subspace::Subspace;
use super::{IkError, IkOptions};
use crate::geom::Point;
use crate::rig::pose::Affine;
use nalgebra::{DMatrix, DVector, Matrix2, Vector2};

/// How one handle column may move in a solve.
#[derive(Clone, Debug, PartialEq)]
pub enum ColumnDofs {
    /// Held at this transform.
    Fixed(Affine),
    /// Any affine map; a positive `rigidity` holds its linear part near a rotation (see
    /// [`IkOptions::rigidity`] for the scale).
    Affine { rigidity: f64 },
    /// Translation only, the linear part held at `linear`.
    Translation { linear: Matrix2<f64> },
    /// `T_parent ∘ local`, where `parent` is an `Affine` or `Rigid` column (a keyed bone under
    /// a free one).
    Follows { parent: usize, local: Affine },
    /// A rotation and a translation, exactly (a bone that keeps its length), turning about
    /// `pivot` (rest canvas px, e.g. the bone's head: only the solver's conditioning depends on
    /// it); `scale`: it may also scale uniformly (a bone allowed to stretch). Solved by the
    /// coupled step of [`super::rigid`].
    Rigid { pivot: Point, scale: bool },
}

/// The point `at` (rest canvas px) moves with `child` and with `parent` alike.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub child: usize,
    pub parent: usize,
    pub at: Point,
}

/// A skinned material point and where it must go.
#[derive(Clone, Debug, PartialEq)]
pub struct DragRow {
    /// The point's skinning row (3m): its position is row · T.
    pub row: Vec<f64>,
    pub target: Point,
    /// `None`: a hard constraint; `Some(w)`: a soft one, relative to one handle's stiffness.
    pub weight: Option<f64>,
}

/// One solve's description.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    pub columns: Vec<ColumnDofs>,
    pub joints: Vec<Joint>,
    pub drags: Vec<DragRow>,
    /// Where each column sits when nothing else decides (the forward-kinematics pose).
    pub anchor: Vec<Affine>,
    /// Momentum terms: (free column, weight relative to the ARAP energy, where its motion would
    /// carry it). The column is pulled toward the prediction through its own mass block of G.
    pub inertia: Vec<(usize, f64, Affine)>,
}

impl Problem {
    /// Whether two problems share P, E and the quadratic form, so one factorization serves both.
    fn same_structure(&self, other: &Problem) -> bool {
        let dofs_match = self.columns.len() == other.columns.len()
            && self
                .columns
                .iter()
                .zip(&other.columns)
                .all(|(a, b)| match (a, b) {
                    (ColumnDofs::Fixed(_), ColumnDofs::Fixed(_)) => true,
                    _ => a == b,
                });
        dofs_match
            && self.joints == other.joints
            && self.inertia.len() == other.inertia.len()
            && self
                .inertia
                .iter()
                .zip(&other.inertia)
                .all(|(a, b)| a.0 == b.0 && a.1 == b.1)
            && self.drags.len() == other.drags.len()
            && self
                .drags
                .iter()
                .zip(&other.drags)
                .all(|(a, b)| a.row == b.row && a.weight == b.weight)
    }
}

/// A solve's result.
#[derive(Clone, Debug)]
pub struct IkSolution {
    /// One affine map per handle column.
    pub transforms: Vec<Affine>,
    pub iterations: usize,
    /// The largest distance between a hard drag's point and its target, px.
    pub drag_error_px: f64,
    /// The reduced (clustered) ARAP energy of the result, px².
    pub energy: f64,
}

/// The factorized global step for one problem structure.
#[derive(Clone, Debug)]
struct System {
    problem: Problem,
    p: DMatrix<f64>,
    /// T-space quadratic form: A + rigidity + anchor + soft drags.
    q_t: DMatrix<f64>,
    /// Hard constraint rows in T space (joints, then hard drags).
    e_t: DMatrix<f64>,
    /// z = x · rhs + y · e.
    x: DMatrix<f64>,
    y: DMatrix<f64>,
    /// X · Pᵀ B.
    x_pt_b: DMatrix<f64>,
    /// Free rigid columns: (column, z offset, λ).
    rigid: Vec<(usize, usize, f64)>,
    anchor_weight: f64,
    /// tr(A) / tr(G): converts mass-weighted distances into energy units.
    energy_per_gram: f64,
    /// The per-entry pull toward the anchor ([`COLUMN_HOLD`] × mean diagonal of A).
    column_hold: f64,
    /// The guarded triangles it was factored with (see [`FastIk::guard`]).
    guard: Vec<Guard>,
    /// Per guarded triangle: X Pᵀ λ Uᵀ (nz × 2), times its cluster's Rᵀ gives its share of z.
    x_pt_guard: Vec<DMatrix<f64>>,
    /// Per guarded triangle: Uᵀ λ (3m × 2), for the coupled step.
    guard_rhs: Vec<DMatrix<f64>>,
    /// The coupled global step, when the problem has rigid columns (then P, X, Y and the
    /// products with them are empty).
    coupled: Option<CoupledStep>,
}

/// A triangle held near its cluster's rotation: λ‖J − R‖²_F (see [`super::fold`]).
#[derive(Clone, Debug, PartialEq)]
struct Guard {
    /// Index among the fold check's triangles.
    triangle: usize,
    /// px².
    lambda: f64,
    /// The cluster whose rotation R is.
    cluster: usize,
}

/// Pull of every handle parameter toward its anchor, relative to A's mean diagonal: negligible
/// for any column that moves vertices, decisive for one that moves none.
pub const COLUMN_HOLD: f64 = 1e-9;

/// How much a guarded triangle's weight grows in each round that finds it still folded.
pub const FOLD_ESCALATION: f64 = 10.0;

/// A folded triangle whose Jacobian the free parameters move by less than this share of its
/// whole dependence on T is left unguarded (the fixed handles fold it).
pub const FOLD_FREE_SHARE: f64 = 1e-9;

/// The skinning-IK solver of one rig: precompute once, then solve per frame or per drag.
#[derive(Clone, Debug)]
pub struct FastIk {
    pub options: IkOptions,
    pub subspace: Subspace,
    /// A bound on |v| over the rig's rest vertices, px: converts a change of a linear part
    /// into a bound on how far a vertex moves.
    extent_px: f64,
    /// The triangles whose orientation is checked after each solve.
    folds: FoldCheck,
    /// Triangles found folding in earlier rounds or solves of the current structure, with their
    /// rigidity weights.
    guard: Vec<Guard>,
    system: Option<System>,
    previous: Option<DMatrix<f64>>,
    /// The solver of the relaxed problem that starts a cold rigid solve ([`FastIk::relaxed_start`]).
    relaxed: Option<Box<FastIk>>,
}

fn affine_to_rows(t: &Affine, out: &mut DMatrix<f64>, j: usize) {
    for c in 0..2 {
        out[(3 * j, c)] = t.linear[(c, 0)];
        out[(3 * j + 1, c)] = t.linear[(c, 1)];
        out[(3 * j + 2, c)] = t.translation[c];
    }
}

fn rows_to_affine(t: &DMatrix<f64>, j: usize) -> Affine {
    Affine {
        linear: Matrix2::new(
            t[(3 * j, 0)],
            t[(3 * j + 1, 0)],
            t[(3 * j, 1)],
            t[(3 * j + 1, 1)],
        ),
        translation: Vector2::new(t[(3 * j + 2, 0)], t[(3 * j + 2, 1)]),
    }
}

/// Stacks per-column transforms into T (3m × 2).
pub fn stack(transforms: &[Affine]) -> DMatrix<f64> {
    let mut t = DMatrix::zeros(3 * transforms.len(), 2);
    for (j, a) in transforms.iter().enumerate() {
        affine_to_rows(a, &mut t, j);
    }
    t
}

/// Unstacks T into per-column transforms.
pub fn unstack(t: &DMatrix<f64>) -> Vec<Affine> {
    (0..t.nrows() / 3).map(|j| rows_to_affine(t, j)).collect()
}

impl FastIk {
    /// Wraps a precomputed subspace. `extent_px` bounds |v| over the rig's rest vertices.
    pub fn new(subspace: Subspace, extent_px: f64, options: IkOptions) -> Self {
        FastIk {
            options,
            subspace,
            extent_px,
            folds: FoldCheck::default(),
            guard: Vec::new(),
            system: None,
            previous: None,
            relaxed: None,
        }
    }

    /// Sets the triangles whose orientation the solver guards (none by default).
    pub fn with_fold_check(mut self, folds: FoldCheck) -> Self {
        self.folds = folds;
        self.guard.clear();
        self.system = None;
        self
    }

    /// How many triangles the fold guard currently holds near rigid.
    pub fn guarded_triangles(&self) -> usize {
        self.guard.len()
    }

    /// Forgets the warm start (e.g. when the animation jumps) and the guarded triangles.
    pub fn reset(&mut self) {
        self.previous = None;
        self.guard.clear();
    }

    /// Mean diagonal of A over the translation entries: the energy stiffness of moving one
    /// handle, the unit soft weights are measured in.
    fn handle_stiffness(&self) -> f64 {
        let m = self.subspace.column_count.max(1);
        let s: f64 = (0..self.subspace.column_count)
            .map(|j| self.subspace.a[(3 * j + 2, 3 * j + 2)])
            .sum();
        (s / m as f64).max(f64::MIN_POSITIVE)
    }

    fn factor(&self, problem: &Problem, guard: &[Guard]) -> Result<System, IkError> {
        let m = self.subspace.column_count;
        if problem.columns.len() != m || problem.anchor.len() != m {
            return Err(IkError::ColumnCount {
                expected: m,
                got: problem.columns.len(),
            });
        }
        let dim = 3 * m;
        let coupled_needed = CoupledStep::needed(&problem.columns);
        // Offsets of free parameters (of the factorized step).
        let mut offset = vec![usize::MAX; m];
        let mut nz = 0;
        for (j, c) in problem.columns.iter().enumerate() {
            match c {
                ColumnDofs::Affine { .. } => {
                    offset[j] = nz;
                    nz += 3;
                }
                ColumnDofs::Translation { .. } => {
                    offset[j] = nz;
                    nz += 1;
                }
                ColumnDofs::Fixed(_) | ColumnDofs::Follows { .. } | ColumnDofs::Rigid { .. } => {}
            }
        }
        if coupled_needed {
            nz = 0;
        }
        let mut p = DMatrix::<f64>::zeros(dim, nz);
        let mut rigid = Vec::new();
        let a = &self.subspace.a;
        let mut q_t = a.clone();
        for (j, c) in problem.columns.iter().enumerate() {
            match c {
                ColumnDofs::Affine { rigidity } => {
                    if !coupled_needed {
                        for k in 0..3 {
                            p[(3 * j + k, offset[j] + k)] = 1.0;
                        }
                    }
                    if *rigidity > 0.0 {
                        let stiffness = 0.5 * (a[(3 * j, 3 * j)] + a[(3 * j + 1, 3 * j + 1)]);
                        let lambda = rigidity * stiffness.max(f64::MIN_POSITIVE);
                        q_t[(3 * j, 3 * j)] += lambda;
                        q_t[(3 * j + 1, 3 * j + 1)] += lambda;
                        rigid.push((j, offset[j], lambda));
                    }
                }
                ColumnDofs::Translation { .. } if !coupled_needed => {
                    p[(3 * j + 2, offset[j])] = 1.0
                }
                // The coupled step parametrizes these itself.
                ColumnDofs::Translation { .. } | ColumnDofs::Rigid { .. } => {}
                ColumnDofs::Follows { .. } if coupled_needed => {}
                ColumnDofs::Follows { parent, local } => {
                    let pj = *parent;
                    if !matches!(problem.columns.get(pj), Some(ColumnDofs::Affine { .. })) {
                        return Err(IkError::BadFollow {
                            column: j,
                            parent: pj,
                        });
                    }
                    // Row c of T_j = (L_p[c,:] G_L, L_p[c,:] G_t + t_p[c]).
                    let (g, gt) = (local.linear, local.translation);
                    let o = offset[pj];
                    p[(3 * j, o)] = g[(0, 0)];
                    p[(3 * j, o + 1)] = g[(1, 0)];
                    p[(3 * j + 1, o)] = g[(0, 1)];
                    p[(3 * j + 1, o + 1)] = g[(1, 1)];
                    p[(3 * j + 2, o)] = gt[0];
                    p[(3 * j + 2, o + 1)] = gt[1];
                    p[(3 * j + 2, o + 2)] = 1.0;
                }
                ColumnDofs::Fixed(_) => {}
            }
        }
        let trace_a: f64 = (0..dim).map(|k| a[(k, k)]).sum();
        let trace_g: f64 = (0..dim).map(|k| self.subspace.gram[(k, k)]).sum();
        let anchor_weight = if trace_g > 0.0 {
            self.options.anchor * trace_a / trace_g
        } else {
            0.0
        };
        q_t += &self.subspace.gram * anchor_weight;
        // A column that moves (almost) no vertex has (almost) no G: hold it at its anchor too.
        let column_hold = COLUMN_HOLD * trace_a / dim.max(1) as f64;
        for k in 0..dim {
            q_t[(k, k)] += column_hold;
        }
        let energy_per_gram = if trace_g > 0.0 {
            trace_a / trace_g
        } else {
            0.0
        };
        for &(j, weight, _) in &problem.inertia {
            let block =
                self.subspace.gram.view((3 * j, 3 * j), (3, 3)) * (weight * energy_per_gram);
            let mut target = q_t.view_mut((3 * j, 3 * j), (3, 3));
            target += block;
        }
        let stiffness = self.handle_stiffness();
        let mut hard: Vec<Vec<f64>> = Vec::new();
        for joint in &problem.joints {
            let mut row = vec![0.0; dim];
            let h = [joint.at.x, joint.at.y, 1.0];
            for k in 0..3 {
                row[3 * joint.child + k] += h[k];
                row[3 * joint.parent + k] -= h[k];
            }
            hard.push(row);
        }
        for drag in &problem.drags {
            match drag.weight {
                None => hard.push(drag.row.clone()),
                Some(w) => {
                    let d = DVector::from_column_slice(&drag.row);
                    q_t += (&d * d.transpose()) * (w * stiffness);
                }
            }
        }
        let mut guard_rhs = Vec::with_capacity(guard.len());
        for g in guard {
            let (u, _, _) = self.folds.jacobian_map(g.triangle);
            q_t += u.tr_mul(&u) * g.lambda;
            guard_rhs.push(u.transpose() * g.lambda);
        }
        let e_t = DMatrix::from_fn(hard.len(), dim, |r, c| hard[r][c]);
        if coupled_needed {
            let coupled =
                CoupledStep::new(&problem.columns, &problem.joints, &q_t, &e_t, stiffness)?;
            return Ok(System {
                problem: problem.clone(),
                x: DMatrix::zeros(0, 0),
                y: DMatrix::zeros(0, e_t.nrows()),
                x_pt_b: DMatrix::zeros(0, self.subspace.b.ncols()),
                p,
                q_t,
                e_t,
                rigid,
                anchor_weight,
                energy_per_gram,
                column_hold,
                guard: guard.to_vec(),
                x_pt_guard: Vec::new(),
                guard_rhs,
                coupled: Some(coupled),
            });
        }
        let h = p.tr_mul(&(&q_t * &p));
        let e = &e_t * &p;
        // Null-space method: z = z_p + N y with E z_p = e in the least-squares sense.
        let (e_pinv, null) = pseudo_inverse_and_null_space(&e, nz)?;
        let reduced = null.tr_mul(&(&h * &null));
        let k = reduced.ncols();
        let x = if k == 0 {
            DMatrix::zeros(nz, nz)
        } else {
            let ridge = 1e-12
                * (0..k)
                    .map(|i| reduced[(i, i)].abs())
                    .fold(0.0, f64::max)
                    .max(1e-300);
            let regular = &reduced + DMatrix::identity(k, k) * ridge;
            let cholesky = regular.cholesky().ok_or(IkError::Singular)?;
            &null * cholesky.solve(&null.transpose())
        };
        let y = (DMatrix::identity(nz, nz) - &x * &h) * &e_pinv;
        let x_pt_b = &x * p.tr_mul(&self.subspace.b);
        let x_pt_guard = guard_rhs.iter().map(|g| &x * p.tr_mul(g)).collect();
        Ok(System {
            problem: problem.clone(),
            p,
            q_t,
            e_t,
            x,
            y,
            x_pt_b,
            rigid,
            anchor_weight,
            energy_per_gram,
            column_hold,
            guard: guard.to_vec(),
            x_pt_guard,
            guard_rhs,
            coupled: None,
        })
    }

    /// Solves `problem`, reusing the last factorization when the structure is unchanged and the
    /// last solution as the starting point.
    pub fn solve(&mut self, problem: &Problem) -> Result<IkSolution, IkError> {
        self.solve_limited(problem, None)
    }

    /// [`FastIk::solve`] with another iteration limit for a warm-started solve.
    pub fn solve_limited(
        &mut self,
        problem: &Problem,
        warm_iterations: Option<usize>,
    ) -> Result<IkSolution, IkError> {
        let same_structure = matches!(&self.system, Some(s) if s.problem.same_structure(problem));
        if !same_structure {
            // Triangles guarded for another set of constraints need not fold under this one.
            self.guard.clear();
        }
        let dim = 3 * self.subspace.column_count;
        let (t, iterations) = match &self.previous {
            Some(prev) if prev.nrows() == dim => {
                let limit = warm_iterations.unwrap_or(self.options.iterations);
                self.iterate_from(problem, prev.clone(), limit)?
            }
            _ if CoupledStep::needed(&problem.columns) => {
                // Rigid columns make the problem non-convex: of the two starts, the result that
                // misses the hard drags least (then has the least energy) is the answer, so it
                // depends on the problem alone.
                let limit = self.options.cold_iterations;
                let relaxed = self.relaxed_start(problem)?;
                let (t_a, n_a) = self.iterate_from(problem, relaxed, limit)?;
                let guard_a = std::mem::take(&mut self.guard);
                let (t_b, n_b) = self.iterate_from(problem, stack(&problem.anchor), limit)?;
                let score = |t: &DMatrix<f64>| {
                    let miss = hard_misses_px(problem, t)
                        .iter()
                        .map(|m| m * m)
                        .sum::<f64>();
                    // Misses that differ by less than this are ties, px².
                    ((miss / MISS_TIE_PX2).round(), self.reduced_energy(t))
                };
                if score(&t_b) < score(&t_a) {
                    (t_b, n_a + n_b)
                } else {
                    self.guard = guard_a;
                    (t_a, n_a + n_b)
                }
            }
            _ => {
                let limit = self.options.cold_iterations;
                self.iterate_from(problem, stack(&problem.anchor), limit)?
            }
        };
        Ok(self.finish(problem, t, iterations))
    }

    /// The answer of record for a static pose: `problem`'s drags taken in their order, each
    /// solved cold only when the answer for the drags before it leaves it unmet.
    ///
    /// With rigid columns the problem is not convex, so a cold solve of more constraints may
    /// settle in another local optimum even where the new constraint is already met: pinning a
    /// point where it is drawn would move the drawing. Here the answer x_j for the first j drags
    /// is x_(j−1) when drag j lies within [`SATISFIED_DRAG_PX`] of its target there (x_(j−1)
    /// meets every constraint of the larger problem, at the same energy), and the cold
    /// [`FastIk::solve`] of those j drags otherwise; x_0 is the anchor. The answer is a function
    /// of the problem alone (the drags' order included): a pin added where a point already is
    /// changes nothing, and the same pins after a reset give the same pose. Drags met at the
    /// anchor (pins at rest) cost nothing; the worst case, every drag unmet in turn, is one cold
    /// solve per drag.
    pub fn solve_static(&mut self, problem: &Problem) -> Result<IkSolution, IkError> {
        let mut t = stack(&problem.anchor);
        let mut iterations = 0;
        for j in 0..problem.drags.len() {
            if drag_miss_px(&problem.drags[j], &t) <= SATISFIED_DRAG_PX {
                continue;
            }
            self.reset();
            let first = Problem {
                drags: problem.drags[..=j].to_vec(),
                ..problem.clone()
            };
            let solution = self.solve(&first)?;
            iterations += solution.iterations;
            t = stack(&solution.transforms);
        }
        Ok(self.finish(problem, t, iterations))
    }

    /// `t` as the solution of `problem` (its largest hard-drag miss and its energy), kept as
    /// the next solve's warm start.
    fn finish(&mut self, problem: &Problem, t: DMatrix<f64>, iterations: usize) -> IkSolution {
        let drag_error_px = hard_misses_px(problem, &t).into_iter().fold(0.0, f64::max);
        let energy = self.reduced_energy(&t);
        let transforms = unstack(&t);
        self.previous = Some(t);
        IkSolution {
            transforms,
            iterations,
            drag_error_px,
            energy,
        }
    }

    /// Local/global iterations from `t` with fold-guard rounds; returns the result and how many
    /// iterations ran.
    fn iterate_from(
        &mut self,
        problem: &Problem,
        mut t: DMatrix<f64>,
        iteration_limit: usize,
    ) -> Result<(DMatrix<f64>, usize), IkError> {
        let mut iterations = 0;
        for round in 0..=self.options.fold_rounds {
            let current = matches!(&self.system,
                Some(s) if s.guard == self.guard && s.problem.same_structure(problem));
            if !current {
                match self.factor(problem, &self.guard) {
                    Ok(system) => self.system = Some(system),
                    // Guard weights so large that the system no longer factors: keep the last
                    // factorization's guard and its result.
                    Err(IkError::Singular) if round > 0 => {
                        if let Some(s) = &self.system {
                            self.guard = s.guard.clone();
                        }
                        break;
                    }
                    Err(e) => return Err(e),
                }
            }
            iterations += self.iterate(problem, &mut t, iteration_limit)?;
            if round == self.options.fold_rounds || self.folds.is_empty() {
                break;
            }
            if !self.guard_folds(&t) {
                break;
            }
        }
        Ok((t, iterations))
    }

    /// A cold start for a problem with rigid columns: the solution with those columns affine
    /// (a convex problem, one answer), each rigid column then turned to its nearest rotation
    /// about its pivot. Starting from the forward-kinematics pose instead, the rigid problem's
    /// iterations settle in whichever local optimum lies nearest that pose.
    fn relaxed_start(&mut self, problem: &Problem) -> Result<DMatrix<f64>, IkError> {
        let relaxed = Problem {
            columns: problem
                .columns
                .iter()
                .map(|c| match c {
                    ColumnDofs::Rigid { .. } => ColumnDofs::Affine { rigidity: 0.0 },
                    other => other.clone(),
                })
                .collect(),
            ..problem.clone()
        };
        // No fold check: `FastIk::new` guards no triangles (the start only needs the shape).
        let solver = self.relaxed.get_or_insert_with(|| {
            Box::new(FastIk::new(
                self.subspace.clone(),
                self.extent_px,
                self.options.clone(),
            ))
        });
        solver.reset();
        let solution = solver.solve(&relaxed)?;
        let mut transforms = solution.transforms;
        for (t, c) in transforms.iter_mut().zip(&problem.columns) {
            if let ColumnDofs::Rigid { pivot, scale } = c {
                let moved = t.apply(*pivot);
                let mut linear = nearest_rotation(&t.linear);
                if *scale {
                    linear *= ((linear.transpose() * t.linear).trace() * 0.5).max(0.0);
                }
                t.linear = linear;
                t.translation = moved.coords - linear * pivot.coords;
            }
        }
        Ok(stack(&transforms))
    }

    /// Guards the checked triangles that `t` folds (nearly) over and that the free parameters can
    /// turn back; returns whether the guard changed.
    fn guard_folds(&mut self, t: &DMatrix<f64>) -> bool {
        let Some(system) = &self.system else {
            return false;
        };
        let mut changed = false;
        for fold in self.folds.folds(t, self.options.fold_area_ratio) {
            if let Some(g) = self.guard.iter_mut().find(|g| g.triangle == fold.triangle) {
                g.lambda *= FOLD_ESCALATION;
                changed = true;
                continue;
            }
            let (u, area, cluster) = self.folds.jacobian_map(fold.triangle);
            // A triangle folded by handles the pose fixes is the pose's doing: no free
            // parameter moves it, and a guard would only weigh on the factorization.
            let free_part = match &system.coupled {
                Some(coupled) => coupled.free_part(&u),
                None => (&u * &system.p).norm(),
            };
            if free_part <= FOLD_FREE_SHARE * u.norm() {
                continue;
            }
            self.guard.push(Guard {
                triangle: fold.triangle,
                lambda: self.options.fold_stiffness * area,
                cluster,
            });
            changed = true;
        }
        changed
    }

    /// Local/global iterations on `t` with the current system, at most `limit`; returns how
    /// many ran.
    fn iterate(
        &self,
        problem: &Problem,
        t: &mut DMatrix<f64>,
        limit: usize,
    ) -> Result<usize, IkError> {
        let Some(system) = &self.system else {
            return Err(IkError::Singular);
        };
        let m = self.subspace.column_count;
        let dim = 3 * m;
        // q: the fixed entries of T.
        let mut q = DMatrix::<f64>::zeros(dim, 2);
        for (j, c) in problem.columns.iter().enumerate() {
            match c {
                ColumnDofs::Fixed(t) => affine_to_rows(t, &mut q, j),
                ColumnDofs::Translation { linear } => {
                    for cc in 0..2 {
                        q[(3 * j, cc)] = linear[(cc, 0)];
                        q[(3 * j + 1, cc)] = linear[(cc, 1)];
                    }
                }
                ColumnDofs::Affine { .. }
                | ColumnDofs::Follows { .. }
                | ColumnDofs::Rigid { .. } => {}
            }
        }
        if let Some(coupled) = &system.coupled {
            coupled.add_constants(&mut q);
        }
        let anchor = stack(&problem.anchor);
        let stiffness = self.handle_stiffness();
        let mut f_const = &self.subspace.gram * &anchor * system.anchor_weight
            + &anchor * system.column_hold
            - &system.q_t * &q;
        for (j, weight, predicted) in &problem.inertia {
            let block =
                self.subspace.gram.view((3 * j, 3 * j), (3, 3)) * (weight * system.energy_per_gram);
            let mut rows = DMatrix::<f64>::zeros(3, 2);
            for c in 0..2 {
                rows[(0, c)] = predicted.linear[(c, 0)];
                rows[(1, c)] = predicted.linear[(c, 1)];
                rows[(2, c)] = predicted.translation[c];
            }
            let pull = block * rows;
            let mut target = f_const.view_mut((3 * j, 0), (3, 2));
            target += pull;
        }
        let mut targets = Vec::with_capacity(system.e_t.nrows());
        targets.extend(problem.joints.iter().map(|_| Point::origin()));
        for drag in &problem.drags {
            match drag.weight {
                None => targets.push(drag.target),
                Some(w) => {
                    for (k, &d) in drag.row.iter().enumerate() {
                        for c in 0..2 {
                            f_const[(k, c)] += w * stiffness * d * drag.target[c];
                        }
                    }
                }
            }
        }
        let e_q = &system.e_t * &q;
        let e = DMatrix::from_fn(targets.len(), 2, |r, c| targets[r][c] - e_q[(r, c)]);
        let z_const = match system.coupled {
            Some(_) => DMatrix::zeros(0, 2),
            None => &system.x * system.p.tr_mul(&f_const) + &system.y * &e,
        };

        let r_count = self.subspace.cluster_count;
        let nz = system.p.ncols();
        let mut r_flat = DMatrix::<f64>::zeros(2 * r_count, 2);
        let rhs_rows = if system.coupled.is_some() { dim } else { nz };
        let mut rigid_rhs = DMatrix::<f64>::zeros(rhs_rows, 2);
        let mut iterations = 0;
        for _ in 0..limit.max(1) {
            iterations += 1;
            // Local step: cluster rotations from C = Bᵀ T, rigid targets from T.
            let c = self.subspace.b.tr_mul(t);
            for k in 0..r_count {
                let ck = Matrix2::new(
                    c[(2 * k, 0)],
                    c[(2 * k, 1)],
                    c[(2 * k + 1, 0)],
                    c[(2 * k + 1, 1)],
                );
                let r = best_rotation(&ck);
                // Rows 2k, 2k+1 hold Rₖᵀ.
                r_flat[(2 * k, 0)] = r[(0, 0)];
                r_flat[(2 * k, 1)] = r[(1, 0)];
                r_flat[(2 * k + 1, 0)] = r[(0, 1)];
                r_flat[(2 * k + 1, 1)] = r[(1, 1)];
            }
            rigid_rhs.fill(0.0);
            // The coupled step takes the pull in T space (rows 3j, 3j + 1).
            let coupled = system.coupled.is_some();
            for &(j, o, lambda) in &system.rigid {
                let o = if coupled { 3 * j } else { o };
                let l = rows_to_affine(t, j).linear;
                let mut target = nearest_rotation(&l);
                if self.options.allow_uniform_scale {
                    let s = (target.transpose() * l).trace() * 0.5;
                    target *= s.max(0.0);
                }
                for cc in 0..2 {
                    rigid_rhs[(o, cc)] = lambda * target[(cc, 0)];
                    rigid_rhs[(o + 1, cc)] = lambda * target[(cc, 1)];
                }
            }
            // Global step.
            let next = if let Some(coupled) = &system.coupled {
                let mut f = &f_const + &self.subspace.b * &r_flat + &rigid_rhs;
                for (g, u_lambda) in system.guard.iter().zip(&system.guard_rhs) {
                    f += u_lambda * r_flat.view((2 * g.cluster, 0), (2, 2));
                }
                coupled.step(t, &f, &e, &q)?
            } else {
                let mut z = &z_const + &system.x_pt_b * &r_flat;
                if !system.rigid.is_empty() {
                    z += &system.x * &rigid_rhs;
                }
                for (g, x_pt_u) in system.guard.iter().zip(&system.x_pt_guard) {
                    z += x_pt_u * r_flat.view((2 * g.cluster, 0), (2, 2));
                }
                &system.p * &z + &q
            };
            let change = (0..m)
                .map(|j| {
                    let d = rows_to_affine(&next, j);
                    let o = rows_to_affine(t, j);
                    (d.linear - o.linear).norm() * self.extent_px
                        + (d.translation - o.translation).norm()
                })
                .fold(0.0, f64::max);
            *t = next;
            if change <= self.options.tolerance_px {
                break;
            }
        }
        Ok(iterations)
    }

    /// The clustered ARAP energy of `t` with its best cluster rotations, px².
    pub fn reduced_energy(&self, t: &DMatrix<f64>) -> f64 {
        let s = &self.subspace;
        let c = s.b.tr_mul(t);
        let mut cross = 0.0;
        for k in 0..s.cluster_count {
            let ck = Matrix2::new(
                c[(2 * k, 0)],
                c[(2 * k, 1)],
                c[(2 * k + 1, 0)],
                c[(2 * k + 1, 1)],
            );
            cross += (best_rotation(&ck) * ck).trace();
        }
        let quadratic = (t.transpose() * &s.a * t).trace();
        (quadratic - 2.0 * cross + s.energy_constant).max(0.0)
    }
}

/// Two solutions whose summed squared hard-drag misses differ by less than this are ranked by
/// their energy, px².
pub const MISS_TIE_PX2: f64 = 1e-4;

/// A drag whose point lies this close to its target under the answer for the drags before it
/// adds nothing to a static pose ([`FastIk::solve_static`]), px: far below what can be seen,
/// far above the rounding of a pin placed where the point is drawn.
pub const SATISFIED_DRAG_PX: f64 = 1e-4;

/// How far `drag`'s point lies from its target under `t`, px.
fn drag_miss_px(drag: &DragRow, t: &DMatrix<f64>) -> f64 {
    let row = DVector::from_column_slice(&drag.row);
    let pos = t.tr_mul(&row);
    (pos[0] - drag.target.x).hypot(pos[1] - drag.target.y)
}

/// How far each hard drag's point lies from its target under `t`, px.
fn hard_misses_px(problem: &Problem, t: &DMatrix<f64>) -> Vec<f64> {
    problem
        .drags
        .iter()
        .filter(|d| d.weight.is_none())
        .map(|d| drag_miss_px(d, t))
        .collect()
}

/// The pseudo-inverse of `e` (nz × rows) and an orthonormal basis of its null space (nz × k),
/// by SVD with a relative rank tolerance.
fn pseudo_inverse_and_null_space(
    e: &DMatrix<f64>,
    nz: usize,
) -> Result<(DMatrix<f64>, DMatrix<f64>), IkError> {
    if e.nrows() == 0 || nz == 0 {
        return Ok((DMatrix::zeros(nz, e.nrows()), DMatrix::identity(nz, nz)));
    }
    // Work on Eᵀ E's eigen-decomposition (nz × nz, symmetric): its eigenvectors with zero
    // eigenvalue span the null space; the others give the pseudo-inverse.
    let ete = e.tr_mul(e);
    let eig = nalgebra::SymmetricEigen::new(ete);
    let largest = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    if !largest.is_finite() {
        return Err(IkError::NonFinite);
    }
    let tolerance = largest * 1e-12;
    let mut range = Vec::new();
    let mut null = Vec::new();
    for (i, &lambda) in eig.eigenvalues.iter().enumerate() {
        if lambda > tolerance {
            range.push((i, lambda));
        } else {
            null.push(i);
        }
    }
    let v = &eig.eigenvectors;
    let mut pinv = DMatrix::zeros(nz, e.nrows());
    for &(i, lambda) in &range {
        let vi = v.column(i);
        // E⁺ = Σ vᵢ vᵢᵀ Eᵀ / λᵢ.
        pinv += (vi * (e * vi).transpose()) / lambda;
    }
    let null_basis = DMatrix::from_fn(nz, null.len(), |r, c| v[(r, null[c])]);
    Ok((pinv, null_basis))
}

impl FastIk {
    /// Precomputes the solver for `meshes` skinned over `column_count` handle columns: rotation
    /// clusters in weight space, then the reduced energy's matrices.
    pub fn precompute(
        meshes: &[super::SkinnedMesh],
        column_count: usize,
        options: IkOptions,
    ) -> Result<Self, IkError> {
        let n: usize = meshes.iter().map(|m| m.rest.len()).sum();
        if n == 0 || column_count == 0 {
            return Err(IkError::NoWeights);
        }
        let mut points = vec![0.0; n * column_count];
        let mut base = 0;
        let mut extent_px: f64 = 0.0;
        for mesh in meshes {
            for (i, row) in mesh.weights.iter().enumerate() {
                for &(j, w) in row {
                    if j as usize >= column_count || !w.is_finite() {
                        return Err(IkError::NonFinite);
                    }
                    points[(base + i) * column_count + j as usize] = w;
                }
            }
            for p in &mesh.rest {
                if !p.x.is_finite() || !p.y.is_finite() {
                    return Err(IkError::NonFinite);
                }
                extent_px = extent_px.max(p.coords.norm());
            }
            base += mesh.rest.len();
        }
        let (clusters, count) = if options.clusters_per_handle == 0 {
            ((0..n as u32).collect(), n)
        } else {
            super::cluster::weight_space_clusters(
                &points,
                column_count,
                options.clusters_per_handle.saturating_mul(column_count),
                options.cluster_iterations,
            )
        };
        let subspace = super::subspace::reduce(meshes, column_count, &clusters, count);
        let folds = FoldCheck::new(
            meshes,
            column_count,
            &clusters,
            options.fold_check_triangles,
        );
        Ok(FastIk::new(subspace, extent_px, options).with_fold_check(folds))
    }
}
