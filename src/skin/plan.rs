//! Packed linear blend skinning: lay a mesh's weights out once, skin it every frame.
//!
//! In: rest positions (canvas px), [`SkinWeights`] and a cap on influences per vertex
//! ([`LbsPlan::precompute`]); then per frame one [`Affine`] per handle (rest canvas → posed
//! canvas). Out: posed positions as interleaved `[x, y]` `f32` canvas px ([`LbsPlan::solve`]).
//!
//! The plan is the per-frame cost cut to the bone: vertices in blocks of [`LANES`], each block
//! holding its rest x and y (f32), then for each of the plan's K influences the lanes' handle
//! ids (u16) and weights (f32), rows shorter than K padded with weight 0. That is 8 + 6K bytes
//! per vertex (32 at K = 4) instead of the compressed rows' 16 + 12K + 4. Each frame the
//! transforms become a small table of displacements (A − I, t) in f32; a vertex moves to
//! p + Σₖ wₖ ((A − I)ₖ p + tₖ), so identity transforms give back the (f32) rest positions bit
//! for bit and blending never subtracts two large, nearly equal numbers.
//!
//! On x86-64 with AVX-512 a block of 16 vertices is skinned in registers: the table is looked up
//! by in-register permutes (up to 128 handles; gathers, which are slow on many CPUs, only past
//! that), so the kernel runs at about the speed memory feeds it its 40 bytes a vertex. Elsewhere
//! a scalar loop does the same arithmetic in the same order (no fused multiply-add), so every
//! path, and every thread count, gives the same bits.

use super::SkinWeights;
use crate::geom::Point;
use crate::rig::pose::Affine;
use rayon::prelude::*;

/// Vertices per block: one 512-bit register of f32.
pub const LANES: usize = 16;

/// The largest influence cap a plan accepts; 2D rigs rarely need more than 4.
pub const MAX_PLAN_INFLUENCES: usize = 8;

/// Below this many vertices, threads cost more than they save.
const PARALLEL_MIN_VERTICES: usize = 8192;

/// Pieces per rayon thread: a second piece each lets a thread that another process slowed down
/// be helped, while few pieces keep rayon's per-piece cost small next to a ~0.1 ms frame.
const PIECES_PER_THREAD: usize = 2;

/// Handles per in-register table: two 512-bit registers of f32 per component.
const TABLE_CHUNK: usize = 32;

/// Up to this many table chunks, permutes beat gathers (4 chunks: 128 handles).
const MAX_PERMUTE_CHUNKS: usize = 4;

/// Displacement components per handle, in table order: (A − I) column by column, then t.
const COMPONENTS: usize = 6;

/// What a caller got wrong building or running a plan.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("max influences must be 1 to {MAX_PLAN_INFLUENCES}, got {0}")]
    InfluenceCap(usize),
    #[error("{rest} rest positions but weights for {weights} vertices")]
    VertexCount { rest: usize, weights: usize },
    #[error("skin weights are malformed: {0}")]
    MalformedWeights(&'static str),
    #[error("vertex {vertex}: rest position is not finite in f32")]
    NonFiniteRest { vertex: usize },
    #[error("vertex {vertex}: weight is not finite in f32")]
    NonFiniteWeight { vertex: usize },
    #[error("vertex {vertex}: handle {handle} is past the plan's limit of 65536 handles")]
    HandleIndex { vertex: usize, handle: u32 },
    #[error("the weights use {needed} handles but {given} transforms were given")]
    MissingTransforms { needed: usize, given: usize },
    #[error("handle {handle}: transform is not finite in f32")]
    NonFiniteTransform { handle: usize },
    #[error("output holds {got} positions, the plan skins {expected}")]
    OutputLength { expected: usize, got: usize },
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
struct LaneF32([f32; LANES]);

#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
struct LaneU16([u16; LANES]);

/// A mesh's weights and rest positions laid out for skinning every frame.
#[derive(Clone, Debug, PartialEq)]
pub struct LbsPlan {
    vertex_count: usize,
    /// K: influences stored per vertex.
    influences: usize,
    /// One past the largest handle id the weights use.
    handle_count: usize,
    /// Block b's rest x, canvas px.
    rest_x: Vec<LaneF32>,
    /// Block b's rest y, canvas px.
    rest_y: Vec<LaneF32>,
    /// Block b's influence k at `b * K + k`.
    handles: Vec<LaneU16>,
    weights: Vec<LaneF32>,
}

impl LbsPlan {
    /// Lays out `rest` and `weights` for [`LbsPlan::solve`], with at most `max_influences`
    /// (1 to [`MAX_PLAN_INFLUENCES`]) per vertex.
    ///
    /// A row with more influences keeps its largest weights (by magnitude; the earlier one on
    /// ties), scaled so that their sum is the row's sum: a motion shared by all handles is still
    /// reproduced. Rows keep their order otherwise.
    pub fn precompute(
        rest: &[Point],
        weights: &SkinWeights,
        max_influences: usize,
    ) -> Result<Self, PlanError> {
        if !(1..=MAX_PLAN_INFLUENCES).contains(&max_influences) {
            return Err(PlanError::InfluenceCap(max_influences));
        }
        Self::build(rest, weights, Some(max_influences))
    }

    /// Lays out `rest` and `weights` keeping every influence: the plan is as wide as the longest
    /// row, so it skins exactly what the rows say (in f32). This is what posing uses: a rig's
    /// rows are sparse (their influence limit is the document's choice, not the plan's).
    pub fn precompute_exact(rest: &[Point], weights: &SkinWeights) -> Result<Self, PlanError> {
        Self::build(rest, weights, None)
    }

    /// [`LbsPlan::precompute`] with an optional cap (none: as wide as the longest row).
    fn build(
        rest: &[Point],
        weights: &SkinWeights,
        max_influences: Option<usize>,
    ) -> Result<Self, PlanError> {
        check_structure(weights)?;
        if weights.vertex_count() != rest.len() {
            return Err(PlanError::VertexCount {
                rest: rest.len(),
                weights: weights.vertex_count(),
            });
        }
        let longest = (0..rest.len())
            .map(|i| (weights.offsets[i + 1] - weights.offsets[i]) as usize)
            .max()
            .unwrap_or(0);
        let influences = longest.clamp(1, max_influences.unwrap_or(longest.max(1)));
        let blocks = rest.len().div_ceil(LANES);
        let mut plan = LbsPlan {
            vertex_count: rest.len(),
            influences,
            handle_count: 0,
            rest_x: vec![LaneF32::default(); blocks],
            rest_y: vec![LaneF32::default(); blocks],
            handles: vec![LaneU16::default(); blocks * influences],
            weights: vec![LaneF32::default(); blocks * influences],
        };
        let mut row: Vec<(u16, f64)> = Vec::with_capacity(longest);
        for (vertex, p) in rest.iter().enumerate() {
            let (block, lane) = (vertex / LANES, vertex % LANES);
            let (x, y) = (p.x as f32, p.y as f32);
            if !(x.is_finite() && y.is_finite()) {
                return Err(PlanError::NonFiniteRest { vertex });
            }
            plan.rest_x[block].0[lane] = x;
            plan.rest_y[block].0[lane] = y;
            row.clear();
            for (handle, w) in weights.row(vertex) {
                if !w.is_finite() {
                    return Err(PlanError::NonFiniteWeight { vertex });
                }
                let id = u16::try_from(handle).map_err(|_| PlanError::HandleIndex {
                    vertex,
                    handle: handle as u32,
                })?;
                plan.handle_count = plan.handle_count.max(handle + 1);
                row.push((id, w));
            }
            keep_largest(&mut row, influences);
            for (k, &(id, w)) in row.iter().enumerate() {
                // Finite in f64 is not enough: the weight must fit f32, also after rescaling.
                let w = w as f32;
                if !w.is_finite() {
                    return Err(PlanError::NonFiniteWeight { vertex });
                }
                plan.handles[block * influences + k].0[lane] = id;
                plan.weights[block * influences + k].0[lane] = w;
            }
        }
        Ok(plan)
    }

    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Influences stored per vertex (the longest row, capped).
    pub fn influences(&self) -> usize {
        self.influences
    }

    /// How many transforms [`LbsPlan::solve`] needs: one past the largest handle id used.
    pub fn handle_count(&self) -> usize {
        self.handle_count
    }

    /// Rest positions as the plan holds them (f32 canvas px): what identity transforms return.
    pub fn rest_positions(&self) -> Vec<[f32; 2]> {
        (0..self.vertex_count)
            .map(|i| {
                let (b, l) = (i / LANES, i % LANES);
                [self.rest_x[b].0[l], self.rest_y[b].0[l]]
            })
            .collect()
    }

    /// Skins the plan's rest positions by `transforms` (at least [`LbsPlan::handle_count`];
    /// index = handle id) into `out` (one `[x, y]` per vertex, canvas px). Large meshes split
    /// across the current rayon pool; the result does not depend on its size.
    pub fn solve(&self, transforms: &[Affine], out: &mut [[f32; 2]]) -> Result<(), PlanError> {
        self.solve_on(transforms, out, Isa::detect())
    }

    fn solve_on(
        &self,
        transforms: &[Affine],
        out: &mut [[f32; 2]],
        isa: Isa,
    ) -> Result<(), PlanError> {
        if out.len() != self.vertex_count {
            return Err(PlanError::OutputLength {
                expected: self.vertex_count,
                got: out.len(),
            });
        }
        let table = DisplacementTable::new(transforms, self.handle_count)?;
        let threads = rayon::current_num_threads();
        if self.vertex_count < PARALLEL_MIN_VERTICES || threads == 1 {
            self.skin_blocks(&table, isa, 0, out);
            return Ok(());
        }
        let blocks = self.vertex_count.div_ceil(LANES);
        let piece_vertices = blocks.div_ceil(threads * PIECES_PER_THREAD) * LANES;
        out.par_chunks_mut(piece_vertices)
            .enumerate()
            .for_each(|(piece, part)| {
                self.skin_blocks(&table, isa, piece * piece_vertices / LANES, part)
            });
        Ok(())
    }

    /// Skins blocks `first_block..` into `out` (which starts at `first_block`'s first vertex).
    fn skin_blocks(
        &self,
        table: &DisplacementTable,
        isa: Isa,
        first_block: usize,
        out: &mut [[f32; 2]],
    ) {
        let full = out.len() / LANES;
        let (whole, tail) = out.split_at_mut(full * LANES);
        let kernel = |first: usize, dst: &mut [[f32; 2]]| match isa {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                // SAFETY: `Isa::Avx512` is only made after detecting avx512f at run time.
                unsafe { avx512::skin_blocks(self, table, first, dst) }
            }
            Isa::Scalar => scalar_blocks(self, table, first, dst),
        };
        kernel(first_block, whole);
        if !tail.is_empty() {
            // The last block's padding lanes are skinned too, into a scratch block.
            let mut scratch = [[0.0f32; 2]; LANES];
            kernel(first_block + full, &mut scratch);
            tail.copy_from_slice(&scratch[..tail.len()]);
        }
    }
}

/// Checks that the compressed rows are consistent, so that indexing them cannot panic.
fn check_structure(weights: &SkinWeights) -> Result<(), PlanError> {
    let SkinWeights {
        offsets,
        handles,
        weights,
    } = weights;
    if handles.len() != weights.len() {
        return Err(PlanError::MalformedWeights(
            "handle and weight lists differ in length",
        ));
    }
    if offsets.is_empty() {
        return if handles.is_empty() {
            Ok(())
        } else {
            Err(PlanError::MalformedWeights("offsets are missing"))
        };
    }
    if offsets[0] != 0 || offsets.windows(2).any(|w| w[0] > w[1]) {
        return Err(PlanError::MalformedWeights(
            "offsets must start at 0 and not decrease",
        ));
    }
    if offsets[offsets.len() - 1] as usize != handles.len() {
        return Err(PlanError::MalformedWeights(
            "the last offset must be the number of entries",
        ));
    }
    Ok(())
}

/// Keeps the `cap` largest-magnitude entries of `row` in their order, rescaled to the full sum.
fn keep_largest(row: &mut Vec<(u16, f64)>, cap: usize) {
    if row.len() <= cap {
        return;
    }
    let full_sum: f64 = row.iter().map(|&(_, w)| w).sum();
    let mut order: Vec<usize> = (0..row.len()).collect();
    // Stable: among equal magnitudes the earlier entry wins.
    order.sort_by(|&a, &b| row[b].1.abs().total_cmp(&row[a].1.abs()));
    order.truncate(cap);
    order.sort_unstable();
    let kept: Vec<(u16, f64)> = order.iter().map(|&i| row[i]).collect();
    let kept_sum: f64 = kept.iter().map(|&(_, w)| w).sum();
    let scale = if kept_sum != 0.0 {
        full_sum / kept_sum
    } else {
        1.0
    };
    row.clear();
    row.extend(kept.into_iter().map(|(h, w)| (h, w * scale)));
}

/// One frame's transforms as displacements in f32, component-major: `values[c * stride + h]`
/// with c = (A−I)₀₀, (A−I)₁₀, (A−I)₀₁, (A−I)₁₁, t_x, t_y. Padded with zeros to a whole number of
/// [`TABLE_CHUNK`]s so that in-register lookups never read past it.
struct DisplacementTable {
    stride: usize,
    values: Vec<f32>,
}

impl DisplacementTable {
    fn new(transforms: &[Affine], handle_count: usize) -> Result<Self, PlanError> {
        if transforms.len() < handle_count {
            return Err(PlanError::MissingTransforms {
                needed: handle_count,
                given: transforms.len(),
            });
        }
        let stride = handle_count.div_ceil(TABLE_CHUNK).max(1) * TABLE_CHUNK;
        let mut values = vec![0.0f32; COMPONENTS * stride];
        for (handle, t) in transforms[..handle_count].iter().enumerate() {
            let a = &t.linear;
            // The subtraction is done in f64: an identity entry becomes exactly 0.
            let components = [
                a[(0, 0)] - 1.0,
                a[(1, 0)],
                a[(0, 1)],
                a[(1, 1)] - 1.0,
                t.translation.x,
                t.translation.y,
            ];
            for (c, v) in components.into_iter().enumerate() {
                let v = v as f32;
                if !v.is_finite() {
                    return Err(PlanError::NonFiniteTransform { handle });
                }
                values[c * stride + handle] = v;
            }
        }
        Ok(DisplacementTable { stride, values })
    }

    fn component(&self, c: usize) -> &[f32] {
        &self.values[c * self.stride..(c + 1) * self.stride]
    }
}

/// Which kernel skins the blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Isa {
    #[cfg(target_arch = "x86_64")]
    Avx512,
    Scalar,
}

impl Isa {
    fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            return Isa::Avx512;
        }
        Isa::Scalar
    }
}

/// The portable kernel: per vertex, the same operations in the same order as the SIMD one.
fn scalar_blocks(
    plan: &LbsPlan,
    table: &DisplacementTable,
    first_block: usize,
    out: &mut [[f32; 2]],
) {
    let k = plan.influences;
    let [d00, d10, d01, d11, tx, ty] = std::array::from_fn(|c| table.component(c));
    let block_count = out.len() / LANES;
    let blocks = first_block..first_block + block_count;
    let handles = plan.handles[blocks.start * k..blocks.end * k].chunks_exact(k);
    let weights = plan.weights[blocks.start * k..blocks.end * k].chunks_exact(k);
    let rest = plan.rest_x[blocks.clone()].iter().zip(&plan.rest_y[blocks]);
    for (((dst, (xs, ys)), hs), ws) in out
        .chunks_exact_mut(LANES)
        .zip(rest)
        .zip(handles)
        .zip(weights)
    {
        for (lane, o) in dst.iter_mut().enumerate() {
            let (x, y) = (xs.0[lane], ys.0[lane]);
            let (mut dx, mut dy) = (0.0f32, 0.0f32);
            for (h, w) in hs.iter().zip(ws) {
                let (h, w) = (h.0[lane] as usize, w.0[lane]);
                dx += w * ((d00[h] * x + d01[h] * y) + tx[h]);
                dy += w * ((d10[h] * x + d11[h] * y) + ty[h]);
            }
            *o = [x + dx, y + dy];
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    //! The AVX-512 kernel: one block of 16 vertices per iteration, all in registers.

    use super::{DisplacementTable, LbsPlan, COMPONENTS, LANES, MAX_PERMUTE_CHUNKS, TABLE_CHUNK};
    use std::arch::x86_64::*;

    /// Skins `out.len() / LANES` whole blocks from `first_block` on.
    ///
    /// # Safety
    /// The CPU must support avx512f.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn skin_blocks(
        plan: &LbsPlan,
        table: &DisplacementTable,
        first_block: usize,
        out: &mut [[f32; 2]],
    ) {
        // Monomorphized per table size, so that the lookup's chunk loop unrolls.
        match table.stride / TABLE_CHUNK {
            1 => blocks::<1>(plan, table, first_block, out),
            2 => blocks::<2>(plan, table, first_block, out),
            3 => blocks::<3>(plan, table, first_block, out),
            4 => blocks::<4>(plan, table, first_block, out),
            _ => blocks::<0>(plan, table, first_block, out),
        }
    }

    /// `CHUNKS` = 1..=[`MAX_PERMUTE_CHUNKS`]: the table sits in registers and is looked up by
    /// permutes; 0: it is gathered from memory.
    #[target_feature(enable = "avx512f")]
    fn blocks<const CHUNKS: usize>(
        plan: &LbsPlan,
        table: &DisplacementTable,
        first_block: usize,
        out: &mut [[f32; 2]],
    ) {
        debug_assert!(CHUNKS <= MAX_PERMUTE_CHUNKS);
        debug_assert!(CHUNKS == 0 || CHUNKS * TABLE_CHUNK == table.stride);
        let k = plan.influences;
        // Registers per component: the low and high 16 entries of each chunk (4 chunks × 2 × 6
        // = 48 zmm at most; the compiler spills the rest to the stack, still cheaper than
        // gathering).
        let mut lo = [[_mm512_setzero_ps(); COMPONENTS]; MAX_PERMUTE_CHUNKS];
        let mut hi = [[_mm512_setzero_ps(); COMPONENTS]; MAX_PERMUTE_CHUNKS];
        for chunk in 0..CHUNKS {
            for c in 0..COMPONENTS {
                let entries = &table.component(c)[chunk * TABLE_CHUNK..][..TABLE_CHUNK];
                for (half, v) in entries.chunks_exact(LANES).zip([&mut lo, &mut hi]) {
                    // SAFETY: `half` is 16 readable f32, read unaligned.
                    v[chunk][c] = unsafe { _mm512_loadu_ps(half.as_ptr()) };
                }
            }
        }
        let lookup = |c: usize, h: __m512i| -> __m512 {
            if CHUNKS == 0 {
                // SAFETY: every handle id in the plan is < handle_count ≤ stride, so each lane
                // reads inside component c's slice.
                unsafe { _mm512_i32gather_ps::<4>(h, table.component(c).as_ptr()) }
            } else {
                // The permute uses an index's low 5 bits; the chunk is the bits above.
                let mut v = _mm512_permutex2var_ps(lo[0][c], h, hi[0][c]);
                for chunk in 1..CHUNKS {
                    let here = _mm512_cmpeq_epi32_mask(
                        _mm512_srli_epi32::<5>(h),
                        _mm512_set1_epi32(chunk as i32),
                    );
                    let from_chunk = _mm512_permutex2var_ps(lo[chunk][c], h, hi[chunk][c]);
                    v = _mm512_mask_mov_ps(v, here, from_chunk);
                }
                v
            }
        };
        // Output order: x0 y0 x1 y1 … from the x and y registers.
        let first_half = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
        let second_half =
            _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
        let block_count = out.len() / LANES;
        let blocks = first_block..first_block + block_count;
        let handles = plan.handles[blocks.start * k..blocks.end * k].chunks_exact(k);
        let weights = plan.weights[blocks.start * k..blocks.end * k].chunks_exact(k);
        let rest = plan.rest_x[blocks.clone()].iter().zip(&plan.rest_y[blocks]);
        for (((dst, (xs, ys)), hs), ws) in out
            .chunks_exact_mut(LANES)
            .zip(rest)
            .zip(handles)
            .zip(weights)
        {
            let x = load(&xs.0);
            let y = load(&ys.0);
            let mut dx = _mm512_setzero_ps();
            let mut dy = _mm512_setzero_ps();
            for (h, w) in hs.iter().zip(ws) {
                // SAFETY: a LaneU16 is 16 u16 = 32 bytes, read unaligned.
                let h = _mm512_cvtepu16_epi32(unsafe {
                    _mm256_loadu_si256(h.0.as_ptr().cast::<__m256i>())
                });
                let w = load(&w.0);
                let ex = _mm512_add_ps(
                    _mm512_add_ps(
                        _mm512_mul_ps(lookup(0, h), x),
                        _mm512_mul_ps(lookup(2, h), y),
                    ),
                    lookup(4, h),
                );
                let ey = _mm512_add_ps(
                    _mm512_add_ps(
                        _mm512_mul_ps(lookup(1, h), x),
                        _mm512_mul_ps(lookup(3, h), y),
                    ),
                    lookup(5, h),
                );
                dx = _mm512_add_ps(dx, _mm512_mul_ps(w, ex));
                dy = _mm512_add_ps(dy, _mm512_mul_ps(w, ey));
            }
            let px = _mm512_add_ps(x, dx);
            let py = _mm512_add_ps(y, dy);
            let dst = dst.as_flattened_mut();
            // SAFETY: `dst` is 16 [f32; 2] = 32 contiguous f32.
            unsafe {
                _mm512_storeu_ps(dst.as_mut_ptr(), _mm512_permutex2var_ps(px, first_half, py));
                _mm512_storeu_ps(
                    dst.as_mut_ptr().add(LANES),
                    _mm512_permutex2var_ps(px, second_half, py),
                );
            }
        }
    }

    /// One lane block of f32.
    #[target_feature(enable = "avx512f")]
    fn load(v: &[f32; LANES]) -> __m512 {
        // SAFETY: 16 readable f32, read unaligned.
        unsafe { _mm512_loadu_ps(v.as_ptr()) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vec2;
    use crate::rig::pose::rotation;
    use crate::skin::linear_blend;

    /// The plan against the f64 reference, in px: f32 carries about 7 significant digits, so
    /// positions of up to ~1000 px through a dozen roundings stay within 2e-3 px.
    const F32_TOLERANCE_PX: f64 = 2e-3;

    /// SplitMix64, so that inputs are the same on every run.
    struct Rng(u64);

    impl Rng {
        fn next_u64(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }

        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
        }

        fn below(&mut self, n: usize) -> usize {
            (self.next_u64() % n as u64) as usize
        }
    }

    /// `n` vertices on a 1024 px canvas, 1 to `max_row` distinct handles each out of `handles`,
    /// positive weights summing to one; and random rotations, scales and translations.
    fn case(
        seed: u64,
        n: usize,
        handles: usize,
        max_row: usize,
    ) -> (Vec<Point>, SkinWeights, Vec<Affine>) {
        let mut rng = Rng(seed);
        let rest: Vec<Point> = (0..n)
            .map(|_| Point::new(rng.range(0.0, 1024.0), rng.range(0.0, 1024.0)))
            .collect();
        let rows: Vec<Vec<(u32, f64)>> = (0..n)
            .map(|_| {
                let len = 1 + rng.below(max_row.min(handles));
                let mut row: Vec<(u32, f64)> = Vec::with_capacity(len);
                while row.len() < len {
                    let h = rng.below(handles) as u32;
                    if row.iter().all(|&(g, _)| g != h) {
                        row.push((h, rng.range(0.01, 1.0)));
                    }
                }
                let sum: f64 = row.iter().map(|&(_, w)| w).sum();
                row.iter().map(|&(h, w)| (h, w / sum)).collect()
            })
            .collect();
        let transforms = (0..handles)
            .map(|_| {
                let scale =
                    nalgebra::Matrix2::new(rng.range(0.8, 1.25), 0.0, 0.0, rng.range(0.8, 1.25));
                Affine {
                    linear: rotation(rng.range(-45.0, 45.0)) * scale,
                    translation: Vec2::new(rng.range(-50.0, 50.0), rng.range(-50.0, 50.0)),
                }
            })
            .collect();
        (rest, SkinWeights::from_rows(&rows), transforms)
    }

    fn bits(v: &[[f32; 2]]) -> Vec<u32> {
        v.iter().flatten().map(|x| x.to_bits()).collect()
    }

    #[test]
    fn plan_matches_the_f64_reference() {
        // 1003 vertices: the last block is partial. Rows of 1 to 4 influences.
        let (rest, weights, transforms) = case(7, 1003, 20, 4);
        let plan = LbsPlan::precompute(&rest, &weights, 4).unwrap();
        assert_eq!(plan.influences(), 4);
        assert_eq!(plan.handle_count(), 20);
        let mut expected = vec![Point::origin(); rest.len()];
        linear_blend(&rest, &weights, &transforms, &mut expected);
        let mut got = vec![[0.0f32; 2]; rest.len()];
        plan.solve(&transforms, &mut got).unwrap();
        let worst = expected
            .iter()
            .zip(&got)
            .map(|(e, g)| (e - Point::new(g[0] as f64, g[1] as f64)).norm())
            .fold(0.0, f64::max);
        assert!(worst < F32_TOLERANCE_PX, "worst error {worst} px");
    }

    #[test]
    fn an_exact_plan_keeps_rows_longer_than_any_cap() {
        // Rows of up to 12 influences, past MAX_PLAN_INFLUENCES: nothing is dropped.
        let (rest, weights, transforms) = case(13, 517, 30, 12);
        let plan = LbsPlan::precompute_exact(&rest, &weights).unwrap();
        assert!(
            plan.influences() > MAX_PLAN_INFLUENCES,
            "{}",
            plan.influences()
        );
        let mut expected = vec![Point::origin(); rest.len()];
        linear_blend(&rest, &weights, &transforms, &mut expected);
        let mut got = vec![[0.0f32; 2]; rest.len()];
        plan.solve(&transforms, &mut got).unwrap();
        let worst = expected
            .iter()
            .zip(&got)
            .map(|(e, g)| (e - Point::new(g[0] as f64, g[1] as f64)).norm())
            .fold(0.0, f64::max);
        assert!(worst < F32_TOLERANCE_PX, "worst error {worst} px");
        let capped = LbsPlan::precompute(&rest, &weights, MAX_PLAN_INFLUENCES).unwrap();
        let mut truncated = vec![[0.0f32; 2]; rest.len()];
        capped.solve(&transforms, &mut truncated).unwrap();
        assert!(bits(&truncated) != bits(&got), "the cap dropped nothing");
    }

    #[test]
    fn identity_transforms_return_the_rest_positions_exactly() {
        // Includes rows longer than the cap (truncated and rescaled).
        let (rest, weights, _) = case(11, 777, 9, 6);
        let plan = LbsPlan::precompute(&rest, &weights, 4).unwrap();
        let mut out = vec![[f32::NAN; 2]; rest.len()];
        plan.solve(&vec![Affine::identity(); 9], &mut out).unwrap();
        assert_eq!(bits(&out), bits(&plan.rest_positions()));
        for (p, o) in rest.iter().zip(&out) {
            assert_eq!(*o, [p.x as f32, p.y as f32]);
        }
    }

    #[test]
    fn every_thread_count_gives_the_same_bits() {
        // Enough vertices to split across threads.
        let (rest, weights, transforms) = case(3, 3 * PARALLEL_MIN_VERTICES + 5, 20, 4);
        let plan = LbsPlan::precompute(&rest, &weights, 4).unwrap();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut out = vec![[0.0f32; 2]; rest.len()];
            pool.install(|| plan.solve(&transforms, &mut out)).unwrap();
            bits(&out)
        };
        let one = run(1);
        for threads in [2, 3, 4] {
            assert!(run(threads) == one, "{threads} threads differ from one");
        }
    }

    #[test]
    fn simd_and_scalar_kernels_give_the_same_bits() {
        // 20 handles: one in-register table; 70: three chunks; 300: gathered. Without AVX-512
        // both runs take the scalar path.
        for handles in [20, 70, 300] {
            let (rest, weights, transforms) = case(handles as u64, 2000, handles, 5);
            let plan = LbsPlan::precompute(&rest, &weights, 5).unwrap();
            let mut detected = vec![[0.0f32; 2]; rest.len()];
            let mut scalar = vec![[0.0f32; 2]; rest.len()];
            plan.solve_on(&transforms, &mut detected, Isa::detect())
                .unwrap();
            plan.solve_on(&transforms, &mut scalar, Isa::Scalar)
                .unwrap();
            assert!(bits(&detected) == bits(&scalar), "{handles} handles");
        }
    }

    #[test]
    fn a_capped_row_keeps_its_largest_weights_and_still_moves_rigidly() {
        let rest = [Point::new(100.0, 50.0)];
        let row = vec![(0, 0.3), (1, 0.05), (2, 0.25), (3, 0.1), (4, 0.3)];
        let weights = SkinWeights::from_rows(&[row]);
        let plan = LbsPlan::precompute(&rest, &weights, 3).unwrap();
        assert_eq!(plan.influences(), 3);
        let lane = |k: usize| (plan.handles[k].0[0], plan.weights[k].0[0]);
        assert_eq!(lane(0).0, 0);
        assert_eq!(lane(1).0, 2);
        assert_eq!(lane(2).0, 4);
        let sum: f32 = (0..3).map(|k| lane(k).1).sum();
        assert!((sum - 1.0).abs() < 1e-6, "{sum}");
        let rigid = Affine {
            linear: rotation(30.0),
            translation: Vec2::new(4.0, -2.0),
        };
        let mut out = [[0.0f32; 2]];
        plan.solve(&[rigid; 5], &mut out).unwrap();
        let moved = rigid.apply(rest[0]);
        assert!((moved - Point::new(out[0][0] as f64, out[0][1] as f64)).norm() < 1e-3);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let (rest, weights, transforms) = case(5, 40, 6, 3);
        for cap in [0, MAX_PLAN_INFLUENCES + 1] {
            assert_eq!(
                LbsPlan::precompute(&rest, &weights, cap),
                Err(PlanError::InfluenceCap(cap))
            );
        }
        assert!(matches!(
            LbsPlan::precompute(&rest[1..], &weights, 4),
            Err(PlanError::VertexCount { .. })
        ));
        let mut broken = weights.clone();
        broken.offsets[3] = 1000;
        assert!(matches!(
            LbsPlan::precompute(&rest, &broken, 4),
            Err(PlanError::MalformedWeights(_))
        ));
        let far = SkinWeights::from_rows(&[vec![(70_000, 1.0)]]);
        assert!(matches!(
            LbsPlan::precompute(&rest[..1], &far, 4),
            Err(PlanError::HandleIndex { vertex: 0, .. })
        ));
        let huge = SkinWeights::from_rows(&[vec![(0, 1e300)]]);
        assert_eq!(
            LbsPlan::precompute(&rest[..1], &huge, 4),
            Err(PlanError::NonFiniteWeight { vertex: 0 })
        );
        let mut nan_rest = rest.clone();
        nan_rest[2].y = f64::NAN;
        assert_eq!(
            LbsPlan::precompute(&nan_rest, &weights, 4),
            Err(PlanError::NonFiniteRest { vertex: 2 })
        );

        let plan = LbsPlan::precompute(&rest, &weights, 4).unwrap();
        let mut out = vec![[0.0f32; 2]; rest.len()];
        assert!(matches!(
            plan.solve(&transforms[..2], &mut out),
            Err(PlanError::MissingTransforms { .. })
        ));
        assert!(matches!(
            plan.solve(&transforms, &mut out[1..]),
            Err(PlanError::OutputLength { .. })
        ));
        let mut huge = transforms.clone();
        huge[1].translation.x = 1e300;
        assert_eq!(
            plan.solve(&huge, &mut out),
            Err(PlanError::NonFiniteTransform { handle: 1 })
        );
    }
}
