//! Skinning IK: precomputation and per-frame solves on a 10k-vertex mesh with 20 handles.
//!
//! The mesh is a 100 × 100 vertex grid over 400 × 400 px (19 602 triangles); the 20 point
//! handles sit on a 5 × 4 lattice inside it, every handle free (affine). Weights are dense (every
//! handle positive at every vertex, like bounded biharmonic weights): normalized Gaussians of
//! the distance to each handle (σ = 60 px), built outside the timing. What is timed:
//!
//! - `ik/precompute/10kx20/{1thread,2threads}`: `FastIk::precompute` (weight-space k-means,
//!   the reduced matrices A, B and G, the fold guard's choice of triangles). Target < 100 ms.
//! - `ik/factor/10kx20`: the first solve of a new constraint structure (two pins and one drag):
//!   the KKT null-space factorization plus one warm solve.
//! - `ik/solve/10kx20`: one warm-started solve (8 local/global iterations at most, then the
//!   fold guard's orientation check of 4096 blended triangles and one per handle) while the
//!   drag target moves, as in the editor. Target < 0.3 ms on one core.
//!
//! On the bundled character (18 bones kept rigid, the default, and one point; about 2,900
//! vertices), two feet pinned and the hand dragged:
//!
//! - `ik/character/cold`: `RigIk::solve_pose`, the answer of record for a static pose or an
//!   animation frame: the relaxed affine solve that starts it, then the rigid iterations from
//!   there (up to 64 of each).
//! - `ik/character/warm`: one warm-started solve while the hand's target circles, as in the
//!   editor. Target < 0.3 ms on one core.
//!
//! The solves run on one thread; the precomputation once in a one-thread rayon pool and once in
//! the default pool. `cargo bench --bench ik`

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, Criterion};
use sinew::geom::Point;
use sinew::ik::fast::DragRow;
use sinew::ik::subspace::skinning_row;
use sinew::ik::{ColumnDofs, FastIk, IkOptions, Problem, SkinnedMesh};
use sinew::rig::pose::Affine;
use std::hint::black_box;

const SIDE: usize = 100;
const HANDLES: usize = 20;
const SIZE_PX: f64 = 400.0;
const SIGMA_PX: f64 = 60.0;

fn grid() -> SkinnedMesh {
    let step = SIZE_PX / (SIDE - 1) as f64;
    let rest: Vec<Point> = (0..SIDE * SIDE)
        .map(|k| Point::new((k % SIDE) as f64 * step, (k / SIDE) as f64 * step))
        .collect();
    let mut triangles = Vec::new();
    for y in 0..SIDE - 1 {
        for x in 0..SIDE - 1 {
            let v = (y * SIDE + x) as u32;
            let s = SIDE as u32;
            triangles.push([v, v + 1, v + s + 1]);
            triangles.push([v, v + s + 1, v + s]);
        }
    }
    let handles: Vec<Point> = (0..HANDLES)
        .map(|j| Point::new(50.0 + 75.0 * (j % 5) as f64, 50.0 + 100.0 * (j / 5) as f64))
        .collect();
    let weights = rest
        .iter()
        .map(|p| {
            let raw: Vec<f64> = handles
                .iter()
                .map(|h| (-(p - h).norm_squared() / (2.0 * SIGMA_PX * SIGMA_PX)).exp() + 1e-6)
                .collect();
            let sum: f64 = raw.iter().sum();
            raw.iter()
                .enumerate()
                .map(|(j, w)| (j as u32, w / sum))
                .collect()
        })
        .collect();
    SkinnedMesh {
        rest,
        triangles,
        weights,
    }
}

fn problem(mesh: &SkinnedMesh, drag_to: [f64; 2]) -> Problem {
    let row = |k: usize| {
        let mut r = vec![0.0; 3 * HANDLES];
        skinning_row(mesh.rest[k], &mesh.weights[k], &mut r);
        r
    };
    let pin = |k: usize| DragRow {
        row: row(k),
        target: mesh.rest[k],
        weight: None,
    };
    Problem {
        columns: vec![ColumnDofs::Affine { rigidity: 0.0 }; HANDLES],
        joints: Vec::new(),
        drags: vec![
            pin(SIDE * (SIDE - 1)),
            pin(SIDE * SIDE - 1),
            DragRow {
                row: row(SIDE / 2),
                target: sinew::geom::Point::new(drag_to[0], drag_to[1]),
                weight: None,
            },
        ],
        anchor: vec![Affine::identity(); HANDLES],
        inertia: Vec::new(),
    }
}

fn bench(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool");
    let mesh = grid();
    let meshes = std::slice::from_ref(&mesh);
    let options = IkOptions::default();
    c.bench_function("ik/precompute/10kx20", |b| {
        b.iter(|| {
            pool.install(|| {
                FastIk::precompute(black_box(meshes), HANDLES, options.clone()).expect("precompute")
            })
        })
    });
    {
        let solver = FastIk::precompute(meshes, HANDLES, options.clone()).expect("precompute");
        let start = mesh.rest[SIDE / 2];
        c.bench_function("ik/factor/10kx20", |b| {
            b.iter(|| {
                let mut fresh = solver.clone();
                fresh
                    .solve(black_box(&problem(&mesh, [start.x + 30.0, start.y - 40.0])))
                    .expect("solves")
            })
        });
        let mut warm = solver.clone();
        warm.solve(&problem(&mesh, [start.x, start.y]))
            .expect("solves");
        // The drag target circles, as a hand on the mouse would move it.
        let targets: Vec<Problem> = (0..64)
            .map(|k| {
                let angle = k as f64 * std::f64::consts::TAU / 64.0;
                problem(
                    &mesh,
                    [start.x + 60.0 * angle.cos(), start.y + 60.0 * angle.sin()],
                )
            })
            .collect();
        let mut k = 0;
        c.bench_function("ik/solve/10kx20", |b| {
            b.iter(|| {
                k = (k + 1) % targets.len();
                warm.solve(black_box(&targets[k])).expect("solves")
            })
        });
    }
}

fn character(c: &mut Criterion) {
    use sinew::rig::pose::IkDrag;
    use sinew::rig::Pose;
    let scene = common::character_scene();
    let mut ik = scene.rig_ik().expect("the character's IK");
    let pose = |to: Point| Pose {
        ik: vec![
            IkDrag {
                at: Point::new(305.0, 440.0),
                to: Point::new(305.0, 440.0),
                weight: None,
            },
            IkDrag {
                at: Point::new(207.0, 440.0),
                to: Point::new(207.0, 440.0),
                weight: None,
            },
            IkDrag {
                at: Point::new(160.0, 330.0),
                to,
                weight: None,
            },
        ],
        ..Pose::default()
    };
    let lift = pose(Point::new(140.0, 250.0));
    c.bench_function("ik/character/cold", |b| {
        b.iter(|| ik.solve_pose(black_box(&lift)).expect("solves"))
    });
    let targets: Vec<Pose> = (0..64)
        .map(|k| {
            let angle = k as f64 * std::f64::consts::TAU / 64.0;
            pose(Point::new(
                150.0 + 30.0 * angle.cos(),
                280.0 + 30.0 * angle.sin(),
            ))
        })
        .collect();
    ik.transforms(&targets[0]).expect("solves");
    let mut k = 0;
    c.bench_function("ik/character/warm", |b| {
        b.iter(|| {
            k = (k + 1) % targets.len();
            ik.transforms(black_box(&targets[k])).expect("solves")
        })
    });
}

criterion_group!(benches, bench, character);
criterion_main!(benches);
