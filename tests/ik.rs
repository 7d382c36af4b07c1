//! Skinning IK on the bundled character: drags are met, nothing folds over, a separate skeleton
//! follows the body through the shape, and the energy is close to the best the rig allows.
//!
//! Quality yardsticks (all measured with the per-vertex ARAP energy of Sorkine & Alexa 2007,
//! cotangent weights clamped at zero):
//! - (a) the exact optimum of the reduced problem in the same constrained subspace (bones rigid,
//!   joints connected, as the solver's defaults say), one rotation per vertex, iterated to
//!   convergence ([`reduced_optimum`]); and, for scale, the looser optimum with every handle a
//!   free affine map and no joints ([`affine_optimum`]);
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
        at: at.into(),
        to: to.into(),
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

/// The exact optimum of the reduced problem in the solver's own subspace (yardstick a).
fn reduced_optimum(meshes: &[SkinnedMesh], pose: &Pose) -> Vec<Affine> {
    optimum_with(
        meshes,
        pose,
        IkOptions {
            clusters_per_handle: 0,
            iterations: 400,
            cold_iterations: 400,
            tolerance_px: 1e-7,
            ..IkOptions::default()
        },
    )
}

/// The optimum with affine bones and no joints: a looser subspace, for scale.
fn affine_optimum(meshes: &[SkinnedMesh], pose: &Pose) -> Vec<Affine> {
    optimum_with(
        meshes,
        pose,
        IkOptions {
            clusters_per_handle: 0,
            bones: sinew::ik::BoneDofs::Affine,
            rigidity: 0.0,
            connect_joints: false,
            iterations: 400,
            cold_iterations: 400,
            tolerance_px: 1e-7,
            ..IkOptions::default()
        },
    )
}

fn optimum_with(meshes: &[SkinnedMesh], pose: &Pose, options: IkOptions) -> Vec<Affine> {
    let mut exact =
        RigIk::precompute(&scene().doc.handles, meshes.to_vec(), options).expect("precompute");
    exact.transforms(pose).expect("solves").transforms
}

fn mesh_drags(meshes: &[SkinnedMesh], drags: &[IkDrag]) -> Vec<MeshDrag> {
    drags
        .iter()
        .map(|d| {
            let (mesh, triangle, barycentric) = grip(meshes, d.at, 2.0).expect("grips");
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
        let (m, t, b) = grip(meshes, d.at, 2.0).expect("grips");
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

/// One drag from the pinned feet: the solution, each drag's miss (px) and the folded triangles.
fn solve_drag(at: [f64; 2], dx: f64, dy: f64) -> (Vec<f64>, usize, usize) {
    let meshes = scene().skinned_meshes().unwrap();
    let mut drags = pins();
    drags.push(drag(at, [at[0] + dx, at[1] + dy]));
    let pose = pose_with(drags.clone());
    let mut ik = scene().rig_ik().unwrap();
    let solution = ik.transforms(&pose).unwrap();
    let misses = drags
        .iter()
        .map(|d| {
            let row = ik.drag_row(d).unwrap();
            let p = sinew::ik::rig::skinned_position(&row.row, &solution.transforms);
            (p.x - d.to[0]).hypot(p.y - d.to[1])
        })
        .collect::<Vec<_>>();
    let folded = inverted(&meshes, &skinned(&meshes, &solution.transforms));
    if std::env::var_os("SINEW_IK_DEBUG").is_some() {
        let all = scene()
            .positions_from_transforms(&solution.transforms, &pose, sinew::skin::Blend::Linear)
            .unwrap();
        let pixmap = scene().render(&all).unwrap();
        pixmap.save_png(format!("target/ik_{dx}_{dy}.png")).unwrap();
    }
    println!(
        "drag ({dx:>5}, {dy:>5}): {} iterations, misses {misses:.2?} px, {folded} inverted \
         triangles, {} guarded",
        solution.iterations,
        ik.solver.guarded_triangles()
    );
    (misses, folded, solution.iterations)
}

const HEAD: [f64; 2] = [256.0, 150.0];
const HAND: [f64; 2] = [160.0, 330.0];

#[test]
fn drags_within_reach_are_met_and_nothing_folds() {
    // Bones keep their length, so a drag is met when the limbs can reach it: the head pushed
    // down and sideways onto the pinned feet, the hand carried far up and sideways.
    for (at, dx, dy) in [
        (HEAD, -60.0, 30.0),
        (HEAD, 85.0, 85.0),
        (HAND, -40.0, -112.0),
        (HAND, 120.0, 0.0),
        (HAND, -120.0, 0.0),
    ] {
        let (misses, folded, _) = solve_drag(at, dx, dy);
        for miss in misses {
            assert!(miss <= 0.05, "drag ({dx}, {dy}) missed by {miss} px");
        }
        assert_eq!(folded, 0, "drag ({dx}, {dy}) folds {folded} triangles");
    }
}

#[test]
fn drags_beyond_reach_are_met_in_the_least_squares_sense() {
    // Rigid limbs cannot stretch from the pinned feet to these targets (the head lifted or
    // carried 120 px sideways, the hand pushed below the feet), and joints never part: the feet
    // and the dragged point share the miss. Each target is still approached: the summed squared
    // miss is under the dragged point's squared distance from its target at rest, and no point
    // misses by more than that distance.
    for (at, dx, dy) in [
        (HEAD, 0.0, -40.0),
        (HEAD, 120.0, 0.0),
        (HEAD, -120.0, 0.0),
        (HEAD, -85.0, -85.0),
        (HEAD, 0.0, 120.0),
        (HAND, 0.0, 120.0),
    ] {
        let (misses, _, _) = solve_drag(at, dx, dy);
        let squared: f64 = misses.iter().map(|m| m * m).sum();
        let start = dx * dx + dy * dy;
        println!(
            "drag ({dx}, {dy}): squared misses {:.2} of the rest pose's",
            squared / start
        );
        assert!(
            squared < start,
            "drag ({dx}, {dy}): squared misses {squared} px² vs {start} px² at rest"
        );
        assert!(misses.iter().all(|&m| m < start.sqrt()), "{misses:?}");
    }
}

#[test]
fn without_the_fold_guard_the_deep_squat_folds() {
    // The guard is what keeps the 120 px squat above unfolded: the energy alone folds it.
    let meshes = scene().skinned_meshes().unwrap();
    let options = IkOptions {
        fold_check_triangles: 0,
        ..IkOptions::default()
    };
    let mut drags = pins();
    drags.push(drag([256.0, 150.0], [256.0, 270.0]));
    let mut ik = RigIk::precompute(&scene().doc.handles, meshes.clone(), options).unwrap();
    let solution = ik.transforms(&pose_with(drags)).unwrap();
    let folded = inverted(&meshes, &skinned(&meshes, &solution.transforms));
    println!("squat without the guard: {folded} inverted triangles");
    assert!(folded > 0);
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
        let head = bone.head;
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
        let affine = skinned(&meshes, &affine_optimum(&meshes, &pose));
        let e_affine = energy(&meshes, &affine);
        let (_, e_b) = full_arap(&meshes, &mesh_drags(&meshes, &drags), &affine, 300, 1e-9);
        let e_naive = energy(&meshes, &skinned(&meshes, &naive(&meshes, &drags, columns)));
        println!(
            "{name}: ours {e_ours:.1} px², (a) reduced optimum {e_a:.1} (affine bones, no joints: \
             {e_affine:.1}), (b) full ARAP {e_b:.1}, naive {e_naive:.1}; \
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
            e_naive >= 2.0 * e_ours,
            "{name}: naive {e_naive} vs ours {e_ours}"
        );
    }
}

#[test]
fn bones_keep_their_length_by_default() {
    let meshes = scene().skinned_meshes().unwrap();
    let handles = &scene().doc.handles;
    let mut drags = pins();
    drags.push(drag([256.0, 150.0], [196.0, 170.0]));
    let pose = pose_with(drags);
    // The largest deviation of a bone's linear part from a rotation (singular values vs 1).
    let stretch = |transforms: &[Affine]| {
        transforms[..handles.bones.len()]
            .iter()
            .map(|t| {
                let s = t.linear.svd(false, false).singular_values;
                (s[0] - 1.0).abs().max((s[1] - 1.0).abs())
            })
            .fold(0.0, f64::max)
    };
    let solution = scene().rig_ik().unwrap().transforms(&pose).unwrap();
    let rigid_stretch = stretch(&solution.transforms);
    let e = energy(&meshes, &skinned(&meshes, &solution.transforms));
    // Affine bones (Fast Automatic Skinning Transformations' handles), for the comparison the
    // options' docs quote.
    let options = IkOptions {
        bones: sinew::ik::BoneDofs::Affine,
        ..IkOptions::default()
    };
    let free = RigIk::precompute(handles, meshes.clone(), options)
        .unwrap()
        .transforms(&pose)
        .unwrap();
    let e_free = energy(&meshes, &skinned(&meshes, &free.transforms));
    println!(
        "rigid bones: largest stretch {rigid_stretch:.1e}, energy {e:.1} px², drag error {:.1e} px; \
         affine bones: largest stretch {:.4}, energy {e_free:.1} px² (rigid/affine {:.1}×)",
        solution.drag_error_px,
        stretch(&free.transforms),
        e / e_free
    );
    assert!(rigid_stretch < 1e-9, "bones stretch by {rigid_stretch}");
    assert!(stretch(&free.transforms) > 0.01, "the control stretches");
    assert!(solution.drag_error_px <= 0.05);
}

/// A 360 × 120 px bar with two skeletons of two bones each, one per half, not connected.
fn two_skeleton_bar() -> Scene {
    bar_rig(serde_json::json!({
        "bones": [
            {"name": "a1", "head": [40, 100], "tail": [110, 100]},
            {"name": "a2", "parent": "a1", "head": [110, 100], "tail": [180, 100]},
            {"name": "b1", "head": [220, 100], "tail": [290, 100]},
            {"name": "b2", "parent": "b1", "head": [290, 100], "tail": [360, 100]}
        ]
    }))
}

/// A 360 × 119 px bar rigged with `handles` (the handles file's JSON).
fn bar_rig(handles: serde_json::Value) -> Scene {
    use sinew::pipeline::{build_rig, Layer};
    let mut pixmap = tiny_skia::Pixmap::new(400, 200).unwrap();
    let mut paint = tiny_skia::Paint::default();
    paint.set_color_rgba8(200, 120, 60, 255);
    let rect = tiny_skia::Rect::from_xywh(20.0, 40.5, 360.0, 119.0).unwrap();
    pixmap.fill_rect(rect, &paint, tiny_skia::Transform::identity(), None);
    let image = common::to_rgba(&pixmap);
    let handles: sinew::rig::Handles = serde_json::from_value(handles).unwrap();
    let layers = vec![Layer::whole("bar", "bar.png", image.clone())];
    let (doc, _) = build_rig(
        &layers,
        std::path::Path::new("."),
        &Default::default(),
        &handles,
    )
    .unwrap();
    Scene::new(doc, &[image]).unwrap()
}

#[test]
fn disjoint_skeletons_in_one_shape_move_together() {
    let bar = two_skeleton_bar();
    let meshes = bar.skinned_meshes().unwrap();
    let columns = handle_columns(&bar.doc.handles);
    // The left end held (two pins fix its turn), the right end lifted by 80 px.
    let drags = vec![
        drag([30.0, 70.0], [30.0, 70.0]),
        drag([30.0, 130.0], [30.0, 130.0]),
        drag([370.0, 100.0], [350.0, 20.0]),
    ];
    let mut ik = bar.rig_ik().unwrap();
    let solution = ik.transforms(&pose_with(drags.clone())).unwrap();
    assert!(
        solution.drag_error_px <= 0.05,
        "drag error {}",
        solution.drag_error_px
    );
    let positions = skinned(&meshes, &solution.transforms);
    assert_eq!(inverted(&meshes, &positions), 0);
    // The right skeleton's root, which nothing drags, rises with the bend; the left one bends
    // at its joint (its first bone, pinned at two points and rigid, stays).
    let lift = |name: &str, at: [f64; 2]| {
        let p = Point::new(at[0], at[1]);
        (solution.transforms[columns.iter().position(|c| c == name).unwrap()].apply(p) - p).y
    };
    let (a2, b1) = (lift("a2", [180.0, 100.0]), lift("b1", [220.0, 100.0]));
    println!("tip of a2 rose {:.1} px, root b1 {:.1} px", -a2, -b1);
    assert!(b1 < -15.0 && a2 < -2.0 && b1 < a2, "a2 {a2}, b1 {b1}");
    let e = energy(&meshes, &positions);
    let e_naive = energy(
        &meshes,
        &skinned(&meshes, &naive(&meshes, &drags, columns.len())),
    );
    println!("bar: ours {e:.1} px², naive {e_naive:.1}");
    assert!(e_naive > 3.0 * e);
}

#[test]
fn a_keyed_point_rides_on_its_free_bone() {
    // One skeleton along the bar, a point near its tip carried by the second bone, keyed 6 px
    // down; the tip dragged up by 80 px.
    let bar = bar_rig(serde_json::json!({
        "bones": [
            {"name": "b1", "head": [40, 100], "tail": [200, 100]},
            {"name": "b2", "parent": "b1", "head": [200, 100], "tail": [360, 100]}
        ],
        "points": [{"name": "p", "at": [330, 90], "parent": "b2"}]
    }));
    let mut pose = pose_with(vec![
        drag([30.0, 70.0], [30.0, 70.0]),
        drag([30.0, 130.0], [30.0, 130.0]),
        drag([370.0, 100.0], [350.0, 20.0]),
    ]);
    pose.points.insert(
        "p".into(),
        sinew::rig::pose::PointPose {
            translate: [0.0, 6.0],
            ..Default::default()
        },
    );
    let solution = bar.rig_ik().unwrap().transforms(&pose).unwrap();
    let (b2, p) = (&solution.transforms[1], &solution.transforms[2]);
    let at = Point::new(330.0, 90.0);
    // Where b2 carries the point's keyed place: the point is there, risen with the bar.
    let keyed = b2.apply(Point::new(330.0, 96.0));
    let shown = p.apply(at);
    println!("p at {shown:?}, b2 carries its keyed place to {keyed:?}");
    assert!((shown - keyed).norm() < 1e-6, "{shown:?} vs {keyed:?}");
    assert!(shown.y < at.y - 30.0, "the point stayed down: {shown:?}");
}

#[test]
fn a_soft_drag_pulls_without_being_met() {
    let mut ik = scene().rig_ik().unwrap();
    let mut drags = pins();
    let target = Point::new(180.0, 150.0);
    drags.push(IkDrag {
        at: Point::new(256.0, 150.0),
        to: target,
        weight: Some(0.05),
    });
    let solution = ik.transforms(&pose_with(drags.clone())).unwrap();
    let row = ik.drag_row(&drags[2]).unwrap();
    let p = sinew::ik::rig::skinned_position(&row.row, &solution.transforms);
    let moved = 256.0 - p.x;
    println!("soft drag: the head moved {moved:.1} px of 76");
    assert!(moved > 5.0 && moved < 75.0, "moved {moved}");
    assert!(solution.drag_error_px <= 0.05, "the pins stay hard");
}

#[test]
fn baking_reproduces_ik_driven_motion_with_plain_keys() {
    let animations: std::collections::BTreeMap<String, serde_json::Value> = serde_json::from_str(
        &std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("assets/character/animations.json"),
        )
        .unwrap(),
    )
    .unwrap();
    let lift = &sinew::anim::parse_animations(&animations).unwrap()["lift"];
    let fps = 10.0;
    let times: Vec<f64> = (0..=20).map(|k| k as f64 / fps).collect();
    let baked = sinew::playback::bake(scene(), lift, &times).unwrap();
    assert!(baked.ik.is_empty());
    let solved: Vec<Vec<Affine>> =
        sinew::scene::frames(scene(), lift, &times, sinew::scene::PlayOptions::default())
            .unwrap()
            .into_iter()
            .map(|frame| frame.transforms)
            .collect();
    let mut worst: f64 = 0.0;
    for (k, &t) in times.iter().enumerate() {
        let pose = baked.sample(t, false);
        assert!(pose.ik.is_empty());
        let from_keys = scene().pose_positions(&pose).unwrap();
        let from_ik = scene()
            .positions_from_transforms(&solved[k], &pose, sinew::skin::Blend::Linear)
            .unwrap();
        for (a, b) in from_keys.iter().flatten().zip(from_ik.iter().flatten()) {
            worst = worst.max((a - b).norm());
        }
    }
    println!("baked keys vs solved frames: {worst:.2e} px");
    assert!(
        worst < 1e-6,
        "baked keys miss the solved frames by {worst} px"
    );
}

#[test]
fn momentum_handles_lag_swing_and_settle() {
    let (lag, swing, settled) = tail_after_hip_jump(0.01);
    println!("tail tip: lags up to {lag:.1} px, swings to {swing:.1} px, ends {settled:.2} px off");
    // The tail's bones are rigid: it swings as a chain, lagging about 19 px.
    assert!(lag > 15.0, "the tail tip should trail the hip (lag {lag})");
    assert!(
        swing < -2.0,
        "the tail tip should swing past (swing {swing})"
    );
    assert!(settled < 1.0, "the tail should settle ({settled} px off)");
    let (stiff_lag, _, _) = tail_after_hip_jump(0.0);
    assert!(
        stiff_lag < 1.0,
        "without momentum the tail follows ({stiff_lag} px)"
    );
}

#[test]
fn momentum_does_not_depend_on_the_frame_rate() {
    // The same hip jump sampled at 24 and at 48 frames per second, and at 48 fps with every
    // other frame dropped in turn (steps of 1/48 and 1/24 s alternating): the tail tip's path,
    // compared at the frames they share, agrees within 10% of its largest lag, and all settle.
    // Inertia 0.03 s keeps ω·h small enough that implicit Euler's own step dependence
    // (numerical damping, first order) stays within that; a velocity extrapolated per frame
    // instead of per second, or a damping counted per frame, is off by 25–35% on these paths.
    let inertia_s = 0.03;
    let at =
        |fps: f64| -> Vec<f64> { (0..=(2.5 * fps) as usize).map(|k| k as f64 / fps).collect() };
    let fine = tail_offsets_at(inertia_s, &at(48.0));
    let coarse = tail_offsets_at(inertia_s, &at(24.0));
    let mut kept = vec![0usize];
    while let Some(&last) = kept.last() {
        let next = last + if kept.len() % 2 == 1 { 1 } else { 2 };
        if next >= fine.len() {
            break;
        }
        kept.push(next);
    }
    let irregular = tail_offsets_at(
        inertia_s,
        &kept.iter().map(|&k| k as f64 / 48.0).collect::<Vec<_>>(),
    );
    let lag = fine.iter().map(|x| x.abs()).fold(0.0, f64::max);
    let differ = |path: &[f64], frames: &mut dyn Iterator<Item = usize>| {
        path.iter()
            .zip(frames)
            .map(|(x, k)| (x - fine[k]).abs())
            .fold(0.0, f64::max)
    };
    let coarse_off = differ(&coarse, &mut (0..).map(|k| 2 * k));
    let irregular_off = differ(&irregular, &mut kept.iter().copied());
    println!(
        "48 fps: largest lag {lag:.1} px; 24 fps differs by {coarse_off:.2} px at most, irregular frames by {irregular_off:.2} px; ends {:.2}, {:.2}, {:.2} px",
        fine.last().unwrap(),
        coarse.last().unwrap(),
        irregular.last().unwrap()
    );
    assert!(coarse_off <= 0.1 * lag, "24 fps differs by {coarse_off} px");
    assert!(
        irregular_off <= 0.1 * lag,
        "irregular frames differ by {irregular_off} px"
    );
    for path in [&fine, &coarse, &irregular] {
        assert!(path.last().unwrap().abs() < 1.0, "settles");
    }
}

/// At 30 fps for 2.5 s (see [`tail_offsets_at`]): (largest lag, farthest swing past, final
/// offset), px.
fn tail_after_hip_jump(inertia_s: f64) -> (f64, f64, f64) {
    let times: Vec<f64> = (0..=75).map(|k| k as f64 / 30.0).collect();
    let offsets = tail_offsets_at(inertia_s, &times);
    let lag = offsets[..10].iter().cloned().fold(0.0, f64::max);
    let swing = offsets[8..].iter().cloned().fold(0.0, f64::min);
    (lag, swing, offsets.last().unwrap().abs())
}

/// The tail tip's offset from where a rigid tail would carry it (px), at each of `times_s`, as
/// the hip jumps 60 px left over a quarter second and then stands still. The first frame is
/// stepped as long as the second.
fn tail_offsets_at(inertia_s: f64, times_s: &[f64]) -> Vec<f64> {
    let meshes = scene().skinned_meshes().unwrap();
    let handles = &scene().doc.handles;
    let mut options = IkOptions::default();
    for name in ["tail_4", "tail_5", "tail_6"] {
        options.momentum.insert(name.into(), inertia_s);
    }
    let mut ik = RigIk::precompute(handles, meshes, options).unwrap();
    let columns = handle_columns(handles);
    let tip_bone = columns.iter().position(|c| c == "tail_6").unwrap();
    let tail_tip = Point::new(452.0, 214.0);
    let mut offsets = Vec::new();
    for (k, &t) in times_s.iter().enumerate() {
        let frame_time_s = if k == 0 {
            times_s[1] - times_s[0]
        } else {
            t - times_s[k - 1]
        };
        let x = -60.0 * (t / 0.25).min(1.0);
        let mut pose = Pose::default();
        pose.bones.insert(
            "hip".into(),
            sinew::rig::pose::BonePose {
                translate: [x, 0.0],
                ..Default::default()
            },
        );
        let solution = ik.step(&pose, frame_time_s).unwrap();
        offsets.push(solution.transforms[tip_bone].apply(tail_tip).x - (tail_tip.x + x));
    }
    offsets
}

#[test]
fn stretchable_bones_stretch_under_ik() {
    // The left forearm scaled 1.5× along its length while the head is dragged sideways: with
    // stretchable blending the hand past the forearm's tail is carried, keeping its size along
    // the forearm; linear blending scales it with the bone.
    let handles = &scene().doc.handles;
    let bone = handles
        .bones
        .iter()
        .position(|b| b.name == "arm_lower_l")
        .unwrap();
    let (head, tail) = (
        Point::new(handles.bones[bone].head[0], handles.bones[bone].head[1]),
        Point::new(handles.bones[bone].tail[0], handles.bones[bone].tail[1]),
    );
    let mut drags = pins();
    drags.push(drag([256.0, 150.0], [216.0, 160.0]));
    let mut pose = pose_with(drags);
    pose.bones.insert(
        "arm_lower_l".into(),
        sinew::rig::pose::BonePose {
            scale: [1.5, 1.0],
            ..Default::default()
        },
    );
    let solution = scene().rig_ik().unwrap().transforms(&pose).unwrap();
    assert!(solution.drag_error_px <= 0.05);
    let part = scene()
        .doc
        .parts
        .iter()
        .position(|p| p.name == "arm_lower_l")
        .unwrap();
    let rest = &scene().rest_positions()[part];
    let axis = tail - head;
    // The hand: rest vertices more than 5 px past the forearm's tail.
    let hand: Vec<usize> = (0..rest.len())
        .filter(|&i| (rest[i] - tail).dot(&axis) / axis.norm() > 5.0)
        .collect();
    assert!(hand.len() > 10, "{} hand vertices", hand.len());
    let posed_axis = {
        let a = solution.transforms[bone].linear * axis;
        a / a.norm()
    };
    // The hand's extent along the (posed) forearm, relative to its rest extent.
    let extent = |points: &[Point], along: nalgebra::Vector2<f64>| {
        let s: Vec<f64> = hand.iter().map(|&i| points[i].coords.dot(&along)).collect();
        s.iter().cloned().fold(f64::MIN, f64::max) - s.iter().cloned().fold(f64::MAX, f64::min)
    };
    let rest_extent = extent(rest, axis / axis.norm());
    let ratio = |blend| {
        let positions = scene()
            .positions_from_transforms(&solution.transforms, &pose, blend)
            .unwrap();
        extent(&positions[part], posed_axis) / rest_extent
    };
    let (stretch, linear) = (
        ratio(sinew::skin::Blend::Stretch),
        ratio(sinew::skin::Blend::Linear),
    );
    // Control: forward kinematics alone (no drags), where stretches always came from the pose.
    let mut fk_pose = pose.clone();
    fk_pose.ik.clear();
    let fk = scene().handle_transforms(&fk_pose).unwrap();
    let fk_positions = scene()
        .positions_from_transforms(&fk, &fk_pose, sinew::skin::Blend::Stretch)
        .unwrap();
    let fk_axis = {
        let a = fk[bone].linear * axis;
        a / a.norm()
    };
    let fk_stretch = extent(&fk_positions[part], fk_axis) / rest_extent;
    println!(
        "hand along the forearm: stretch blending {stretch:.3}×, linear {linear:.3}× its rest \
         extent (forward kinematics, stretch blending: {fk_stretch:.3}×)"
    );
    // Under IK the free upper arm is an affine map and shortens (the solver measures the
    // linearly blended shape, so it offsets part of the forearm's scale), so the hand is not
    // its rest size either way; but stretchable blending removes exactly the forearm's own
    // 1.5× from it, which linear blending keeps.
    assert!(
        (fk_stretch - 1.0).abs() < 0.05,
        "forward kinematics {fk_stretch}"
    );
    assert!(
        (linear / stretch - 1.5).abs() < 0.1,
        "linear {linear} vs stretch blending {stretch}"
    );
}

/// A static pose has one answer: pins added where points already are move nothing (each
/// vertex within 1e-6 px), even after drags that bend the character, and a solver that has
/// solved other poses gives the same answer as a fresh one.
#[test]
fn pins_where_points_already_are_move_nothing() {
    let mut ik = scene().rig_ik().unwrap();
    let meshes = scene().skinned_meshes().unwrap();
    let mut drags = pins();
    drags.push(drag([256.0, 150.0], [206.0, 175.0]));
    drags.push(drag([160.0, 330.0], [125.0, 240.0]));
    let before = ik.solve_pose(&pose_with(drags.clone())).unwrap();
    let shown = skinned(&meshes, &before.transforms);
    // Pin three more points of the drawing where they are drawn, one after the other.
    for (part, vertex) in [(0, 0), (meshes.len() / 2, 3), (meshes.len() - 1, 7)] {
        let at = meshes[part].rest[vertex];
        let to = shown[part][vertex];
        drags.push(drag([at.x, at.y], [to.x, to.y]));
        let after = ik.solve_pose(&pose_with(drags.clone())).unwrap();
        let moved = shown
            .iter()
            .flatten()
            .zip(skinned(&meshes, &after.transforms).iter().flatten())
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(
            moved < 1e-6,
            "a pin where the point is moved the drawing {moved} px"
        );
    }
    let pose = pose_with(drags);
    ik.solve_pose(&pose_with(pins())).unwrap();
    let used = ik.solve_pose(&pose).unwrap();
    let fresh = scene().rig_ik().unwrap().solve_pose(&pose).unwrap();
    assert_eq!(
        used.transforms, fresh.transforms,
        "the answer depends on the history"
    );
}
