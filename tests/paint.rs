//! Weight painting and locked handles through the document: commands, undo, recomputes that
//! keep locked weights (same mesh and re-traced), saving and reopening the locks.

mod command;
mod common;

use command::scratch;
use common::document::{bar_layer, bone, compute};
use sinew::document::{Command, Document, DocumentError};
use sinew::geom::Point;
use sinew::weights::{BrushMode, BrushOptions, Falloff};

/// A bar with three bones along it, weights computed.
fn arm(dir: &std::path::Path) -> Document {
    let mut doc = Document::new();
    doc.apply(Command::AddLayer(bar_layer("bar", dir, true)))
        .unwrap();
    doc.apply(Command::AddBone(bone(
        "a",
        None,
        [20.0, 40.0],
        [110.0, 40.0],
    )))
    .unwrap();
    doc.apply(Command::AddBone(bone(
        "b",
        Some("a"),
        [110.0, 40.0],
        [200.0, 40.0],
    )))
    .unwrap();
    doc.apply(Command::AddBone(bone(
        "c",
        Some("b"),
        [200.0, 40.0],
        [300.0, 40.0],
    )))
    .unwrap();
    compute(&mut doc);
    doc
}

/// The bar's weight rows.
fn rows(doc: &Document) -> Vec<Vec<(u32, f64)>> {
    doc.posable().expect("current weights").doc.parts[0]
        .weights
        .as_ref()
        .expect("weights")
        .rows
        .clone()
}

fn column(rows: &[Vec<(u32, f64)>], c: u32) -> Vec<f64> {
    rows.iter()
        .map(|r| r.iter().find(|e| e.0 == c).map_or(0.0, |e| e.1))
        .collect()
}

fn vertices(doc: &Document) -> Vec<Point> {
    doc.state().rig.as_ref().expect("a rig").doc.parts[0]
        .mesh
        .vertices
        .clone()
}

fn check_rows(rows: &[Vec<(u32, f64)>]) {
    for row in rows {
        let sum: f64 = row.iter().map(|e| e.1).sum();
        assert!((sum - 1.0).abs() < 1e-9, "{row:?}");
        assert!(row.iter().all(|e| (0.0..=1.0).contains(&e.1)), "{row:?}");
    }
}

/// Sets the document's influence limit to `k` and recomputes the weights.
fn limit_and_compute(doc: &mut Document, k: usize) {
    let mut options = doc.state().options.clone();
    options.weights.max_influences = Some(k);
    doc.apply(Command::SetOptions(options)).unwrap();
    compute(doc);
}

/// A stroke adding handle b's weight at full strength over discs of `radius_px` along
/// `samples_px`.
fn fill_b(samples_px: Vec<Point>, radius_px: f64) -> Command {
    Command::PaintWeights {
        part: "bar".into(),
        handle: "b".into(),
        mode: BrushMode::Add,
        samples_px,
        options: BrushOptions {
            radius_px,
            strength: 1.0,
            falloff: Falloff::Constant,
            spacing: 0.25,
        },
    }
}

/// A stroke painting `handle` along the bar's middle from x = 130 to 190.
fn stroke(handle: &str, mode: BrushMode) -> Command {
    Command::PaintWeights {
        part: "bar".into(),
        handle: handle.into(),
        mode,
        samples_px: vec![
            Point::new(130.0, 40.0),
            Point::new(160.0, 38.0),
            Point::new(190.0, 40.0),
        ],
        options: BrushOptions {
            radius_px: 30.0,
            strength: 0.6,
            falloff: Falloff::Smooth,
            spacing: 0.25,
        },
    }
}

#[test]
fn painting_keeps_locked_handles_and_undoes_in_one_step() {
    let tmp = scratch("undo");
    let dir = tmp.path();
    let mut doc = arm(dir);
    let before = rows(&doc);
    // Columns: a = 0, b = 1, c = 2.
    doc.apply(Command::SetLocked {
        handle: "c".into(),
        locked: true,
    })
    .unwrap();
    assert!(doc.posable().is_some(), "locking keeps the weights current");
    doc.apply(stroke("a", BrushMode::Add)).unwrap();
    let painted = rows(&doc);
    check_rows(&painted);
    let (a0, a1) = (column(&before, 0), column(&painted, 0));
    let v = vertices(&doc);
    let raised = (0..v.len())
        .filter(|&i| (v[i][0] - 160.0).abs() < 20.0)
        .map(|i| a1[i] - a0[i])
        .fold(0.0, f64::max);
    assert!(raised > 0.3, "a rose by at most {raised} under the stroke");
    for (x, y) in column(&before, 2).iter().zip(column(&painted, 2)) {
        assert_eq!(x.to_bits(), y.to_bits(), "the locked column changed");
    }
    // Far from the stroke nothing moved.
    for i in (0..v.len()).filter(|&i| (v[i][0] - 160.0).abs() > 70.0) {
        assert_eq!(painted[i], before[i], "vertex at {:?}", v[i]);
    }
    // One stroke is one undo step.
    assert!(doc.undo());
    assert_eq!(rows(&doc), before);
    assert!(doc.state().locked.contains("c"));
    assert!(doc.redo());
    assert_eq!(rows(&doc), painted);

    // A locked handle cannot be painted; unknown parts and handles are refused; nothing
    // changes.
    let err = doc.apply(stroke("c", BrushMode::Add)).unwrap_err();
    assert!(matches!(err, DocumentError::LockedHandle(_)), "{err}");
    assert!(matches!(
        doc.apply(stroke("nope", BrushMode::Add)),
        Err(DocumentError::UnknownHandle(_))
    ));
    let Command::PaintWeights {
        handle,
        mode,
        samples_px,
        options,
        ..
    } = stroke("a", BrushMode::Smooth)
    else {
        unreachable!()
    };
    assert!(matches!(
        doc.apply(Command::PaintWeights {
            part: "leg".into(),
            handle,
            mode,
            samples_px,
            options,
        }),
        Err(DocumentError::UnknownLayer(_))
    ));
    assert!(matches!(
        doc.apply(Command::SetLocked {
            handle: "nope".into(),
            locked: true
        }),
        Err(DocumentError::UnknownHandle(_))
    ));
    assert_eq!(rows(&doc), painted);

    // Stale weights cannot be painted.
    doc.apply(Command::MoveBone {
        name: "a".into(),
        head: Point::new(22.0, 40.0),
        tail: Point::new(110.0, 40.0),
    })
    .unwrap();
    assert!(matches!(
        doc.apply(stroke("a", BrushMode::Add)),
        Err(DocumentError::NoWeights)
    ));
}

#[test]
fn recomputing_with_a_lock_keeps_the_influence_limit() {
    let tmp = scratch("limit");
    let dir = tmp.path();
    let mut doc = arm(dir);
    doc.apply(fill_b(
        vec![Point::new(230.0, 40.0), Point::new(280.0, 40.0)],
        30.0,
    ))
    .unwrap();
    doc.apply(Command::SetLocked {
        handle: "b".into(),
        locked: true,
    })
    .unwrap();
    // A point where b was painted: the fresh rows there pair it with c, beside the locked b.
    doc.apply(Command::AddPoint(sinew::rig::PointHandle {
        name: "p".into(),
        at: Point::new(250.0, 40.0),
        parent: None,
    }))
    .unwrap();
    limit_and_compute(&mut doc, 2);
    let kept = rows(&doc);
    check_rows(&kept);
    let widest = kept.iter().map(Vec::len).max().unwrap_or(0);
    assert!(widest <= 2, "a row has {widest} influences");
    // b stays where it was painted.
    let v = vertices(&doc);
    let b = column(&kept, 1);
    let i = v
        .iter()
        .position(|p| (p[0] - 270.0).abs() < 8.0 && (p[1] - 40.0).abs() < 8.0)
        .expect("a vertex near (270, 40)");
    assert!(b[i] > 0.5, "b at {:?} is {}", v[i], b[i]);
}

#[test]
fn painting_keeps_the_influence_limit() {
    let tmp = scratch("paint-limit");
    let dir = tmp.path();
    let mut doc = arm(dir);
    // c painted over a's end of the bar, where a and b already weigh every vertex.
    let paint_c = |strength: f64| Command::PaintWeights {
        part: "bar".into(),
        handle: "c".into(),
        mode: BrushMode::Add,
        samples_px: vec![Point::new(40.0, 40.0), Point::new(100.0, 40.0)],
        options: BrushOptions {
            radius_px: 30.0,
            strength,
            ..Default::default()
        },
    };
    limit_and_compute(&mut doc, 2);
    doc.apply(paint_c(0.5)).unwrap();
    let painted = rows(&doc);
    check_rows(&painted);
    let widest = painted.iter().map(Vec::len).max().unwrap_or(0);
    assert!(widest <= 2, "a row has {widest} influences");
    assert!(
        column(&painted, 2).iter().any(|&w| w > 0.3),
        "c was not painted"
    );

    // With one influence per vertex a light stroke cannot take any vertex over: refused, and
    // no undo step.
    limit_and_compute(&mut doc, 1);
    let before = rows(&doc);
    match doc.apply(paint_c(0.05)) {
        Err(DocumentError::NothingPainted {
            at_limit,
            limit: Some(1),
        }) => assert!(at_limit > 0),
        other => panic!("expected the limit to refuse the stroke, got {other:?}"),
    }
    assert_eq!(rows(&doc), before);
}

#[test]
fn recomputing_keeps_locked_weights_on_the_same_and_a_new_mesh() {
    let tmp = scratch("recompute");
    let dir = tmp.path();
    let mut doc = arm(dir);
    let fresh = rows(&doc);
    // Paint b far into c's side, lock b, then edit a bone so the weights must be recomputed.
    doc.apply(fill_b(
        vec![Point::new(230.0, 40.0), Point::new(280.0, 40.0)],
        30.0,
    ))
    .unwrap();
    let painted = rows(&doc);
    let v_old = vertices(&doc);
    doc.apply(Command::SetLocked {
        handle: "b".into(),
        locked: true,
    })
    .unwrap();
    doc.apply(Command::MoveBone {
        name: "a".into(),
        head: Point::new(20.0, 44.0),
        tail: Point::new(110.0, 40.0),
    })
    .unwrap();
    compute(&mut doc);
    let kept = rows(&doc);
    check_rows(&kept);
    // Bones are embedded in the mesh, so moving one may move vertices: compare the locked
    // column where a vertex stayed (elsewhere it is carried over, see below).
    let v_new = vertices(&doc);
    let b_painted = column(&painted, 1);
    let b_fresh = column(&fresh, 1);
    let b_kept = column(&kept, 1);
    let mut compared = 0;
    for (i, p) in v_new.iter().enumerate() {
        if let Some(j) = v_old.iter().position(|q| q == p) {
            assert!(
                (b_kept[i] - b_painted[j]).abs() < 1e-9,
                "b at {p:?}: kept {} painted {}",
                b_kept[i],
                b_painted[j]
            );
            compared += 1;
        }
    }
    assert!(
        compared > 10,
        "{compared} of {} vertices stayed",
        v_new.len()
    );
    // Where the stroke went, b is far above what a plain recompute gives.
    let far = v_new
        .iter()
        .position(|p| (p[0] - 255.0).abs() < 8.0 && (p[1] - 40.0).abs() < 8.0)
        .expect("a vertex near (255, 40)");
    let j = v_old
        .iter()
        .position(|q| (q[0] - v_new[far][0]).hypot(q[1] - v_new[far][1]) < 10.0)
        .expect("an old vertex nearby");
    assert!(
        b_kept[far] > 0.9 && b_fresh[j] < 0.2,
        "{} {}",
        b_kept[far],
        b_fresh[j]
    );

    // Re-trace with another mesh density: the locked weights are carried over by position.
    let mut options = doc.state().options.clone();
    options.mesh.max_area_fraction *= 0.5;
    doc.apply(Command::SetOptions(options)).unwrap();
    compute(&mut doc);
    let remeshed = rows(&doc);
    check_rows(&remeshed);
    let v_remeshed = vertices(&doc);
    assert_ne!(v_remeshed.len(), v_new.len(), "the mesh changed");
    let b_remeshed = column(&remeshed, 1);
    for (i, p) in v_remeshed.iter().enumerate() {
        if (p[0] - 255.0).abs() < 15.0 && (p[1] - 40.0).abs() < 12.0 {
            assert!(b_remeshed[i] > 0.85, "b at {p:?} is {}", b_remeshed[i]);
        }
    }

    // Unlocked, a recompute overwrites the painted weights.
    doc.apply(Command::SetLocked {
        handle: "b".into(),
        locked: false,
    })
    .unwrap();
    doc.apply(Command::MoveBone {
        name: "a".into(),
        head: Point::new(20.0, 40.0),
        tail: Point::new(110.0, 40.0),
    })
    .unwrap();
    compute(&mut doc);
    let plain = column(&rows(&doc), 1);
    let v = vertices(&doc);
    let i = v
        .iter()
        .position(|p| (p[0] - 255.0).abs() < 8.0 && (p[1] - 40.0).abs() < 8.0)
        .expect("a vertex near (255, 40)");
    assert!(plain[i] < 0.2, "{}", plain[i]);
}

#[test]
fn locks_are_saved_and_reopened() {
    let tmp = scratch("save");
    let dir = tmp.path();
    let mut doc = arm(dir);
    let path = dir.join("arm.json");
    doc.save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(!text.contains("\"locked\""), "no locks, no field");
    // Paint b where c rules, lock it, rename it: the recompute keeps its weights.
    doc.apply(fill_b(vec![Point::new(250.0, 40.0)], 20.0))
        .unwrap();
    let painted = column(&rows(&doc), 1);
    doc.apply(Command::SetLocked {
        handle: "b".into(),
        locked: true,
    })
    .unwrap();
    doc.apply(Command::Rename {
        from: "b".into(),
        to: "mid".into(),
    })
    .unwrap();
    compute(&mut doc);
    let kept = rows(&doc);
    let scene = doc.posable().unwrap();
    assert_eq!(
        scene.doc.parts[0].weights.as_ref().unwrap().handles,
        vec!["a", "mid", "c"]
    );
    check_rows(&kept);
    let v = vertices(&doc);
    let near = (0..v.len())
        .filter(|&i| (v[i][0] - 250.0).hypot(v[i][1] - 40.0) < 18.0)
        .collect::<Vec<_>>();
    assert!(!near.is_empty());
    for i in near {
        assert!(
            painted[i] == 1.0 && column(&kept, 1)[i] == 1.0,
            "mid at {:?}",
            v[i]
        );
    }
    doc.save(&path).unwrap();
    let reopened = Document::open(&path).unwrap();
    assert_eq!(
        reopened.state().locked.iter().collect::<Vec<_>>(),
        vec!["mid"]
    );
    assert!(reopened.posable().is_some());
    doc.apply(Command::Delete { name: "mid".into() }).unwrap();
    assert!(doc.state().locked.is_empty());
}

#[test]
fn locked_weights_survive_saving_a_stale_rig_and_reopening() {
    let tmp = scratch("stale");
    let dir = tmp.path();
    let mut doc = arm(dir);
    doc.apply(fill_b(vec![Point::new(250.0, 40.0)], 20.0))
        .unwrap();
    let v = vertices(&doc);
    let near: Vec<usize> = (0..v.len())
        .filter(|&i| (v[i][0] - 250.0).hypot(v[i][1] - 40.0) < 18.0)
        .collect();
    assert!(!near.is_empty());
    doc.apply(Command::SetLocked {
        handle: "b".into(),
        locked: true,
    })
    .unwrap();
    // A point handle added far from the stroke makes the weights stale; save and reopen.
    doc.apply(Command::AddPoint(sinew::rig::PointHandle {
        name: "tip".into(),
        at: Point::new(40.0, 40.0),
        parent: None,
    }))
    .unwrap();
    let path = dir.join("stale.json");
    doc.save(&path).unwrap();
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let part = &saved["parts"][0];
    assert!(
        part.get("weights").is_none(),
        "stale weights are not weights"
    );
    assert!(
        part.get("stale_weights").is_some(),
        "kept aside for the lock"
    );
    let mut reopened = Document::open(&path).unwrap();
    assert!(
        reopened.posable().is_none(),
        "the reopened rig needs computing"
    );
    compute(&mut reopened);
    let kept = rows(&reopened);
    check_rows(&kept);
    let v_new = vertices(&reopened);
    let handles = &reopened.posable().unwrap().doc.parts[0]
        .weights
        .as_ref()
        .unwrap()
        .handles;
    let b = handles.iter().position(|h| h == "b").unwrap() as u32;
    for i in near {
        let j = v_new
            .iter()
            .position(|p| *p == v[i])
            .expect("the stroke's vertices stay where they were");
        assert_eq!(column(&kept, b)[j], 1.0, "b at {:?}", v[i]);
    }

    // Without locks nothing is kept aside: the file is as before.
    doc.apply(Command::SetLocked {
        handle: "b".into(),
        locked: false,
    })
    .unwrap();
    doc.save(&path).unwrap();
    assert!(!std::fs::read_to_string(&path)
        .unwrap()
        .contains("stale_weights"));
}
