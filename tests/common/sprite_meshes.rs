//! The weight benchmark's meshes, shared by benches/weights.rs and tests/two_level.rs: the
//! critter's largest outline at 512², meshes searched to a vertex count, point handles by
//! farthest-point sampling, and the coarse mesh of the same outline that two-level weights
//! solve on.

use sinew::geom::{ring_signed_area, triangle_area2, Point};
use sinew::mesh::{triangulate, triangulate_with_handles, HandleGeometry, Mesh, MeshOptions};
use sinew::trace::{trace, Outline, TraceOptions};
use sinew::weights::support::SupportSolver;
use sinew::weights::two_level::carry_to;
use sinew::weights::{
    bounded_biharmonic_weights, BbwOptions, BoundaryConditions, Domain, TwoLevelOptions,
    TwoLevelPolish, WeightMatrix,
};

/// The sprite's canvas side, px.
pub const SPRITE_SIZE: u32 = 512;

/// The canvas area, px².
pub fn canvas_area_px2() -> f64 {
    (SPRITE_SIZE * SPRITE_SIZE) as f64
}

/// The critter's largest outline (everything but the separate blob).
pub fn main_outline() -> Outline {
    let image = super::critter(SPRITE_SIZE);
    // Coarse tracing (2 px simplification): with the default 0.5 px, refinement around the thin
    // antenna alone gives some 1.4k vertices at any area limit, too many for the 1k case.
    let outlines = trace(&image, &TraceOptions::coarse()).expect("trace");
    outlines
        .into_iter()
        .max_by(|a, b| ring_signed_area(&a.outer).total_cmp(&ring_signed_area(&b.outer)))
        .expect("an outline")
}

/// Triangulates `outline` with `max_area_fraction` searched to give about `target` vertices.
pub fn mesh_near(outline: &Outline, target: usize) -> (Mesh, f64) {
    let canvas = canvas_area_px2();
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
pub fn farthest_points(mesh: &Mesh, count: usize) -> Vec<usize> {
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

/// Each of `handles` (vertices) fixed to its own column.
pub fn point_conditions(handles: &[usize]) -> BoundaryConditions {
    let mut bc = BoundaryConditions {
        handle_count: handles.len(),
        ..Default::default()
    };
    for (j, &v) in handles.iter().enumerate() {
        bc.fix_to_handle(v, j);
    }
    bc
}

/// The coarse mesh two-level weights solve on (largest triangle = `fine`'s area over
/// `coarse_vertices`, as `sinew rig --coarse-weights` builds it) and its boundary conditions
/// for the point handles at `fine`'s vertices `handles`. Handles inside the shape are inserted
/// as mesh vertices (as the pipeline inserts handle geometry); a handle on the outline (where
/// farthest-point sampling puts them) may lie on a fine-only split of an outline edge, so the
/// nearest coarse vertex is moved onto it instead.
pub fn coarse_mesh(
    outline: &Outline,
    fine: &Mesh,
    handles: &[usize],
    coarse_vertices: usize,
) -> (Mesh, BoundaryConditions) {
    let area_px2: f64 = fine
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| fine.vertices[v as usize]);
            0.5 * triangle_area2(a, b, c).abs()
        })
        .sum();
    let mut on_outline = vec![false; fine.vertices.len()];
    let mut edges: Vec<(u32, u32)> = fine
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    for (k, e) in edges.iter().enumerate() {
        let shared = (k > 0 && edges[k - 1] == *e) || edges.get(k + 1) == Some(e);
        if !shared {
            on_outline[e.0 as usize] = true;
            on_outline[e.1 as usize] = true;
        }
    }
    let points: Vec<Point> = handles
        .iter()
        .filter(|&&h| !on_outline[h])
        .map(|&h| fine.vertices[h])
        .collect();
    let options = MeshOptions {
        max_area_fraction: area_px2 / coarse_vertices as f64 / canvas_area_px2(),
        ..MeshOptions::default()
    };
    let geometry = HandleGeometry {
        points,
        ..Default::default()
    };
    let mut mesh = triangulate_with_handles(
        std::slice::from_ref(outline),
        &geometry,
        canvas_area_px2(),
        &options,
    )
    .expect("coarse mesh")
    .domain;
    let mut used = vec![false; mesh.vertices.len()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let at: Vec<usize> = handles
        .iter()
        .map(|&h| {
            let p = fine.vertices[h];
            (0..mesh.vertices.len())
                .filter(|&v| used[v])
                .min_by(|&a, &b| {
                    (mesh.vertices[a] - p)
                        .norm()
                        .total_cmp(&(mesh.vertices[b] - p).norm())
                })
                .expect("a coarse vertex")
        })
        .collect();
    for (&h, &c) in handles.iter().zip(&at) {
        mesh.vertices[c] = fine.vertices[h];
    }
    (mesh, point_conditions(&at))
}

/// Two-level bounded biharmonic weights on `fine` (whose [`Domain`] is `domain`) for the point
/// handles at its vertices `handles` (conditions `bc`) with the default [`TwoLevelOptions`],
/// as `sinew rig --coarse-weights` computes them: the coarse mesh ([`coarse_mesh`]), its exact
/// solve, the carry to `fine`, the polish there, rows normalized.
pub fn two_level(
    outline: &Outline,
    fine: &Mesh,
    domain: &Domain,
    handles: &[usize],
    bc: &BoundaryConditions,
) -> WeightMatrix {
    let options = TwoLevelOptions::default();
    assert_eq!(options.polish, TwoLevelPolish::Support);
    // As `two_level_weights` does: the fine support solver is prepared beside the coarse solve.
    let (solved, solver) = rayon::join(
        || {
            let (coarse, coarse_bc) = coarse_mesh(outline, fine, handles, options.coarse_vertices);
            let coarse_domain = Domain::planar(&coarse.vertices, &coarse.triangles);
            let (solved, _) =
                bounded_biharmonic_weights(&coarse_domain, &coarse_bc, &BbwOptions::default())
                    .expect("coarse bbw solve");
            carry_to(&coarse, &solved, &fine.vertices)
        },
        || SupportSolver::new(domain, bc).expect("support solver"),
    );
    let mut w = solver
        .solve(&solved, options.support_floor)
        .expect("support solve");
    w.normalize_rows();
    w
}
