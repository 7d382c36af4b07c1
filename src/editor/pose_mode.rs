//! Pose mode: drag any point of the drawing and the skinning IK moves the whole shape; the
//! first drag also pins the grabbed skeleton's root where it is ([`implicit_root_pin`]), so a
//! limb bends rather than the whole character sliding; shift-click pins a point where it is
//! shown; every drag stays as a pin of the pose. A drag that starts on a bone's line rotates
//! the bone about its head (as in Spine); the FK gizmo and G/R/S pose the selected bone or
//! point.
//!
//! In: the pose edited (the document's, or animate mode's at the playhead), pointer and keys.
//! Out: `SetPose` commands (or animate mode's unkeyed pose), and the posed vertices the canvas
//! draws. Every pose goes to vertices one way, [`pose_frame`]: the library's
//! [`Scene::handle_transforms`] (no warm start: the result depends on the pose only, not on the
//! editing that led to it) and [`Scene::positions_from_transforms`]; animate mode's playhead
//! frame comes from [`crate::scene::Playhead`], then the same skinning.

use super::canvas::{self, Placed};
use super::identity::Identity;
use super::{gizmo, EditorApp, Gesture, Mode};
use crate::document::Command;
use crate::geom::Point;
use crate::pipeline::Scene;
use crate::rig::pose::IkDrag;
use crate::rig::Pose;
use crate::skin::Blend;
use eframe::egui::{self, Key, Pos2};
use std::sync::Arc;

/// Posed vertex positions of a built rig, for one pose.
pub struct Posed {
    pub(super) scene: Identity<Scene>,
    /// How the positions were blended.
    blend: Blend,
    /// The animation and time played, when the pose is a playhead's frame (its transforms may
    /// carry momentum, so the pose alone does not decide them).
    pub(super) played: Option<Played>,
    pub pose: Pose,
    pub positions: Vec<Vec<Point>>,
    /// Per handle column, the transform shown ([`Scene::handle_transforms`]'s).
    pub transforms: Vec<crate::rig::Affine>,
    /// The handles where the pose puts them (bones' heads and tails, points), for drawing.
    pub handles: crate::rig::Handles,
}

/// An animation played at a time, as [`Posed`] remembers it.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Played {
    animation: crate::anim::Animation,
    time_s: f64,
    pub(super) options: crate::scene::PlayOptions,
}

impl Posed {
    fn new(
        scene: &Arc<Scene>,
        blend: Blend,
        played: Option<Played>,
        pose: Pose,
        positions: Vec<Vec<Point>>,
        transforms: Vec<crate::rig::Affine>,
    ) -> Self {
        let map = |t: &crate::rig::Affine, p: Point| t.apply(p);
        let mut handles = scene.doc.handles.clone();
        let bone_count = handles.bones.len();
        for (b, t) in handles.bones.iter_mut().zip(&transforms) {
            (b.head, b.tail) = (map(t, b.head), map(t, b.tail));
        }
        for (p, t) in handles
            .points
            .iter_mut()
            .zip(transforms.iter().skip(bone_count))
        {
            p.at = map(t, p.at);
        }
        // Cage vertices follow the points in column order, one column each.
        let mut cage_columns = transforms.iter().skip(bone_count + handles.points.len());
        for cage in &mut handles.cages {
            for (v, t) in cage.polygon.iter_mut().zip(cage_columns.by_ref()) {
                *v = map(t, *v);
            }
        }
        Posed {
            scene: Identity::of(scene),
            blend,
            played,
            pose,
            positions,
            transforms,
            handles,
        }
    }
}

/// Pose mode's own state: the pose shown, posed.
#[derive(Default)]
pub struct PoseMode {
    /// The last pose posed, for drawing and picking (animate mode's too).
    pub posed: Option<Posed>,
    /// The rig whose skinning-IK precomputation was started in the background.
    ik_warmed: Option<Identity<Scene>>,
}

/// The skin picker's entry for "no skin".
const NO_SKIN: &str = "(none)";

/// The one way from a pose to posed vertices, as `sinew render` takes it: the scene's handle
/// transforms (forward kinematics, bone IK, then the skinning IK solved from the
/// forward-kinematics pose with no warm start, so the result depends on the pose only), then
/// skinning with `blend`.
pub fn pose_frame(
    scene: &Scene,
    pose: &Pose,
    blend: Blend,
) -> Result<(Vec<crate::rig::Affine>, Vec<Vec<Point>>), String> {
    let transforms = scene.handle_transforms(pose).map_err(|e| e.to_string())?;
    let positions = scene
        .positions_from_transforms(&transforms, pose, blend)
        .map_err(|e| e.to_string())?;
    Ok((transforms, positions))
}

impl EditorApp {
    /// Starts the skinning-IK precomputation of a newly posable rig on another thread, so the
    /// first drag in pose mode does not wait for it (the scene caches the result).
    pub(super) fn warm_ik(&mut self) {
        let Some(scene) = self.doc.posable() else {
            return;
        };
        if self
            .pose_mode
            .ik_warmed
            .as_ref()
            .is_some_and(|k| k.is(scene))
        {
            return;
        }
        self.pose_mode.ik_warmed = Some(Identity::of(scene));
        let scene = scene.clone();
        std::thread::spawn(move || {
            // Errors show up again, with a message, when the editor asks for the solver.
            let _ = scene.rig_ik();
        });
    }

    pub(super) fn pose_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Pose");
        if self.doc.posable().is_none() {
            ui.label("Compute the weights in rig mode to pose.");
            return;
        }
        ui.label("Drag any point of the drawing; shift-click pins a point.");
        // One row: the side panel's height is the tree's below.
        ui.horizontal_wrapped(|ui| {
            let pins = self.doc.state().pose.ik.len();
            ui.label(format!("{pins} pins and drags"));
            if ui.button("Clear pins").clicked() {
                let mut pose = self.doc.state().pose.clone();
                pose.ik.clear();
                self.apply(Command::SetPose(pose));
            }
            if ui.button("Rest pose").clicked() {
                self.apply(Command::SetPose(Pose::default()));
            }
        });
    }

    /// The tree view under pose and animate mode's panels.
    pub(super) fn pose_tree(&mut self, ui: &mut egui::Ui) {
        self.skin_picker(ui);
        ui.separator();
        ui.heading("Tree");
        self.tree_area(ui);
    }

    /// The skin the canvas draws, when the rig has skins: "(none)" shows each slot's own part.
    fn skin_picker(&mut self, ui: &mut egui::Ui) {
        let Some(scene) = self.doc.posable() else {
            return;
        };
        if scene.doc.skins.is_empty() {
            return;
        }
        let names: Vec<String> = scene.doc.skins.keys().cloned().collect();
        let shown = self.doc.state().slots.shown.clone();
        let label = if shown.is_empty() {
            NO_SKIN.to_string()
        } else {
            shown.join(" + ")
        };
        let mut chosen = None;
        egui::ComboBox::from_label("Skin")
            .selected_text(label)
            .show_ui(ui, |ui| {
                if ui.selectable_label(shown.is_empty(), NO_SKIN).clicked() {
                    chosen = Some(Vec::new());
                }
                for name in names {
                    let on = shown.len() == 1 && shown[0] == name;
                    if ui.selectable_label(on, &name).clicked() {
                        chosen = Some(vec![name]);
                    }
                }
            });
        if let Some(skins) = chosen.filter(|s| *s != shown) {
            self.apply(Command::ShowSkins(skins));
        }
    }

    /// Poses `scene` for the static `pose` through [`pose_frame`] into [`PoseMode::posed`]
    /// (kept while the rig, the pose and the blend stay the same).
    pub(super) fn update_posed(&mut self, scene: &Arc<Scene>, pose: &Pose) -> Result<(), String> {
        let blend = self.render_settings.blend;
        if self.pose_mode.posed.as_ref().is_some_and(|p| {
            p.scene.is(scene) && p.blend == blend && p.played.is_none() && p.pose == *pose
        }) {
            return Ok(());
        }
        let (transforms, positions) = pose_frame(scene, pose, blend)?;
        self.pose_mode.posed = Some(Posed::new(
            scene,
            blend,
            None,
            pose.clone(),
            positions,
            transforms,
        ));
        Ok(())
    }

    /// Poses `scene` as the animation edited plays at the playhead, through the library's
    /// [`crate::scene::Playhead`] (pure in the time; momentum simulated from the start), sampled
    /// and blended as File → Render's settings say.
    pub(super) fn update_posed_at_playhead(&mut self, scene: &Arc<Scene>) -> Result<(), String> {
        let name = self.animate.animation.clone();
        let Some(animation) = self.doc.state().animations.get(&name).cloned() else {
            // No such animation (yet): the rest pose, as sampling it gives.
            return self.update_posed(scene, &self.sampled_pose());
        };
        let (blend, time_s) = (self.render_settings.blend, self.animate.time_s);
        // A rig made for Spine previews Spine's curve evaluation.
        let sampling = match self.doc.state().target {
            Some(t) if spine_target(t) => crate::anim::SampleOptions {
                curves: crate::anim::CurveEvaluation::SpineRuntime,
            },
            _ => self.render_settings.sampling,
        };
        let options = crate::scene::PlayOptions {
            sampling,
            looping: false,
        };
        let played = Played {
            animation: animation.clone(),
            time_s,
            options,
        };
        if self.pose_mode.posed.as_ref().is_some_and(|p| {
            p.scene.is(scene) && p.blend == blend && p.played.as_ref() == Some(&played)
        }) {
            return Ok(());
        }
        let frame = crate::scene::Playhead::new(scene, &animation, options)
            .frame(time_s)
            .map_err(|e| e.to_string())?;
        let positions = scene
            .positions_from_transforms(&frame.transforms, &frame.pose, blend)
            .map_err(|e| e.to_string())?;
        self.pose_mode.posed = Some(Posed::new(
            scene,
            blend,
            Some(played),
            frame.pose,
            positions,
            frame.transforms,
        ));
        Ok(())
    }

    pub(super) fn pose_gestures(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        placed: Placed,
        scene: &Arc<Scene>,
    ) {
        if self.fk_gestures(ctx, response, placed, scene) {
            return;
        }
        let pointer = response.interact_pointer_pos();
        let shift = ctx.input(|i| i.modifiers.shift);
        // The rest point of the drawing under the pointer and where it is shown now.
        let grab = |app: &mut EditorApp, at: Pos2| -> Option<(Point, Point)> {
            let posed = app.pose_mode.posed.as_ref().filter(|p| p.scene.is(scene))?;
            let rest = rest_point_under(
                scene,
                &posed.positions,
                &posed.pose,
                placed.canvas_from_screen(at),
            )?;
            match shown_position(scene, rest, &posed.transforms) {
                Ok(shown) => Some((rest, shown)),
                Err(e) => {
                    app.fail(e);
                    None
                }
            }
        };
        if response.drag_started_by(egui::PointerButton::Primary) {
            // Where the button went down, not where the drag was recognized.
            let origin = ctx.input(|i| i.pointer.press_origin()).or(pointer);
            if let Some(at) = origin {
                let c = placed.canvas_from_screen(at);
                let mut pose = self.edited_pose();
                // Grabbing an existing pin moves it; anywhere else on the drawing adds a drag.
                // Either starts where the point is shown and follows the pointer's motion.
                let existing = pose.ik.iter().position(|d| {
                    placed.screen_from_canvas(d.to).distance(at) <= canvas::PICK_RADIUS_PT
                });
                let index = match existing {
                    Some(i) => Some(i),
                    None => grab(self, at).map(|(rest, shown)| {
                        // The first drag also holds the grabbed skeleton's root (a pin after
                        // it, drawn as one), so a limb bends instead of the whole character
                        // following.
                        let first = pose.ik.is_empty();
                        pose.ik.push(IkDrag {
                            at: rest,
                            to: shown,
                            weight: None,
                        });
                        let index = pose.ik.len() - 1;
                        let posed = self.pose_mode.posed.as_ref().filter(|_| first);
                        if let Some(pin) =
                            posed.and_then(|p| implicit_root_pin(scene, rest, &p.transforms))
                        {
                            pose.ik.push(pin);
                        }
                        index
                    }),
                };
                if let Some(index) = index {
                    let to = pose.ik[index].to;
                    self.gesture = Some(Gesture::PoseDrag {
                        index,
                        pose,
                        offset: to - c,
                    });
                }
            }
        }
        if let (Some(at), true) = (pointer, response.dragged()) {
            if let Some(Gesture::PoseDrag {
                index,
                pose,
                offset,
            }) = &mut self.gesture
            {
                let c = placed.canvas_from_screen(at);
                pose.ik[*index].to = c + *offset;
            }
        }
        if response.drag_stopped() {
            if let Some(Gesture::PoseDrag { pose, .. }) = self.gesture.take() {
                self.commit_pose(pose);
            }
        }
        if response.clicked() && !shift {
            // A click selects the handle under it (for the gizmo and G/R/S), or nothing.
            if let (Some(at), Some(posed)) = (pointer, &self.pose_mode.posed) {
                self.selected = canvas::pick(&placed, &posed.handles, at);
            }
        }
        if response.clicked() && shift {
            // A pin holds the point where it is shown: the drawing does not move.
            if let Some((rest, shown)) = pointer.and_then(|at| grab(self, at)) {
                let mut pose = self.edited_pose();
                pose.ik.push(IkDrag {
                    at: rest,
                    to: shown,
                    weight: None,
                });
                self.commit_pose(pose);
            }
        }
    }

    /// Where the selected bone or point is shown, for its gizmo; `None` when nothing posable
    /// is selected.
    pub(super) fn fk_target(&self, scene: &Arc<Scene>) -> Option<crate::rig::fk_edit::FkTarget> {
        let (name, posed) = (self.selected.as_deref()?, self.pose_mode.posed.as_ref()?);
        crate::rig::fk_edit::target(&scene.doc.handles, &posed.transforms, name).ok()
    }

    /// The FK gizmo and the G/R/S keys. Returns whether they took the pointer this frame.
    pub(super) fn fk_gestures(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        placed: Placed,
        scene: &Arc<Scene>,
    ) -> bool {
        let handles = &scene.doc.handles;
        let hover = ctx.input(|i| i.pointer.hover_pos());
        if let Some(Gesture::Fk(g)) = &mut self.gesture {
            let pointer = if g.modal {
                hover
            } else {
                response.interact_pointer_pos()
            };
            if let Some(at) = pointer {
                if let Err(e) = g.update(handles, placed.canvas_from_screen(at)) {
                    self.message = Some(e.to_string());
                    self.message_is_error = true;
                }
            }
            let (confirm, cancel) = if g.modal {
                (response.clicked(), response.secondary_clicked())
            } else {
                (response.drag_stopped(), false)
            };
            if confirm {
                if let Some(Gesture::Fk(g)) = self.gesture.take() {
                    self.commit_pose(g.preview);
                }
            } else if cancel {
                self.gesture = None;
            }
            return true;
        }
        if self.gesture.is_some() {
            return false;
        }
        let press = if response.drag_started_by(egui::PointerButton::Primary) {
            ctx.input(|i| i.pointer.press_origin())
        } else {
            None
        };
        // The selected handle's gizmo first; else a drag that starts on a bone's line rotates
        // that bone about its head, where it joins its parent (Spine's default).
        let gizmo_hit = press.and_then(|at| {
            let target = self.fk_target(scene)?;
            Some((gizmo::hit(&placed, &target, at)?, at))
        });
        // Pins and drags lie over the bones: grabbing one moves it (see `pose_gestures`).
        let on_pin = |at: Pos2| {
            self.edited_pose()
                .ik
                .iter()
                .any(|d| placed.screen_from_canvas(d.to).distance(at) <= canvas::PICK_RADIUS_PT)
        };
        if let (None, Some(at)) = (gizmo_hit, press.filter(|&at| !on_pin(at))) {
            let bone = self.pose_mode.posed.as_ref().and_then(|posed| {
                canvas::pick(&placed, &posed.handles, at)
                    .filter(|name| handles.bones.iter().any(|b| &b.name == name))
            });
            if let Some(bone) = bone {
                self.selected = Some(bone);
                return self.start_fk(handles, &placed, gizmo::FkKind::Rotate, at, false);
            }
        }
        let (Some(_), Some(_)) = (self.selected.as_ref(), self.fk_target(scene)) else {
            return false;
        };
        let typing = ctx.text_edit_focused();
        let key = ctx.input(|i| {
            [
                (Key::G, gizmo::FkKind::Grab),
                (Key::R, gizmo::FkKind::Rotate),
                (Key::S, gizmo::FkKind::Scale),
            ]
            .into_iter()
            // The key event's own modifiers: a quick Ctrl+S has released Ctrl by the end
            // of the frame, and must not scale.
            .find(|(k, _)| {
                !typing
                    && i.events.iter().any(|e| {
                        matches!(e, egui::Event::Key { key, pressed: true, modifiers, .. }
                            if key == k && modifiers.is_none())
                    })
            })
            .map(|(_, kind)| kind)
        });
        let (kind, at, modal) = match (key, hover, gizmo_hit) {
            (Some(kind), Some(at), _) => (kind, at, true),
            (_, _, Some((kind, at))) => (kind, at, false),
            _ => return false,
        };
        self.start_fk(handles, &placed, kind, at, modal)
    }

    /// Starts an FK gesture of `kind` on the selected handle at `at` (screen points); `modal`
    /// when a key started it (it follows the pointer until a click). Returns whether it took
    /// the pointer.
    fn start_fk(
        &mut self,
        handles: &crate::rig::Handles,
        placed: &Placed,
        kind: gizmo::FkKind,
        at: Pos2,
        modal: bool,
    ) -> bool {
        let (Some(name), Some(shown)) = (
            self.selected.clone(),
            self.pose_mode.posed.as_ref().map(|p| p.transforms.clone()),
        ) else {
            return false;
        };
        match gizmo::FkGesture::start(
            handles,
            &self.edited_pose(),
            &shown,
            &name,
            kind,
            placed.canvas_from_screen(at),
            modal,
        ) {
            Ok(g) => self.gesture = Some(Gesture::Fk(Box::new(g))),
            Err(e) => self.fail(e.to_string()),
        }
        true
    }

    /// The pose the canvas edits: the document's in pose mode; in animate mode the pose being
    /// prepared for a key (the animation sampled at the current time until it is edited).
    pub fn edited_pose(&self) -> Pose {
        match self.mode {
            Mode::Animate => self
                .animate
                .shown
                .clone()
                .unwrap_or_else(|| self.sampled_pose()),
            _ => self.doc.state().pose.clone(),
        }
    }

    /// Makes `pose` the pose edited: the document's in pose mode; in animate mode the pose
    /// shown until keyed, or keyed at once (the channels it changed) when auto-key is on.
    pub(super) fn commit_pose(&mut self, pose: Pose) {
        match self.mode {
            Mode::Animate if self.timeline.auto_key => {
                let before = self.sampled_pose();
                if pose == before {
                    self.animate.shown = None;
                    return;
                }
                let (animation, time_s) = (self.animate.animation.clone(), self.animate.time_s);
                if self.apply(Command::KeyChanges {
                    animation: animation.clone(),
                    time_s,
                    before,
                    pose: pose.clone(),
                }) {
                    self.animate.shown = None;
                    self.message = Some(format!("auto-keyed '{animation}' at {time_s:.3} s"));
                } else {
                    self.animate.shown = Some(pose);
                }
            }
            Mode::Animate => self.animate.shown = Some(pose),
            _ => {
                self.apply(Command::SetPose(pose));
            }
        }
    }
}

/// The rest position of the drawing's point shown at `at_px` (canvas px) in the posed
/// `positions`: the frontmost part `pose` shows (its draw order, hidden parts left out) whose
/// posed triangle contains it, barycentrically.
pub fn rest_point_under(
    scene: &Scene,
    positions: &[Vec<Point>],
    pose: &Pose,
    p: Point,
) -> Option<Point> {
    let draws = crate::playback::pose_draws(scene, positions, pose);
    for draw in draws.iter().rev().filter(|d| d.visible) {
        let (Some(part), posed) = (scene.doc.parts.get(draw.part), draw.positions_px) else {
            continue;
        };
        for t in &part.mesh.triangles {
            if t.iter().any(|&i| i as usize >= posed.len()) {
                continue;
            }
            let [a, b, c] = t.map(|i| posed[i as usize]);
            let Some([wa, wb, wc]) = crate::geom::barycentric(p, a, b, c) else {
                continue;
            };
            if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
                let rest = t.map(|i| part.mesh.vertices[i as usize]);
                return Some(Point::from(
                    wa * rest[0].coords + wb * rest[1].coords + wc * rest[2].coords,
                ));
            }
        }
    }
    None
}

/// The pin a first drag of the drawing adds, as Spine holds a skeleton's root: at the head of
/// the root of the bone that weighs the rest point `at` (canvas px) most, where `transforms`
/// show it. `None` when that bone is a root itself (grabbing the root moves the whole
/// skeleton), when no bone weighs the point, or when the rig cannot say.
pub fn implicit_root_pin(
    scene: &Scene,
    at: Point,
    transforms: &[crate::rig::Affine],
) -> Option<IkDrag> {
    let ik = scene.rig_ik().ok()?;
    let grip = ik
        .drag_row(&IkDrag {
            at,
            to: at,
            weight: None,
        })
        .ok()?;
    let bones = &scene.doc.handles.bones;
    // Bones are the rig's first weight columns; a column's weight is its row's third entry.
    let (grabbed, _) = bones
        .iter()
        .enumerate()
        .map(|(j, bone)| (bone, grip.row.get(3 * j + 2).copied().unwrap_or(0.0)))
        .filter(|(_, w)| *w > 0.0)
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let root = scene.doc.handles.root_bone(&grabbed.name)?;
    if root.name == grabbed.name {
        return None;
    }
    let shown = shown_position(scene, root.head, transforms).ok()?;
    Some(IkDrag {
        at: root.head,
        to: shown,
        weight: None,
    })
}

/// Where the rest point `at` is shown under `transforms`: the skinning IK's own grip of it
/// (its skinning row), skinned. A pin at `at` with this target is already met, so adding it
/// leaves the drawing where it is.
pub fn shown_position(
    scene: &Scene,
    at: Point,
    transforms: &[crate::rig::Affine],
) -> Result<Point, String> {
    let ik = scene.rig_ik().map_err(|e| e.to_string())?;
    let grip = ik
        .drag_row(&IkDrag {
            at,
            to: at,
            weight: None,
        })
        .map_err(|e| e.to_string())?;
    if grip.row.len() != 3 * transforms.len() {
        return Err(format!(
            "{} transforms for a rig of {} handle columns",
            transforms.len(),
            grip.row.len() / 3
        ));
    }
    Ok(crate::ik::rig::skinned_position(&grip.row, transforms))
}

/// Whether `target` is a Spine line.
fn spine_target(target: crate::io::RuntimeTarget) -> bool {
    use crate::io::RuntimeTarget::*;
    matches!(target, Spine41 | Spine42 | Spine43)
}

/// What the timeline says the preview plays for a rig made for `target`: Spine's curves, or
/// (DragonBones, glTF, whose baked keys the editor does not replay) exactly, with where to see
/// the runtime's playback.
pub(super) fn target_label(target: crate::io::RuntimeTarget) -> String {
    if spine_target(target) {
        format!("Plays as {} (its curves)", target.label())
    } else {
        format!(
            "Target {}: the preview plays exactly; sinew render plays as {}",
            target.label(),
            target.label()
        )
    }
}
