//! Automatic rigging on generated shapes (a star, a letter with a hole, stick figures, a blob,
//! each also with noise on its outline) and on the bundled character: bones inside the shape,
//! limb tips at bone ends, noise adds no bones, the humanoid template names and parents the
//! character's limbs, cages contain every opaque pixel, points start at extremities; then
//! `sinew autorig` → `sinew rig --handles` → `sinew pose` with no manual step, and a golden
//! image of the proposed rig over the character.

#[cfg(feature = "cli")]
mod command;
mod common;
// The generated shapes, beside this file (a test crate root looks for modules in tests/).
#[path = "autorig/shapes.rs"]
mod shapes;

#[cfg(feature = "cli")]
use command::{scratch, sinew};
use image::RgbaImage;
use shapes::{blob, capsules, letter_p, quadruped, star, stick_figure, stick_tips, to_rgba};
use sinew::autorig::shape::Shape;
use sinew::autorig::{autorig, AutorigOptions, LayerRef, TemplateChoice};
use sinew::geom::segments_touch;
use sinew::geom::{point_in_ring, Point};
use sinew::rig::Handles;
use sinew::trace::TraceOptions;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use tiny_skia::Pixmap;

// ---------------------------------------------------------------- helpers

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn assets() -> PathBuf {
    root().join("assets/character")
}

fn load(path: &Path) -> RgbaImage {
    sinew::io::load_png(path).expect("a PNG")
}

fn propose(images: &[(&str, &RgbaImage)], options: &AutorigOptions) -> Handles {
    let layers: Vec<LayerRef> = images
        .iter()
        .map(|(name, image)| LayerRef::whole(name, image))
        .collect();
    autorig(&layers, &[], options).expect("autorig").handles
}

/// Bones of the medial axis (no template).
fn one(image: &RgbaImage) -> Handles {
    let options = AutorigOptions {
        template: TemplateChoice::None,
        ..AutorigOptions::default()
    };
    propose(&[("shape", image)], &options)
}

/// With `SINEW_AUTORIG_DUMP=DIR`, writes the proposal drawn over `image` to DIR/`name`.png
/// (to look at a failing case).
fn dump(name: &str, image: &RgbaImage, handles: &Handles) {
    if let Some(dir) = std::env::var_os("SINEW_AUTORIG_DUMP") {
        let picture =
            sinew::autorig::draw_preview(&[LayerRef::whole("sprite", image)], handles).unwrap();
        sinew::io::save_png(&Path::new(&dir).join(format!("{name}.png")), &picture).unwrap();
    }
}

fn traced(image: &RgbaImage) -> Shape {
    Shape::trace(image, &TraceOptions::default())
        .expect("traces")
        .expect("a shape")
}

fn pt(a: impl Into<Point>) -> Point {
    a.into()
}

/// Every bone, sampled every half pixel, lies inside the traced outlines.
fn assert_bones_inside(handles: &Handles, shape: &Shape, what: &str) {
    assert!(!handles.bones.is_empty(), "{what}: no bones");
    for b in &handles.bones {
        let (h, t) = (pt(b.head), pt(b.tail));
        let steps = ((t - h).norm() * 2.0).ceil() as usize + 1;
        for s in 0..=steps {
            let p = h + (t - h) * (s as f64 / steps as f64);
            assert!(
                shape.contains(p),
                "{what}: bone {} leaves the shape at {p:?}",
                b.name
            );
        }
    }
}

/// Distance from `p` to the nearest bone end (head or tail).
fn nearest_bone_end(handles: &Handles, p: Point) -> f64 {
    handles
        .bones
        .iter()
        .flat_map(|b| [pt(b.head), pt(b.tail)])
        .map(|e| (e - p).norm())
        .fold(f64::INFINITY, f64::min)
}

/// Limb tips are the centers of round caps or sharp corners: bone ends are within this, px.
const TIP_TOLERANCE_PX: f64 = 6.0;

fn assert_tips_at_bone_ends(handles: &Handles, tips: &[Point], what: &str) {
    for &tip in tips {
        let d = nearest_bone_end(handles, tip);
        assert!(
            d <= TIP_TOLERANCE_PX,
            "{what}: limb tip {tip:?} is {d:.1} px from the nearest bone end"
        );
    }
}

// ---------------------------------------------------------------- skeletons

#[test]
fn stick_figure_bones_inside_with_a_bone_end_at_every_limb_tip() {
    let image = stick_figure(false);
    let h = one(&image);
    dump("stick", &image, &h);
    assert_bones_inside(&h, &traced(&image), "stick figure");
    assert_tips_at_bone_ends(&h, &stick_tips(), "stick figure");
    h.validate().unwrap();
}

#[test]
fn star_bones_reach_every_point_of_the_star() {
    for noise in [false, true] {
        let (image, tips) = star(noise);
        let h = one(&image);
        let what = if noise { "noisy star" } else { "star" };
        dump(what, &image, &h);
        assert_bones_inside(&h, &traced(&image), what);
        assert_tips_at_bone_ends(&h, &tips, what);
    }
}

#[test]
fn letter_with_a_hole_keeps_bones_off_the_hole() {
    let (image, tips) = letter_p();
    let shape = traced(&image);
    assert_eq!(shape.outlines[0].holes.len(), 1, "the P has its hole");
    let h = one(&image);
    dump("letter", &image, &h);
    assert_bones_inside(&h, &shape, "letter P");
    assert_tips_at_bone_ends(&h, &tips, "letter P");
    // The bowl is rigged all around its hole: some bone passes on each side of it.
    let sides = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)];
    for (dx, dy) in sides {
        let probe = Point::new(120.0 + 43.0 * dx, 95.0 + 43.0 * dy);
        let near = h
            .bones
            .iter()
            .any(|b| sinew::geom::segment_distance(probe, pt(b.head), pt(b.tail)).0 < 12.0);
        assert!(near, "no bone in the bowl near {probe:?}");
    }
}

#[test]
fn outline_noise_adds_no_bones() {
    let clean = one(&stick_figure(false));
    let noisy = one(&stick_figure(true));
    let noisy_image = stick_figure(true);
    dump("noisy stick", &noisy_image, &noisy);
    dump("blob", &blob(false), &one(&blob(false)));
    dump("noisy blob", &blob(true), &one(&blob(true)));
    assert_bones_inside(&noisy, &traced(&noisy_image), "noisy stick figure");
    assert_tips_at_bone_ends(&noisy, &stick_tips(), "noisy stick figure");
    assert_eq!(
        noisy.bones.len(),
        clean.bones.len(),
        "the noisy stick figure has other bones than the clean one"
    );
    let (clean_blob, noisy_blob) = (one(&blob(false)), one(&blob(true)));
    assert_eq!(noisy_blob.bones.len(), clean_blob.bones.len(), "noisy blob");
    assert_bones_inside(&noisy_blob, &traced(&blob(true)), "noisy blob");
    let (clean_star, noisy_star) = (one(&star(false).0), one(&star(true).0));
    assert_eq!(noisy_star.bones.len(), clean_star.bones.len(), "noisy star");
}

#[test]
fn the_bone_budget_is_respected() {
    let image = star(false).0;
    for max in [1, 3, 5, 8] {
        let mut options = AutorigOptions::default();
        options.skeleton.max_bones = Some(max);
        let h = propose(&[("star", &image)], &options);
        assert!(
            h.bones.len() <= max,
            "{} bones for a budget of {max}",
            h.bones.len()
        );
        assert!(!h.bones.is_empty());
        assert_bones_inside(&h, &traced(&image), "star with a budget");
    }
}

fn character_flat() -> RgbaImage {
    load(&assets().join("flat.png"))
}

fn humanoid(image: &RgbaImage) -> Handles {
    let options = AutorigOptions {
        template: TemplateChoice::Humanoid,
        ..AutorigOptions::default()
    };
    propose(&[("flat", image)], &options)
}

#[test]
fn humanoid_template_names_and_parents_the_characters_limbs() {
    let image = character_flat();
    let h = humanoid(&image);
    assert_bones_inside(&h, &traced(&image), "character");
    let by_name: HashMap<&str, &sinew::rig::Bone> =
        h.bones.iter().map(|b| (b.name.as_str(), b)).collect();
    let expected_parents = [
        ("hip", None),
        ("chest", Some("hip")),
        ("neck", Some("chest")),
        ("head", Some("neck")),
        ("arm_upper_l", Some("chest")),
        ("arm_lower_l", Some("arm_upper_l")),
        ("arm_upper_r", Some("chest")),
        ("arm_lower_r", Some("arm_upper_r")),
        ("leg_upper_l", Some("hip")),
        ("leg_lower_l", Some("leg_upper_l")),
        ("leg_upper_r", Some("hip")),
        ("leg_lower_r", Some("leg_upper_r")),
    ];
    for (name, parent) in expected_parents {
        let bone = by_name
            .get(name)
            .unwrap_or_else(|| panic!("no bone '{name}'"));
        assert_eq!(bone.parent.as_deref(), parent, "parent of {name}");
    }
    // The limbs are where the character's hand-made rig has them (assets/character/handles.json):
    // every elbow, knee, hand and ankle within 16 px.
    let truth: Handles =
        serde_json::from_str(&std::fs::read_to_string(assets().join("handles.json")).unwrap())
            .unwrap();
    for limb in [
        "arm_upper_l",
        "arm_lower_l",
        "arm_upper_r",
        "arm_lower_r",
        "leg_upper_l",
        "leg_lower_l",
        "leg_upper_r",
        "leg_lower_r",
    ] {
        let ours = pt(by_name[limb].tail);
        let theirs = pt(truth.bones.iter().find(|b| b.name == limb).unwrap().tail);
        let d = (ours - theirs).norm();
        assert!(d < 16.0, "{limb} ends {d:.1} px from the hand-made rig's");
    }
    // The character's left (screen right) is "_l".
    assert!(by_name["arm_lower_l"].tail[0] > by_name["arm_lower_r"].tail[0]);
}

#[test]
fn quadruped_template_finds_head_tail_and_four_legs() {
    let image = quadruped();
    let options = AutorigOptions {
        template: TemplateChoice::Quadruped,
        ..AutorigOptions::default()
    };
    dump("dog", &image, &one(&image));
    let h = propose(&[("dog", &image)], &options);
    dump("dog template", &image, &h);
    assert_bones_inside(&h, &traced(&image), "quadruped");
    let by_name: HashMap<&str, &sinew::rig::Bone> =
        h.bones.iter().map(|b| (b.name.as_str(), b)).collect();
    for (name, parent) in [
        ("hip", None),
        ("chest", Some("hip")),
        ("neck", Some("chest")),
        ("head", Some("neck")),
        ("tail_1", Some("hip")),
        ("leg_front_upper_l", Some("chest")),
        ("leg_front_upper_r", Some("chest")),
        ("leg_back_upper_l", Some("hip")),
        ("leg_back_upper_r", Some("hip")),
        ("leg_back_lower_r", Some("leg_back_upper_r")),
    ] {
        let bone = by_name
            .get(name)
            .unwrap_or_else(|| panic!("no bone '{name}'"));
        assert_eq!(bone.parent.as_deref(), parent, "parent of {name}");
    }
    // The head is the round end up front (the head bone or the extra bones it carries reach
    // its center), the tail at the back.
    let head_center = Point::new(40.0, 50.0);
    let nearest = h
        .bones
        .iter()
        .min_by(|a, b| {
            (pt(a.tail) - head_center)
                .norm()
                .total_cmp(&(pt(b.tail) - head_center).norm())
        })
        .unwrap();
    assert!((pt(nearest.tail) - head_center).norm() < TIP_TOLERANCE_PX);
    let mut at = Some(nearest.name.as_str());
    while at.is_some_and(|n| n != "head") {
        at = by_name[at.unwrap()].parent.as_deref();
    }
    assert_eq!(
        at,
        Some("head"),
        "the head's center is not on the head's chain"
    );
    assert!(by_name["tail_1"].tail[0] > 180.0);
    // Front legs are near the head's end, back legs near the tail's.
    for leg in ["leg_front_lower_l", "leg_front_lower_r"] {
        assert!(by_name[leg].tail[0] < 128.0, "{leg}");
        assert!(by_name[leg].tail[1] > 180.0, "{leg} does not reach down");
    }
    for leg in ["leg_back_lower_l", "leg_back_lower_r"] {
        assert!(by_name[leg].tail[0] > 128.0, "{leg}");
    }
}

/// The bundled character's layer files, back to front, as command-line arguments.
#[cfg(feature = "cli")]
fn character_layer_paths() -> Vec<String> {
    character_layers()
        .into_iter()
        .map(|(n, _)| {
            assets()
                .join(format!("{n}.png"))
                .to_str()
                .unwrap()
                .to_string()
        })
        .collect()
}

fn character_layers() -> Vec<(String, RgbaImage)> {
    let list: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(assets().join("layers.json")).unwrap())
            .unwrap();
    list["layers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| {
            let name = n.as_str().unwrap().to_string();
            let image = load(&assets().join(format!("{name}.png")));
            (name, image)
        })
        .collect()
}

/// The bundled character's layers, proposed as a layered file is (automatic template).
fn character_proposal() -> (Vec<(String, RgbaImage)>, sinew::autorig::Proposal) {
    let layers = character_layers();
    let refs: Vec<LayerRef> = layers.iter().map(|(n, i)| LayerRef::whole(n, i)).collect();
    let proposal = autorig(&refs, &[], &AutorigOptions::default()).expect("autorig");
    (layers, proposal)
}

#[test]
fn layers_are_body_parts_with_their_own_bones_bound_to_them() {
    let (layers, proposal) = character_proposal();
    let h = &proposal.handles;
    assert_eq!(proposal.template, Some(sinew::autorig::Template::Humanoid));
    for (name, image) in &layers {
        // Every part has a bone; each bone is bound to its part alone and lies inside it.
        let own: Vec<&sinew::rig::Bone> = h
            .bones
            .iter()
            .filter(|b| h.bind[&b.name] == vec![name.clone()])
            .collect();
        assert!(!own.is_empty(), "part {name} has no bone");
        let shape = traced(image);
        for b in own {
            assert!(
                shape.segment_inside(pt(b.head), pt(b.tail)),
                "bone {} leaves part {name}",
                b.name
            );
        }
    }
    assert!(
        h.bones.iter().all(|b| h.bind[&b.name].len() == 1),
        "a bone weighs two parts"
    );
}

#[test]
fn layered_hierarchy_is_what_an_animator_builds() {
    let (layers, proposal) = character_proposal();
    let h = &proposal.handles;
    let by_name: HashMap<&str, &sinew::rig::Bone> =
        h.bones.iter().map(|b| (b.name.as_str(), b)).collect();
    let parent = |n: &str| by_name[n].parent.as_deref();
    let part_of = |n: &str| h.bind[n][0].as_str();
    // The root at the hips: the torso's lower bone, from its bottom up.
    let roots: Vec<&str> = h
        .bones
        .iter()
        .filter(|b| b.parent.is_none())
        .map(|b| b.name.as_str())
        .collect();
    assert_eq!(roots, ["hip"]);
    assert_eq!(part_of("hip"), "torso");
    assert_eq!(parent("chest"), Some("hip"));
    assert!(
        by_name["hip"].head[1] > by_name["chest"].tail[1],
        "the spine runs up"
    );
    // Limbs: template names from the layer names, chains joined at the layers' seams.
    for side in ["l", "r"] {
        let bone = |n: &str| format!("{n}_{side}");
        assert_eq!(parent(&bone("arm_upper")), Some("chest"));
        assert_eq!(parent(&bone("arm_lower")), Some(bone("arm_upper").as_str()));
        assert_eq!(parent(&bone("leg_upper")), Some("hip"));
        assert_eq!(parent(&bone("leg_lower")), Some(bone("leg_upper").as_str()));
        for limb in ["arm", "leg"] {
            let (upper, lower) = (
                by_name[bone(&format!("{limb}_upper")).as_str()],
                by_name[bone(&format!("{limb}_lower")).as_str()],
            );
            assert_eq!(upper.tail, lower.head, "{limb}_{side} is not one chain");
        }
    }
    // The tail hangs from the hips, not from a thigh it passes behind; the lantern from the
    // hand that holds it; the head from the chest, turning at the neck.
    let tail_root = h
        .bones
        .iter()
        .find(|b| {
            part_of(&b.name) == "tail"
                && by_name[b.parent.as_deref().unwrap()].name != b.name
                && part_of(b.parent.as_deref().unwrap()) != "tail"
        })
        .expect("a tail bone hangs from another part");
    assert_eq!(tail_root.parent.as_deref(), Some("hip"));
    let bag = h
        .bones
        .iter()
        .find(|b| part_of(&b.name) == "bag")
        .expect("the lantern has a bone");
    assert_eq!(bag.parent.as_deref(), Some("arm_lower_r"));
    assert_eq!(parent("head"), Some("chest"));
    let head_image = &layers.iter().find(|l| l.0 == "head").unwrap().1;
    let head_shape = traced(head_image);
    let torso_shape = traced(&layers.iter().find(|l| l.0 == "torso").unwrap().1);
    let pivot = pt(by_name["head"].head);
    assert!(
        head_shape.contains(pivot) && torso_shape.contains(pivot),
        "the head turns where it overlaps the torso (the neck), not at {pivot:?}"
    );
    assert!(
        by_name["head"].tail[1] < by_name["head"].head[1],
        "the head bone points up"
    );
    // Nothing is named extra_N or bone_N: every bone has a template or layer name.
    assert!(h
        .bones
        .iter()
        .all(|b| !b.name.starts_with("extra_") && !b.name.starts_with("bone_")));
}

#[test]
fn parts_that_overlap_nothing_hang_from_the_nearest_part() {
    let mut a = Pixmap::new(200, 100).unwrap();
    capsules(&mut a, &[((20.0, 50.0), (80.0, 50.0))], 20.0);
    let mut b = Pixmap::new(200, 100).unwrap();
    capsules(&mut b, &[((120.0, 30.0), (180.0, 70.0))], 20.0);
    let (a, b) = (to_rgba(&a), to_rgba(&b));
    let options = AutorigOptions {
        template: TemplateChoice::None,
        ..AutorigOptions::default()
    };
    let h = propose(&[("a", &a), ("b", &b)], &options);
    assert_eq!(h.bones.len(), 2);
    // The larger capsule is the root, along its axis; the other hangs from it, its bone
    // from the joint (their closest points) along its own axis.
    let bb = h.bones.iter().find(|x| x.name == "b").unwrap();
    assert_eq!(bb.parent, None);
    let dir = pt(bb.tail) - pt(bb.head);
    assert!((dir.y / dir.x - 40.0 / 60.0).abs() < 0.05, "{dir:?}");
    let ba = h.bones.iter().find(|x| x.name == "a").unwrap();
    assert_eq!(ba.parent.as_deref(), Some("b"));
    assert!(
        ba.head[0] > ba.tail[0],
        "a's bone starts at its end nearer b"
    );
    assert!(
        (ba.head[1] - ba.tail[1]).abs() < 3.0,
        "a's bone follows its axis"
    );
}

// ---------------------------------------------------------------- cages and points

fn assert_cage_contains_every_opaque_pixel(
    image: &RgbaImage,
    ring: &[Point],
    max: usize,
    what: &str,
) {
    assert!(ring.len() <= max, "{what}: {} vertices > {max}", ring.len());
    for (x, y, px) in image.enumerate_pixels() {
        if px[3] == 0 {
            continue;
        }
        for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            let p = Point::new(x as f64 + dx, y as f64 + dy);
            assert!(
                point_in_ring(p, ring),
                "{what}: pixel corner {p:?} outside the cage"
            );
        }
    }
    // Simple: no two non-adjacent edges touch.
    let n = ring.len();
    for i in 0..n {
        for j in (i + 2)..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            assert!(
                !segments_touch(ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n]),
                "{what}: cage edges {i} and {j} cross"
            );
        }
    }
}

#[test]
fn cages_contain_every_opaque_pixel_with_at_most_n_vertices() {
    let flat = character_flat();
    let mut cases: Vec<(&str, RgbaImage)> = vec![
        ("character", flat),
        ("star", star(true).0),
        ("letter", letter_p().0),
        ("stick figure", stick_figure(true)),
    ];
    cases.push(("blob", blob(true)));
    for (what, image) in &cases {
        for max in [6, 12, 24] {
            let options = AutorigOptions {
                cage_vertices: Some(max),
                ..AutorigOptions::default()
            };
            let h = propose(&[("x", image)], &options);
            let ring: Vec<Point> = h.cages[0].polygon.iter().map(|&p| pt(p)).collect();
            assert_cage_contains_every_opaque_pixel(image, &ring, max, what);
        }
    }
    // The cage hugs the shape: the star's 12-vertex cage is far smaller than its bounding box.
    let options = AutorigOptions {
        cage_vertices: Some(12),
        ..AutorigOptions::default()
    };
    let h = propose(&[("star", &star(false).0)], &options);
    let ring: Vec<Point> = h.cages[0].polygon.iter().map(|&p| pt(p)).collect();
    let area = sinew::geom::ring_signed_area(&ring).abs();
    assert!(area < 0.75 * 220.0 * 210.0, "star cage area {area:.0} px²");
}

#[test]
fn first_points_land_on_the_extremities_and_all_lie_inside() {
    let (image, tips) = star(false);
    let options = AutorigOptions {
        point_count: 9,
        ..AutorigOptions::default()
    };
    let h = propose(&[("star", &image)], &options);
    assert_eq!(h.points.len(), 9);
    let shape = traced(&image);
    for p in &h.points {
        assert!(shape.contains(pt(p.at)), "{} outside", p.name);
    }
    // The first five are the star's five points (within 20 px of each tip, one per tip).
    for tip in &tips {
        let d = h.points[..5]
            .iter()
            .map(|p| (pt(p.at) - tip).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(d < 20.0, "no early point near tip {tip:?} ({d:.1} px)");
    }
    // Each is carried by its nearest bone, so a tip's point turns with the arm it ends.
    for p in &h.points {
        let distance = |b: &sinew::rig::Bone| sinew::geom::segment_distance(p.at, b.head, b.tail).0;
        let carrier = h.bones.iter().find(|b| Some(&b.name) == p.parent.as_ref());
        let carrier = carrier.unwrap_or_else(|| panic!("{} is loose", p.name));
        let nearest = h.bones.iter().map(distance).fold(f64::INFINITY, f64::min);
        assert_eq!(
            distance(carrier),
            nearest,
            "{} rides on {}",
            p.name,
            carrier.name
        );
    }
}

#[test]
fn proposals_are_deterministic() {
    let image = character_flat();
    let options = AutorigOptions {
        template: TemplateChoice::Humanoid,
        cage_vertices: Some(16),
        point_count: 5,
        ..AutorigOptions::default()
    };
    let a = serde_json::to_string(&propose(&[("flat", &image)], &options)).unwrap();
    let b = serde_json::to_string(&propose(&[("flat", &image)], &options)).unwrap();
    assert_eq!(a, b);
}

// ---------------------------------------------------------------- end to end and golden

#[cfg(feature = "cli")]
fn ok(out: &std::process::Output, what: &str) {
    assert!(
        out.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[cfg(feature = "cli")]
#[test]
fn autorig_then_rig_then_pose_works_with_no_manual_step() {
    let tmp = scratch("e2e");
    let dir = tmp.path();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let flat = s(&assets().join("flat.png"));
    let handles = dir.join("handles.json");
    let handles_s = s(&handles);
    let out = sinew(&[
        "autorig",
        &flat,
        "-o",
        &s(&handles),
        "--template",
        "humanoid",
    ]);
    ok(&out, "autorig");
    for weights in [
        &["--weights", "bbw"][..],
        &["--weights", "rigid", "--blend", "8"][..],
    ] {
        let rig = dir.join("rig.json");
        let mut args = vec!["rig", &flat, "--handles", &handles_s, "-o"];
        let rig_s = s(&rig);
        args.push(&rig_s);
        args.extend(weights);
        ok(&sinew(&args), "rig");
        let pose = dir.join("pose.json");
        std::fs::write(
            &pose,
            r#"{"bones": {"arm_upper_l": {"rotate": 40}, "arm_lower_l": {"rotate": 30},
                          "leg_upper_r": {"rotate": -15}, "head": {"rotate": 8}}}"#,
        )
        .unwrap();
        let (posed, rest, vertices) = (
            dir.join("posed.png"),
            dir.join("rest.png"),
            dir.join("v.json"),
        );
        ok(
            &sinew(&[
                "pose",
                &rig_s,
                "--pose",
                &s(&pose),
                "-o",
                &s(&posed),
                "--vertices",
                &s(&vertices),
            ]),
            "pose",
        );
        ok(&sinew(&["pose", &rig_s, "-o", &s(&rest)]), "rest pose");
        // The rest pose draws the sprite back; the pose moves the raised forearm's hand away.
        let (posed, rest) = (load(&posed), load(&rest));
        let hand = |img: &RgbaImage| img.get_pixel(358, 343)[3];
        assert!(hand(&rest) > 200, "{weights:?}: the hand at rest");
        assert!(hand(&posed) < 50, "{weights:?}: the hand did not move");
        // Skinning IK on the proposed rig: feet pinned, the left hand dragged up and out.
        let drag = dir.join("drag.json");
        std::fs::write(
            &drag,
            r#"{"ik": [{"at": [305, 440], "to": [305, 440]}, {"at": [207, 440], "to": [207, 440]},
                       {"at": [356, 340], "to": [410, 260]}]}"#,
        )
        .unwrap();
        let dragged = dir.join("dragged.png");
        ok(
            &sinew(&["pose", &rig_s, "--pose", &s(&drag), "-o", &s(&dragged)]),
            "pose with ik drags",
        );
        let dragged = load(&dragged);
        assert!(
            hand(&dragged) < 50,
            "{weights:?}: the dragged hand did not move"
        );
        assert!(
            dragged.get_pixel(410, 260)[3] > 200,
            "{weights:?}: the hand did not arrive"
        );
        assert!(
            dragged.get_pixel(305, 440)[3] > 200,
            "{weights:?}: a pinned foot moved"
        );
        // Rigid weights: at most two influences per vertex.
        if weights.contains(&"rigid") {
            let doc: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&rig).unwrap()).unwrap();
            for row in doc["parts"][0]["weights"]["rows"].as_array().unwrap() {
                assert!(row.as_array().unwrap().len() <= 2);
            }
        }
    }
}

#[cfg(feature = "cli")]
#[test]
fn layered_autorig_then_rig_then_pose_moves_each_part_with_its_bone() {
    let tmp = scratch("layers");
    let dir = tmp.path();
    let paths = character_layer_paths();
    let (handles, rig, posed) = (dir.join("h.json"), dir.join("rig.json"), dir.join("p.png"));
    let mut args = vec!["autorig".to_string()];
    args.extend(paths.iter().cloned());
    args.extend(["-o".into(), handles.to_str().unwrap().into()]);
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&sinew(&argv), "autorig layers");
    let mut args = vec!["rig".to_string()];
    args.extend(paths.iter().cloned());
    args.extend([
        "--handles".into(),
        handles.to_str().unwrap().into(),
        "-o".into(),
        rig.to_str().unwrap().into(),
    ]);
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&sinew(&argv), "rig layers");
    // Turning the lower left arm moves the left hand; the right hand stays.
    let pose = dir.join("pose.json");
    std::fs::write(&pose, r#"{"bones": {"arm_lower_l": {"rotate": 70}}}"#).unwrap();
    let rig_s = rig.to_str().unwrap();
    ok(
        &sinew(&[
            "pose",
            rig_s,
            "--pose",
            pose.to_str().unwrap(),
            "-o",
            posed.to_str().unwrap(),
        ]),
        "pose layers",
    );
    let posed = load(&posed);
    assert!(
        posed.get_pixel(358, 343)[3] < 50,
        "the left hand did not move"
    );
    assert!(posed.get_pixel(156, 340)[3] > 200, "the right hand moved");
}

#[cfg(feature = "cli")]
#[test]
fn autorig_bad_input_is_one_line_and_exit_2() {
    let tmp = scratch("bad");
    let dir = tmp.path();
    let bad = dir.join("bad.png");
    std::fs::write(&bad, b"not a png").unwrap();
    let out_path = dir.join("h.json");
    let out = sinew(&[
        "autorig",
        bad.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr)
            .trim_end()
            .lines()
            .count(),
        1
    );
    assert!(!out_path.exists());
    let flat = assets().join("flat.png");
    let out = sinew(&[
        "autorig",
        flat.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
        "--cage",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("at least 3"));
    assert!(!out_path.exists());
}

#[test]
fn proposed_rig_over_the_character_matches_golden() {
    let image = character_flat();
    let options = AutorigOptions {
        template: TemplateChoice::Humanoid,
        cage_vertices: Some(16),
        point_count: 6,
        ..AutorigOptions::default()
    };
    let h = propose(&[("flat", &image)], &options);
    let actual = sinew::autorig::draw_preview(&[LayerRef::whole("flat", &image)], &h).unwrap();
    common::golden::check(
        "autorig_character",
        &actual,
        "autorig",
        common::golden::premultiplied_tolerance,
    );
}

#[test]
fn layered_proposal_over_the_character_matches_golden() {
    let (layers, proposal) = character_proposal();
    let refs: Vec<LayerRef> = layers.iter().map(|(n, i)| LayerRef::whole(n, i)).collect();
    let actual = sinew::autorig::draw_preview(&refs, &proposal.handles).unwrap();
    common::golden::check(
        "autorig_layered_character",
        &actual,
        "autorig",
        common::golden::premultiplied_tolerance,
    );
}

/// The bundled character's layers rigged with the automatic proposal (template, binding) and
/// posed: the head turned at the neck, an arm raised, the tail swung, a knee bent. Every part
/// must move with its own bones only (no tearing across the layers' seams).
#[cfg(feature = "cli")]
#[test]
fn layered_proposal_rigged_and_posed_matches_golden() {
    let tmp = scratch("layered-posed");
    let dir = tmp.path();
    let paths = character_layer_paths();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (handles, rig, posed, pose) = (
        dir.join("h.json"),
        dir.join("rig.json"),
        dir.join("posed.png"),
        dir.join("pose.json"),
    );
    let run = |head: &[&str], tail: &[String]| {
        let mut args: Vec<String> = head.iter().map(|a| a.to_string()).collect();
        args.extend(tail.iter().cloned());
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        sinew(&argv)
    };
    let out = run(
        &["autorig"],
        &[paths.clone(), vec!["-o".into(), s(&handles)]].concat(),
    );
    ok(&out, "autorig");
    assert!(String::from_utf8_lossy(&out.stdout).contains("template: humanoid"));
    ok(
        &run(
            &["rig"],
            &[
                paths,
                vec!["--handles".into(), s(&handles), "-o".into(), s(&rig)],
            ]
            .concat(),
        ),
        "rig",
    );
    std::fs::write(
        &pose,
        r#"{"bones": {"head": {"rotate": -20}, "arm_upper_l": {"rotate": 70},
            "arm_lower_l": {"rotate": 30}, "leg_lower_r": {"rotate": 25},
            "tail": {"rotate": 20}, "chest": {"rotate": 8}}}"#,
    )
    .unwrap();
    ok(
        &sinew(&["pose", &s(&rig), "--pose", &s(&pose), "-o", &s(&posed)]),
        "pose",
    );
    common::golden::check(
        "autorig_layered_posed",
        &load(&posed),
        "autorig",
        common::golden::premultiplied_tolerance,
    );
}

/// `sinew autorig` on a PSD of the bundled character's layers (written by psd-tools, each
/// layer trimmed to its pixels and placed at its offset) proposes the rig the PNG layers get,
/// and its `--preview` is the whole canvas with the bones drawn over the composite.
#[cfg(feature = "cli")]
#[test]
fn a_psd_of_the_layers_gets_the_same_rig_and_a_whole_canvas_preview() {
    let tmp = scratch("psd");
    let dir = tmp.path();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let psd = root().join("tests/fixtures/layered/bundled_character.psd");
    let (from_psd, preview) = (dir.join("psd.json"), dir.join("preview.png"));
    ok(
        &sinew(&[
            "autorig",
            &s(&psd),
            "-o",
            &s(&from_psd),
            "--preview",
            &s(&preview),
        ]),
        "autorig psd",
    );
    let psd_handles: Handles =
        serde_json::from_str(&std::fs::read_to_string(&from_psd).unwrap()).unwrap();
    let (_, png) = character_proposal();
    let png_handles = png.handles;
    assert_eq!(psd_handles.bind, png_handles.bind);
    assert_eq!(psd_handles.bones.len(), png_handles.bones.len());
    for (a, b) in psd_handles.bones.iter().zip(&png_handles.bones) {
        assert_eq!((&a.name, &a.parent), (&b.name, &b.parent));
        // Trimmed layers trace to within a tenth of a pixel of whole-canvas ones.
        let d = (pt(a.head) - pt(b.head))
            .norm()
            .max((pt(a.tail) - pt(b.tail)).norm());
        assert!(d < 0.1, "{}: {d} px", a.name);
    }
    let picture = load(&preview);
    assert_eq!(picture.dimensions(), (512, 512));
    // The hip bone's kite (a root bone, drawn red) over the torso.
    let hip = &psd_handles.bones.iter().find(|b| b.name == "hip").unwrap();
    let mid = pt(hip.head) + (pt(hip.tail) - pt(hip.head)) * 0.5;
    let px = picture.get_pixel(mid.x as u32, mid.y as u32);
    assert!(
        px[0] > px[1] + 40 && px[0] > px[2] + 40,
        "no red root bone at {mid:?}: {px:?}"
    );
}

// ---------------------------------------------------------------- the evaluation set

/// A character of the evaluation set (`tests/fixtures/autorig-eval`, drawn by
/// `tools/autorig-eval/make_set.py`): its sprite, kind, bone budget and reference joints.
struct EvalCharacter {
    image: RgbaImage,
    budget: [usize; 2],
    template: TemplateChoice,
    joints: Vec<(String, Point)>,
}

fn eval_character(name: &str) -> EvalCharacter {
    let dir = root().join("tests/fixtures/autorig-eval");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join(format!("{name}.json"))).unwrap())
            .unwrap();
    let template = match meta["kind"].as_str().unwrap() {
        "humanoid" => TemplateChoice::Humanoid,
        "quadruped" => TemplateChoice::Quadruped,
        _ => TemplateChoice::None,
    };
    let budget = [0, 1].map(|k| meta["budget"][k].as_u64().unwrap() as usize);
    let joints = meta["joints"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| {
            let xy = [0, 1].map(|i| v[i].as_f64().unwrap());
            (k.clone(), Point::new(xy[0], xy[1]))
        })
        .collect();
    EvalCharacter {
        image: load(&dir.join(format!("{name}.png"))),
        budget,
        template,
        joints,
    }
}

fn propose_for(c: &EvalCharacter) -> Handles {
    let options = AutorigOptions {
        template: c.template,
        ..AutorigOptions::default()
    };
    propose(&[("sprite", &c.image)], &options)
}

/// The height of the opaque pixels' box, px.
fn opaque_height(image: &RgbaImage) -> f64 {
    let rows: Vec<u32> = image
        .enumerate_pixels()
        .filter(|(_, _, p)| p[3] > 0)
        .map(|(_, y, _)| y)
        .collect();
    let (lo, hi) = (rows.iter().min().unwrap(), rows.iter().max().unwrap());
    (hi - lo + 1) as f64
}

/// A handful of the evaluation set (the whole set runs through tools/autorig-eval/score.py):
/// a stick figure with juggling balls (four pieces), a cartoon with a detached head, a dog, a
/// dragon and a sword. Every bone inside, every piece with a bone, the count within the
/// budget, no bone shorter than the default fraction of the size, and the median distance
/// from a reference joint to the nearest bone end under 8 % of the height.
#[test]
fn evaluation_characters_get_rigs_an_animator_keeps() {
    for name in ["stick_juggler", "detached_head", "dog", "dragon", "sword"] {
        let c = eval_character(name);
        let h = propose_for(&c);
        dump(name, &c.image, &h);
        let shape = traced(&c.image);
        assert_bones_inside(&h, &shape, name);
        let n = h.bones.len();
        assert!(
            (c.budget[0]..=c.budget[1]).contains(&n),
            "{name}: {n} bones, budget {:?}",
            c.budget
        );
        let size = sinew::autorig::budget::size_px(&shape);
        let shortest = sinew::autorig::SkeletonOptions::default().min_bone_fraction * size;
        for b in &h.bones {
            let len = (pt(b.tail) - pt(b.head)).norm();
            assert!(len >= shortest, "{name}: bone {} is {len:.1} px", b.name);
        }
        for (k, outline) in shape.outlines.iter().enumerate() {
            let reached = h.bones.iter().any(|b| {
                let m = (pt(b.head).coords + pt(b.tail).coords) * 0.5;
                point_in_ring(Point::from(m), &outline.outer)
            });
            assert!(reached, "{name}: piece {k} has no bone");
        }
        let height = opaque_height(&c.image);
        let mut errors: Vec<f64> = c
            .joints
            .iter()
            .map(|(_, j)| nearest_bone_end(&h, *j) / height)
            .collect();
        errors.sort_by(f64::total_cmp);
        let median = errors[errors.len() / 2];
        assert!(median < 0.08, "{name}: median joint error {median:.3}");
    }
}

#[test]
fn humanoid_limbs_join_the_spine_and_the_head_hangs_from_a_neck() {
    let c = eval_character("chibi");
    let h = propose_for(&c);
    let by_name: HashMap<&str, &sinew::rig::Bone> =
        h.bones.iter().map(|b| (b.name.as_str(), b)).collect();
    assert_eq!(by_name["neck"].parent.as_deref(), Some("chest"));
    assert_eq!(by_name["head"].parent.as_deref(), Some("neck"));
    // Each upper limb starts within its limb's width of the spine bone it hangs from.
    for (limb, parent) in [
        ("arm_upper_l", "chest"),
        ("arm_upper_r", "chest"),
        ("leg_upper_l", "hip"),
        ("leg_upper_r", "hip"),
    ] {
        let (b, p) = (by_name[limb], by_name[parent]);
        assert_eq!(b.parent.as_deref(), Some(parent), "{limb}");
        let gap = sinew::geom::segment_distance(pt(b.head), pt(p.head), pt(p.tail)).0;
        assert!(gap < 60.0, "{limb} starts {gap:.1} px from {parent}");
    }
}

#[test]
fn proposed_rigs_over_two_evaluation_characters_match_golden() {
    for (name, golden) in [
        ("stick_juggler", "autorig_juggler"),
        ("dragon", "autorig_dragon"),
    ] {
        let c = eval_character(name);
        let h = propose_for(&c);
        let actual =
            sinew::autorig::draw_preview(&[LayerRef::whole("sprite", &c.image)], &h).unwrap();
        common::golden::check(
            golden,
            &actual,
            "autorig",
            common::golden::premultiplied_tolerance,
        );
    }
}

/// Handles that reach only the body of a character whose head is drawn apart: `sinew rig`
/// builds the rig, the head following the nearest bone, with a one-line warning.
#[cfg(feature = "cli")]
#[test]
fn rig_binds_pieces_no_handle_reaches_with_a_one_line_warning() {
    let tmp = scratch("autorig-unreached");
    let dir = tmp.path();
    let sprite = root().join("tests/fixtures/autorig-eval/detached_head.png");
    let handles = dir.join("handles.json");
    std::fs::write(
        &handles,
        r#"{"bones": [{"name": "body", "head": [256, 315], "tail": [256, 250]}]}"#,
    )
    .unwrap();
    let rig = dir.join("rig.json");
    let out = sinew(&[
        "rig",
        sprite.to_str().unwrap(),
        "--handles",
        handles.to_str().unwrap(),
        "-o",
        rig.to_str().unwrap(),
    ]);
    ok(&out, "rig");
    let stderr = String::from_utf8_lossy(&out.stderr);
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.contains("pieces no handle reaches"))
        .collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains("mesh vertices") && warnings[0].contains("body"));
    assert!(rig.exists());
}

/// The template chosen for real sprites nobody here drew (`tests/fixtures/autorig-real`,
/// sources in tools/autorig-real/LICENSES.md), with no template given: animals whose head is
/// carried ahead of the body (a three-quarter lion, a tall fawn) are quadrupeds, a wide
/// policeman whose head sits over his middle is a person, a kite and its tails is neither.
#[test]
fn real_sprites_get_the_template_of_their_kind() {
    let dir = root().join("tests/fixtures/autorig-real");
    for (name, want) in [
        ("lion", Some(sinew::autorig::Template::Quadruped)),
        ("fawn", Some(sinew::autorig::Template::Quadruped)),
        ("cow", Some(sinew::autorig::Template::Quadruped)),
        ("police_man", Some(sinew::autorig::Template::Humanoid)),
        ("skeleton", Some(sinew::autorig::Template::Humanoid)),
        ("kid", Some(sinew::autorig::Template::Humanoid)),
        ("kite", None),
        ("swallow", None),
    ] {
        let image = load(&dir.join(format!("{name}.png")));
        let layers = [LayerRef::whole("sprite", &image)];
        let proposal = autorig(&layers, &[], &AutorigOptions::default()).expect("autorig");
        assert_eq!(proposal.template, want, "{name}: {:?}", proposal.notes);
        assert!(
            proposal.notes.iter().any(|n| n.starts_with("template: ")),
            "{name}: the choice is explained: {:?}",
            proposal.notes
        );
    }
}

/// A real T-posed kid (openclipart-svg `kid_01.svg`, public domain) whose fingers touch: the
/// outline nearly meets itself at the hand, the medial axis closes a small cycle there and has
/// no end at that hand. The humanoid template still fits (the cycle's cut is a candidate hand):
/// both arms and legs are named, and every wrist and ankle placed by hand has a bone end near it.
#[test]
fn the_humanoid_template_fits_a_hand_whose_fingers_touch() {
    let dir = root().join("tests/fixtures/autorig-real");
    let image = load(&dir.join("kid.png"));
    let layers = [LayerRef::whole("sprite", &image)];
    let proposal = autorig(&layers, &[], &AutorigOptions::default()).expect("autorig");
    assert_eq!(proposal.template, Some(sinew::autorig::Template::Humanoid));
    assert!(
        !proposal.notes.iter().any(|n| n.contains("does not match")),
        "{:?}",
        proposal.notes
    );
    for name in [
        "arm_upper_l",
        "arm_lower_r",
        "leg_upper_l",
        "leg_lower_r",
        "head",
    ] {
        assert!(
            proposal.handles.bones.iter().any(|b| b.name == name),
            "{name} in {:?}",
            proposal.handles.bones
        );
    }
    let height = opaque_height(&image);
    // Reference joints from tests/fixtures/autorig-real/kid.json (placed by hand).
    for (joint, at) in [
        ("wrist_l", Point::new(430.0, 125.0)),
        ("wrist_r", Point::new(60.0, 140.0)),
        ("ankle_l", Point::new(312.0, 590.0)),
        ("ankle_r", Point::new(196.0, 590.0)),
    ] {
        let miss = nearest_bone_end(&proposal.handles, at) / height;
        assert!(
            miss < 0.06,
            "{joint}: the nearest bone end is {:.1} % of the height away",
            100.0 * miss
        );
    }
}
