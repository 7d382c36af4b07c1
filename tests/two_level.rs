//! Two-level weights against the exact solve on the same meshes (issue: speed at production
//! sizes): the bundled character and the generated critter at about 5k and 20k vertices, with
//! bones and point handles. Per mesh: the largest weight difference, the ratio of the
//! bi-Laplacian energies (Σ_j w_jᵀ K M⁻¹ K w_j over the drawn mesh), bounds and partition of
//! unity, and both solves' times (printed, not asserted: speed lives in benches/weights.rs).
//! The two-level weights use the default [`TwoLevelOptions`]: a 500-vertex coarse mesh and
//! one solve per handle on the carried weights' support (`sinew::weights::support`).

mod common;

use sinew::geom::Point;
use sinew::io::{BuildOptions, RigDocument};
use sinew::pipeline::{self, Layer};
use sinew::rig::{Bone, Handles, PointHandle};
use sinew::weights::{Domain, TwoLevelOptions, WeightOptions};
use std::time::Instant;

/// The largest weight difference the issue asks for: met on the benchmark's meshes (point
/// handles on the outline, measured 0.009–0.010) and on the rigs with bones (measured 0.024
/// and 0.016 on the critter, 0.027 on the character, docs/two-level-weights.md).
const MAX_WEIGHT_DIFFERENCE: f64 = 0.03;
/// The benchmark meshes' figure with margin (measured 0.0093 and 0.0098).
const MAX_WEIGHT_DIFFERENCE_BENCHMARK: f64 = 0.015;
const MAX_ENERGY_RATIO: f64 = 1.05;
const EXACT: f64 = 1e-9;

fn character() -> (Vec<Layer>, Handles) {
    common::character_layers()
}

/// The critter at 512² with a spine of two bones and eight point handles.
fn critter(max_area_fraction: f64) -> (Vec<Layer>, Handles, BuildOptions) {
    let s = 2.0;
    let point = |name: &str, at: [f64; 2]| PointHandle {
        name: name.into(),
        at: Point::new(at[0] * s, at[1] * s),
        parent: None,
    };
    let bone = |name: &str, parent: Option<&str>, head: [f64; 2], tail: [f64; 2]| Bone {
        name: name.into(),
        parent: parent.map(Into::into),
        head: Point::new(head[0] * s, head[1] * s),
        tail: Point::new(tail[0] * s, tail[1] * s),
    };
    let handles = Handles {
        bones: vec![
            bone("hip", None, [128.0, 195.0], [128.0, 140.0]),
            bone("chest", Some("hip"), [128.0, 140.0], [128.0, 90.0]),
        ],
        points: vec![
            point("antenna", [145.6, 17.0]),
            point("ring", [205.0, 130.5]),
            point("blob", [40.0, 230.0]),
            point("cheek", [150.0, 72.0]),
            point("belly", [88.0, 175.0]),
            point("side", [170.0, 170.0]),
            point("chin", [128.0, 112.0]),
            point("foot", [128.0, 205.0]),
        ],
        ..Default::default()
    };
    let layers = vec![Layer::whole(
        "critter",
        std::env::temp_dir().join("critter.png"),
        common::critter(512),
    )];
    let mut options = BuildOptions::default();
    options.mesh.max_area_fraction = max_area_fraction;
    (layers, handles, options)
}

fn rig(layers: &[Layer], handles: &Handles, options: &BuildOptions) -> (RigDocument, f64) {
    let start = Instant::now();
    let (doc, reports) =
        pipeline::build_rig(layers, &std::env::temp_dir(), options, handles).unwrap();
    for r in &reports {
        if !r.unconverged.is_empty() {
            println!("unconverged: {:?}", r.unconverged);
        }
    }
    (doc, start.elapsed().as_secs_f64())
}

/// Per part: (vertex count, max |Δw|, energy ratio), after checking bounds and partition of
/// unity of the two-level weights.
fn compare(exact: &RigDocument, two: &RigDocument) -> Vec<(usize, f64, f64)> {
    exact
        .parts
        .iter()
        .zip(&two.parts)
        .map(|(e, t)| {
            assert_eq!(
                e.mesh.vertices, t.mesh.vertices,
                "the drawn mesh is the same"
            );
            let (we, wt) = (e.weights.as_ref().unwrap(), t.weights.as_ref().unwrap());
            let m = we.handles.len();
            let dense = |rows: &Vec<Vec<(u32, f64)>>| -> Vec<Vec<f64>> {
                rows.iter()
                    .map(|row| {
                        let mut d = vec![0.0; m];
                        for &(c, v) in row {
                            d[c as usize] = v;
                        }
                        d
                    })
                    .collect()
            };
            let (de, dt) = (dense(&we.rows), dense(&wt.rows));
            for row in &dt {
                assert!((row.iter().sum::<f64>() - 1.0).abs() < EXACT, "{row:?}");
                assert!(row.iter().all(|&w| (-EXACT..=1.0 + EXACT).contains(&w)));
            }
            // The largest difference and where it is (vertex, column).
            let (worst, at) = de
                .iter()
                .flatten()
                .zip(dt.iter().flatten())
                .map(|(a, b)| (a - b).abs())
                .enumerate()
                .fold(
                    (0.0, 0),
                    |(w, at), (k, d)| if d > w { (d, k) } else { (w, at) },
                );
            if worst > 0.0 {
                let (v, c) = (at / m, at % m);
                println!(
                    "  {}: worst at vertex {v} {:?}, column {} ({}): exact {:.4}, two-level {:.4}",
                    e.name, e.mesh.vertices[v], c, we.handles[c], de[v][c], dt[v][c]
                );
            }
            let q = Domain::planar(&e.mesh.vertices, &e.mesh.triangles).bilaplacian();
            let energy = |d: &[Vec<f64>]| -> f64 {
                (0..m)
                    .map(|j| {
                        let w: Vec<f64> = d.iter().map(|r| r[j]).collect();
                        let qw = sinew::weights::sparse::mat_vec(&q, &w);
                        w.iter().zip(&qw).map(|(a, b)| a * b).sum::<f64>()
                    })
                    .sum()
            };
            (e.mesh.vertices.len(), worst, energy(&dt) / energy(&de))
        })
        .collect()
}

fn two_level(options: &BuildOptions) -> BuildOptions {
    let mut two = options.clone();
    two.weights = WeightOptions {
        two_level: Some(TwoLevelOptions::default()),
        ..options.weights.clone()
    };
    two
}

fn check(name: &str, layers: &[Layer], handles: &Handles, options: &BuildOptions) {
    let (exact, t_exact) = rig(layers, handles, options);
    let (two, t_two) = rig(layers, handles, &two_level(options));
    let rows = compare(&exact, &two);
    let vertices: usize = rows.iter().map(|r| r.0).sum();
    let worst = rows.iter().map(|r| r.1).fold(0.0, f64::max);
    let ratio = rows.iter().map(|r| r.2).fold(0.0, f64::max);
    println!(
        "{name}: {vertices} drawn vertices in {} parts; max |Δw| {worst:.4}, energy ratio \
         (worst part) {ratio:.4}; whole rig exact {t_exact:.2} s, two-level {t_two:.2} s",
        rows.len()
    );
    assert!(worst <= MAX_WEIGHT_DIFFERENCE, "{name}: max |Δw| {worst}");
    assert!(ratio <= MAX_ENERGY_RATIO, "{name}: energy ratio {ratio}");
}

#[test]
fn two_level_weights_match_the_exact_solve_on_the_critter() {
    for (label, fraction) in [("critter 5k", 1.0 / 5000.0), ("critter 20k", 1.0 / 22000.0)] {
        let (layers, handles, options) = critter(fraction);
        check(label, &layers, &handles, &options);
    }
}

#[test]
fn two_level_weights_match_the_exact_solve_on_the_character() {
    let (layers, handles) = character();
    let mut options = BuildOptions::default();
    // The bundled parts are small: a finer mesh makes the fine/coarse ratio worth it.
    options.mesh.max_area_fraction /= 8.0;
    check("character", &layers, &handles, &options);
}

/// The benchmark's meshes (benches/weights.rs, `two_level` against `bbw`): the critter's
/// outline at about 5k and 20k vertices, 10 point handles by farthest-point sampling.
#[test]
fn two_level_weights_match_the_exact_solve_on_the_benchmark_meshes() {
    use common::sprite_meshes::{
        farthest_points, main_outline, mesh_near, point_conditions, two_level,
    };
    use sinew::weights::{bounded_biharmonic_weights, BbwOptions};
    let outline = main_outline();
    for target in [5_000, 20_000] {
        let (mesh, _) = mesh_near(&outline, target);
        let domain = Domain::planar(&mesh.vertices, &mesh.triangles);
        let handles = farthest_points(&mesh, 10);
        let bc = point_conditions(&handles);
        let start = Instant::now();
        let (mut exact, _) =
            bounded_biharmonic_weights(&domain, &bc, &BbwOptions::default()).unwrap();
        exact.normalize_rows();
        let t_exact = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let two = two_level(&outline, &mesh, &domain, &handles, &bc);
        let t_two = start.elapsed().as_secs_f64();
        for i in 0..two.vertex_count {
            let row = two.row(i);
            assert!((row.iter().sum::<f64>() - 1.0).abs() < EXACT, "{row:?}");
            assert!(row.iter().all(|&w| (0.0..=1.0).contains(&w)));
        }
        let worst = exact
            .data
            .iter()
            .zip(&two.data)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let q = domain.bilaplacian();
        let energy = |w: &sinew::weights::WeightMatrix| -> f64 {
            (0..w.handle_count)
                .map(|j| {
                    let c = w.column(j);
                    let qc = sinew::weights::sparse::mat_vec(&q, &c);
                    c.iter().zip(&qc).map(|(a, b)| a * b).sum::<f64>()
                })
                .sum()
        };
        let ratio = energy(&two) / energy(&exact);
        println!(
            "benchmark mesh {} vertices × 10 handles: max |Δw| {worst:.4}, energy ratio \
             {ratio:.4}; exact {t_exact:.2} s, two-level {t_two:.2} s",
            mesh.vertices.len()
        );
        assert!(
            worst <= MAX_WEIGHT_DIFFERENCE_BENCHMARK,
            "{target}: max |Δw| {worst}"
        );
        assert!(ratio <= MAX_ENERGY_RATIO, "{target}: energy ratio {ratio}");
    }
}
