//! What each [`Command`] does to a document's [`State`]: [`apply_to`] checks the command
//! against the state and returns the next state, or why the command cannot apply (the state is
//! not touched). [`super::Document::apply`] keeps the undo history around it.

use super::*;

/// The state after `command`, or why it cannot apply.
pub(super) fn apply_to(state: &State, command: Command) -> Result<State, DocumentError> {
    let mut next = state.clone();
    let mut inputs_changed = true;
    match command {
        Command::AddLayer(layer) => {
            if next.layers.iter().any(|l| l.name == layer.name) {
                return Err(DocumentError::DuplicateLayer(layer.name));
            }
            let got = layer.canvas_px;
            if let Some(first) = next.layers.first() {
                let canvas = first.canvas_px;
                if got != canvas {
                    return Err(DocumentError::LayerSize {
                        name: layer.name,
                        got,
                        canvas,
                    });
                }
            }
            next.layers.push(Arc::new(layer));
        }
        Command::RemoveLayer { name } => {
            let index = next
                .layers
                .iter()
                .position(|l| l.name == name)
                .ok_or_else(|| DocumentError::UnknownLayer(name.clone()))?;
            next.layers.remove(index);
            next.slots.remove_part(&name);
            for parts in next.handles.bind.values_mut() {
                parts.retain(|p| *p != name);
            }
            // A handle bound to that part alone is bound to nothing: it weighs every part again
            // (a binding lists at least one part).
            next.handles.bind.retain(|_, parts| !parts.is_empty());
        }
        Command::AddBone(bone) => next.handles.bones.push(bone),
        Command::MoveBone { name, head, tail } => {
            let bone = next
                .handles
                .bones
                .iter_mut()
                .find(|b| b.name == name)
                .ok_or(DocumentError::UnknownHandle(name))?;
            bone.head = head;
            bone.tail = tail;
        }
        Command::AddPoint(point) => next.handles.points.push(point),
        Command::MovePoint { name, at } => {
            let point = next
                .handles
                .points
                .iter_mut()
                .find(|p| p.name == name)
                .ok_or(DocumentError::UnknownHandle(name))?;
            point.at = at;
        }
        Command::Rename { from, to } => {
            if !next.handles.names().any(|n| n == from) {
                return Err(DocumentError::UnknownHandle(from));
            }
            next.handles.rename(&from, &to);
            rename_in_pose(&mut next.pose, &from, &to);
            if next.locked.remove(&from) {
                next.locked.insert(to);
                // The previous weights follow, so a recompute still finds the locked column.
                let columns = crate::rig::handle_columns(&state.handles)
                    .into_iter()
                    .zip(crate::rig::handle_columns(&next.handles))
                    .filter(|(a, b)| a != b)
                    .collect();
                next.rig = state
                    .rig
                    .as_ref()
                    .map(|scene| Arc::new(scene.with_columns_renamed(&columns)));
            }
        }
        Command::Reparent { handle, parent } => {
            let point = next.handles.points.iter().position(|p| p.name == handle);
            if let Some(parent) = &parent {
                if !next.handles.bones.iter().any(|b| b.name == *parent) {
                    return Err(DocumentError::UnknownHandle(parent.clone()));
                }
            }
            if let Some(i) = point {
                // A point hangs from a bone; no bone hangs from a point, so no loop.
                next.handles.points[i].parent = parent;
            } else {
                reparent_bone(&mut next.handles, handle, parent)?;
            }
        }
        Command::Delete { name } => {
            if !next.handles.names().any(|n| n == name) {
                return Err(DocumentError::UnknownHandle(name));
            }
            next.handles.delete(&name);
            next.locked.remove(&name);
            next.pose.bones.remove(&name);
            next.pose.points.remove(&name);
            next.pose.cages.remove(&name);
        }
        Command::SetOptions(options) => next.options = options,
        Command::SetRig(scene, key) => {
            if *key != rig_inputs_of(state).key() {
                return Err(DocumentError::OutdatedRig);
            }
            next.rig = Some(scene);
            next.rig_current = true;
            inputs_changed = false;
        }
        Command::SetKey {
            animation,
            time_s,
            pose,
            keep,
            sampling,
        } => {
            check_key_time(time_s)?;
            let before = animation_named(state, &animation);
            let mut anim = before.clone();
            key_pose(state, &mut anim, time_s, pose, &keep, &sampling);
            if anim == before && state.animations.contains_key(&animation) {
                return Err(DocumentError::NothingToKey(time_s));
            }
            store_animation(&mut next, &animation, anim)?;
            inputs_changed = false;
        }
        Command::KeyAttachment {
            animation,
            slot,
            time_s,
            attachment,
        } => {
            check_key_time(time_s)?;
            let mut anim = animation_named(state, &animation);
            animations::key_attachment(state, &mut anim, &slot, time_s, attachment)?;
            store_animation(&mut next, &animation, anim)?;
            inputs_changed = false;
        }
        Command::KeyDeform {
            animation,
            part,
            time_s,
            offsets,
        } => {
            check_key_time(time_s)?;
            let mut anim = animation_named(state, &animation);
            animations::key_deform(state, &mut anim, &part, time_s, offsets)?;
            store_animation(&mut next, &animation, anim)?;
            inputs_changed = false;
        }
        Command::DeleteKeys { animation, time_s } => {
            check_key_time(time_s)?;
            let keys = keys_at(&animation_named(state, &animation), time_s);
            edit_animation(&mut next, animation, |name, anim| {
                edit::delete_keys(name, anim, &keys)
            })?;
            inputs_changed = false;
        }
        Command::SetPose(pose) => {
            let scene = state
                .rig
                .as_ref()
                .filter(|_| state.rig_current)
                .ok_or(DocumentError::NoWeights)?;
            scene.handle_transforms(&pose)?;
            next.pose = pose;
            inputs_changed = false;
        }
        Command::ShowSkins(skins) => {
            if let Some(rig) = &state.rig {
                let shown = rig
                    .with_skins(&skins)
                    .map_err(|e| DocumentError::Slots(e.to_string()))?;
                next.rig = Some(Arc::new(shown));
            }
            next.slots.shown = skins;
            inputs_changed = false;
        }
        Command::SetHandles(handles) => set_handles(&mut next, handles),
        Command::Propose { handles, record } => {
            set_handles(&mut next, handles);
            next.autorig = Some(record);
        }
        Command::SetBind { handle, parts } => {
            if !state.handles.names().any(|n| n == handle) {
                return Err(DocumentError::UnknownHandle(handle));
            }
            if let Some(part) = parts
                .iter()
                .find(|p| !state.layers.iter().any(|l| l.name == **p))
            {
                return Err(DocumentError::UnknownLayer(part.clone()));
            }
            if parts.is_empty() {
                next.handles.bind.remove(&handle);
            } else {
                // In draw order, each once: the same binding reads the same in the file.
                let bound: Vec<String> = state
                    .layers
                    .iter()
                    .map(|l| l.name.clone())
                    .filter(|l| parts.contains(l))
                    .collect();
                next.handles.bind.insert(handle, bound);
            }
        }
        Command::AddCage(cage) => next.handles.cages.push(cage),
        Command::AddRegion(region) => next.handles.regions.push(region),
        Command::SetPolygon { name, polygon } => {
            let target = next
                .handles
                .cages
                .iter_mut()
                .map(|c| (&c.name, &mut c.polygon))
                .chain(
                    next.handles
                        .regions
                        .iter_mut()
                        .map(|r| (&r.name, &mut r.polygon)),
                )
                .find(|(n, _)| **n == name)
                .map(|(_, p)| p)
                .ok_or_else(|| DocumentError::UnknownHandle(name.clone()))?;
            if target.len() != polygon.len() {
                return Err(DocumentError::PolygonSize {
                    name,
                    got: polygon.len(),
                    expected: target.len(),
                });
            }
            *target = polygon;
            // A posed cage keeps its pose; the rest polygon moved under it.
        }
        Command::PaintWeights {
            part,
            handle,
            mode,
            samples_px,
            options,
        } => {
            next.rig = Some(Arc::new(paint_weights(
                state,
                &part,
                &handle,
                mode,
                &samples_px,
                &options,
            )?));
            inputs_changed = false;
        }
        Command::SetPhysics(constraint) => {
            let slot = next
                .handles
                .physics
                .iter_mut()
                .find(|c| c.name == constraint.name)
                .ok_or_else(|| DocumentError::UnknownHandle(constraint.name.clone()))?;
            *slot = constraint;
            next.handles.validate()?;
            if let Some(rig) = &state.rig {
                next.rig = Some(Arc::new(rig.with_physics(next.handles.physics.clone())));
            }
            inputs_changed = false;
        }
        Command::SetLocked { handle, locked } => {
            if !state.handles.names().any(|n| n == handle) {
                return Err(DocumentError::UnknownHandle(handle));
            }
            if locked {
                next.locked.insert(handle);
            } else {
                next.locked.remove(&handle);
            }
            inputs_changed = false;
        }
        Command::MoveKeys {
            animation,
            keys,
            delta_s,
        } => {
            edit_animation(&mut next, animation, |name, json| {
                edit::move_keys(name, json, &keys, delta_s)
            })?;
            inputs_changed = false;
        }
        Command::PasteKeys {
            animation,
            at_s,
            keys,
        } => {
            edit_animation(&mut next, animation, |name, json| {
                edit::paste_keys(name, json, at_s, &keys)
            })?;
            inputs_changed = false;
        }
        Command::DeleteTimelineKeys { animation, keys } => {
            edit_animation(&mut next, animation, |name, json| {
                edit::delete_keys(name, json, &keys)
            })?;
            inputs_changed = false;
        }
        Command::SetCurve {
            animation,
            key,
            curve,
        } => {
            edit_animation(&mut next, animation, |name, json| {
                edit::set_curve(name, json, &key, &curve)
            })?;
            inputs_changed = false;
        }
        Command::SetCurves { animation, curves } => {
            edit_animation(&mut next, animation, |name, json| {
                let mut edited = json.clone();
                for (key, curve) in &curves {
                    edited = edit::set_curve(name, &edited, key, curve)?;
                }
                Ok(edited)
            })?;
            inputs_changed = false;
        }
        Command::Animations(edit) => {
            animations::apply(&mut next, edit)?;
            inputs_changed = false;
        }
        Command::Events(edit) => {
            events::apply(&mut next, edit)?;
            inputs_changed = false;
        }
        Command::KeyChanges {
            animation,
            time_s,
            before,
            pose,
        } => {
            check_key_time(time_s)?;
            let mut anim = animation_named(state, &animation);
            if animations::key_changes(&mut anim, time_s, &before, &pose, &[]) == 0 {
                return Err(DocumentError::NothingToKey(time_s));
            }
            store_animation(&mut next, &animation, anim)?;
            inputs_changed = false;
        }
    }
    if inputs_changed {
        next.handles.validate()?;
        next.rig_current = false;
    }
    Ok(next)
}

/// Replaces the handles; the pose and the locks forget handles that are gone.
fn set_handles(next: &mut State, handles: Handles) {
    next.handles = handles;
    let names: BTreeSet<&str> = next.handles.names().collect();
    next.pose.bones.retain(|n, _| names.contains(n.as_str()));
    next.pose.points.retain(|n, _| names.contains(n.as_str()));
    next.pose.cages.retain(|n, _| names.contains(n.as_str()));
    next.locked.retain(|n| names.contains(n.as_str()));
}

pub(super) fn rig_inputs_of(state: &State) -> RigInputs {
    RigInputs {
        layers: state.layers.clone(),
        handles: state.handles.clone(),
        options: state.options.clone(),
        locked: state.locked.clone(),
        previous: state.rig.clone(),
        slots: state.slots.clone(),
    }
}

fn rename_in_pose(pose: &mut Pose, from: &str, to: &str) {
    if let Some(v) = pose.bones.remove(from) {
        pose.bones.insert(to.to_string(), v);
    }
    if let Some(v) = pose.points.remove(from) {
        pose.points.insert(to.to_string(), v);
    }
    if let Some(v) = pose.cages.remove(from) {
        pose.cages.insert(to.to_string(), v);
    }
}

/// Hangs bone `bone` from `parent` (a known bone, or none), refusing a loop.
fn reparent_bone(
    handles: &mut Handles,
    bone: String,
    parent: Option<String>,
) -> Result<(), DocumentError> {
    if let Some(parent) = &parent {
        // Walk up from the new parent: meeting `bone` would close a loop.
        let mut up = Some(parent.clone());
        let mut steps = 0;
        while let Some(name) = up {
            if name == bone || steps > handles.bones.len() {
                return Err(DocumentError::ReparentCycle {
                    bone,
                    parent: parent.clone(),
                });
            }
            steps += 1;
            up = handles
                .bones
                .iter()
                .find(|b| b.name == name)
                .and_then(|b| b.parent.clone());
        }
    }
    let b = handles
        .bones
        .iter_mut()
        .find(|b| b.name == bone)
        .ok_or(DocumentError::UnknownHandle(bone))?;
    b.parent = parent;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two 8×8 layers, `body` behind `arm`, and two bones.
    fn two_parts() -> Document {
        let mut doc = Document::new();
        for name in ["body", "arm"] {
            let image = image::RgbaImage::new(8, 8);
            doc.apply(Command::AddLayer(Layer::whole(
                name,
                format!("{name}.png"),
                image,
            )))
            .unwrap();
        }
        for (name, y) in [("a", 2.0), ("b", 5.0)] {
            doc.apply(Command::AddBone(Bone {
                name: name.into(),
                parent: None,
                head: Point::new(1.0, y),
                tail: Point::new(6.0, y),
            }))
            .unwrap();
        }
        doc
    }

    fn bind(doc: &Document, handle: &str) -> Option<Vec<String>> {
        doc.state().handles.bind.get(handle).cloned()
    }

    fn set_bind(doc: &mut Document, handle: &str, parts: &[&str]) -> Result<(), DocumentError> {
        doc.apply(Command::SetBind {
            handle: handle.into(),
            parts: parts.iter().map(|p| p.to_string()).collect(),
        })
    }

    #[test]
    fn set_bind_binds_in_draw_order_unbinds_with_no_part_and_refuses_unknown_names() {
        let mut doc = two_parts();
        set_bind(&mut doc, "a", &["arm", "body"]).unwrap();
        assert_eq!(bind(&doc, "a"), Some(vec!["body".into(), "arm".into()]));
        assert!(!doc.state().rig_current, "the weights need computing again");
        set_bind(&mut doc, "a", &[]).unwrap();
        assert_eq!(bind(&doc, "a"), None);
        assert!(doc.undo());
        assert_eq!(bind(&doc, "a"), Some(vec!["body".into(), "arm".into()]));
        assert!(matches!(
            set_bind(&mut doc, "a", &["wing"]),
            Err(DocumentError::UnknownLayer(p)) if p == "wing"
        ));
        assert!(matches!(
            set_bind(&mut doc, "ghost", &["arm"]),
            Err(DocumentError::UnknownHandle(h)) if h == "ghost"
        ));
        assert_eq!(bind(&doc, "a"), Some(vec!["body".into(), "arm".into()]));
    }

    #[test]
    fn renaming_deleting_and_removing_a_layer_keep_the_bindings_valid() {
        let mut doc = two_parts();
        set_bind(&mut doc, "a", &["arm"]).unwrap();
        set_bind(&mut doc, "b", &["arm", "body"]).unwrap();
        doc.apply(Command::Rename {
            from: "a".into(),
            to: "upper".into(),
        })
        .unwrap();
        assert_eq!(bind(&doc, "a"), None);
        assert_eq!(bind(&doc, "upper"), Some(vec!["arm".into()]));
        // The arm's layer goes: `upper`, bound to it alone, weighs every part again; `b`
        // keeps the body.
        doc.apply(Command::RemoveLayer { name: "arm".into() })
            .unwrap();
        assert_eq!(bind(&doc, "upper"), None);
        assert_eq!(bind(&doc, "b"), Some(vec!["body".into()]));
        doc.apply(Command::Delete { name: "b".into() }).unwrap();
        assert!(doc.state().handles.bind.is_empty());
        doc.state().handles.validate().unwrap();
    }

    #[test]
    fn a_proposal_and_its_template_are_one_undo_step() {
        let mut doc = two_parts();
        let before = doc.state().handles.clone();
        let mut proposed = before.clone();
        proposed.bones.truncate(1);
        let record = io::AutorigRecord {
            template: io::RecordedTemplate::Humanoid,
        };
        doc.apply(Command::Propose {
            handles: proposed.clone(),
            record,
        })
        .unwrap();
        assert_eq!(doc.state().handles, proposed);
        assert_eq!(doc.state().autorig, Some(record));
        assert!(doc.undo());
        assert_eq!(doc.state().handles, before);
        assert_eq!(doc.state().autorig, None);
    }
}
