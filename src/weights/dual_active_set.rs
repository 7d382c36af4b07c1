//! Box-constrained QPs that share one Hessian, by a dual active-set method over one shared
//! sparse factorization: the default solver of bounded biharmonic weights.
//!
//! In: a factored SPD matrix H (the bi-Laplacian restricted to the free vertices, n_F × n_F,
//! [`PatternCholesky`]) and, per handle, the unconstrained minimizer x₀ = −H⁻¹g of
//! ½ xᵀHx + gᵀx. Out: per handle the minimizer subject to 0 ≤ x ≤ 1 (weights, unitless), the
//! bounds it holds active, and how many steps it took — or the reason it gave up, so the caller
//! can fall back to the interior-point method.
//!
//! The method is Goldfarb & Idnani's dual algorithm ("A numerically stable dual method for
//! solving strictly convex quadratic programs", Math. Programming 27, 1983): start at the
//! unconstrained minimum, add the most violated bound, and drop any bound whose multiplier would
//! turn negative on the way, so every iterate is the exact minimizer over its active set. With
//! bounds as the only inequalities, everything it needs of H is the block S = (H⁻¹)[W, W] for
//! the set W of vertices whose bounds it ever looks at: a dense |W| × |W| matrix, shared by all
//! handles (they have the same H and differ only in x₀). For point-handle BBW the bounds that
//! end up active are few (a few dozen to ~150 vertices per handle, not growing with the mesh:
//! the weights are positive almost everywhere), so W stays at a few hundred vertices.
//!
//! W grows in rounds: each round takes, per handle, the most violated vertices outside W in
//! the current full-length iterate, computes their columns H⁻¹e_i with one batched multi-RHS
//! solve (far cheaper per column than single solves), runs the dense dual method on W for
//! every handle (in parallel), and recomputes the full iterates x = x₀ + H⁻¹ Σ ±u_i e_i with one
//! more batched solve. It stops when no vertex anywhere violates a bound by more than
//! [`DualActiveSetOptions::feasibility_tolerance`]. The result is the QP's solution to
//! round-off, not an approximation: the tolerance only decides which violations count.
//!
//! Tried before this and measured worse (see ARCHITECTURE.md): an interior point per handle
//! (one numeric factorization per iteration, ~17 per handle), primal–dual active set (cycles:
//! H is not an M-matrix), ADMM over one factorization (slow tail), local support.

use super::sparse::PatternCholesky;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Parameters of the dual active-set solve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DualActiveSetOptions {
    /// A weight more than this outside [0, 1] violates its bound and is constrained; smaller
    /// excursions (round-off) are clamped at the end. Default 1e-9.
    pub feasibility_tolerance: f64,
    /// Vertices (H⁻¹ columns) added per handle per round, the most violated first. Larger
    /// means fewer rounds but more columns that end up unused. Default 48.
    pub columns_per_round: usize,
    /// Most vertices whose H⁻¹ columns are kept; the dense block costs 8·|W|² bytes
    /// (72 MB at the default). Handles unfinished when W would outgrow it fall back to the
    /// interior point. Default 3000.
    pub max_columns: usize,
    /// Rounds (column batches) before the unfinished handles fall back. Default 60.
    pub max_rounds: usize,
    /// Dual steps (adding or dropping one bound) per handle before it falls back. Default 20000.
    pub max_steps: usize,
    /// A new bound whose column is this dependent on the active ones (its Schur complement
    /// relative to its diagonal entry) makes the handle fall back. Default 1e-13.
    pub dependence_tolerance: f64,
}

impl Default for DualActiveSetOptions {
    fn default() -> Self {
        DualActiveSetOptions {
            feasibility_tolerance: 1e-9,
            columns_per_round: 48,
            max_columns: 3000,
            max_rounds: 60,
            max_steps: 20_000,
            dependence_tolerance: 1e-13,
        }
    }
}

/// Why a handle's dual active-set solve gave up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum DualActiveSetError {
    #[error("more than the allowed number of dual steps")]
    TooManySteps,
    #[error("a new bound's column depends numerically on the active ones")]
    Dependent,
    #[error("the constrained vertex set outgrew max_columns")]
    TooManyColumns,
    #[error("no convergence within max_rounds")]
    TooManyRounds,
}

/// One handle's answer.
#[derive(Clone, Debug)]
pub struct BoxSolution {
    /// The minimizer over the free vertices, in [0, 1], active bounds exactly 0 or 1.
    pub x: Vec<f64>,
    /// Dual steps taken.
    pub steps: usize,
    /// Bounds active at the solution.
    pub active: usize,
}

/// What the whole solve did, for reports and benchmarks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DualActiveSetStats {
    /// Vertices whose H⁻¹ columns were computed (|W|).
    pub columns: usize,
    /// Rounds of column batches.
    pub rounds: usize,
}

/// Columns per batched solve: fixed (not derived from the thread count) so that every column
/// is computed by the same arithmetic whatever the parallelism, and results are byte-identical.
const SOLVE_CHUNK: usize = 16;

/// Solves H X = B in place for the columns of `b` (column-major, `chol.len()` rows), in
/// fixed-size chunks spread over rayon's threads.
pub(crate) fn solve_columns(chol: &PatternCholesky, b: &mut [f64]) {
    let len = chol.len();
    if len == 0 {
        return;
    }
    b.par_chunks_mut(len * SOLVE_CHUNK)
        .for_each(|chunk| chol.solve_in_place(chunk));
}

/// S = (H⁻¹)[W, W], dense and symmetric, grown a batch of vertices at a time.
struct InverseBlock {
    /// W: free-vertex indices, in the order they were added.
    vertices: Vec<usize>,
    /// Position in W of each free vertex, or `usize::MAX`.
    position: Vec<usize>,
    /// Column-major with leading dimension `stride`: S(i, k) = data[k * stride + i].
    data: Vec<f64>,
    stride: usize,
}

impl InverseBlock {
    fn new(free_count: usize) -> Self {
        InverseBlock {
            vertices: Vec::new(),
            position: vec![usize::MAX; free_count],
            data: Vec::new(),
            stride: 0,
        }
    }

    fn len(&self) -> usize {
        self.vertices.len()
    }

    fn column(&self, k: usize) -> &[f64] {
        &self.data[k * self.stride..k * self.stride + self.len()]
    }

    fn get(&self, i: usize, k: usize) -> f64 {
        self.data[k * self.stride + i]
    }

    /// Adds `batch` (free vertices not yet in W) with one batched solve for their columns.
    fn extend(&mut self, chol: &PatternCholesky, batch: &[usize]) {
        let n = chol.len();
        let old = self.len();
        let new = old + batch.len();
        if new > self.stride {
            let stride = new.max(2 * self.stride);
            let mut data = vec![0.0; stride * stride];
            for k in 0..old {
                data[k * stride..k * stride + old].copy_from_slice(self.column(k));
            }
            self.data = data;
            self.stride = stride;
        }
        for (k, &v) in batch.iter().enumerate() {
            self.position[v] = old + k;
            self.vertices.push(v);
        }
        let mut y = vec![0.0; n * batch.len()];
        for (k, &v) in batch.iter().enumerate() {
            y[k * n + v] = 1.0;
        }
        solve_columns(chol, &mut y);
        let stride = self.stride;
        for k in 0..batch.len() {
            let column = &y[k * n..(k + 1) * n];
            let c = old + k;
            for (i, &v) in self.vertices.iter().enumerate() {
                self.data[c * stride + i] = column[v];
            }
            // The old columns' new rows, by symmetry (each pair is computed once, so S stays
            // exactly symmetric).
            for i in 0..old {
                self.data[i * stride + c] = column[self.vertices[i]];
            }
        }
    }
}

/// One handle's dual active-set state over the part of W it watches.
struct HandleState {
    /// Unconstrained minimizer over the free vertices.
    x0: Vec<f64>,
    /// Current iterate over the free vertices: x₀ + H⁻¹ Σ sᵢuᵢeᵢ.
    x: Vec<f64>,
    /// The vertices whose bounds this handle checks in its dense steps (positions in W): the
    /// ones it found violated. Other handles' columns are shared but not scanned, which keeps
    /// each step at O(|watch| · |active|).
    watch: Vec<usize>,
    /// The free vertex of each watched position.
    watch_vertex: Vec<usize>,
    /// Per free vertex: whether it is in `watch` or `pending`.
    watched: Vec<bool>,
    /// Free vertices to add to `watch` once their columns exist.
    pending: Vec<usize>,
    /// The iterate at the watched vertices (watch order), updated by the dual steps.
    x_w: Vec<f64>,
    /// Active bounds: index in `watch`, sign (+1 lower bound x ≥ 0, −1 upper bound −x ≥ −1)
    /// and multiplier (≥ 0).
    active: Vec<usize>,
    sign: Vec<f64>,
    u: Vec<f64>,
    /// Whether each watched vertex is active.
    is_active: Vec<bool>,
    /// Cholesky factor of M = D S[A, A] D (D = diag(sign)), rows of the lower triangle.
    factor: Vec<Vec<f64>>,
    steps: usize,
    /// Whether the full iterate violates no bound.
    feasible: bool,
    failed: Option<DualActiveSetError>,
}

impl HandleState {
    fn new(x0: Vec<f64>, seed: Vec<usize>) -> Self {
        let mut watched = vec![false; x0.len()];
        for &v in &seed {
            watched[v] = true;
        }
        HandleState {
            x: x0.clone(),
            watched,
            x0,
            watch: Vec::new(),
            watch_vertex: Vec::new(),
            pending: seed,
            x_w: Vec::new(),
            active: Vec::new(),
            sign: Vec::new(),
            u: Vec::new(),
            is_active: Vec::new(),
            factor: Vec::new(),
            steps: 0,
            feasible: false,
            failed: None,
        }
    }

    fn working(&self) -> bool {
        !self.feasible && self.failed.is_none()
    }

    /// How far `x` lies outside [0, 1] (0 inside).
    fn violation(x: f64) -> f64 {
        (-x).max(x - 1.0).max(0.0)
    }

    /// Sets `pending` to up to `count` unwatched free vertices violating a bound by more than
    /// `tolerance`, most violated first (ties by index, for determinism), and `feasible` to
    /// whether nothing but active bounds is violated.
    fn find_candidates(&mut self, tolerance: f64, count: usize) {
        let mut violated: Vec<(f64, usize)> = Vec::new();
        let mut any = false;
        for (i, &xi) in self.x.iter().enumerate() {
            if Self::violation(xi) > tolerance {
                any = true;
                if !self.watched[i] {
                    violated.push((Self::violation(xi), i));
                }
            }
        }
        // Violated watched vertices that are active are at their bounds up to round-off.
        if any && violated.is_empty() && self.pending.is_empty() {
            any = self.active_free_violation(tolerance);
        }
        self.feasible = !any;
        violated.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        violated.truncate(count);
        for (_, i) in violated {
            self.watched[i] = true;
            self.pending.push(i);
        }
    }

    /// Whether some watched, inactive vertex violates a bound.
    fn active_free_violation(&self, tolerance: f64) -> bool {
        let mut active = vec![false; self.watch.len()];
        for &a in &self.active {
            active[a] = true;
        }
        (0..self.watch.len())
            .any(|i| !active[i] && Self::violation(self.x[self.vertex(i)]) > tolerance)
    }

    /// The free vertex of watch index `i`.
    fn vertex(&self, i: usize) -> usize {
        self.watch_vertex[i]
    }
    /// Watches the pending vertices (their columns are now in the block) and re-reads x at
    /// the watched vertices from the full iterate (the dual steps accumulate round-off).
    fn sync(&mut self, block: &InverseBlock) {
        for &v in &self.pending {
            self.watch.push(block.position[v]);
            self.watch_vertex.push(v);
        }
        self.pending.clear();
        self.x_w = self.watch_vertex.iter().map(|&v| self.x[v]).collect();
        self.is_active.resize(self.watch.len(), false);
        for (k, &a) in self.active.iter().enumerate() {
            self.x_w[a] = if self.sign[k] > 0.0 { 0.0 } else { 1.0 };
        }
    }

    /// Rebuilds the Cholesky factor of D S[A, A] D from scratch (after a bound is dropped).
    fn refactor(&mut self, block: &InverseBlock, dependence: f64) -> Result<(), DualActiveSetError> {
        self.factor.clear();
        for k in 0..self.active.len() {
            let m: Vec<f64> = (0..k)
                .map(|j| {
                    self.sign[j] * self.sign[k] * block.get(self.watch[self.active[j]], self.watch[self.active[k]])
                })
                .collect();
            let l = self.forward(&m);
            let diagonal = block.get(self.watch[self.active[k]], self.watch[self.active[k]]);
            let d2 = diagonal - l.iter().map(|v| v * v).sum::<f64>();
            if d2 <= dependence * diagonal {
                return Err(DualActiveSetError::Dependent);
            }
            let mut row = l;
            row.push(d2.sqrt());
            self.factor.push(row);
        }
        Ok(())
    }

    /// Solves L y = m (L = `factor`, lower triangular, k × k with k = m.len()).
    fn forward(&self, m: &[f64]) -> Vec<f64> {
        let mut y = m.to_vec();
        for i in 0..y.len() {
            let row = &self.factor[i];
            let s: f64 = row[..i].iter().zip(&y[..i]).map(|(a, b)| a * b).sum();
            y[i] = (y[i] - s) / row[i];
        }
        y
    }

    /// Solves Lᵀ r = y in place.
    fn backward(&self, r: &mut [f64]) {
        for i in (0..r.len()).rev() {
            let row = &self.factor[i];
            r[i] /= row[i];
            let ri = r[i];
            for (rj, &l) in r[..i].iter_mut().zip(&row[..i]) {
                *rj -= l * ri;
            }
        }
    }

    /// Goldfarb–Idnani on W: adds violated bounds (most violated first) until x_w is feasible.
    fn solve_on_block(
        &mut self,
        block: &InverseBlock,
        options: &DualActiveSetOptions,
    ) -> Result<(), DualActiveSetError> {
        let mut z = vec![0.0; self.watch.len()];
        loop {
            // The most violated bound at W (ties by position, for determinism).
            let mut worst = (options.feasibility_tolerance, usize::MAX);
            let mut best = 0.0;
            let steepest = std::env::var("SINEW_DAS_STEEP").is_ok();
            for (p, &xp) in self.x_w.iter().enumerate() {
                let v = Self::violation(xp);
                if v > options.feasibility_tolerance && !self.is_active[p] {
                    let score = if steepest { v * v / block.get(self.watch[p], self.watch[p]) } else { v };
                    if score > best {
                        best = score;
                        worst = (v, p);
                    }
                }
            }
            let p = worst.1;
            if p == usize::MAX {
                return Ok(());
            }
            // The bound as nᵀx ≥ b with n = s·e_p: x ≥ 0 (s = +1, b = 0) or −x ≥ −1.
            let (s_p, b_p) = if self.x_w[p] < 0.0 {
                (1.0, 0.0)
            } else {
                (-1.0, -1.0)
            };
            let mut u_p = 0.0;
            loop {
                self.steps += 1;
                if self.steps > options.max_steps {
                    return Err(DualActiveSetError::TooManySteps);
                }
                // m = D S[A, p] s_p; l = L⁻¹ m; the Schur complement d² = S_pp − lᵀl is
                // nᵀz, the constraint's curvature along the step direction.
                let m: Vec<f64> = self
                    .active
                    .iter()
                    .zip(&self.sign)
                    .map(|(&a, &s)| s * s_p * block.get(self.watch[a], self.watch[p]))
                    .collect();
                let l = self.forward(&m);
                let diagonal = block.get(self.watch[p], self.watch[p]);
                let d2 = diagonal - l.iter().map(|v| v * v).sum::<f64>();
                if d2 <= options.dependence_tolerance * diagonal {
                    return Err(DualActiveSetError::Dependent);
                }
                // r = M⁻¹ m: how the active multipliers change per unit of u_p.
                let mut r = l.clone();
                self.backward(&mut r);
                // z = H⁻¹(n_p − N_A r) at W: the primal step per unit of u_p.
                let column = block.column(self.watch[p]);
                for (zi, &i) in z.iter_mut().zip(&self.watch) {
                    *zi = s_p * column[i];
                }
                for (k, &a) in self.active.iter().enumerate() {
                    let c = self.sign[k] * r[k];
                    let column = block.column(self.watch[a]);
                    for (zi, &i) in z.iter_mut().zip(&self.watch) {
                        *zi -= c * column[i];
                    }
                }
                let full_step = (b_p - s_p * self.x_w[p]) / d2;
                // The first active multiplier to reach zero blocks the step.
                let mut partial = (f64::INFINITY, usize::MAX);
                for (k, (&rk, &uk)) in r.iter().zip(&self.u).enumerate() {
                    if rk > 0.0 && uk / rk < partial.0 {
                        partial = (uk / rk, k);
                    }
                }
                let t = full_step.min(partial.0);
                for (xi, &zi) in self.x_w.iter_mut().zip(&z) {
                    *xi += t * zi;
                }
                for (uk, &rk) in self.u.iter_mut().zip(&r) {
                    *uk -= t * rk;
                }
                u_p += t;
                if partial.0 < full_step {
                    // Drop the blocking bound and try again with the smaller active set.
                    let k = partial.1;
                    self.is_active[self.active[k]] = false;
                    self.active.remove(k);
                    self.sign.remove(k);
                    self.u.remove(k);
                    self.refactor(block, options.dependence_tolerance)?;
                } else {
                    self.x_w[p] = b_p * s_p;
                    for (k, &a) in self.active.iter().enumerate() {
                        self.x_w[a] = if self.sign[k] > 0.0 { 0.0 } else { 1.0 };
                    }
                    self.active.push(p);
                    self.sign.push(s_p);
                    self.u.push(u_p);
                    self.is_active[p] = true;
                    let mut row = l;
                    row.push(d2.sqrt());
                    self.factor.push(row);
                    break;
                }
            }
        }
    }

    /// The active bounds' forces Σ sᵢuᵢeᵢ as a full-length right-hand side.
    fn forces(&self, out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
        for (k, &a) in self.active.iter().enumerate() {
            out[self.watch_vertex[a]] = self.sign[k] * self.u[k];
        }
    }
}

/// Solves min ½ xᵀHx + gᵀx, 0 ≤ x ≤ 1 for every handle's unconstrained minimizer in `x0`
/// (each of length `chol.len()`), H factored in `chol`. Handles solve in parallel; columns of
/// H⁻¹ are shared between them.
pub fn solve_box_qps(
    chol: &PatternCholesky,
    x0: Vec<Vec<f64>>,
    seeds: Vec<Vec<usize>>,
    options: &DualActiveSetOptions,
) -> (Vec<Result<BoxSolution, DualActiveSetError>>, DualActiveSetStats) {
    let n = chol.len();
    let mut block = InverseBlock::new(n);
    let mut states: Vec<HandleState> = x0
        .into_iter()
        .zip(seeds)
        .map(|(x0, seed)| HandleState::new(x0, seed))
        .collect();
    let mut stats = DualActiveSetStats::default();
    loop {
        // New vertices for W: the most violated outside it, per handle.
        let mut batch: Vec<usize> = Vec::new();
        let mut in_batch = vec![false; n];
        for state in states.iter_mut().filter(|s| s.working()) {
            state.find_candidates(options.feasibility_tolerance, options.columns_per_round);
            for &v in &state.pending {
                if block.position[v] == usize::MAX && !in_batch[v] {
                    in_batch[v] = true;
                    batch.push(v);
                }
            }
        }
        if states.iter().all(|s| !s.working()) {
            break;
        }
        let error = if stats.rounds >= options.max_rounds {
            Some(DualActiveSetError::TooManyRounds)
        } else if block.len() + batch.len() > options.max_columns {
            Some(DualActiveSetError::TooManyColumns)
        } else {
            None
        };
        if let Some(e) = error {
            for s in states.iter_mut().filter(|s| s.working()) {
                s.failed = Some(e);
            }
            break;
        }
        stats.rounds += 1;
        if std::env::var("SINEW_DAS_DEBUG").is_ok() {
            let info: Vec<String> = states.iter().map(|s| {
                let out = s.x.iter().enumerate().filter(|&(i, &x)| HandleState::violation(x) > options.feasibility_tolerance && !s.watched[i]).count();
                let worst = s.x.iter().map(|&x| HandleState::violation(x)).fold(0.0, f64::max);
                format!("{}:{}/{}/{:.1e}", if s.working() {"w"} else {"-"}, s.active.len(), out, worst)
            }).collect();
            eprintln!("round {} W {} batch {} | {}", stats.rounds, block.len(), batch.len(), info.join(" "));
        }
        batch.sort_unstable();
        block.extend(chol, &batch);
        states.par_iter_mut().filter(|s| s.working()).for_each(|s| {
            s.sync(&block);
            if let Err(e) = s.solve_on_block(&block, options) {
                s.failed = Some(e);
            }
        });
        // Full iterates: x = x₀ + H⁻¹ (forces of the active bounds), one batched solve.
        let updating: Vec<usize> = (0..states.len()).filter(|&j| states[j].working()).collect();
        let mut rhs = vec![0.0; n * updating.len()];
        for (c, &j) in updating.iter().enumerate() {
            states[j].forces(&mut rhs[c * n..(c + 1) * n]);
        }
        solve_columns(chol, &mut rhs);
        for (c, &j) in updating.iter().enumerate() {
            let s = &mut states[j];
            for ((xi, &x0i), &yi) in s.x.iter_mut().zip(&s.x0).zip(&rhs[c * n..(c + 1) * n]) {
                *xi = x0i + yi;
            }
        }
    }
    stats.columns = block.len();
    let results = states
        .into_iter()
        .map(|s| {
            if let Some(e) = s.failed {
                return Err(e);
            }
            let mut x = s.x;
            for v in &mut x {
                *v = v.clamp(0.0, 1.0);
            }
            for (k, &a) in s.active.iter().enumerate() {
                x[s.watch_vertex[a]] = if s.sign[k] > 0.0 { 0.0 } else { 1.0 };
            }
            Ok(BoxSolution {
                x,
                steps: s.steps,
                active: s.active.len(),
            })
        })
        .collect();
    (results, stats)
}
