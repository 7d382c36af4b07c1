//! The key-editing commands (`MoveKeys`, `PasteKeys`, `DeleteTimelineKeys`, `SetCurve`)
//! through [`Document::apply`]: what they do, what they refuse, and undo.

use super::*;
use crate::anim::edit::{TimelineId, TransformChannel};
use crate::rig::pose::BonePose;

fn arm(channel: TransformChannel) -> TimelineId {
    TimelineId::Bone {
        bone: "arm".into(),
        channel,
    }
}

fn key(timeline: &TimelineId, time_s: f64) -> KeyRef {
    KeyRef {
        timeline: timeline.clone(),
        time_s,
    }
}

/// `arm` keyed at 0 s (0°) and 1 s (90°): every transform channel gets both keys.
fn keyed() -> Document {
    let mut doc = Document::new();
    for (time_s, rotate) in [(0.0, 0.0), (1.0, 90.0)] {
        let mut pose = Pose::default();
        pose.bones.insert(
            "arm".into(),
            BonePose {
                rotate,
                ..Default::default()
            },
        );
        doc.apply(Command::SetKey {
            animation: "wave".into(),
            time_s,
            pose,
            keep: vec!["arm".into()],
            sampling: Default::default(),
        })
        .expect("keyed");
    }
    doc
}

fn times(doc: &Document, timeline: &TimelineId) -> Vec<f64> {
    edit::timelines(&animation_named(doc.state(), "wave"))
        .into_iter()
        .find(|(t, _)| t == timeline)
        .map(|(_, times)| times)
        .unwrap_or_default()
}

fn rotate_at(doc: &Document, time_s: f64) -> f64 {
    let anim = animation_named(doc.state(), "wave");
    anim.sample(time_s, false).bones["arm"].rotate
}

#[test]
fn moving_keys_is_one_undoable_step() {
    let mut doc = keyed();
    let rotate = arm(TransformChannel::Rotate);
    let scale = arm(TransformChannel::Scale);
    doc.apply(Command::MoveKeys {
        animation: "wave".into(),
        keys: vec![key(&rotate, 1.0)],
        delta_s: 0.5,
    })
    .expect("moved");
    assert_eq!(times(&doc, &rotate), vec![0.0, 1.5]);
    assert_eq!(times(&doc, &scale), vec![0.0, 1.0], "one channel only");
    assert!((rotate_at(&doc, 0.75) - 45.0).abs() < 1e-9);
    assert!(doc.undo());
    assert_eq!(times(&doc, &rotate), vec![0.0, 1.0]);
    assert!(doc.redo());
    assert_eq!(times(&doc, &rotate), vec![0.0, 1.5]);
}

#[test]
fn refused_key_edits_leave_the_document_as_it_was() {
    let mut doc = keyed();
    let rotate = arm(TransformChannel::Rotate);
    let before = doc.state().animations.clone();
    let collide = doc.apply(Command::MoveKeys {
        animation: "wave".into(),
        keys: vec![key(&rotate, 0.0)],
        delta_s: 1.0,
    });
    assert!(
        matches!(
            collide,
            Err(DocumentError::KeyEdit(edit::EditError::Collision { .. }))
        ),
        "{:?}",
        collide.err()
    );
    let early = doc.apply(Command::MoveKeys {
        animation: "wave".into(),
        keys: vec![key(&rotate, 1.0)],
        delta_s: -2.0,
    });
    assert!(matches!(
        early,
        Err(DocumentError::KeyEdit(edit::EditError::BadTime(_)))
    ));
    let missing = doc.apply(Command::DeleteTimelineKeys {
        animation: "run".into(),
        keys: vec![key(&rotate, 0.0)],
    });
    assert!(missing.is_err());
    let last = doc.apply(Command::SetCurve {
        animation: "wave".into(),
        key: key(&rotate, 1.0),
        curve: Curve::Bezier(vec![1.0, 0.0, 1.0, 0.0]),
    });
    assert!(matches!(
        last,
        Err(DocumentError::KeyEdit(edit::EditError::LastKey { .. }))
    ));
    assert_eq!(doc.state().animations, before);
    // The only undo steps are the two keys.
    assert!(doc.undo() && doc.undo());
    assert!(!doc.can_undo());
}

#[test]
fn paste_delete_and_curves_undo_in_order() {
    let mut doc = keyed();
    let rotate = arm(TransformChannel::Rotate);
    let translate = arm(TransformChannel::Translate);
    let copied = edit::copy_keys(
        &animation_named(doc.state(), "wave"),
        &[key(&rotate, 0.0), key(&rotate, 1.0)],
    )
    .expect("copied");
    doc.apply(Command::PasteKeys {
        animation: "wave".into(),
        at_s: 2.0,
        keys: copied,
    })
    .expect("pasted");
    assert_eq!(times(&doc, &rotate), vec![0.0, 1.0, 2.0, 3.0]);
    assert!((rotate_at(&doc, 3.0) - 90.0).abs() < 1e-9);
    assert_eq!(times(&doc, &translate), vec![0.0, 1.0]);

    doc.apply(Command::DeleteTimelineKeys {
        animation: "wave".into(),
        keys: vec![key(&translate, 0.0), key(&rotate, 2.0)],
    })
    .expect("deleted");
    assert_eq!(times(&doc, &translate), vec![1.0]);
    assert_eq!(times(&doc, &rotate), vec![0.0, 1.0, 3.0]);

    // Ease in and out: flat at both ends, so a tenth of the way the arm has barely moved.
    doc.apply(Command::SetCurve {
        animation: "wave".into(),
        key: key(&rotate, 0.0),
        curve: Curve::Bezier(vec![0.5, 0.0, 0.5, 90.0]),
    })
    .expect("curved");
    assert!(
        rotate_at(&doc, 0.1) < 0.1 * 90.0 / 2.0,
        "{}",
        rotate_at(&doc, 0.1)
    );
    assert!((rotate_at(&doc, 0.5) - 45.0).abs() < 1e-9);

    assert!(doc.undo());
    assert!((rotate_at(&doc, 0.1) - 9.0).abs() < 1e-9, "linear again");
    assert!(doc.undo());
    assert_eq!(times(&doc, &rotate), vec![0.0, 1.0, 2.0, 3.0]);
    assert_eq!(times(&doc, &translate), vec![0.0, 1.0]);
    assert!(doc.undo());
    assert_eq!(times(&doc, &rotate), vec![0.0, 1.0]);
}
