//! Animate mode's deform tool: vertices dragged with a soft radius, keyed at the playhead,
//! shown on the canvas, undone, saved and read back.

use super::*;
use crate::editor::deform_tool::falloff;
use crate::geom::Vec2;

#[test]
fn the_deform_tool_keys_soft_offsets_at_the_playhead() {
    let mut h = open_character("deform-tool");
    h.key_press(Key::Num3);
    h.run();
    click_shown(&mut h, "New animation");
    click_shown(&mut h, "Deform tool");
    set_number(&mut h, "Deform radius", 20.0);
    assert_eq!(h.state().deform.radius_px, 20.0);
    let grip = torso_point(&h);
    let scene = h.state().doc.posable().expect("posable").clone();
    let part = scene
        .doc
        .parts
        .iter()
        .position(|p| p.name == "torso")
        .expect("a torso");
    let rest = scene.doc.parts[part].mesh.vertices.clone();
    let grabbed = rest
        .iter()
        .position(|&v| v == grip)
        .expect("a torso vertex");
    let before = shown_vertices(&h);

    let motion = Vec2::new(6.0, -4.0);
    drag(&mut h, grip, grip + motion);
    let offsets = |h: &Harness<'_, EditorApp>| -> Option<(f64, Vec<Vec2>)> {
        let anim =
            crate::document::animation_named(h.state().doc.state(), &h.state().animate.animation);
        let keys = anim.deform.get("torso")?;
        assert_eq!(keys.len(), 1);
        Some((keys[0].time, keys[0].value.clone()))
    };
    let (time, keyed) = offsets(&h).unwrap_or_else(|| panic!("{:?}", h.state().message));
    assert_eq!(time, 0.0);
    assert_eq!(keyed.len(), rest.len());
    // At rest the skinning maps an offset to itself: each vertex moved by the falloff of its
    // distance from the press, none beyond the radius.
    let mut moved = 0;
    for (v, offset) in keyed.iter().enumerate() {
        let w = falloff((rest[v] - grip).norm(), 20.0);
        let expected = w * motion;
        assert!(
            (offset - expected).norm() < 0.01,
            "vertex {v}: {offset:?} vs {expected:?}"
        );
        moved += usize::from(w > 0.0);
    }
    assert!(moved > 3, "{moved} vertices within the radius");
    assert!((keyed[grabbed] - motion).norm() < 0.01);
    // The canvas shows the grabbed vertex where the pointer let go; other parts stay.
    let shown = shown_vertices(&h);
    let at = shown[part][grabbed];
    assert!((at - (grip + motion)).norm() < 0.01, "{at:?}");
    for (p, (a, b)) in before.iter().zip(&shown).enumerate() {
        if p != part {
            assert_eq!(a, b, "part {p} moved");
        }
    }

    // Undo takes the key back; redo brings it again.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert!(offsets(&h).is_none());
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    h.run();
    assert_eq!(offsets(&h).map(|o| o.1), Some(keyed.clone()));

    // A press far from every shown part deforms nothing and says why; the tool off again.
    drag(&mut h, [2.0, 2.0], [12.0, 2.0]);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("within the deform radius"), "{message}");
    assert_eq!(offsets(&h).map(|o| o.1), Some(keyed.clone()));
    click_shown(&mut h, "Deform tool");
    assert!(!h.state().deform.enabled);

    // Saved with Ctrl+S and read back: the deform key, of the mesh's vertex count.
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run();
    wait_for(&mut h, |app| !app.saving());
    assert!(!h.state().doc.dirty(), "{:?}", h.state().message);
    let path = h.state().doc.path.clone().expect("saved");
    let saved = crate::io::RigDocument::load(&path).expect("loads");
    saved
        .check_animations()
        .expect("the deform key fits the mesh");
    let key = &saved.animations[&h.state().animate.animation].deform["torso"][0];
    assert_eq!(key.value, keyed);
}
