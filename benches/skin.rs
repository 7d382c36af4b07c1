//! Linear blend skinning of 100k vertices with 4 influences each: the f64 compressed-row path
//! (`sinew::skin::linear_blend`) against the packed f32 plan (`sinew::skin::LbsPlan::solve`).
//!
//! Rest positions, weights (4 distinct handles per vertex out of 20, positive, summing to one) and
//! the 20 affine transforms (rotation, anisotropic scale, translation) are random from a fixed
//! seed, built once outside the timing; outputs are preallocated. Each path runs inside a rayon
//! pool of fixed size (`ThreadPoolBuilder`), 1 and 2 threads:
//!
//! - `lbs/100kx4/f64_csr_{1,2}thread`: the per-frame cost of `linear_blend` (f64 points).
//! - `lbs/100kx4/f32_plan_{1,2}thread`: the per-frame cost of `LbsPlan::solve` (f32 `[x, y]`),
//!   including turning the 20 transforms into its table.
//! - `lbs_plan_precompute/100kx4`: the one-off `LbsPlan::precompute`.
//!
//! Target (on the two-core reference machine): 100k×4 < 0.25 ms on two threads.
//!
//! `cargo bench --bench skin`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use sinew::geom::{Point, Vec2};
use sinew::rig::pose::{rotation, Affine};
use sinew::skin::{linear_blend, LbsPlan, SkinWeights};
use std::hint::black_box;

const VERTICES: usize = 100_000;
const INFLUENCES: usize = 4;
const HANDLES: u32 = 20;

/// SplitMix64: a small seeded generator, so the inputs are the same on every run.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    fn below(&mut self, n: u32) -> u32 {
        (self.next_u64() % n as u64) as u32
    }
}

fn inputs() -> (Vec<Point>, SkinWeights, Vec<Affine>) {
    let mut rng = Rng(0x5eed_1234_abcd_0042);
    let rest: Vec<Point> = (0..VERTICES)
        .map(|_| Point::new(rng.range(0.0, 1024.0), rng.range(0.0, 1024.0)))
        .collect();
    let rows: Vec<Vec<(u32, f64)>> = (0..VERTICES)
        .map(|_| {
            let mut handles: Vec<u32> = Vec::with_capacity(INFLUENCES);
            while handles.len() < INFLUENCES {
                let h = rng.below(HANDLES);
                if !handles.contains(&h) {
                    handles.push(h);
                }
            }
            handles.sort_unstable();
            let raw: Vec<f64> = (0..INFLUENCES).map(|_| rng.range(0.01, 1.0)).collect();
            let sum: f64 = raw.iter().sum();
            handles
                .into_iter()
                .zip(raw.iter().map(|w| w / sum))
                .collect()
        })
        .collect();
    let weights = SkinWeights::from_rows(&rows);
    let transforms: Vec<Affine> = (0..HANDLES)
        .map(|_| {
            let scale =
                nalgebra::Matrix2::new(rng.range(0.8, 1.25), 0.0, 0.0, rng.range(0.8, 1.25));
            Affine {
                linear: rotation(rng.range(-45.0, 45.0)) * scale,
                translation: Vec2::new(rng.range(-50.0, 50.0), rng.range(-50.0, 50.0)),
            }
        })
        .collect();
    (rest, weights, transforms)
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("rayon pool")
}

fn lbs(c: &mut Criterion) {
    let (rest, weights, transforms) = inputs();
    let plan = LbsPlan::precompute(&rest, &weights, INFLUENCES).expect("plan");
    let mut out_f64 = vec![Point::origin(); rest.len()];
    let mut out_f32 = vec![[0.0f32; 2]; rest.len()];
    let id = format!("{}kx{INFLUENCES}", VERTICES / 1000);
    let mut group = c.benchmark_group("lbs");
    group.throughput(Throughput::Elements(VERTICES as u64));
    for threads in [1, 2] {
        let pool = pool(threads);
        let suffix = if threads == 1 { "thread" } else { "threads" };
        group.bench_function(
            BenchmarkId::new(&id, format!("f64_csr_{threads}{suffix}")),
            |b| {
                pool.install(|| {
                    b.iter(|| linear_blend(black_box(&rest), &weights, &transforms, &mut out_f64))
                })
            },
        );
        group.bench_function(
            BenchmarkId::new(&id, format!("f32_plan_{threads}{suffix}")),
            |b| {
                pool.install(|| {
                    b.iter(|| {
                        black_box(&plan)
                            .solve(&transforms, &mut out_f32)
                            .expect("solve")
                    })
                })
            },
        );
    }
    group.finish();
    let mut group = c.benchmark_group("lbs_plan_precompute");
    group.sample_size(10);
    group.bench_function(&id, |b| {
        b.iter(|| LbsPlan::precompute(black_box(&rest), &weights, INFLUENCES).expect("plan"))
    });
    group.finish();
}

criterion_group!(benches, lbs);
criterion_main!(benches);
