//! Skinning-weight solves on sprite meshes of about 1k, 5k and 20k vertices (50k with
//! `SINEW_BENCH_LARGE=1`) with 4, 10 and 20 point handles.
//!
//! The meshes come from the generated `critter` sprite (`tests/common`) at 512²: its largest piece
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
//! BBW 5k×10 < 0.1 s, 20k×10 < 1 s, 50k×10 < 3 s.
//!
//! `cargo bench --bench weights`; one case: `cargo bench --bench weights -- 'bbw/5kx10$'`;
//! with 50k: `SINEW_BENCH_LARGE=1 cargo bench --bench weights`.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use sinew::geom::ring_signed_area;
use sinew::mesh::{triangulate, Mesh, MeshOptions};
use sinew::trace::{trace, Outline, TraceOptions};
use sinew::weights::{
    biharmonic_weights, bounded_biharmonic_weights, harmonic_weights, BbwOptions, BbwReport,
    BoundaryConditions, Domain,
};
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Cases predicted to take longer than this per call are skipped (`SINEW_BENCH_SKIP_ABOVE_SECS`
/// overrides it).
const SKIP_ABOVE_SECS: f64 = 20.0;
/// The sprite's canvas side, px.
const SPRITE_SIZE: u32 = 512;
const HANDLE_COUNTS: [usize; 3] = [4, 10, 20];

#[derive(Clone, Copy, Debug, PartialEq)]
enum Method {
    Bbw,
    Biharmonic,
    Harmonic,
}

impl Method {
    const ALL: [Method; 3] = [Method::Bbw, Method::Biharmonic, Method::Harmonic];

    fn name(self) -> &'static str {
        match self {
            Method::Bbw => "bbw",
            Method::Biharmonic => "biharmonic",
            Method::Harmonic => "harmonic",
        }
    }

    /// One solve; the BBW report for `Bbw`.
    fn run(self, domain: &Domain, bc: &BoundaryConditions) -> Option<BbwReport> {
        match self {
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

/// The critter's largest outline (everything but the separate blob).
fn main_outline() -> Outline {
    let image = common::critter(SPRITE_SIZE);
    // Coarse tracing (2 px simplification): with the default 0.5 px, refinement around the thin
    // antenna alone gives some 1.4k vertices at any area limit, too many for the 1k case.
    let outlines = trace(&image, &TraceOptions::coarse()).expect("trace");
    outlines
        .into_iter()
        .max_by(|a, b| ring_signed_area(&a.outer).total_cmp(&ring_signed_area(&b.outer)))
        .expect("an outline")
}

/// Triangulates `outline` with `max_area_fraction` searched to give about `target` vertices.
fn mesh_near(outline: &Outline, target: usize) -> (Mesh, f64) {
    let canvas = (SPRITE_SIZE * SPRITE_SIZE) as f64;
    let outline_points = outline.outer.len() + outline.holes.iter().map(Vec::len).sum::<usize>();
    let mesh_with = |fraction: f64| {
        let options = MeshOptions {
            max_area_fraction: fraction,
            ..MeshOptions::default()
        };
        triangulate(std::slice::from_ref(outline), canvas, &options).expect("triangulate")
    };
    // Interior vertices grow about as 1 / fraction: rescale the fraction by the ratio of
    // interior counts until within 2%.
    let mut fraction = MeshOptions::default().max_area_fraction;
    let mut best: Option<(Mesh, f64)> = None;
    for _ in 0..12 {
        let mesh = mesh_with(fraction);
        let n = mesh.vertices.len();
        let error = |m: &Mesh| (m.vertices.len() as f64 / target as f64 - 1.0).abs();
        if best.as_ref().is_none_or(|(b, _)| error(&mesh) < error(b)) {
            best = Some((mesh, fraction));
        }
        if (n as f64 / target as f64 - 1.0).abs() <= 0.02 {
            break;
        }
        let have = n.saturating_sub(outline_points).max(1) as f64;
        let want = target.saturating_sub(outline_points).max(1) as f64;
        fraction *= have / want;
    }
    best.expect("a mesh")
}

/// `count` vertices by farthest-point sampling, from the vertex farthest from the centroid.
fn farthest_points(mesh: &Mesh, count: usize) -> Vec<usize> {
    let v = &mesh.vertices;
    let n = v.len() as f64;
    let (cx, cy) = v
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p.x / n, y + p.y / n));
    let farthest = |d: &[f64]| {
        (0..d.len())
            .max_by(|&a, &b| d[a].total_cmp(&d[b]).then(b.cmp(&a)))
            .unwrap()
    };
    let d_centroid: Vec<f64> = v.iter().map(|p| (p.x - cx).hypot(p.y - cy)).collect();
    let mut chosen = vec![farthest(&d_centroid)];
    let mut d: Vec<f64> = vec![f64::INFINITY; v.len()];
    while chosen.len() < count {
        let last = v[*chosen.last().unwrap()];
        for (di, p) in d.iter_mut().zip(v) {
            *di = di.min((p - last).norm());
        }
        chosen.push(farthest(&d));
    }
    chosen
}

fn boundary_conditions(handles: &[usize]) -> BoundaryConditions {
    let mut bc = BoundaryConditions {
        handle_count: handles.len(),
        ..Default::default()
    };
    for (j, &v) in handles.iter().enumerate() {
        bc.fix_to_handle(v, j);
    }
    bc
}

struct Case {
    label: &'static str,
    mesh: Mesh,
    domain: Domain,
}

fn secs(d: Duration) -> f64 {
    d.as_secs_f64()
}

fn time_once(method: Method, domain: &Domain, bc: &BoundaryConditions) -> (f64, Option<BbwReport>) {
    let start = Instant::now();
    let report = method.run(domain, bc);
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
            let points: Vec<[f64; 2]> = mesh.vertices.iter().map(|p| [p.x, p.y]).collect();
            let domain = Domain::new(&points, &mesh.triangles);
            println!(
                "mesh {label}: {} vertices, {} triangles (max_area_fraction {fraction:.3e}, {SPRITE_SIZE}² canvas)",
                mesh.vertices.len(),
                mesh.triangles.len()
            );
            Case {
                label,
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
    let mut pilot = vec![[[0.0; HANDLE_COUNTS.len()]; 3]; pilot_cases];
    for (ci, case) in cases.iter().take(pilot_cases).enumerate() {
        for (hi, &h) in HANDLE_COUNTS.iter().enumerate() {
            let bc = boundary_conditions(&farthest_points(&case.mesh, h));
            let mut report = BbwReport::default();
            for (mi, &m) in Method::ALL.iter().enumerate() {
                let (t, r) = time_once(m, &case.domain, &bc);
                pilot[ci][hi][mi] = t;
                if let Some(r) = r {
                    report = r;
                }
            }
            println!(
                "pilot {}x{h}: bbw {:.3} s (interior-point iterations per handle {:?}{}), biharmonic {:.3} s, harmonic {:.3} s",
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
                let bc = boundary_conditions(&farthest_points(&case.mesh, h));
                let mut group = c.benchmark_group(method.name());
                group.sample_size(10);
                // Calls take milliseconds to seconds: one call per iteration count step.
                group.sampling_mode(SamplingMode::Flat);
                group.bench_function(&id, |b| b.iter(|| method.run(&case.domain, &bc)));
                group.finish();
            }
        }
    }
}

criterion_group!(benches, weights);
criterion_main!(benches);
