//! The editor's document model: commands, undo/redo, background rig builds, saving.

mod command;
mod common;

use common::document::{bar_layer, bone, compute};
use image::RgbaImage;
use sinew::document::{autosave_path, compute_rig, Command, Document, DocumentError};
use sinew::geom::Point;
use sinew::pipeline::Layer;
use sinew::rig::pose::IkDrag;
use sinew::rig::{PointHandle, Pose};
use std::sync::atomic::AtomicBool;

/// A document with one bar layer and a two-bone arm along it, weights computed.
fn arm_document() -> Document {
    arm_document_with(bar_layer("bar", &std::env::temp_dir(), false))
}

fn arm_document_with(layer: Layer) -> Document {
    let mut doc = Document::new();
    doc.apply(Command::AddLayer(layer)).unwrap();
    doc.apply(Command::AddBone(bone(
        "upper",
        None,
        [20.0, 40.0],
        [160.0, 40.0],
    )))
    .unwrap();
    doc.apply(Command::AddBone(bone(
        "lower",
        Some("upper"),
        [160.0, 40.0],
        [300.0, 40.0],
    )))
    .unwrap();
    compute(&mut doc);
    doc
}

#[test]
fn edits_undo_and_redo_in_order() {
    let mut doc = arm_document();
    assert!(doc.posable().is_some());
    let before = doc.state().handles.clone();
    doc.apply(Command::AddPoint(PointHandle {
        name: "tip".into(),
        at: Point::new(290.0, 50.0),
        parent: None,
    }))
    .unwrap();
    // Handles changed: the rig is stale until weights are computed again.
    assert!(doc.posable().is_none());
    assert_eq!(doc.state().handles.points.len(), 1);
    assert!(doc.undo());
    assert_eq!(doc.state().handles, before);
    assert!(doc.posable().is_some(), "undo restores the weighted rig");
    assert!(doc.redo());
    assert_eq!(doc.state().handles.points.len(), 1);
    assert!(!doc.redo());
    // A new command clears the redo stack.
    doc.undo();
    doc.apply(Command::MoveBone {
        name: "lower".into(),
        head: Point::new(160.0, 40.0),
        tail: Point::new(280.0, 40.0),
    })
    .unwrap();
    assert!(!doc.can_redo());
}

#[test]
fn a_failing_command_changes_nothing() {
    let mut doc = arm_document();
    let handles = doc.state().handles.clone();
    let undo_depth_probe = doc.can_undo();
    // A cycle, an unknown name, a duplicate name, a clash on rename.
    let bad = [
        Command::Reparent {
            handle: "upper".into(),
            parent: Some("lower".into()),
        },
        Command::Delete {
            name: "nobody".into(),
        },
        Command::AddBone(bone("upper", None, [0.0, 0.0], [5.0, 0.0])),
        Command::Rename {
            from: "upper".into(),
            to: "lower".into(),
        },
    ];
    for command in bad {
        assert!(doc.apply(command).is_err());
        assert_eq!(doc.state().handles, handles);
        assert!(doc.posable().is_some());
    }
    assert_eq!(doc.can_undo(), undo_depth_probe);
    // A layer on a canvas of another size is refused too.
    let bar = bar_layer("small", &std::env::temp_dir(), false);
    let small = sinew::pipeline::Layer::whole("small", bar.path, RgbaImage::new(10, 10));
    assert!(matches!(
        doc.apply(Command::AddLayer(small)),
        Err(DocumentError::LayerSize { .. })
    ));
}

#[test]
fn rename_and_delete_follow_every_reference() {
    let mut doc = arm_document();
    let mut pose = Pose::default();
    pose.bones.insert(
        "lower".into(),
        sinew::rig::pose::BonePose {
            rotate: 30.0,
            ..Default::default()
        },
    );
    doc.apply(Command::SetPose(pose)).unwrap();
    doc.apply(Command::Rename {
        from: "upper".into(),
        to: "shoulder".into(),
    })
    .unwrap();
    let h = &doc.state().handles;
    assert_eq!(h.bones[1].parent.as_deref(), Some("shoulder"));
    doc.apply(Command::Delete {
        name: "shoulder".into(),
    })
    .unwrap();
    let h = &doc.state().handles;
    assert_eq!(h.bones.len(), 1);
    assert_eq!(h.bones[0].parent, None, "the child moved up to the root");
    assert!(doc.state().pose.bones.contains_key("lower"));
}

#[test]
fn a_rig_built_for_older_inputs_is_refused() {
    let mut doc = arm_document();
    doc.apply(Command::MoveBone {
        name: "lower".into(),
        head: Point::new(160.0, 40.0),
        tail: Point::new(250.0, 40.0),
    })
    .unwrap();
    let stale_inputs = doc.rig_inputs();
    doc.apply(Command::AddPoint(PointHandle {
        name: "tip".into(),
        at: Point::new(290.0, 50.0),
        parent: None,
    }))
    .unwrap();
    let scene = compute_rig(
        &stale_inputs,
        &std::env::temp_dir(),
        &AtomicBool::new(false),
        &mut |_, _| {},
    )
    .unwrap();
    assert!(matches!(
        doc.apply(Command::SetRig(
            std::sync::Arc::new(scene),
            Box::new(stale_inputs.key())
        )),
        Err(DocumentError::OutdatedRig)
    ));
    assert!(doc.posable().is_none());
    // Cancelled before the first part: nothing is built.
    let cancelled = compute_rig(
        &doc.rig_inputs(),
        &std::env::temp_dir(),
        &AtomicBool::new(true),
        &mut |_, _| {},
    );
    assert!(matches!(cancelled, Err(DocumentError::Cancelled)));
}

#[test]
fn posing_needs_current_weights_and_a_valid_pose() {
    let mut doc = arm_document();
    let mut drag = Pose::default();
    drag.ik.push(IkDrag {
        at: Point::new(300.0, 40.0),
        to: Point::new(250.0, 0.0),
        weight: None,
    });
    doc.apply(Command::SetPose(drag.clone())).unwrap();
    let mut unknown = Pose::default();
    unknown.bones.insert("ghost".into(), Default::default());
    assert!(doc.apply(Command::SetPose(unknown)).is_err());
    doc.apply(Command::AddPoint(PointHandle {
        name: "tip".into(),
        at: Point::new(290.0, 50.0),
        parent: None,
    }))
    .unwrap();
    assert!(matches!(
        doc.apply(Command::SetPose(drag)),
        Err(DocumentError::NoWeights)
    ));
}

#[test]
fn saves_atomically_and_reopens_ready_to_pose() {
    let tmp = command::scratch("document-save");
    let dir = tmp.path();
    // The image must live where the saved file can refer to it.
    let mut layer = bar_layer("bar", &std::env::temp_dir(), false);
    layer.path = dir.join("bar.png");
    layer.image.save(&layer.path).unwrap();
    let mut doc = arm_document_with(layer);
    let path = dir.join("arm.json");
    doc.save(&path).unwrap();
    assert!(!doc.dirty());
    let reopened = Document::open(&path).unwrap();
    assert!(reopened.posable().is_some());
    assert_eq!(reopened.state().handles, doc.state().handles);
    // A stale rig saves without weights, and reopens asking for them.
    doc.apply(Command::MoveBone {
        name: "lower".into(),
        head: Point::new(160.0, 40.0),
        tail: Point::new(250.0, 40.0),
    })
    .unwrap();
    // "Modified" is the state against the saved one: undoing back to it is clean again,
    // redoing the edit is modified again.
    assert!(doc.dirty());
    doc.undo();
    assert!(!doc.dirty());
    doc.redo();
    assert!(doc.dirty());
    let autosaved = doc.autosave(&path).unwrap();
    assert_eq!(autosaved, autosave_path(&path));
    let reopened = Document::open(&autosaved).unwrap();
    assert!(reopened.posable().is_none());
    assert_eq!(
        reopened.state().handles.bones[1].tail,
        Point::new(250.0, 40.0)
    );
}

#[test]
fn the_bundled_character_opens_and_poses() {
    let tmp = command::scratch("document-character");
    let dir = tmp.path();
    let mut scene_doc = common::character_scene().doc;
    let assets = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/character");
    for part in &mut scene_doc.parts {
        part.image = assets.join(&part.image).to_string_lossy().into_owned();
    }
    // With the bundled animations and the events their walk fires.
    let read = |file: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(assets.join(file)).unwrap()).unwrap()
    };
    scene_doc.animations = sinew::anim::animations_from_json(&read("animations.json")).unwrap();
    scene_doc.events = sinew::anim::events_from_json(&read("events.json")).unwrap();
    let grip = scene_doc.parts[0].mesh.vertices[0];
    let path = dir.join("character.json");
    scene_doc.save(&path).unwrap();
    let mut doc = Document::open(&path).unwrap();
    assert!(doc.posable().is_some());
    let mut pose = Pose::default();
    pose.ik.push(IkDrag {
        at: grip,
        to: Point::new(grip[0] + 20.0, grip[1] - 10.0),
        weight: None,
    });
    doc.apply(Command::SetPose(pose)).unwrap();
    assert_eq!(doc.state().pose.ik.len(), 1);
    assert!(doc.undo());
    assert!(doc.state().pose.ik.is_empty());
    // Saving from the editor keeps the events and the keys that fire them.
    let again = dir.join("again.json");
    doc.save(&again).unwrap();
    let saved = sinew::io::RigDocument::load(&again).unwrap();
    assert_eq!(saved.events, scene_doc.events);
    assert!(!saved.animations["walk"].events.is_empty());
    assert_eq!(saved.animations, scene_doc.animations);
    // Recomputing the weights (a rig built again from the layers) keeps the slots and skins:
    // the rebuilt rig draws them, and the saved file still has them.
    assert!(!scene_doc.skins.is_empty(), "the character has skins");
    let slots = |d: &sinew::io::RigDocument| -> Vec<(String, Option<String>)> {
        d.parts
            .iter()
            .map(|p| (p.name.clone(), p.slot.clone()))
            .collect()
    };
    compute(&mut doc);
    let rebuilt = &doc.posable().expect("posable after the recompute").doc;
    assert_eq!(rebuilt.skins, scene_doc.skins);
    assert_eq!(slots(rebuilt), slots(&scene_doc));
    let recomputed = dir.join("recomputed.json");
    doc.save(&recomputed).unwrap();
    let saved = sinew::io::RigDocument::load(&recomputed).unwrap();
    assert_eq!(saved.skins, scene_doc.skins);
    assert_eq!(slots(&saved), slots(&scene_doc));
    // Removing an attachment's layer drops it from the slots and the skins that show it.
    doc.apply(Command::RemoveLayer {
        name: "bag_pail".into(),
    })
    .unwrap();
    assert!(doc.state().slots.skins["pail"].is_empty());
    assert!(!doc.state().slots.attachments.contains_key("bag_pail"));
}

#[test]
fn keys_set_replace_sample_and_delete() {
    use sinew::document::{animation_named, key_times};
    let mut doc = arm_document();
    let drag = |to: Point| {
        let mut pose = Pose::default();
        pose.ik.push(IkDrag {
            at: Point::new(300.0, 40.0),
            to,
            weight: None,
        });
        pose.bones.insert(
            "upper".into(),
            sinew::rig::pose::BonePose {
                rotate: to[1] / 10.0,
                ..Default::default()
            },
        );
        pose
    };
    // "upper" kept, as when it is the selected bone: every channel keyed at each time.
    let key = |time_s: f64, pose: Pose| Command::SetKey {
        animation: "wave".into(),
        time_s,
        pose,
        keep: vec!["upper".into()],
        sampling: Default::default(),
    };
    doc.apply(key(0.0, drag(Point::new(300.0, 40.0)))).unwrap();
    doc.apply(key(1.0, drag(Point::new(260.0, 0.0)))).unwrap();
    // The same time again replaces the key instead of adding one.
    doc.apply(key(1.0, drag(Point::new(280.0, 10.0)))).unwrap();
    let anim = animation_named(doc.state(), "wave");
    assert_eq!(key_times(&anim), vec![0.0, 1.0]);
    assert_eq!(anim.ik.len(), 1, "one timeline per rest point");
    let half = anim.sample(0.5, false);
    assert_eq!(half.ik[0].to, Point::new(290.0, 25.0));
    assert_eq!(half.bones["upper"].rotate, 2.5);
    // Keys are undoable edits; weights stay current.
    assert!(doc.posable().is_some());
    doc.undo();
    let anim = animation_named(doc.state(), "wave");
    assert_eq!(anim.sample(1.0, false).ik[0].to, Point::new(260.0, 0.0));
    doc.apply(Command::DeleteKeys {
        animation: "wave".into(),
        time_s: 0.0,
    })
    .unwrap();
    let anim = animation_named(doc.state(), "wave");
    assert_eq!(key_times(&anim), vec![1.0]);
    assert!(doc
        .apply(key(f64::NAN, Pose::default()))
        .is_err_and(|e| matches!(e, DocumentError::KeyTime(_))));
}

#[test]
fn cages_regions_and_proposed_handles_are_commands() {
    use sinew::rig::{Cage, Region};
    let mut doc = arm_document();
    let around = vec![
        Point::new(5.0, 10.0),
        Point::new(315.0, 10.0),
        Point::new(315.0, 70.0),
        Point::new(5.0, 70.0),
    ];
    doc.apply(Command::AddCage(Cage {
        name: "cage".into(),
        polygon: around.clone(),
    }))
    .unwrap();
    doc.apply(Command::AddRegion(Region {
        name: "grip".into(),
        polygon: vec![
            Point::new(40.0, 30.0),
            Point::new(60.0, 30.0),
            Point::new(60.0, 50.0),
        ],
    }))
    .unwrap();
    assert_eq!(doc.state().handles.cages.len(), 1);
    assert_eq!(doc.state().handles.regions.len(), 1);
    assert!(
        doc.posable().is_none(),
        "new handles make the weights stale"
    );

    // Moving a polygon keeps its vertex count.
    let moved: Vec<Point> = around.iter().map(|p| Point::new(p.x, p.y + 2.0)).collect();
    doc.apply(Command::SetPolygon {
        name: "cage".into(),
        polygon: moved.clone(),
    })
    .unwrap();
    assert_eq!(doc.state().handles.cages[0].polygon, moved);
    let err = doc
        .apply(Command::SetPolygon {
            name: "cage".into(),
            polygon: moved[..3].to_vec(),
        })
        .unwrap_err();
    assert!(matches!(err, DocumentError::PolygonSize { .. }), "{err}");
    assert!(matches!(
        doc.apply(Command::SetPolygon {
            name: "nope".into(),
            polygon: moved.clone(),
        }),
        Err(DocumentError::UnknownHandle(_))
    ));

    // The automatic rig's proposal replaces every handle in one undoable step; the pose
    // forgets the handles that are gone.
    compute(&mut doc);
    let mut pose = Pose::default();
    pose.bones.insert("upper".into(), Default::default());
    doc.apply(Command::SetPose(pose)).unwrap();
    let before = doc.state().handles.clone();
    let proposal = sinew::jobs::propose_handles(&doc.state().layers, &[], &Default::default())
        .expect("the bar gets a skeleton");
    assert!(!proposal.handles.bones.is_empty());
    doc.apply(Command::SetHandles(proposal.handles.clone()))
        .unwrap();
    assert_eq!(doc.state().handles, proposal.handles);
    let names: Vec<&str> = proposal.handles.names().collect();
    assert!(doc
        .state()
        .pose
        .bones
        .keys()
        .all(|n| names.contains(&n.as_str())));
    assert!(doc.undo());
    assert_eq!(doc.state().handles, before);
}
