//! Skinning IK on the bundled character: drags are met, nothing folds over, a separate skeleton
//! follows the body through the shape, and the energy is close to the best the rig allows.
//!
//! Quality yardsticks (all measured with the per-vertex ARAP energy of Sorkine & Alexa 2007,
//! cotangent weights clamped at zero):
//! - (a) the exact optimum of the reduced problem: every handle a free affine map, one rotation
//!   per vertex, iterated to convergence ([`reduced_optimum`]);
//! - (b) the full per-vertex ARAP deformation, no skinning subspace ([`full_arap`]);
//! - naive posing: only the handle with the largest weight under each drag moves, by the drag.

mod common;

use sinew::geom::Point;
use sinew::ik::arap::{arap_energy, cotangent_edges};
use sinew::ik::reference::{full_arap, MeshDrag};
use sinew::ik::rig::grip;
use sinew::ik::{IkOptions, RigIk, SkinnedMesh};
use sinew::pipeline::Scene;
use sinew::rig::pose::{handle_columns, Affine, IkDrag};
use sinew::rig::Pose;
use std::sync::OnceLock;

fn scene() -> &'static Scene {
    static SCENE: OnceLock<Scene> = OnceLock::new();
    SCENE.get_or_init(common::character_scene)
}

/// Linear blend skinning of every mesh under per-column transforms.
fn skinned(meshes: &[SkinnedMesh], transforms: &[Affine]) -> Vec<Vec<Point>> {
    meshes
        .iter()
        .map(|m| {
            m.rest
                .iter()
                .zip(&m.weights)
                .map(|(p, row)| {
                    let mut q = Point::origin();
                    for &(j, w) in row {
                        q += transforms[j as usize].apply(*p).coords * w;
                    }
                    q
                })
                .collect()
        })
        .collect()
}

fn energy(meshes: &[SkinnedMesh], positions: &[Vec<Point>]) -> f64 {
    meshes
        .iter()
        .zip(positions)
        .map(|(m, p)| arap_energy(&m.rest, p, &cotangent_edges(&m.rest, &m.triangles)))
        .sum()
}

/// Triangles whose signed area changed sign or collapsed.
fn inverted(meshes: &[SkinnedMesh], positions: &[Vec<Point>]) -> usize {
    let area = |a: Point, b: Point, c: Point| (b - a).x * (c - a).y - (b - a).y * (c - a).x;
    meshes
        .iter()
        .zip(positions)
        .map(|(m, p)| {
            m.triangles
                .iter()
                .filter(|t| {
                    let rest = area(
                        m.rest[t[0] as usize],
                        m.rest[t[1] as usize],
                        m.rest[t[2] as usize],
                    );
                    let now = area(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
                    rest * now <= 0.0
                })
                .count()
        })
        .sum()
}

fn drag(at: [f64; 2], to: [f64; 2]) -> IkDrag {
    IkDrag {
        at,
        to,
        weight: None,
    }
}

/// Feet pinned where they stand.
fn pins() -> Vec<IkDrag> {
    vec![
        drag([305.0, 440.0], [305.0, 440.0]),
        drag([207.0, 440.0], [207.0, 440.0]),
    ]
}

fn pose_with(drags: Vec<IkDrag>) -> Pose {
    Pose {
        ik: drags,
        ..Pose::default()
    }
}

/// The exact optimum of the reduced problem (yardstick a).
fn reduced_optimum(meshes: &[SkinnedMesh], pose: &Pose) -> Vec<Affine> {
    let options = IkOptions {
        clusters_per_handle: 0,
        rigidity: 0.0,
        connect_joints: false,
        iterations: 400,
        cold_iterations: 400,
        tolerance_px: 1e-7,
        ..IkOptions::default()
    };
    let mut exact =
        RigIk::precompute(&scene().doc.handles, meshes.to_vec(), options).expect("precompute");
    exact.transforms(pose).expect("solves").transforms
}

fn mesh_drags(meshes: &[SkinnedMesh], drags: &[IkDrag]) -> Vec<MeshDrag> {
    drags
        .iter()
        .map(|d| {
            let (mesh, triangle, barycentric) =
                grip(meshes, Point::new(d.at[0], d.at[1]), 2.0).expect("grips");
            MeshDrag {
                mesh,
                triangle,
                barycentric,
                target: d.to,
            }
        })
        .collect()
}

/// Only the handle weighing most under each drag moves, by the drag.
fn naive(meshes: &[SkinnedMesh], drags: &[IkDrag], columns: usize) -> Vec<Affine> {
    let mut out = vec![Affine::identity(); columns];
    for d in drags {
        let (m, t, b) = grip(meshes, Point::new(d.at[0], d.at[1]), 2.0).expect("grips");
        let mut weights = vec![0.0; columns];
        for (k, &v) in meshes[m].triangles[t].iter().enumerate() {
            for &(j, w) in &meshes[m].weights[v as usize] {
                weights[j as usize] += b[k] * w;
            }
        }
        let j = (0..columns).fold(
            0,
            |best, j| if weights[j] > weights[best] { j } else { best },
        );
        out[j].translation += nalgebra::Vector2::new(d.to[0] - d.at[0], d.to[1] - d.at[1]);
    }
    out
}

#[test]
fn drags_are_met_and_nothing_folds() {
    let meshes = scene().skinned_meshes().unwrap();
    // A third of the character's height is about 120 px. Pressing the head straight down onto
    // the pinned feet by that much folds the legs (they cannot get shorter), so the squat
    // stops at half of it; the hand travels the full third.
    let head = [256.0, 150.0];
    let hand = [160.0, 330.0];
    for (at, dx, dy) in [
        (head, 0.0, -40.0),
        (head, -60.0, 30.0),
        (head, 120.0, 0.0),
        (head, 0.0, 60.0),
        (head, -85.0, -85.0),
        (hand, -40.0, -112.0),
    ] {
        let mut drags = pins();
        drags.push(drag(at, [at[0] + dx, at[1] + dy]));
        let pose = pose_with(drags.clone());
        let mut ik = scene().rig_ik().unwrap();
        let solution = ik.transforms(&pose).unwrap();
        let positions = skinned(&meshes, &solution.transforms);
        for d in &drags {
            let row = ik.drag_row(d).unwrap();
            let p = sinew::ik::rig::skinned_position(&row.row, &solution.transforms);
            let miss = (p.x - d.to[0]).hypot(p.y - d.to[1]);
            assert!(
                miss <= 0.05,
                "drag ({dx}, {dy}): point {:?} misses {:?} by {miss} px",
                d.at,
                d.to
            );
        }
        let folded = inverted(&meshes, &positions);
        if std::env::var_os("SINEW_IK_DEBUG").is_some() {
            let all = scene()
                .positions_from_transforms(&solution.transforms, &pose, sinew::skin::Blend::Linear)
                .unwrap();
            let pixmap = scene().render(&all).unwrap();
            pixmap.save_png(format!("target/ik_{dx}_{dy}.png")).unwrap();
        }
        println!(
            "drag ({dx:>5}, {dy:>5}): {} iterations, drag error {:.2e} px, {folded} inverted triangles",
            solution.iterations, solution.drag_error_px
        );
        assert_eq!(folded, 0, "drag ({dx}, {dy}) folds {folded} triangles");
    }
}

#[test]
fn the_separate_arm_skeleton_follows_the_body() {
    let handles = &scene().doc.handles;
    let columns = handle_columns(handles);
    let column = |name: &str| columns.iter().position(|c| c == name).unwrap();
    let mut drags = pins();
    // Sway the chest 50 px to the left.
    drags.push(drag([256.0, 230.0], [206.0, 230.0]));
    let solution = scene()
        .rig_ik()
        .unwrap()
        .transforms(&pose_with(drags))
        .unwrap();
    for arm in ["arm_upper_l", "arm_upper_r"] {
        let bone = handles.bones.iter().find(|b| b.name == arm).unwrap();
        let head = Point::new(bone.head[0], bone.head[1]);
        let moved = solution.transforms[column(arm)].apply(head) - head;
        println!(
            "{arm}: shoulder moved by ({:.1}, {:.1}) px",
            moved.x, moved.y
        );
        assert!(
            moved.x < -25.0,
            "{arm} stayed behind: its shoulder moved {moved:?}"
        );
    }
}

#[test]
fn energy_is_close_to_the_best_the_rig_allows() {
    let meshes = scene().skinned_meshes().unwrap();
    let columns = handle_columns(&scene().doc.handles).len();
    for (name, dx, dy) in [
        ("head left", -60.0, 20.0),
        ("head up", 0.0, -40.0),
        ("lean right", 90.0, 30.0),
    ] {
        let mut drags = pins();
        drags.push(drag([256.0, 150.0], [256.0 + dx, 150.0 + dy]));
        let pose = pose_with(drags.clone());
        let ours = scene().rig_ik().unwrap().transforms(&pose).unwrap();
        let ours_positions = skinned(&meshes, &ours.transforms);
        let e_ours = energy(&meshes, &ours_positions);
        let optimum = skinned(&meshes, &reduced_optimum(&meshes, &pose));
        let e_a = energy(&meshes, &optimum);
        let (_, e_b) = full_arap(&meshes, &mesh_drags(&meshes, &drags), &optimum, 300, 1e-9);
        let e_naive = energy(&meshes, &skinned(&meshes, &naive(&meshes, &drags, columns)));
        println!(
            "{name}: ours {e_ours:.1} px², (a) reduced optimum {e_a:.1}, (b) full ARAP {e_b:.1}, naive {e_naive:.1}; \
             ours/(a) {:.3}, ours/(b) {:.2}, naive/ours {:.1}",
            e_ours / e_a,
            e_ours / e_b,
            e_naive / e_ours
        );
        assert!(
            e_ours <= 1.3 * e_a,
            "{name}: ours {e_ours} vs reduced optimum {e_a}"
        );
        assert!(
            e_naive >= 3.0 * e_ours,
            "{name}: naive {e_naive} vs ours {e_ours}"
        );
    }
}

#[test]
fn rigid_bones_stay_rigid_on_request() {
    let meshes = scene().skinned_meshes().unwrap();
    let handles = &scene().doc.handles;
    let options = IkOptions {
        rigidity: 100.0,
        ..IkOptions::default()
    };
    let mut ik = RigIk::precompute(handles, meshes.clone(), options).unwrap();
    let mut drags = pins();
    drags.push(drag([256.0, 150.0], [196.0, 170.0]));
    let solution = ik.transforms(&pose_with(drags)).unwrap();
    let stretch = solution.transforms[..handles.bones.len()]
        .iter()
        .map(|t| {
            let s = t.linear.svd(false, false).singular_values;
            (s[0] - 1.0).abs().max((s[1] - 1.0).abs())
        })
        .fold(0.0, f64::max);
    let e = energy(&meshes, &skinned(&meshes, &solution.transforms));
    println!(
        "rigid bones: largest stretch {stretch:.4}, energy {e:.1} px², drag error {:.1e} px",
        solution.drag_error_px
    );
    assert!(stretch < 0.03, "bones stretch by {stretch}");
    assert!(solution.drag_error_px <= 0.05);
}
