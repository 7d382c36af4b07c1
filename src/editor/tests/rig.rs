//! Rig mode driven through the UI: bones, weights, undo; cages, regions, the mesh preview and the
//! automatic rig; painting weights with a locked handle.

use super::*;

#[test]
fn rig_weigh_pose_undo_through_the_ui() {
    let mut h = open_character("flow");
    h.get_by_label("Weights are up to date");
    let bones_before = h.state().doc.state().handles.bones.len();
    let inside = torso_point(&h);
    let tail = [inside[0] + 12.0, inside[1] + 8.0];

    // Rig mode: draw a bone inside the torso with the bone tool.
    click_shown(&mut h, "Bone");
    drag(&mut h, inside, tail);
    let handles = &h.state().doc.state().handles;
    assert_eq!(
        handles.bones.len(),
        bones_before + 1,
        "{:?}",
        h.state().message
    );
    let added = handles.bones.last().expect("a bone");
    assert!(
        distance(added.tail, tail) < 1.0,
        "{added:?}, wanted tail {tail:?}"
    );
    assert!(
        h.state().doc.posable().is_none(),
        "new handle: weights stale"
    );
    h.get_by_label("Weights need computing");

    // Computing runs in the background; the UI keeps drawing frames meanwhile.
    press_shown(&mut h, "Compute weights");
    h.step();
    assert!(h.state().computing());
    h.step();
    h.get_by_label("Cancel");
    wait_for_weights(&mut h);
    assert!(h.state().doc.posable().is_some(), "{:?}", h.state().message);

    // Pose mode: drag a point of the torso; the pose gets a drag and the shape moves.
    h.key_press(Key::Num2);
    h.run();
    assert_eq!(h.state().mode, Mode::Pose);
    // The new bone is still selected, and its gizmo sits where the torso will be gripped: a
    // click on empty canvas deselects it.
    assert!(h.state().selected.is_some());
    click(&mut h, Point::new(4.0, 4.0));
    assert_eq!(h.state().selected, None);
    let grip = torso_point(&h);
    drag(&mut h, grip, [grip[0] + 25.0, grip[1] - 15.0]);
    // The torso's middle is the root bone's own: the drag holds no other point.
    let pose = &h.state().doc.state().pose;
    assert_eq!(pose.ik.len(), 1, "{:?}", h.state().message);
    assert!(distance(pose.ik[0].at, grip) < 1.0);
    assert!(distance(pose.ik[0].to, [grip[0] + 25.0, grip[1] - 15.0]) < 1.0);
    let posed = h.state().pose_mode.posed.as_ref().expect("posed");
    let moved = posed
        .positions
        .iter()
        .flatten()
        .zip(
            h.state()
                .doc
                .posable()
                .expect("rig")
                .rest_positions()
                .iter()
                .flatten(),
        )
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(moved > 10.0, "the shape moved only {moved} px");

    // Undo the drag with the keyboard, then redo it.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert!(h.state().doc.state().pose.ik.is_empty());
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    h.run();
    assert_eq!(h.state().doc.state().pose.ik.len(), 1);
}

#[test]
fn cages_regions_mesh_preview_and_automatic_rig_in_rig_mode() {
    let mut h = open_character("rigtools");
    assert_eq!(h.state().mode, Mode::Rig);
    let before = h.state().doc.state().handles.clone();

    // A cage: four clicks, then a click on the first vertex closes it.
    click_shown(&mut h, "Cage");
    let square = [
        [150.0, 150.0],
        [360.0, 150.0],
        [360.0, 380.0],
        [150.0, 380.0],
    ];
    for p in square {
        click(&mut h, p);
    }
    assert!(h.state().doc.state().handles.cages.is_empty(), "still open");
    click(&mut h, square[0]);
    let cages = &h.state().doc.state().handles.cages;
    assert_eq!(cages.len(), 1);
    assert_eq!(cages[0].polygon.len(), 4);
    assert!(distance(cages[0].polygon[2], square[2]) < 0.5);
    let cage = cages[0].name.clone();
    assert_eq!(h.state().selected.as_deref(), Some(cage.as_str()));

    // A region: three clicks and Enter.
    click_shown(&mut h, "Region");
    for p in [[240.0, 250.0], [270.0, 250.0], [255.0, 280.0]] {
        click(&mut h, p);
    }
    h.key_press(Key::Enter);
    h.run();
    assert_eq!(h.state().doc.state().handles.regions.len(), 1);

    // The select tool drags the cage by its outline.
    click_shown(&mut h, "Select");
    drag(&mut h, [255.0, 150.0], [265.0, 140.0]);
    let moved = &h.state().doc.state().handles.cages[0].polygon;
    assert!(
        distance(moved[0], Point::new(160.0, 140.0)) < 0.5,
        "{moved:?}"
    );

    // The traced mesh, rebuilt live when a meshing option changes.
    wheel_into_view(&mut h, By::new().label("Show the traced mesh"));
    press_shown(&mut h, "Show the traced mesh");
    wait_until(&mut h, "the mesh preview", |app| {
        !app.previewing() && app.preview_vertex_count().is_some()
    });
    let fine = h.state().preview_vertex_count().expect("a preview");
    let mut options = h.state().doc.state().options.clone();
    options.mesh.max_area_fraction *= 16.0;
    assert!(h.state_mut().apply(Command::SetOptions(options)));
    wait_until(&mut h, "the coarser preview", |app| {
        !app.previewing() && app.preview_vertex_count() != Some(fine)
    });
    let coarse = h.state().preview_vertex_count().expect("a preview");
    assert!(
        coarse < fine,
        "{coarse} vertices at a 16× area limit, {fine} before"
    );

    // The automatic rig replaces the handles; undo brings the hand-made ones back.
    let hand_made = h.state().doc.state().handles.clone();
    wheel_into_view(&mut h, By::new().label("Propose handles"));
    press_shown(&mut h, "Propose handles");
    wait_until(&mut h, "the automatic rig", |app| {
        !app.rig_tools.proposing()
    });
    let proposed = h.state().doc.state().handles.clone();
    assert!(!proposed.bones.is_empty(), "{:?}", h.state().message);
    assert_ne!(proposed, hand_made);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(h.state().doc.state().handles, hand_made);
    assert_ne!(hand_made, before);
}

#[test]
fn paint_weights_with_a_locked_handle_through_the_ui() {
    let mut h = open_character("paint");
    h.get_by_label("Weights are up to date");
    let torso = |app: &EditorApp| {
        let scene = app.doc.posable().expect("posable").clone();
        let index = scene
            .doc
            .parts
            .iter()
            .position(|p| p.name == "torso")
            .expect("a torso");
        (scene, index)
    };
    let (scene, index) = torso(h.state());
    let before = scene.doc.parts[index].weights.clone().expect("weights");
    let column = |w: &crate::io::WeightsDoc, name: &str| -> Vec<f64> {
        let c = w.handles.iter().position(|h| h == name).expect("a column") as u32;
        w.rows
            .iter()
            .map(|r| r.iter().find(|e| e.0 == c).map_or(0.0, |e| e.1))
            .collect()
    };

    // Lock the head from its box in the handle list, select the chest, take the brush.
    click_shown(&mut h, "lock head");
    assert!(
        h.state().doc.state().locked.contains("head"),
        "{:?}",
        h.state().message
    );
    click_shown(&mut h, "chest");
    assert_eq!(h.state().selected.as_deref(), Some("chest"));
    click_shown(&mut h, "Paint");
    h.get_by_label("Subtract");
    assert_eq!(h.state().paint.mode, crate::weights::BrushMode::Add);
    set_number(&mut h, "Brush radius px:", 24.0);
    set_number(&mut h, "Brush strength:", 0.5);
    assert_eq!(h.state().paint.options.radius_px, 24.0);
    assert_eq!(h.state().paint.options.strength, 0.5);

    // One stroke across the hip–chest joint. While it runs, the canvas shows a preview; the
    // document changes once, at release, to exactly that preview.
    let (from, to) = ([240.0, 262.0], [272.0, 262.0]);
    h.drag_at(screen(&h, from));
    h.step();
    for k in 1..=4 {
        let t = k as f64 / 4.0;
        h.hover_at(screen(&h, [from[0] + t * (to[0] - from[0]), from[1]]));
        h.step();
    }
    let preview = h.state().shown_rows(index).expect("a preview").to_vec();
    assert_eq!(
        torso(h.state()).0.doc.parts[index].weights.as_ref(),
        Some(&before),
        "the document waits for the release"
    );
    h.drop_at(screen(&h, to));
    h.step();
    h.run();
    let (scene, index) = torso(h.state());
    let after = scene.doc.parts[index].weights.clone().expect("weights");
    assert_eq!(after.rows, preview);
    let (chest0, chest1) = (column(&before, "chest"), column(&after, "chest"));
    let v = &scene.doc.parts[index].mesh.vertices;
    let raised = (0..v.len())
        .filter(|&i| distance(v[i], Point::new(256.0, 262.0)) < 12.0)
        .map(|i| chest1[i] - chest0[i])
        .fold(0.0, f64::max);
    assert!(
        raised > 0.1,
        "chest rose by {raised}: {:?}",
        h.state().message
    );
    let head = column(&before, "head");
    assert!(head.iter().any(|&w| w > 0.01), "the head weighs the torso");
    for (a, b) in head.iter().zip(column(&after, "head")) {
        assert_eq!(a.to_bits(), b.to_bits(), "the locked head column changed");
    }
    // Read back from the saved file: weights are written at f32 precision.
    for row in &after.rows {
        let sum: f64 = row.iter().map(|e| e.1).sum();
        assert!((sum - 1.0).abs() < 1e-6, "{row:?}");
    }
    // The side panel reads out the weights under the pointer.
    h.get_by_label_contains("torso vertex");

    // The stroke is one undo step.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    let (scene, index) = torso(h.state());
    assert_eq!(scene.doc.parts[index].weights.as_ref(), Some(&before));
    assert!(h.state().doc.state().locked.contains("head"));

    // Redo the stroke, lock the chest too and recompute: the painted chest stays.
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    h.run();
    click_shown(&mut h, "lock chest");
    press_shown(&mut h, "Compute weights");
    wait_for_weights(&mut h);
    let (scene, index) = torso(h.state());
    let recomputed = scene.doc.parts[index].weights.clone().expect("weights");
    assert_eq!(h.state().message.as_deref(), Some("weights computed"));
    assert_eq!(column(&recomputed, "chest"), chest1);
    for row in &recomputed.rows {
        let sum: f64 = row.iter().map(|e| e.1).sum();
        assert!((sum - 1.0).abs() < 1e-9, "{row:?}");
    }
}

#[test]
fn the_heat_map_has_a_legend_naming_the_handle_whose_weights_it_shows() {
    let mut h = open_character("legend");
    h.get_by_label("Weights are up to date");
    assert!(h.query_by_label_contains("weights of").is_none());
    // Selecting a bone in the tree shows its weights and the legend says whose they are.
    click_shown(&mut h, "chest");
    assert_eq!(h.state().selected.as_deref(), Some("chest"));
    h.get_by_label("weights of chest");
    click_shown(&mut h, "head");
    h.get_by_label("weights of head");
    assert!(h.query_by_label("weights of chest").is_none());
    // Stale weights draw no heat map, so no legend either.
    click_shown(&mut h, "Bone");
    let inside = torso_point(&h);
    drag(&mut h, inside, [inside[0] + 12.0, inside[1] + 8.0]);
    h.get_by_label("Weights need computing");
    assert!(h.query_by_label_contains("weights of").is_none());
}
