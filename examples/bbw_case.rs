//! Writes bounded biharmonic weight problems and sinew's solutions as JSON, for the libigl
//! comparison in `tools/libigl-oracle/`.
//!
//! `cargo run --release --example bbw_case -- OUT_DIR` writes `OUT_DIR/<case>.json`:
//!
//! ```text
//! {"vertices": [[x, y], ...], "triangles": [[a, b, c], ...],
//!  "b": [fixed vertex, ...], "bc": [[w per handle] per fixed vertex],
//!  "weights": [[w per handle] per vertex],   // sinew's BBW, rows normalized
//!  "weights_unnormalized": [...],            // the same before normalizing
//!  "seconds": ...,                           // Domain::new + bounded solve + normalize
//!                                           // (the fastest of --repeat runs)
//!  "cpu_seconds": ..., "threads": ...,       // CPU time of the same (all threads), rayon threads
//!  "max_iterations": ...,
//!  "handles": [column name, ...], "iterations": [...], "unconverged": [...],
//!  "stiffness": {"rows": [...], "cols": [...], "values": [...]},   // sinew's K = −L
//!  "mass": [...],                            // sinew's lumped mass per vertex
//!  "reference_weights": [...], "reference_weights_unnormalized": [...],
//!  "reference_seconds": ...}                // with --reference: clarabel's
//!                                           // (or "reference_error": why it failed)
//! ```
//!
//! Options after OUT_DIR: `--max-iterations N` (sinew's interior-point iteration limit, default as in
//! [`BbwOptions`]), `--reference` (also solve with clarabel, sinew's interior-point
//! yardstick, normalized), `--repeat N` (solve N times, report the fastest) and case names to
//! write only those.
//!
//! Cases: `critter` (a generated sprite, five point handles and a two-bone chain),
//! `character_torso` (the bundled character's torso layer with the bones of
//! `assets/character/handles.json` that touch it) and `critter_large` (the sprite at 512 px,
//! meshed finely, ten point handles); named only: `bench_5k`, `bench_20k`, `bench_50k` (the
//! weights benchmark's meshes and handles, `benches/weights.rs`).

#[path = "../tests/common/mod.rs"]
mod common;

use image::RgbaImage;
use serde_json::{json, Value};
use sinew::geom::Point;
use sinew::mesh::{triangulate_with_handles, MeshOptions};
use sinew::pipeline::handle_geometry;
use sinew::rig::{handle_columns, Bone, Handles, PointHandle};
use sinew::trace::{trace, TraceOptions};
use sinew::weights::boundary::boundary_conditions;
use sinew::weights::reference::bounded_biharmonic_reference;
use sinew::weights::{
    bounded_biharmonic_weights, BbwOptions, BoundaryConditions, Domain, WeightMatrix,
};
use std::path::{Path, PathBuf};
use std::time::Instant;

fn bone(name: &str, parent: Option<&str>, head: [f64; 2], tail: [f64; 2]) -> Bone {
    Bone {
        name: name.into(),
        parent: parent.map(Into::into),
        head: head.into(),
        tail: tail.into(),
    }
}

fn point(name: &str, at: [f64; 2]) -> PointHandle {
    PointHandle {
        name: name.into(),
        at: at.into(),
        parent: None,
    }
}

/// Handles for `common::critter(256 * scale)`: points on the antenna, the ring, the separate
/// blob, the head and the belly, and a two-bone chain up the body.
fn critter_handles(scale: f64, extra_points: bool) -> Handles {
    let s = |p: [f64; 2]| [p[0] * scale, p[1] * scale];
    let mut points = vec![
        point("antenna", s([145.6, 17.0])),
        point("ring", s([205.0, 130.5])),
        point("blob", s([40.0, 230.0])),
        point("cheek", s([150.0, 72.0])),
        point("belly", s([88.0, 175.0])),
    ];
    if extra_points {
        points.extend([
            point("ring_bottom", s([205.0, 169.5])),
            point("foot_l", s([100.0, 200.0])),
            point("foot_r", s([160.0, 200.0])),
            point("ear", s([105.0, 60.0])),
            point("side", s([178.0, 125.0])),
        ]);
    }
    let bones = if extra_points {
        Vec::new()
    } else {
        vec![
            bone("hip", None, s([128.0, 195.0]), s([128.0, 140.0])),
            bone("chest", Some("hip"), s([128.0, 140.0]), s([128.0, 90.0])),
        ]
    };
    Handles {
        bones,
        points,
        ..Default::default()
    }
}

/// One BBW problem on the weight domain of a traced and meshed sprite.
struct Case {
    name: &'static str,
    vertices: Vec<Point>,
    triangles: Vec<[u32; 3]>,
    columns: Vec<String>,
    bc: BoundaryConditions,
}

/// Traces `image`, meshes it with the handles' geometry embedded (as the pipeline does) and
/// takes the boundary conditions from the handles. Also returns, per column, how many vertices
/// the handle fixes.
fn embed(
    name: &'static str,
    image: &RgbaImage,
    handles: &Handles,
    mesh_options: &MeshOptions,
) -> (Case, Vec<usize>) {
    handles.validate().expect("valid handles");
    let outlines = trace(image, &TraceOptions::default()).expect("trace");
    let canvas_area = image.width() as f64 * image.height() as f64;
    let embedded = triangulate_with_handles(
        &outlines,
        &handle_geometry(handles),
        canvas_area,
        mesh_options,
    )
    .expect("mesh");
    let mesh = embedded.domain;
    let (bc, touched) = boundary_conditions(&mesh.vertices, handles);
    let case = Case {
        name,
        vertices: mesh.vertices,
        triangles: mesh.triangles,
        columns: handle_columns(handles),
        bc,
    };
    (case, touched)
}

/// [`embed`] for handles that must all touch the mesh.
fn embed_all(
    name: &'static str,
    image: &RgbaImage,
    handles: &Handles,
    mesh_options: &MeshOptions,
) -> Case {
    let (case, touched) = embed(name, image, handles, mesh_options);
    if let Some(c) = touched.iter().position(|&n| n == 0) {
        panic!("{name}: handle '{}' fixes no vertex", case.columns[c]);
    }
    case
}

/// Keeps only the handle columns that fix at least one vertex (with weight > 0), and only the
/// mesh pieces that some fixed vertex reaches (the rig binds the others rigidly, which is no
/// BBW problem).
fn restrict(mut case: Case) -> Case {
    let m = case.bc.handle_count;
    let keep: Vec<usize> = (0..m)
        .filter(|&j| (0..case.bc.vertices.len()).any(|k| case.bc.values[k * m + j] > 0.0))
        .collect();

    // Vertices reached from a fixed vertex through triangles.
    let n = case.vertices.len();
    let mut neighbours = vec![Vec::new(); n];
    for t in &case.triangles {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            neighbours[a].push(b);
            neighbours[b].push(a);
        }
    }
    let mut reached = vec![false; n];
    let mut stack = case.bc.vertices.clone();
    for &v in &stack {
        reached[v] = true;
    }
    while let Some(i) = stack.pop() {
        for &j in &neighbours[i] {
            if !reached[j] {
                reached[j] = true;
                stack.push(j);
            }
        }
    }
    let mut new_index = vec![u32::MAX; n];
    let mut vertices = Vec::new();
    for i in 0..n {
        if reached[i] && !neighbours[i].is_empty() {
            new_index[i] = vertices.len() as u32;
            vertices.push(case.vertices[i]);
        }
    }
    let triangles: Vec<[u32; 3]> = case
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&v| new_index[v as usize] != u32::MAX))
        .map(|t| t.map(|v| new_index[v as usize]))
        .collect();

    let mut bc = BoundaryConditions {
        handle_count: keep.len(),
        ..Default::default()
    };
    for (k, &v) in case.bc.vertices.iter().enumerate() {
        if new_index[v] == u32::MAX {
            continue;
        }
        let row = &case.bc.values[k * m..(k + 1) * m];
        let weights: Vec<(usize, f64)> = keep
            .iter()
            .enumerate()
            .map(|(c, &j)| (c, row[j]))
            .filter(|&(_, w)| w != 0.0)
            .collect();
        bc.fix(new_index[v] as usize, &weights);
    }
    case.columns = keep.iter().map(|&j| case.columns[j].clone()).collect();
    case.vertices = vertices;
    case.triangles = triangles;
    case.bc = bc;
    case
}

fn character_torso(assets: &Path) -> Case {
    let image = sinew::io::load_png(&assets.join("torso.png")).expect("torso.png");
    let text = std::fs::read_to_string(assets.join("handles.json")).expect("handles.json");
    let handles: Handles = serde_json::from_str(&text).expect("handles.json");
    // As the pipeline does: every handle's geometry is embedded in the part's mesh and the
    // boundary conditions come from all handles; the columns that miss the torso are dropped.
    let (case, _) = embed("character_torso", &image, &handles, &MeshOptions::default());
    restrict(case)
}

/// CPU time of the whole process (all threads) in seconds, from /proc/self/stat (Linux; the
/// ticks are usually 10 ms). NaN elsewhere. Wall time alone misleads on a shared machine.
fn process_cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the parenthesized command name; utime and stime are fields 14 and 15.
    let Some(rest) = stat.rfind(')').map(|i| &stat[i + 1..]) else {
        return f64::NAN;
    };
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |k: usize| fields.get(k).and_then(|f| f.parse::<f64>().ok());
    match (ticks(11), ticks(12)) {
        (Some(user), Some(system)) => (user + system) / CLOCK_TICKS_PER_SECOND,
        _ => f64::NAN,
    }
}

/// Linux's USER_HZ on every common platform.
const CLOCK_TICKS_PER_SECOND: f64 = 100.0;

/// How the example solves: sinew's interior-point options, and whether to add clarabel's answer.
struct Settings {
    bbw: BbwOptions,
    reference: bool,
    /// Solve this many times and report the fastest (the machine may be shared).
    repeat: usize,
}

fn rows_of(w: &WeightMatrix) -> Vec<&[f64]> {
    (0..w.vertex_count).map(|i| w.row(i)).collect()
}

fn solve_and_write(case: &Case, out_dir: &Path, settings: &Settings) -> PathBuf {
    let points: Vec<[f64; 2]> = case.vertices.iter().map(|p| [p.x, p.y]).collect();
    let solve = || {
        let cpu = process_cpu_seconds();
        let start = Instant::now();
        let domain = Domain::new(&points, &case.triangles);
        let (mut weights, report) =
            bounded_biharmonic_weights(&domain, &case.bc, &settings.bbw).expect("bbw solve");
        let unnormalized = weights.clone();
        let empty = weights.normalize_rows();
        let seconds = start.elapsed().as_secs_f64();
        let cpu = process_cpu_seconds() - cpu;
        (domain, weights, unnormalized, report, empty, seconds, cpu)
    };
    let (domain, weights, unnormalized, report, empty, mut seconds, mut cpu_seconds) = solve();
    for _ in 1..settings.repeat {
        let again = solve();
        seconds = seconds.min(again.5);
        cpu_seconds = cpu_seconds.min(again.6);
    }

    let reference = settings.reference.then(|| {
        let start = Instant::now();
        let w = bounded_biharmonic_reference(&domain, &case.bc, false).map(|raw| {
            let mut w = raw.clone();
            w.normalize_rows();
            (w, raw)
        });
        (w, start.elapsed().as_secs_f64())
    });

    let m = case.bc.handle_count;
    let b: Vec<usize> = case.bc.vertices.clone();
    let bc: Vec<&[f64]> = case.bc.values.chunks(m).collect();
    let (mut ki, mut kj, mut kv) = (Vec::new(), Vec::new(), Vec::new());
    for (i, row) in domain.stiffness.outer_iterator().enumerate() {
        for (j, &v) in row.iter() {
            ki.push(i);
            kj.push(j);
            kv.push(v);
        }
    }
    let mut doc: Value = json!({
        "vertices": points,
        "triangles": case.triangles,
        "b": b,
        "bc": bc,
        "weights": rows_of(&weights),
        "weights_unnormalized": rows_of(&unnormalized),
        "seconds": seconds,
        "cpu_seconds": cpu_seconds,
        "threads": rayon::current_num_threads(),
        "max_iterations": settings.bbw.max_iterations,
        "handles": case.columns,
        "iterations": report.iterations,
        "unconverged": report.unconverged,
        "empty_rows": empty,
        "stiffness": {"rows": ki, "cols": kj, "values": kv},
        "mass": domain.mass,
    });
    match &reference {
        Some((Ok((w, raw)), seconds)) => {
            doc["reference_weights"] = json!(rows_of(w));
            doc["reference_weights_unnormalized"] = json!(rows_of(raw));
            doc["reference_seconds"] = json!(seconds);
        }
        Some((Err(e), _)) => doc["reference_error"] = json!(e.to_string()),
        None => {}
    }
    let path = out_dir.join(format!("{}.json", case.name));
    std::fs::write(&path, serde_json::to_vec(&doc).expect("json")).expect("write case");
    eprintln!(
        "{:<16} {:>6} vertices {:>6} triangles {:>3} handles {:>5} fixed  sinew {:.3} s \
         ({:.2} s CPU)  interior-point iterations {:?}{}",
        case.name,
        case.vertices.len(),
        case.triangles.len(),
        m,
        b.len(),
        seconds,
        cpu_seconds,
        report.iterations,
        if report.unconverged.is_empty() {
            String::new()
        } else {
            format!("  UNCONVERGED {:?}", report.unconverged)
        }
    );
    match &reference {
        Some((Ok(_), seconds)) => eprintln!("{:<16} clarabel {seconds:.3} s", case.name),
        Some((Err(e), seconds)) => {
            eprintln!(
                "{:<16} clarabel failed after {seconds:.3} s: {e}",
                case.name
            )
        }
        None => {}
    }
    path
}

fn main() {
    let usage = "usage: bbw_case OUT_DIR [--max-iterations N] [--reference] [--repeat N] [CASE...]";
    let mut args = std::env::args().skip(1);
    let out_dir = PathBuf::from(args.next().expect(usage));
    let mut settings = Settings {
        bbw: BbwOptions::default(),
        reference: false,
        repeat: 1,
    };
    let mut only: Vec<String> = Vec::new();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--max-iterations" => {
                settings.bbw.max_iterations =
                    args.next().and_then(|n| n.parse().ok()).expect(usage);
            }
            "--reference" => settings.reference = true,
            "--repeat" => {
                settings.repeat = args.next().and_then(|n| n.parse().ok()).expect(usage);
            }
            _ if arg.starts_with("--") => panic!("{usage}"),
            _ => only.push(arg),
        }
    }
    std::fs::create_dir_all(&out_dir).expect("create OUT_DIR");
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/character");
    let wanted = |name: &str| only.is_empty() || only.iter().any(|o| o == name);

    if wanted("critter") {
        let case = embed_all(
            "critter",
            &common::critter(256),
            &critter_handles(1.0, false),
            &MeshOptions::default(),
        );
        solve_and_write(&case, &out_dir, &settings);
    }
    if wanted("character_torso") {
        solve_and_write(&character_torso(&assets), &out_dir, &settings);
    }
    // The weights benchmark's meshes (benches/weights.rs: the same outline, meshes and ten
    // farthest-point handles), for libigl's timings beside the benchmark's; written only when
    // named.
    for (name, target) in [
        ("bench_5k", 5_000),
        ("bench_20k", 20_000),
        ("bench_50k", 50_000),
    ] {
        if only.iter().any(|o| o == name) {
            let (mesh, _) =
                common::sprite_meshes::mesh_near(&common::sprite_meshes::main_outline(), target);
            let handles = common::sprite_meshes::farthest_points(&mesh, 10);
            let case = Case {
                name,
                vertices: mesh.vertices,
                triangles: mesh.triangles,
                columns: (0..handles.len()).map(|j| format!("point{j}")).collect(),
                bc: common::sprite_meshes::point_conditions(&handles),
            };
            solve_and_write(&case, &out_dir, &settings);
        }
    }
    if wanted("critter_large") {
        // About 5k vertices: triangles of at most ~13 px² on the 512² canvas.
        let fine = MeshOptions {
            max_area_fraction: 1.0 / 20_000.0,
            ..MeshOptions::default()
        };
        let case = embed_all(
            "critter_large",
            &common::critter(512),
            &critter_handles(2.0, true),
            &fine,
        );
        solve_and_write(&case, &out_dir, &settings);
    }
}
