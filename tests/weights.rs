//! Weights and posing end to end, on the bundled character and on generated shapes: partition
//! of unity, bounds, interpolation, locality, content awareness, and forward kinematics with
//! linear blend skinning (identity, whole-rig rigid motion, one bent joint).

use image::{Rgba, RgbaImage};
use sinew::geom::segment_distance;
use sinew::geom::{triangle_area2, Point, Vec2};
use sinew::io::{BuildOptions, RigDocument};
use sinew::pipeline::{self, Layer, Scene};
use sinew::rig::pose::{rotation, BonePose, PointPose};
use sinew::rig::{handle_columns, Bone, Handles, PointHandle, Pose};
use sinew::weights::WeightOptions;

mod common;

const SUM_TOLERANCE: f64 = 1e-9;

fn character() -> (Vec<Layer>, Handles) {
    common::character_layers()
}

fn rig(layers: &[Layer], handles: &Handles, options: &BuildOptions) -> RigDocument {
    pipeline::build_rig(layers, &std::env::temp_dir(), options, handles)
        .unwrap()
        .0
}

fn scene(layers: &[Layer], doc: RigDocument) -> Scene {
    let images: Vec<_> = layers.iter().map(|l| l.image.clone()).collect();
    Scene::new(doc, &images).unwrap()
}

fn layer(name: &str, image: RgbaImage) -> Layer {
    Layer::whole(
        name,
        std::env::temp_dir().join(format!("{name}.png")),
        image,
    )
}

/// Posing skins in f32 (the packed plan) on the f64 rest points: a motion lands within this of
/// the exact answer (f32 carries ~7 digits; displacements here are under a few hundred px).
const F32_SKINNING_TOLERANCE_PX: f64 = 1e-3;
#[test]
fn character_weights_sum_to_one_stay_bounded_and_interpolate() {
    let (layers, handles) = character();
    let doc = rig(&layers, &handles, &BuildOptions::default());
    let columns = handle_columns(&handles);
    for part in &doc.parts {
        let weights = part.weights.as_ref().expect("weights");
        assert_eq!(weights.handles, columns);
        for (i, row) in weights.rows.iter().enumerate() {
            let sum: f64 = row.iter().map(|e| e.1).sum();
            assert!(
                (sum - 1.0).abs() < SUM_TOLERANCE,
                "{}: row {i} sums to {sum}",
                part.name
            );
            assert!(
                row.iter().all(|e| (0.0..=1.0).contains(&e.1)),
                "{}: row {i} out of bounds",
                part.name
            );
            // A vertex lying on exactly one bone (not at a joint) belongs to it alone.
            let p = Point::new(part.mesh.vertices[i][0], part.mesh.vertices[i][1]);
            let on: Vec<usize> = handles
                .bones
                .iter()
                .enumerate()
                .filter(|(_, b)| segment_distance(p, b.head, b.tail).0 < 1e-6)
                .map(|(j, _)| j)
                .collect();
            if on.len() == 1 {
                assert_eq!(
                    row,
                    &vec![(on[0] as u32, 1.0)],
                    "{}: vertex {i} on bone {}",
                    part.name,
                    columns[on[0]]
                );
            }
        }
    }
}

/// An opaque bar, 300 × 40 px, on a 320 × 80 canvas.
fn bar(color: impl Fn(u32) -> [u8; 3]) -> RgbaImage {
    RgbaImage::from_fn(320, 80, |x, y| {
        if (10..310).contains(&x) && (20..60).contains(&y) {
            let c = color(x);
            Rgba([c[0], c[1], c[2], 255])
        } else {
            Rgba([0, 0, 0, 0])
        }
    })
}

fn cross_bone(name: &str, x: f64) -> Bone {
    Bone {
        name: name.into(),
        parent: None,
        head: Point::new(x, 10.0),
        tail: Point::new(x, 70.0),
    }
}

/// A bone chain's bounded solve reaches the rounding floor of its gradient residual long before
/// an absolute 1e-10 (|H||x| ~ 3e6 on the critter's hip): the solver must stop there rather than
/// spin to its iteration limit and report the bone unconverged.
#[test]
fn a_bone_chain_on_the_critter_converges_on_every_handle() {
    let point = |name: &str, at: [f64; 2]| PointHandle {
        name: name.into(),
        at: at.into(),
        parent: None,
    };
    let bone = |name: &str, parent: Option<&str>, head: [f64; 2], tail: [f64; 2]| Bone {
        name: name.into(),
        parent: parent.map(Into::into),
        head: head.into(),
        tail: tail.into(),
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
        ],
        ..Default::default()
    };
    let layers = [layer("critter", common::critter(256))];
    let (stopped, reports) = pipeline::build_rig(
        &layers,
        &std::env::temp_dir(),
        &BuildOptions::default(),
        &handles,
    )
    .unwrap();
    for report in &reports {
        assert!(report.unconverged.is_empty(), "{report:?}");
    }
    // Without the floor the same handles run to the iteration limit (30 iterations more, μ down
    // to 1e-42) and end within 1e-4 of where the floor stopped them: less than either answer's
    // distance to libigl's converged active set on this case (1.6e-4, tools/libigl-oracle).
    let mut no_floor = BuildOptions::default();
    no_floor.weights.bbw.residual_round_off = 0.0;
    let (limit, reports) =
        pipeline::build_rig(&layers, &std::env::temp_dir(), &no_floor, &handles).unwrap();
    assert!(reports.iter().any(|r| !r.unconverged.is_empty()));
    let dense = |doc: &RigDocument| -> Vec<f64> {
        doc.parts
            .iter()
            .flat_map(|p| {
                let w = p.weights.as_ref().expect("weights");
                w.rows.iter().flat_map(|row| {
                    let mut d = vec![0.0; w.handles.len()];
                    for &(c, v) in row {
                        d[c as usize] = v;
                    }
                    d
                })
            })
            .collect()
    };
    let worst = dense(&stopped)
        .iter()
        .zip(&dense(&limit))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!("critter weights, floor stop vs iteration limit: max difference {worst:.2e}");
    assert!(worst < 1e-4, "{worst}");
}

#[test]
fn weights_vanish_where_other_handles_cut_a_handle_off() {
    // Three bones across the bar's whole height split it into regions; the first bone's weight
    // must vanish beyond the second (to the interior-point solver's accuracy, which the libigl
    // comparison puts at about 1e-3).
    let layers = [layer("bar", bar(|_| [200, 100, 50]))];
    let handles = Handles {
        bones: vec![
            cross_bone("a", 60.0),
            cross_bone("b", 150.0),
            cross_bone("c", 250.0),
        ],
        ..Default::default()
    };
    let doc = rig(&layers, &handles, &BuildOptions::default());
    let part = &doc.parts[0];
    let weights = part.weights.as_ref().unwrap();
    const VANISHED: f64 = 1e-3;
    let beyond: Vec<f64> = part
        .mesh
        .vertices
        .iter()
        .zip(&weights.rows)
        .filter(|(v, _)| v[0] > 150.0 + 1e-6)
        .map(|(_, row)| row.iter().find(|e| e.0 == 0).map_or(0.0, |e| e.1))
        .collect();
    let largest = beyond.iter().cloned().fold(0.0, f64::max);
    eprintln!(
        "bone a beyond bone b: {} vertices, largest weight {largest:.1e}",
        beyond.len()
    );
    assert!(beyond.len() > 50);
    assert!(
        largest < VANISHED,
        "bone a keeps weight {largest} beyond bone b"
    );
    // Near its own bone, a dominates.
    let near_a = part
        .mesh
        .vertices
        .iter()
        .zip(&weights.rows)
        .filter(|(v, _)| (v[0] - 60.0).abs() < 1.0);
    for (v, row) in near_a {
        let a = row.iter().find(|e| e.0 == 0).map_or(0.0, |e| e.1);
        assert!(a > 0.9, "bone a has only {a} at {v:?}");
    }
}

/// Position along the bar's center line where `w` changes fastest, from mesh vertices near it.
fn steepest_x(doc: &RigDocument, handle: u32) -> f64 {
    let part = &doc.parts[0];
    let weights = part.weights.as_ref().unwrap();
    let mut samples: Vec<(f64, f64)> = part
        .mesh
        .vertices
        .iter()
        .zip(&weights.rows)
        .filter(|(v, _)| (v[1] - 40.0).abs() < 6.0)
        .map(|(v, row)| {
            (
                v[0],
                row.iter().find(|e| e.0 == handle).map_or(0.0, |e| e.1),
            )
        })
        .collect();
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Slope between samples at least a few px apart, to average out mesh irregularity.
    const SPAN_PX: f64 = 6.0;
    let mut best = (0.0, 0.0);
    for (i, &(x0, w0)) in samples.iter().enumerate() {
        if let Some(&(x1, w1)) = samples[i..].iter().find(|s| s.0 >= x0 + SPAN_PX) {
            let slope = (w1 - w0).abs() / (x1 - x0);
            if slope > best.0 {
                best = (slope, 0.5 * (x0 + x1));
            }
        }
    }
    best.1
}

#[test]
fn content_aware_weights_change_fastest_across_a_color_edge() {
    const EDGE_X: u32 = 110;
    let image = bar(|x| {
        if x < EDGE_X {
            [230, 40, 40]
        } else {
            [40, 60, 230]
        }
    });
    let layers = [layer("bar", image)];
    let handles = Handles {
        points: vec![
            PointHandle {
                name: "left".into(),
                at: Point::new(40.0, 40.0),
                parent: None,
            },
            PointHandle {
                name: "right".into(),
                at: Point::new(280.0, 40.0),
                parent: None,
            },
        ],
        ..Default::default()
    };
    let plain = rig(&layers, &handles, &BuildOptions::default());
    let aware_options = BuildOptions {
        weights: WeightOptions {
            content_aware: Some(200.0),
            ..Default::default()
        },
        ..Default::default()
    };
    let aware = rig(&layers, &handles, &aware_options);
    let (x_plain, x_aware) = (steepest_x(&plain, 0), steepest_x(&aware, 0));
    eprintln!("steepest change of the left handle's weight: plain at x = {x_plain:.1}, content-aware at x = {x_aware:.1}, color edge at {EDGE_X}");
    assert!(
        (x_aware - EDGE_X as f64).abs() < 8.0,
        "content-aware weights are steepest at {x_aware}"
    );
    assert!(
        (x_plain - EDGE_X as f64).abs() > 20.0,
        "plain weights are already steepest at the edge ({x_plain})"
    );
}

#[test]
fn identity_pose_reproduces_the_rest_mesh_exactly() {
    let (layers, handles) = character();
    let scene = scene(&layers, rig(&layers, &handles, &BuildOptions::default()));
    assert_eq!(
        scene.pose_positions(&Pose::default()).unwrap(),
        scene.rest_positions()
    );
}

#[test]
fn a_whole_rig_rigid_motion_moves_every_vertex_rigidly() {
    let (layers, handles) = character();
    let scene = scene(&layers, rig(&layers, &handles, &BuildOptions::default()));
    let (angle_deg, shift) = (23.0, Vec2::new(-12.0, 7.5));
    let r = rotation(angle_deg);
    let moved = |p: Point| r * p.coords + shift;
    let mut pose = Pose::default();
    for bone in handles.bones.iter().filter(|b| b.parent.is_none()) {
        let head = moved(bone.head) - bone.head.coords;
        pose.bones.insert(
            bone.name.clone(),
            BonePose {
                rotate: angle_deg,
                translate: [head.x, head.y],
                ..Default::default()
            },
        );
    }
    for point in &handles.points {
        let d = moved(point.at) - point.at.coords;
        pose.points.insert(
            point.name.clone(),
            PointPose {
                rotate: angle_deg,
                translate: [d.x, d.y],
                ..Default::default()
            },
        );
    }
    let posed = scene.pose_positions(&pose).unwrap();
    for (rest, posed) in scene.rest_positions().iter().zip(&posed) {
        for (p, q) in rest.iter().zip(posed) {
            let want = moved(Point::new(p.x, p.y));
            assert!(
                (q.coords - want).norm() < F32_SKINNING_TOLERANCE_PX,
                "{p:?} went to {q:?}, not {want:?}"
            );
        }
    }
}

#[test]
fn bending_one_joint_bends_the_limb_smoothly() {
    let (layers, handles) = character();
    let doc = rig(&layers, &handles, &BuildOptions::default());
    let scene = scene(&layers, doc.clone());
    let mut pose = Pose::default();
    pose.bones.insert(
        "arm_lower_l".into(),
        BonePose {
            rotate: 60.0,
            ..Default::default()
        },
    );
    let posed = scene.pose_positions(&pose).unwrap();
    let elbow = Point::new(332.0, 282.0);
    for (part, positions) in doc.parts.iter().zip(&posed) {
        if !part.name.starts_with("arm_") || !part.name.ends_with("_l") {
            continue;
        }
        // No triangle of the arm turns inside out.
        for t in &part.mesh.triangles {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            assert!(
                triangle_area2(a, b, c) > 0.0,
                "{}: triangle {t:?} inverted",
                part.name
            );
        }
        // Near the elbow the two bones blend; far from it, each vertex follows one bone.
        let weights = part.weights.as_ref().unwrap();
        let blended = part
            .mesh
            .vertices
            .iter()
            .zip(&weights.rows)
            .filter(|(v, row)| {
                (Point::new(v[0], v[1]) - elbow).norm() < 12.0
                    && row.iter().filter(|e| e.1 > 0.05).count() >= 2
            })
            .count();
        assert!(
            blended > 0,
            "{}: no blended vertices around the elbow",
            part.name
        );
    }
    // The hand turns about the elbow by the bone's rotation.
    let lower = doc
        .parts
        .iter()
        .position(|p| p.name == "arm_lower_l")
        .unwrap();
    let hand = Point::new(359.0, 345.0);
    let (i, _) = doc.parts[lower]
        .mesh
        .vertices
        .iter()
        .enumerate()
        .min_by(|a, b| {
            (Point::new(a.1[0], a.1[1]) - hand)
                .norm()
                .total_cmp(&(Point::new(b.1[0], b.1[1]) - hand).norm())
        })
        .unwrap();
    let rest = Point::new(
        doc.parts[lower].mesh.vertices[i][0],
        doc.parts[lower].mesh.vertices[i][1],
    );
    let want = elbow + rotation(60.0) * (rest - elbow);
    assert!(
        (posed[lower][i] - want).norm() < 1.0,
        "hand at {:?}, expected {want:?}",
        posed[lower][i]
    );
}

#[test]
fn cages_reaching_past_the_shape_and_regions_get_weights() {
    use sinew::rig::{Cage, Region};
    let layers = [layer("bar", bar(|_| [90, 160, 60]))];
    // The cage sticks out above and below the bar; the region is a patch inside it.
    let handles = Handles {
        cages: vec![Cage {
            name: "cage".into(),
            polygon: vec![
                Point::new(0.0, 5.0),
                Point::new(320.0, 5.0),
                Point::new(320.0, 75.0),
                Point::new(0.0, 75.0),
            ],
        }],
        regions: vec![Region {
            name: "patch".into(),
            polygon: vec![
                Point::new(140.0, 30.0),
                Point::new(170.0, 30.0),
                Point::new(170.0, 50.0),
                Point::new(140.0, 50.0),
            ],
        }],
        ..Default::default()
    };
    let doc = rig(&layers, &handles, &BuildOptions::default());
    let part = &doc.parts[0];
    let weights = part.weights.as_ref().unwrap();
    assert_eq!(
        weights.handles,
        ["cage.0", "cage.1", "cage.2", "cage.3", "patch"]
    );
    for (v, row) in part.mesh.vertices.iter().zip(&weights.rows) {
        assert!((row.iter().map(|e| e.1).sum::<f64>() - 1.0).abs() < SUM_TOLERANCE);
        let inside_patch = (140.0..=170.0).contains(&v[0]) && (30.0..=50.0).contains(&v[1]);
        if inside_patch {
            assert_eq!(row, &vec![(4, 1.0)], "vertex {v:?} inside the region");
        }
    }
    // The drawn mesh stays the sprite's: nothing of the cage's outside part is drawn.
    assert!(part
        .mesh
        .vertices
        .iter()
        .all(|v| v[1] > 15.0 && v[1] < 65.0));
    // Moving every cage vertex by the same offset (and the region with it) translates the bar.
    let scene = scene(&layers, doc.clone());
    let mut pose = Pose::default();
    let shift = Vec2::new(6.0, -4.0);
    let polygon = handles.cages[0].polygon.iter().map(|p| p + shift).collect();
    pose.cages
        .insert("cage".into(), sinew::rig::pose::CagePose { polygon });
    let posed = scene.pose_positions(&pose).unwrap();
    for (p, q) in scene.rest_positions()[0].iter().zip(&posed[0]) {
        let w_patch = weights.rows[scene.rest_positions()[0]
            .iter()
            .position(|r| r == p)
            .unwrap()]
        .iter()
        .find(|e| e.0 == 4)
        .map_or(0.0, |e| e.1);
        // The region stays at rest (nothing posed it), so its share of each vertex does not move.
        let want = Point::new(
            p.x + (1.0 - w_patch) * shift[0],
            p.y + (1.0 - w_patch) * shift[1],
        );
        assert!(
            (q - want).norm() < F32_SKINNING_TOLERANCE_PX,
            "{q:?} not {want:?}"
        );
    }
}

#[test]
fn a_bound_handle_leaves_other_parts_alone() {
    // Two layers overlapping in the middle of the bar; bone "b" crosses both but is bound to
    // the first: the second layer's mesh must not carry it nor any of its weight.
    let layers = [
        layer("front", bar(|_| [200, 100, 50])),
        layer("back", bar(|_| [50, 100, 200])),
    ];
    let mut handles = Handles {
        bones: vec![cross_bone("a", 60.0), cross_bone("b", 150.0)],
        ..Default::default()
    };
    handles.bind.insert("b".into(), vec!["front".into()]);
    let doc = rig(&layers, &handles, &BuildOptions::default());
    let weight_of_b = |part: usize| -> f64 {
        let rows = &doc.parts[part].weights.as_ref().unwrap().rows;
        rows.iter()
            .flat_map(|row| row.iter().filter(|e| e.0 == 1).map(|e| e.1))
            .fold(0.0, f64::max)
    };
    assert!(weight_of_b(0) > 0.99, "b weighs its own part");
    assert_eq!(weight_of_b(1), 0.0, "b must not weigh the other part");
    // Bound to a part that is not a layer: a clear error.
    handles.bind.insert("b".into(), vec!["nowhere".into()]);
    let err = pipeline::build_rig(
        &layers,
        &std::env::temp_dir(),
        &BuildOptions::default(),
        &handles,
    )
    .expect_err("an unknown part is an error");
    assert!(err.to_string().contains("'nowhere'"), "{err}");
}

/// An exact axis-aligned rectangle traces with a vertex where its outline runs straight on;
/// meshing used to split the collinear edges into slivers of 1e-16 px² whose cotangents made
/// the biharmonic systems unfactorable.
#[test]
fn an_exact_rectangle_gets_weights_with_every_method() {
    let image = RgbaImage::from_fn(400, 200, |x, y| {
        if (20..380).contains(&x) && (40..160).contains(&y) {
            Rgba([200, 120, 60, 255])
        } else {
            Rgba([0, 0, 0, 0])
        }
    });
    let layers = [layer("rectangle", image)];
    let handles = Handles {
        bones: vec![Bone {
            name: "arm".into(),
            parent: None,
            head: Point::new(40.0, 100.0),
            tail: Point::new(110.0, 100.0),
        }],
        ..Default::default()
    };
    for method in [
        sinew::weights::WeightMethod::Bbw,
        sinew::weights::WeightMethod::Biharmonic,
        sinew::weights::WeightMethod::Harmonic,
    ] {
        let mut options = BuildOptions::default();
        options.weights.method = method;
        let (doc, _) = pipeline::build_rig(&layers, &std::env::temp_dir(), &options, &handles)
            .unwrap_or_else(|e| panic!("{method:?}: {e}"));
        let part = &doc.parts[0];
        let v = &part.mesh.vertices;
        for t in &part.mesh.triangles {
            let p = t.map(|i| Point::new(v[i as usize][0], v[i as usize][1]));
            assert!(
                sinew::mesh::triangle_min_angle_deg(p) > 1.0,
                "{method:?}: sliver {p:?}"
            );
        }
    }
}
