//! Skinning-weight solves on sprite meshes of about 1k, 5k and 20k vertices (50k with
//! `SINEW_BENCH_LARGE=1`) with 4, 10 and 20 point handles.
//!
//! The meshes come from the generated `critter` sprite (`tests/common/sprite_meshes.rs`) at 512²: its largest piece
//! (body, head, ring-shaped handle with a hole, thin antenna: non-convex and not simply
//! connected), traced with `TraceOptions::coarse()` and triangulated with
//! `MeshOptions::max_area_fraction` searched at setup to hit each vertex count (the actual counts
//! are printed). Handles are point handles at vertices chosen by
//! farthest-point sampling (deterministic; the first handles of a larger set are the smaller set),
//! each fixing one vertex with `BoundaryConditions::fix_to_handle`.
//!
//! Groups, each `<verts>x<handles>` (e.g. `bbw/5kx10`):
//! - `bbw`: the whole `bounded_biharmonic_weights` call (bi-Laplacian assembly, the unconstrained
//!   warm start and the interior-point iterations), default `BbwOptions`.
//! - `two_level`: two-level bounded biharmonic weights with the default `TwoLevelOptions` (the
//!   coarse mesh of the same outline with the handles as vertices, about 500 vertices, built
//!   inside the timing; its exact solve; the carry; one solve per handle on the carried
//!   support, `sinew::weights::support`; rows normalized). Its quality against `bbw` is
//!   asserted in tests/two_level.rs on the same meshes.
//! - `biharmonic`: one unconstrained biharmonic solve on the same mesh, the floor under `bbw`.
//! - `harmonic`: one harmonic (Laplace) solve.
//!
//! The domain (cotangent stiffness, mass) is built once outside the timing. Before measuring, each
//! method and handle count is timed once at 1k and 5k (printed, with BBW's interior-point iterations
//! per handle; this pilot runs whatever the filter); larger cases whose time extrapolated from
//! those two (exponent measured between them, at least 1.5) exceeds 20 s per call are skipped
//! and reported as skipped rather than left to hang (`SINEW_BENCH_SKIP_ABOVE_SECS=<s>` changes
//! the limit). Sampling is flat with 10 samples: a case costs about 11 calls.
//!
//! Targets (on the two-core reference machine; solves run handles in parallel with rayon):
//! BBW 5k×10 < 0.1 s, 20k×10 < 1 s, 50k×10 < 3 s; two-level (issue 24) 5k×10 < 0.1 s,
//! 20k×10 < 0.4 s, 50k×10 < 1 s.
//!
//! `cargo bench --bench weights`; one case: `cargo bench --bench weights -- 'bbw/5kx10$'`;
//! with 50k: `SINEW_BENCH_LARGE=1 cargo bench --bench weights`.

#[path = "../tests/common/mod.rs"]
mod common;

use common::sprite_meshes::{
    farthest_points, main_outline, mesh_near, point_conditions, two_level, SPRITE_SIZE,
};
use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use sinew::mesh::Mesh;
use sinew::trace::Outline;
use sinew::weights::{
    biharmonic_weights, bounded_biharmonic_weights, harmonic_weights, BbwOptions, BbwReport,
    BoundaryConditions, Domain,
};
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Cases predicted to take longer than this per call are skipped (`SINEW_BENCH_SKIP_ABOVE_SECS`
/// overrides it).
const SKIP_ABOVE_SECS: f64 = 20.0;
const HANDLE_COUNTS: [usize; 3] = [4, 10, 20];

#[derive(Clone, Copy, Debug, PartialEq)]
enum Method {
    Bbw,
    TwoLevel,
    Biharmonic,
    Harmonic,
}

impl Method {
    const ALL: [Method; 4] = [
        Method::Bbw,
        Method::TwoLevel,
        Method::Biharmonic,
        Method::Harmonic,
    ];

    fn name(self) -> &'static str {
        match self {
            Method::Bbw => "bbw",
            Method::TwoLevel => "two_level",
            Method::Biharmonic => "biharmonic",
            Method::Harmonic => "harmonic",
        }
    }

    /// One solve; the BBW report for `Bbw`.
    fn run(self, case: &Case, handles: &[usize], bc: &BoundaryConditions) -> Option<BbwReport> {
        let domain = &case.domain;
        match self {
            Method::TwoLevel => {
                black_box(two_level(
                    &case.outline,
                    &case.mesh,
                    &case.domain,
                    handles,
                    bc,
                ));
                None
            }
            Method::Bbw => {
                let (w, report) = bounded_biharmonic_weights(domain, bc, &BbwOptions::default())
                    .expect("bbw solve");
                black_box(w);
                Some(report)
            }
            Method::Biharmonic => {
                black_box(biharmonic_weights(domain, bc).expect("biharmonic solve"));
                None
            }
            Method::Harmonic => {
                black_box(harmonic_weights(domain, bc).expect("harmonic solve"));
                None
            }
        }
    }
}

struct Case {
    label: &'static str,
    outline: Outline,
    mesh: Mesh,
    domain: Domain,
}

fn secs(d: Duration) -> f64 {
    d.as_secs_f64()
}

fn time_once(
    method: Method,
    case: &Case,
    handles: &[usize],
    bc: &BoundaryConditions,
) -> (f64, Option<BbwReport>) {
    let start = Instant::now();
    let report = method.run(case, handles, bc);
    (secs(start.elapsed()), report)
}

fn weights(c: &mut Criterion) {
    let mut targets: Vec<(&'static str, usize)> =
        vec![("1k", 1_000), ("5k", 5_000), ("20k", 20_000)];
    let large = std::env::var("SINEW_BENCH_LARGE").is_ok_and(|v| !v.is_empty() && v != "0");
    if large {
        targets.push(("50k", 50_000));
    }
    let skip_above = std::env::var("SINEW_BENCH_SKIP_ABOVE_SECS")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(SKIP_ABOVE_SECS);
    let outline = main_outline();
    let cases: Vec<Case> = targets
        .iter()
        .map(|&(label, target)| {
            let (mesh, fraction) = mesh_near(&outline, target);
            let domain = Domain::planar(&mesh.vertices, &mesh.triangles);
            println!(
                "mesh {label}: {} vertices, {} triangles (max_area_fraction {fraction:.3e}, {SPRITE_SIZE}² canvas)",
                mesh.vertices.len(),
                mesh.triangles.len()
            );
            Case {
                label,
                outline: outline.clone(),
                mesh,
                domain,
            }
        })
        .collect();
    if !large {
        println!("(50k meshes: set SINEW_BENCH_LARGE=1)");
    }

    // Pilot: one timed call per method and handle count at the two smallest sizes, to extrapolate
    // (with the exponent measured between them, at least 1.5) to the larger ones.
    let pilot_cases = 2.min(cases.len());
    let mut pilot = vec![[[0.0; Method::ALL.len()]; HANDLE_COUNTS.len()]; pilot_cases];
    for (ci, case) in cases.iter().take(pilot_cases).enumerate() {
        for (hi, &h) in HANDLE_COUNTS.iter().enumerate() {
            let handles = farthest_points(&case.mesh, h);
            let bc = point_conditions(&handles);
            let mut report = BbwReport::default();
            for (mi, &m) in Method::ALL.iter().enumerate() {
                let (t, r) = time_once(m, case, &handles, &bc);
                pilot[ci][hi][mi] = t;
                if let Some(r) = r {
                    report = r;
                }
            }
            println!(
                "pilot {}x{h}: bbw {:.3} s (interior-point iterations per handle {:?}{}), two-level {:.3} s, biharmonic {:.3} s, harmonic {:.3} s",
                case.label,
                pilot[ci][hi][0],
                report.iterations,
                if report.unconverged.is_empty() {
                    String::new()
                } else {
                    format!(", unconverged {:?}", report.unconverged)
                },
                pilot[ci][hi][1],
                pilot[ci][hi][2],
                pilot[ci][hi][3],
            );
        }
    }
    let predict = |ci: usize, hi: usize, mi: usize| -> f64 {
        if ci < pilot_cases {
            return pilot[ci][hi][mi];
        }
        let n = |i: usize| cases[i].mesh.vertices.len() as f64;
        let (t0, t1) = (pilot[0][hi][mi], pilot[pilot_cases - 1][hi][mi]);
        let exponent = if pilot_cases >= 2 && t0 > 0.0 && t1 > 0.0 {
            ((t1 / t0).ln() / (n(1) / n(0)).ln()).max(1.5)
        } else {
            1.5
        };
        t1 * (n(ci) / n(pilot_cases - 1)).powf(exponent)
    };

    for (mi, &method) in Method::ALL.iter().enumerate() {
        for (ci, case) in cases.iter().enumerate() {
            for (hi, &h) in HANDLE_COUNTS.iter().enumerate() {
                let id = format!("{}x{h}", case.label);
                let estimate = predict(ci, hi, mi);
                if estimate > skip_above {
                    println!(
                        "{}/{id}: skipped ({} vertices; about {estimate:.0} s per call expected, over {skip_above} s)",
                        method.name(),
                        case.mesh.vertices.len()
                    );
                    continue;
                }
                let handles = farthest_points(&case.mesh, h);
                let bc = point_conditions(&handles);
                let mut group = c.benchmark_group(method.name());
                group.sample_size(10);
                // Calls take milliseconds to seconds: one call per iteration count step.
                group.sampling_mode(SamplingMode::Flat);
                group.bench_function(&id, |b| b.iter(|| method.run(case, &handles, &bc)));
                group.finish();
            }
        }
    }
}

criterion_group!(benches, weights);
criterion_main!(benches);
