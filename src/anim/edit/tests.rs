//! [`super`]'s edits on typed animations: what they do, what they refuse.

use super::*;
use crate::geom::Point;
use serde_json::json;

fn parsed(name: &str, v: Value) -> Animation {
    Animation::from_json(name, &v).unwrap()
}

fn rotate(bone: &str) -> TimelineId {
    TimelineId::Bone {
        bone: bone.into(),
        channel: TransformChannel::Rotate,
    }
}

fn key(timeline: &TimelineId, time_s: f64) -> KeyRef {
    KeyRef {
        timeline: timeline.clone(),
        time_s,
    }
}

/// `arm` rotates 0 → 90 → 0 over keys at 0, 1, 2; its translate has one key; one IK drag.
fn walk() -> Animation {
    parsed(
        "walk",
        json!({
            "bones": {"arm": {
                "rotate": [{"time": 0, "value": 0}, {"time": 1, "value": 90},
                           {"time": 2, "value": 0}],
                "translate": [{"time": 1, "value": [3, 4]}]}},
            "ik": [{"at": [1, 2], "to": [{"time": 0, "value": [5, 6]}]}],
            "parts": {"head": {"visible": [{"time": 0, "value": true}]}}
        }),
    )
}

fn times(animation: &Animation, timeline: &TimelineId) -> Vec<f64> {
    timelines(animation)
        .into_iter()
        .find(|(t, _)| t == timeline)
        .map(|(_, times)| times)
        .unwrap_or_default()
}

fn arm_rotate(animation: &Animation) -> &[crate::anim::Key<f64>] {
    animation.bones["arm"].rotate.as_deref().unwrap_or_default()
}

fn rotate_values(animation: &Animation) -> Vec<f64> {
    arm_rotate(animation).iter().map(|k| k.value).collect()
}

fn bezier(numbers: &[f64]) -> Curve {
    Curve::Bezier(numbers.to_vec())
}

#[test]
fn lists_every_timeline_with_its_times() {
    let listed = timelines(&walk());
    let ids: Vec<String> = listed.iter().map(|(t, _)| t.label()).collect();
    assert_eq!(
        ids,
        ["arm rotate", "arm translate", "ik[0]", "head visible"]
    );
    assert_eq!(listed[0].1, vec![0.0, 1.0, 2.0]);
    assert!(!TimelineId::PartVisible {
        part: "head".into()
    }
    .has_curves());
}

#[test]
fn moving_keys_keeps_values_and_reorders() {
    let arm = rotate("arm");
    let moved = move_keys("walk", &walk(), &[key(&arm, 0.0)], 1.5).unwrap();
    assert_eq!(times(&moved, &arm), vec![1.0, 1.5, 2.0]);
    assert_eq!(rotate_values(&moved), vec![90.0, 0.0, 0.0]);
    // A block moves past the places its own keys leave.
    let block = [key(&arm, 1.0), key(&arm, 2.0)];
    let moved = move_keys("walk", &walk(), &block, 1.0).unwrap();
    assert_eq!(times(&moved, &arm), vec![0.0, 2.0, 3.0]);
    assert_eq!(rotate_values(&moved), vec![0.0, 90.0, 0.0]);
    // Other timelines of the same handle stay.
    let translate = TimelineId::Bone {
        bone: "arm".into(),
        channel: TransformChannel::Translate,
    };
    assert_eq!(times(&moved, &translate), vec![1.0]);
}

#[test]
fn moves_that_collide_or_leave_time_are_refused() {
    let arm = rotate("arm");
    let walk = walk();
    assert_eq!(
        move_keys("walk", &walk, &[key(&arm, 0.0)], 1.0),
        Err(EditError::Collision {
            timeline: "arm rotate".into(),
            time_s: 1.0
        })
    );
    assert_eq!(
        move_keys("walk", &walk, &[key(&arm, 1.0)], -1.5),
        Err(EditError::BadTime(-0.5))
    );
    assert!(matches!(
        move_keys("walk", &walk, &[key(&arm, 1.0)], f64::NAN),
        Err(EditError::BadShift(_))
    ));
    assert!(matches!(
        move_keys("walk", &walk, &[key(&arm, 0.5)], 0.1),
        Err(EditError::UnknownKey { .. })
    ));
    assert!(matches!(
        move_keys("walk", &walk, &[key(&rotate("leg"), 0.0)], 0.1),
        Err(EditError::UnknownTimeline(_))
    ));
    // A collision on one timeline refuses the whole move.
    let both = [key(&TimelineId::Ik { index: 0 }, 0.0), key(&arm, 0.0)];
    assert!(move_keys("walk", &walk, &both, 1.0).is_err());
}

/// `walk` with a Bézier segment from the arm's key at 0 to its key at 1.
fn curved_walk() -> Animation {
    set_curve(
        "walk",
        &walk(),
        &key(&rotate("arm"), 0.0),
        &Curve::Bezier(vec![0.25, 10.0, 0.75, 80.0]),
    )
    .unwrap()
}

#[test]
fn bezier_handles_keep_their_fraction_of_the_segment() {
    let arm = rotate("arm");
    let curved = curved_walk();
    // Stretching the segment to 0 → 2 doubles the handle times; values stay.
    let stretched = move_keys("walk", &curved, &[key(&arm, 1.0), key(&arm, 2.0)], 1.0).unwrap();
    assert_eq!(
        arm_rotate(&stretched)[0].curve,
        bezier(&[0.5, 10.0, 1.5, 80.0])
    );
    // Deleting the key that ended the segment stretches it to the next one.
    let deleted = delete_keys("walk", &curved, &[key(&arm, 1.0)]).unwrap();
    assert_eq!(
        arm_rotate(&deleted)[0].curve,
        bezier(&[0.5, 10.0, 1.5, 80.0])
    );
    // Moving the curved key itself shifts and squeezes its handles with it.
    let shifted = move_keys("walk", &curved, &[key(&arm, 0.0)], 0.5).unwrap();
    assert_eq!(
        arm_rotate(&shifted)[0].curve,
        bezier(&[0.625, 10.0, 0.875, 80.0])
    );
}

#[test]
fn deleting_the_last_keys_removes_the_timeline_and_its_owner() {
    let arm = rotate("arm");
    let translate = TimelineId::Bone {
        bone: "arm".into(),
        channel: TransformChannel::Translate,
    };
    let all: Vec<KeyRef> = [0.0, 1.0, 2.0].iter().map(|&t| key(&arm, t)).collect();
    let gone = delete_keys("walk", &walk(), &all).unwrap();
    assert!(gone.bones["arm"].rotate.is_none());
    assert_eq!(times(&gone, &translate), vec![1.0]);
    let mut rest = all.clone();
    rest.push(key(&translate, 1.0));
    rest.push(key(&TimelineId::Ik { index: 0 }, 0.0));
    let gone = delete_keys("walk", &walk(), &rest).unwrap();
    assert!(gone.bones.is_empty(), "{gone:?}");
    assert!(gone.ik.is_empty(), "{gone:?}");
    assert!(matches!(
        delete_keys("walk", &walk(), &[key(&arm, 3.0)]),
        Err(EditError::UnknownKey { .. })
    ));
}

#[test]
fn emptying_several_ik_drags_in_one_edit_removes_each() {
    let drag =
        |at: f64, time: f64| json!({"at": [at, at], "to": [{"time": time, "value": [at, 0]}]});
    let three = parsed(
        "walk",
        json!({"ik": [drag(0.0, 0.0), drag(5.0, 0.0), drag(9.0, 1.0)]}),
    );
    let keys = [
        key(&TimelineId::Ik { index: 0 }, 0.0),
        key(&TimelineId::Ik { index: 1 }, 0.0),
    ];
    // Drag 1 is still drag 1 after drag 0 lost its last key.
    let left = delete_keys("walk", &three, &keys).unwrap();
    assert_eq!(left.ik.len(), 1);
    assert_eq!(left.ik[0].at, Point::new(9.0, 9.0));
}

#[test]
fn a_copied_key_of_another_kind_is_refused() {
    let copied = CopiedKey {
        timeline: rotate("arm"),
        offset_s: 0.0,
        key: json!({"time": 0, "value": [1, 2]}),
        next_time_s: None,
    };
    let refused = paste_keys("walk", &walk(), 0.5, &[copied]).unwrap_err();
    assert!(
        matches!(&refused, EditError::MalformedKey { key: 0, .. }),
        "{refused}"
    );
    assert!(refused
        .to_string()
        .starts_with("arm rotate: copied key 0 is malformed"));
}

#[test]
fn copy_and_paste_at_a_time() {
    let arm = rotate("arm");
    let ik = TimelineId::Ik { index: 0 };
    let walk = walk();
    let copied = copy_keys(&walk, &[key(&arm, 1.0), key(&arm, 2.0), key(&ik, 0.0)]).unwrap();
    assert_eq!(copied.len(), 3);
    assert_eq!(copied[0].offset_s, 1.0);
    assert_eq!(copied[2].offset_s, 0.0);
    let pasted = paste_keys("walk", &walk, 2.0, &copied).unwrap();
    // Offsets count from the earliest copied key (the IK drag's at 0): 90 at 3, 0 at 4.
    assert_eq!(times(&pasted, &arm), vec![0.0, 1.0, 2.0, 3.0, 4.0]);
    assert_eq!(rotate_values(&pasted), vec![0.0, 90.0, 0.0, 90.0, 0.0]);
    assert_eq!(times(&pasted, &ik), vec![0.0, 2.0]);
    // Pasting over existing keys replaces them.
    let over = paste_keys("walk", &walk, 1.0, &copied[..1]).unwrap();
    assert_eq!(times(&over, &arm), vec![0.0, 1.0, 2.0]);
    assert_eq!(rotate_values(&over), vec![0.0, 90.0, 90.0]);
    // Into an animation without that timeline: created; an IK drag must exist.
    let empty = Animation::default();
    let created = paste_keys("other", &empty, 0.5, &copied[..2]).unwrap();
    assert_eq!(times(&created, &arm), vec![1.5, 2.5]);
    assert_eq!(
        paste_keys("other", &empty, 0.0, &copied[2..]),
        Err(EditError::UnknownTimeline("ik[0]".into()))
    );
    assert!(matches!(
        paste_keys("walk", &walk, -1.0, &copied),
        Err(EditError::BadTime(_))
    ));
}

#[test]
fn pasted_bezier_handles_fit_their_new_segment() {
    let arm = rotate("arm");
    let curved = curved_walk();
    let copied = copy_keys(&curved, &[key(&arm, 0.0)]).unwrap();
    let pasted = paste_keys("walk", &curved, 1.5, &copied).unwrap();
    // The segment 1.5 → 2 is half as long as the copied 0 → 1.
    assert_eq!(
        arm_rotate(&pasted)[2].curve,
        bezier(&[1.625, 10.0, 1.875, 80.0])
    );
    pasted.validate("walk").unwrap();
}

#[test]
fn curves_are_set_and_checked() {
    let arm = rotate("arm");
    let walk = walk();
    let stepped = set_curve("walk", &walk, &key(&arm, 1.0), &Curve::Stepped).unwrap();
    assert_eq!(arm_rotate(&stepped)[1].curve, Curve::Stepped);
    let back = set_curve("walk", &stepped, &key(&arm, 1.0), &Curve::Linear).unwrap();
    assert_eq!(back, walk);
    assert!(matches!(
        set_curve(
            "walk",
            &walk,
            &key(&arm, 2.0),
            &Curve::Bezier(vec![2.0, 0.0, 2.0, 0.0])
        ),
        Err(EditError::LastKey { .. })
    ));
    assert!(matches!(
        set_curve(
            "walk",
            &walk,
            &key(
                &TimelineId::PartVisible {
                    part: "head".into()
                },
                0.0
            ),
            &Curve::Stepped
        ),
        Err(EditError::NoCurves(_))
    ));
    // The timeline check refuses a wrong length and a handle outside the segment.
    let ik = TimelineId::Ik { index: 0 };
    let longer = paste_keys(
        "walk",
        &walk,
        1.0,
        &copy_keys(&walk, &[key(&ik, 0.0)]).unwrap(),
    )
    .unwrap();
    assert!(matches!(
        set_curve(
            "walk",
            &longer,
            &key(&ik, 0.0),
            &Curve::Bezier(vec![0.3, 1.0, 0.6, 2.0])
        ),
        Err(EditError::Animation(AnimError::Timeline {
            problem: crate::anim::TimelineError::CurveLength { .. },
            ..
        }))
    ));
    assert!(matches!(
        set_curve(
            "walk",
            &walk,
            &key(&arm, 0.0),
            &Curve::Bezier(vec![1.5, 1.0, 0.6, 2.0])
        ),
        Err(EditError::Animation(AnimError::Timeline {
            problem: crate::anim::TimelineError::CurveTime { .. },
            ..
        }))
    ));
}

#[test]
fn an_ease_bezier_leaves_and_reaches_its_keys_flat_and_passes_the_middle_halfway() {
    let segment = Segment {
        start_s: 1.0,
        end_s: 2.0,
        start: vec![0.0, 10.0],
        end: vec![30.0, -10.0],
        curve: Curve::Linear,
    };
    let eased = Segment {
        curve: Curve::Bezier(segment.ease_bezier()),
        ..segment.clone()
    };
    for c in 0..2 {
        let (v0, v1) = (segment.start[c], segment.end[c]);
        // Symmetric handles: halfway in time is halfway in value.
        assert!((eased.value_at(c, 1.5) - (v0 + v1) / 2.0).abs() < 1e-6);
        // Flat at both ends: after 2 % of the time it has moved under 1 % of the way.
        let near_start = (eased.value_at(c, 1.02) - v0) / (v1 - v0);
        let near_end = (v1 - eased.value_at(c, 1.98)) / (v1 - v0);
        assert!(
            near_start < 0.01 && near_end < 0.01,
            "{near_start} {near_end}"
        );
        assert!(near_start > 0.0 && near_end > 0.0);
    }
}

#[test]
fn a_segment_and_its_linear_bezier_play_alike() {
    let ik = TimelineId::Ik { index: 0 };
    let walk = walk();
    let two = paste_keys(
        "walk",
        &walk,
        0.8,
        &[CopiedKey {
            timeline: ik.clone(),
            offset_s: 0.0,
            key: json!({"time": 0, "value": [9, -2]}),
            next_time_s: None,
        }],
    )
    .unwrap();
    let segment = segment(&two, &key(&ik, 0.0)).unwrap();
    assert_eq!((segment.start_s, segment.end_s), (0.0, 0.8));
    assert_eq!(segment.start, vec![5.0, 6.0]);
    assert_eq!(segment.end, vec![9.0, -2.0]);
    assert_eq!(segment.channels(), 2);
    let bezier = Segment {
        curve: Curve::Bezier(segment.linear_bezier()),
        ..segment.clone()
    };
    for i in 0..=10 {
        let t = 0.08 * i as f64;
        for c in 0..2 {
            let (a, b) = (segment.value_at(c, t), bezier.value_at(c, t));
            assert!((a - b).abs() < 1e-9, "{t} {c}: {a} {b}");
        }
    }
    // And the document's sampling agrees once the curve is stored.
    let stored = set_curve("walk", &two, &key(&ik, 0.0), &bezier.curve).unwrap();
    let pose = stored.sample(0.2, false);
    assert!((pose.ik[0].to[0] - 6.0).abs() < 1e-9, "{:?}", pose.ik);
    let rotate_last = segment_error(&walk);
    assert!(matches!(rotate_last, Err(EditError::LastKey { .. })));
}

fn segment_error(walk: &Animation) -> Result<Segment, EditError> {
    segment(walk, &key(&rotate("arm"), 2.0))
}

#[test]
fn a_key_put_inside_an_eased_segment_leaves_the_motion_unchanged() {
    use crate::anim::sample::sample_keys;
    let eased = vec![
        Key {
            time: 0.0,
            value: [0.0, 0.0],
            curve: Curve::Bezier(vec![0.6, 0.0, 0.7, 40.0, 0.2, -5.0, 0.9, 30.0]),
        },
        Key {
            time: 1.0,
            value: [40.0, 20.0],
            curve: Curve::Linear,
        },
    ];
    let mut keys = eased.clone();
    let at = 0.35;
    let value = sample_keys(&keys, at).unwrap();
    put_key(&mut keys, at, value);
    assert_eq!(keys.len(), 3);
    // The result is a valid timeline (handles inside their segments), and plays the same.
    let animation = Animation {
        bones: [(
            "arm".to_string(),
            crate::anim::BoneTimelines {
                translate: Some(keys.clone()),
                ..Default::default()
            },
        )]
        .into(),
        ..Default::default()
    };
    animation.validate("eased").unwrap();
    for k in 0..=100 {
        let t = k as f64 / 100.0;
        let (a, b) = (
            sample_keys(&eased, t).unwrap(),
            sample_keys(&keys, t).unwrap(),
        );
        assert!(
            (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9,
            "{t}: {a:?} {b:?}"
        );
    }
    // A different value moves the curve there, and only near the new key.
    let mut moved = eased.clone();
    put_key(&mut moved, at, [value[0] + 5.0, value[1]]);
    let b = sample_keys(&moved, at).unwrap();
    assert!((b[0] - value[0] - 5.0).abs() < 1e-9);
    assert_eq!(sample_keys(&moved, 1.0), sample_keys(&eased, 1.0));
    // On an existing key it replaces the value; after the last one it appends a linear key.
    put_key(&mut moved, 1.0, [1.0, 2.0]);
    put_key(&mut moved, 2.0, [3.0, 4.0]);
    assert_eq!(moved.len(), 4);
    assert_eq!(moved[2].value, [1.0, 2.0]);
    assert_eq!(moved[3].curve, Curve::Linear);
}

/// A hand swapped to a fist at 0.5 s, a squash keyed on the body, footsteps (two events at 1 s).
fn grab() -> Animation {
    parsed(
        "grab",
        json!({
            "parts": {"hand": {"attachment": [{"time": 0, "value": "hand"},
                                              {"time": 0.5, "value": "fist"}]}},
            "deform": {"body": [{"time": 0, "value": [[0, 0], [0, 0]],
                                 "curve": [0.25, 0, 0.75, 1]},
                                {"time": 1, "value": [[0, 2], [0, 4]]}]},
            "events": [{"time": 0.5, "name": "step", "int": 1},
                       {"time": 1, "name": "step", "int": 2},
                       {"time": 1, "name": "cue", "string": "go"}]
        }),
    )
}

#[test]
fn attachment_deform_and_event_keys_are_rows_like_the_others() {
    let anim = grab();
    let listed = timelines(&anim);
    let ids: Vec<String> = listed.iter().map(|(t, _)| t.label()).collect();
    assert_eq!(ids, ["body deform", "hand attachment", "events"]);
    // Events at one time are one key of the row.
    assert_eq!(listed[2].1, vec![0.5, 1.0]);
    let (attachment, deform, events) = (
        TimelineId::Attachment {
            slot: "hand".into(),
        },
        TimelineId::Deform {
            part: "body".into(),
        },
        TimelineId::Events,
    );
    assert!(!attachment.has_curves() && !events.has_curves() && deform.has_curves());

    // Moving the events at 1 s moves both, in their order; the attachment key moves alone.
    let moved = move_keys(
        "grab",
        &anim,
        &[key(&events, 1.0), key(&attachment, 0.5)],
        0.25,
    )
    .unwrap();
    let fired: Vec<(f64, &str)> = moved
        .events
        .iter()
        .map(|k| (k.time, k.name.as_str()))
        .collect();
    assert_eq!(fired, [(0.5, "step"), (1.25, "step"), (1.25, "cue")]);
    let swap = moved.parts["hand"].attachment.as_ref().unwrap();
    assert_eq!(
        (swap[1].time, swap[1].value.as_deref()),
        (0.75, Some("fist"))
    );
    // Onto the other event time: events may share it; attachment keys may not.
    let shared = move_keys("grab", &anim, &[key(&events, 0.5)], 0.5).unwrap();
    assert_eq!(shared.events.len(), 3);
    assert!(shared.events.iter().all(|k| k.time == 1.0));
    assert!(matches!(
        move_keys("grab", &anim, &[key(&attachment, 0.0)], 0.5),
        Err(EditError::Collision { .. })
    ));

    // Stepped rows have no curve; a deform key's is one 0..1 curve for all its offsets.
    assert!(matches!(
        set_curve("grab", &anim, &key(&attachment, 0.0), &Curve::Stepped),
        Err(EditError::NoCurves(_))
    ));
    let segment = segment(&anim, &key(&deform, 0.0)).unwrap();
    assert_eq!(
        (segment.start.clone(), segment.end.clone()),
        (vec![0.0], vec![1.0])
    );
    let stepped = set_curve("grab", &anim, &key(&deform, 0.0), &Curve::Stepped).unwrap();
    assert_eq!(stepped.deform["body"][0].curve, Curve::Stepped);

    // Copy the events at 1 s and the deform key at 1 s; paste them at 2 s.
    let copied = copy_keys(&anim, &[key(&events, 1.0), key(&deform, 1.0)]).unwrap();
    assert_eq!(copied.len(), 3);
    let pasted = paste_keys("grab", &anim, 2.0, &copied).unwrap();
    let at_two: Vec<(&str, Option<i32>)> = pasted
        .events
        .iter()
        .filter(|k| k.time == 2.0)
        .map(|k| (k.name.as_str(), k.int))
        .collect();
    assert_eq!(at_two, [("step", Some(2)), ("cue", None)]);
    let offsets = &pasted.deform["body"][2].value;
    assert_eq!(
        offsets,
        &[
            crate::geom::Vec2::new(0.0, 2.0),
            crate::geom::Vec2::new(0.0, 4.0)
        ]
    );
    // Pasted again at the same time: replaced, not doubled.
    let again = paste_keys("grab", &pasted, 2.0, &copied).unwrap();
    assert_eq!(again, pasted);

    // Deleting the rows' keys removes them, and the emptied timelines with them.
    let all: Vec<KeyRef> = listed
        .iter()
        .flat_map(|(t, times)| times.iter().map(|&s| key(t, s)))
        .collect();
    let emptied = delete_keys("grab", &anim, &all).unwrap();
    assert_eq!(emptied, Animation::default());
    assert!(matches!(
        delete_keys("grab", &emptied, &[key(&events, 0.5)]),
        Err(EditError::UnknownTimeline(_))
    ));
}
