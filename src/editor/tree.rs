//! The tree view (rig, pose and animate modes' side panel): skeletons with their bones nested
//! under their parents (and each bone's physics constraints, [`super::physics_fields`], and
//! the points it carries), the loose points, cages and regions, and the parts (slots) front to
//! back.
//!
//! In: the document's handles and layers, clicks, F2 or a double click (rename in place),
//! rig mode's drags of a bone or point onto a bone (or onto the skeletons' "no parent" row; a
//! drag held near the tree's top or bottom edge scrolls it, so any row can be reached), the
//! parts' eye boxes. Out: the selection (the canvas's: one and the same), `Rename` and
//! `Reparent` commands (undoable; a loop is refused with a message), and which parts the canvas hides (a view setting, not part of the document: the
//! posed picture drops them from the library's draw list; rig mode leaves their images out).

use super::{EditorApp, Mode};
use crate::document::Command;
use eframe::egui::{self, Key};
use std::collections::{BTreeMap, BTreeSet};

/// A bone or point being dragged in the tree (egui's drag-and-drop payload).
struct DraggedHandle(String);

/// While a handle is dragged, a pointer within this distance of the tree's visible top or
/// bottom edge (inside or out) scrolls the tree that way, points.
pub const AUTOSCROLL_BAND_PT: f32 = 24.0;
/// The scrolling speed with the pointer at the edge or beyond, points per second; it falls
/// linearly to zero at the band's inner side.
pub const AUTOSCROLL_SPEED_PT_PER_S: f32 = 480.0;

/// Frames over which a mode switch scrolls the selected row into view ([`TreeState`]).
const REVEAL_FRAMES: u8 = 2;

/// The tree's height in the side panel at least, points (a short window scrolls the panel to
/// show it whole). About eight rows.
pub const MIN_TREE_HEIGHT_PT: f32 = 170.0;
/// Rig mode's tree takes this share of the side panel's height (the tools, the selection's
/// fields and the weights share the rest); pose and animate mode's tree, last in its panel,
/// takes the whole rest.
pub const RIG_TREE_SHARE: f32 = 0.45;

/// The tree's own state.
#[derive(Default)]
pub struct TreeState {
    /// Parts the canvas does not draw (by name).
    pub hidden_parts: BTreeSet<String>,
    /// Rig mode's choice, per slot with several attachments, of the one the canvas shows
    /// (`None`: nothing). A view setting: the setup pose keys no attachment. A slot not listed
    /// shows the attachment its skins give it, else its own part.
    pub rig_attachments: BTreeMap<String, Option<String>>,
    /// The handle being renamed in place, and the name typed so far.
    renaming: Option<(String, String)>,
    /// The rename field wants the keyboard (it just appeared).
    focus: bool,
    /// The physics constraint whose fields are shown ([`super::physics_fields`]).
    pub physics: Option<String>,
    /// The mode the tree was last shown in.
    pub(super) mode_shown: Option<Mode>,
    /// Frames left in which the selected handle's row is scrolled into view (after a mode
    /// switch: each mode's panel puts the tree elsewhere).
    pub(super) reveal_frames: u8,
    /// The side panel's height this frame, points.
    pub(super) panel_height_pt: f32,
}

impl TreeState {
    /// After a mode switch: the selected row (if any) is scrolled into view.
    pub(super) fn reveal_after_switch(&mut self) {
        self.reveal_frames = REVEAL_FRAMES;
    }
}

impl EditorApp {
    /// Selects handle `name`, as a click on the canvas does.
    pub fn select_handle(&mut self, name: &str) {
        self.selected = Some(name.to_string());
        self.rig_mode.rename_to = name.to_string();
    }

    /// The tree in its own scroll area, as tall as the side panel leaves it: in rig mode
    /// [`RIG_TREE_SHARE`] of the panel, else the rest of the panel; never less than
    /// [`MIN_TREE_HEIGHT_PT`]. (Its height follows the panel, not the selection: a click on a
    /// row never moves the rows.)
    pub(super) fn tree_area(&mut self, ui: &mut egui::Ui) {
        let most_pt = match self.mode {
            Mode::Rig => (RIG_TREE_SHARE * self.tree.panel_height_pt).max(MIN_TREE_HEIGHT_PT),
            _ => f32::INFINITY,
        };
        egui::ScrollArea::vertical()
            .id_salt(("tree", self.mode as u8))
            .max_height(most_pt)
            .min_scrolled_height(MIN_TREE_HEIGHT_PT)
            .show(ui, |ui| self.tree_view(ui));
    }

    /// The tree: skeletons, points, cages, regions, parts.
    fn tree_view(&mut self, ui: &mut egui::Ui) {
        let typing = ui.ctx().text_edit_focused();
        if !typing && ui.input(|i| super::file_menu::plain_key(i, Key::F2)) {
            if let Some(name) = self.selected.clone() {
                self.start_rename(&name);
            }
        }
        scroll_while_dragging(ui);
        let handles = self.doc.state().handles.clone();
        egui::CollapsingHeader::new("Skeletons")
            .default_open(true)
            .show(ui, |ui| {
                let roots: Vec<String> = handles
                    .bones
                    .iter()
                    .filter(|b| b.parent.is_none())
                    .map(|b| b.name.clone())
                    .collect();
                if roots.is_empty() {
                    ui.label("No bones yet (the Bone tool draws them).");
                }
                for root in roots {
                    self.bone_subtree(ui, &handles, &root, 0);
                }
                // While a handle is dragged: a row to drop it on to make it a skeleton's root
                // (a bone) or loose (a point).
                if egui::DragAndDrop::has_payload_of_type::<DraggedHandle>(ui.ctx()) {
                    let row = ui.add(
                        egui::Label::new("(drop here: no parent)").sense(egui::Sense::hover()),
                    );
                    if let Some(handle) = row.dnd_release_payload::<DraggedHandle>() {
                        self.reparent(&handle.0, None);
                    }
                }
            });
        let groups = [
            (
                "Points",
                handles
                    .points
                    .iter()
                    .filter(|p| p.parent.is_none())
                    .map(|p| p.name.clone())
                    .collect(),
            ),
            (
                "Cages",
                handles.cages.iter().map(|c| c.name.clone()).collect(),
            ),
            (
                "Regions",
                handles.regions.iter().map(|r| r.name.clone()).collect(),
            ),
        ];
        for (title, names) in groups {
            let names: Vec<String> = names;
            if names.is_empty() {
                continue;
            }
            egui::CollapsingHeader::new(title)
                .default_open(true)
                .show(ui, |ui| {
                    for name in names {
                        let row = self.handle_row(ui, &name);
                        if title == "Points" {
                            self.drag_source(row, &name);
                        }
                    }
                });
        }
        self.parts_tree(ui);
    }

    fn bone_subtree(
        &mut self,
        ui: &mut egui::Ui,
        handles: &crate::rig::Handles,
        name: &str,
        depth: usize,
    ) {
        // A cycle cannot be saved, but a tree never recurses without end.
        if depth > handles.bones.len() {
            return;
        }
        let row = ui
            .horizontal(|ui| {
                ui.add_space(12.0 * depth as f32);
                self.handle_row(ui, name)
            })
            .inner;
        // Rig mode (the setup pose, where the hierarchy is edited): drag a bone's or point's
        // row onto a bone's row to hang it there.
        if let (Some(row), Mode::Rig) = (self.drag_source(row, name), self.mode) {
            if row
                .dnd_hover_payload::<DraggedHandle>()
                .is_some_and(|b| b.0 != name)
            {
                let stroke = ui.visuals().selection.stroke;
                ui.painter()
                    .rect_stroke(row.rect, 2.0, stroke, egui::StrokeKind::Outside);
            }
            if let Some(handle) = row.dnd_release_payload::<DraggedHandle>() {
                if handle.0 != name {
                    self.reparent(&handle.0, Some(name));
                }
            }
        }
        self.physics_rows(ui, name, depth);
        // The points the bone carries, one level in.
        for point in handles
            .points
            .iter()
            .filter(|p| p.parent.as_deref() == Some(name))
        {
            let row = ui
                .horizontal(|ui| {
                    ui.add_space(12.0 * (depth + 1) as f32);
                    self.handle_row(ui, &point.name)
                })
                .inner;
            self.drag_source(row, &point.name);
        }
        let children: Vec<String> = handles
            .bones
            .iter()
            .filter(|b| b.parent.as_deref() == Some(name))
            .map(|b| b.name.clone())
            .collect();
        for child in children {
            self.bone_subtree(ui, handles, &child, depth + 1);
        }
    }

    /// One handle: its name to click (select) or double-click (rename); its rename field while
    /// renamed; rig mode's lock box. Returns the name's response (none while renamed).
    fn handle_row(&mut self, ui: &mut egui::Ui, name: &str) -> Option<egui::Response> {
        ui.horizontal(|ui| {
            if self.mode == Mode::Rig {
                self.lock_box(ui, name);
            }
            if let Some((from, to)) = &mut self.tree.renaming {
                if from == name {
                    let label = ui.label("New name:");
                    let field = ui
                        .add(egui::TextEdit::singleline(to).desired_width(110.0))
                        .labelled_by(label.id);
                    if std::mem::take(&mut self.tree.focus) {
                        field.request_focus();
                    }
                    if field.lost_focus() {
                        let enter = ui.input(|i| i.key_pressed(Key::Enter));
                        let (from, to) = self.tree.renaming.take().unwrap_or_default();
                        if enter && to != from {
                            self.rename_handle(&from, &to);
                        }
                    }
                    return None;
                }
            }
            let selected = self.selected.as_deref() == Some(name);
            let mut response = ui.selectable_label(selected, name);
            if let Some(parts) = self.doc.state().handles.bind.get(name) {
                // The binding (rig mode's selection panel edits it).
                response = response.on_hover_text(format!("weighs only {}", parts.join(", ")));
            }
            if selected && self.tree.reveal_frames > 0 {
                self.tree.reveal_frames -= 1;
                // At once, not animated: the panel was just laid out anew. Again over the next
                // frames: panels sized by their content (the timeline) settle a frame later.
                response.scroll_to_me_animation(None, egui::style::ScrollAnimation::none());
                if self.tree.reveal_frames > 0 {
                    ui.ctx().request_repaint();
                }
            }
            if response.clicked() {
                self.select_handle(name);
            }
            if response.double_clicked() {
                self.start_rename(name);
            }
            Some(response)
        })
        .inner
    }

    /// In rig mode, makes a handle's row draggable (its payload: the handle's name); returns
    /// the row's response with the drag sensed.
    fn drag_source(&self, row: Option<egui::Response>, name: &str) -> Option<egui::Response> {
        let row = row.filter(|_| self.mode == Mode::Rig)?;
        let row = row.interact(egui::Sense::drag());
        row.dnd_set_drag_payload(DraggedHandle(name.to_string()));
        Some(row)
    }

    /// Hangs bone or point `handle` from bone `parent` (none: a skeleton's root, or a loose
    /// point) through the document's undoable `Reparent`; the rest geometry is in canvas px, so
    /// the handle stays where it is drawn. A parent that would close a loop is refused with the
    /// document's message.
    pub fn reparent(&mut self, handle: &str, parent: Option<&str>) {
        let handles = &self.doc.state().handles;
        let is_bone = handles.bones.iter().any(|b| b.name == handle);
        if handles.parent_of(handle) == Some(parent) {
            return;
        }
        if self.apply(Command::Reparent {
            handle: handle.to_string(),
            parent: parent.map(str::to_string),
        }) {
            self.message = Some(match (parent, is_bone) {
                (Some(p), _) => format!("'{handle}' now hangs from '{p}'"),
                (None, true) => format!("'{handle}' is now a skeleton's root"),
                (None, false) => format!("'{handle}' is now a loose point"),
            });
        }
    }

    fn start_rename(&mut self, name: &str) {
        self.select_handle(name);
        self.tree.renaming = Some((name.to_string(), name.to_string()));
        self.tree.focus = true;
    }

    /// Renames a handle everywhere (the document's `Rename`); the selection follows.
    pub fn rename_handle(&mut self, from: &str, to: &str) {
        if self.apply(Command::Rename {
            from: from.to_string(),
            to: to.to_string(),
        }) {
            if self.selected.as_deref() == Some(from) {
                self.select_handle(to);
            }
            self.message = Some(format!("renamed '{from}' to '{to}'"));
        }
    }

    /// The parts front to back (the top one is drawn over the others), each with its eye box.
    fn parts_tree(&mut self, ui: &mut egui::Ui) {
        let parts: Vec<String> = self
            .doc
            .state()
            .layers
            .iter()
            .rev()
            .map(|l| l.name.clone())
            .collect();
        if parts.is_empty() {
            return;
        }
        egui::CollapsingHeader::new("Parts (front to back)")
            .default_open(true)
            .show(ui, |ui| {
                for part in parts {
                    let mut shown = !self.tree.hidden_parts.contains(&part);
                    if ui
                        .checkbox(&mut shown, format!("show {part}"))
                        .on_hover_text("show or hide the part on the canvas")
                        .changed()
                    {
                        if shown {
                            self.tree.hidden_parts.remove(&part);
                        } else {
                            self.tree.hidden_parts.insert(part.clone());
                        }
                    }
                    self.attachment_list(ui, &part);
                }
            });
    }

    /// A slot's attachments (when it has more than its own part), the one shown ticked; a
    /// click shows another: keyed at the playhead in animate mode (an attachment key), the
    /// pose's in pose mode, a view setting in rig mode (to see and weigh each attachment).
    fn attachment_list(&mut self, ui: &mut egui::Ui, slot: &str) {
        let names = crate::document::animations::slot_attachments(self.doc.state(), slot);
        if names.len() < 2 || self.doc.state().slots.attachments.contains_key(slot) {
            return;
        }
        let shown = if self.mode == Mode::Rig {
            self.rig_attachment(slot)
        } else {
            let pose = self.edited_pose();
            match pose.parts.get(slot) {
                Some(p) if !p.visible => None,
                Some(p) => Some(
                    p.attachment
                        .clone()
                        .unwrap_or_else(|| self.default_attachment(slot)),
                ),
                None => Some(self.default_attachment(slot)),
            }
        };
        let mut chosen = None;
        ui.indent(("attachments", slot), |ui| {
            for name in names.into_iter().map(Some).chain([None]) {
                let label = match &name {
                    Some(n) => format!("{slot} shows {n}"),
                    None => format!("{slot} shows nothing"),
                };
                if ui.radio(shown == name, label).clicked() && shown != name {
                    chosen = Some(name);
                }
            }
        });
        if let Some(attachment) = chosen {
            self.show_attachment(slot, attachment);
        }
    }

    /// What slot `slot` shows by default: the part the last shown skin gives it, else its own.
    fn default_attachment(&self, slot: &str) -> String {
        let slots = &self.doc.state().slots;
        slots
            .shown
            .iter()
            .rev()
            .find_map(|skin| slots.skins.get(skin)?.get(slot).cloned())
            .unwrap_or_else(|| slot.to_string())
    }

    /// The attachment rig mode shows in `slot` (`None`: nothing): the one picked in the tree,
    /// else [`Self::default_attachment`].
    fn rig_attachment(&self, slot: &str) -> Option<String> {
        match self.tree.rig_attachments.get(slot) {
            Some(picked) => picked.clone(),
            None => Some(self.default_attachment(slot)),
        }
    }

    /// Whether rig mode draws part `name` (its image, mesh and weights): every part but the
    /// attachments a slot does not show ([`Self::rig_attachment`]). The eye boxes hide images
    /// on top of this.
    pub fn rig_shows_part(&self, name: &str) -> bool {
        let state = self.doc.state();
        let slot = state
            .slots
            .attachments
            .get(name)
            .map_or(name, String::as_str);
        if crate::document::animations::slot_attachments(state, slot).len() < 2 {
            return true;
        }
        self.rig_attachment(slot).as_deref() == Some(name)
    }

    /// Shows `attachment` (none: nothing) in `slot`: an attachment key at the playhead in
    /// animate mode, the document's pose in pose mode, the canvas's view in rig mode.
    pub fn show_attachment(&mut self, slot: &str, attachment: Option<String>) {
        if self.mode == Mode::Rig {
            self.message = Some(format!(
                "'{slot}' shows {} while rigging",
                attachment.as_deref().unwrap_or("nothing")
            ));
            self.tree
                .rig_attachments
                .insert(slot.to_string(), attachment);
            return;
        }
        let part = |pose: &mut crate::rig::Pose| {
            let p = pose.parts.entry(slot.to_string()).or_default();
            p.visible = attachment.is_some();
            p.attachment = attachment.clone();
        };
        if self.mode == Mode::Animate {
            let time_s = self.animate.time_s;
            if self.apply(Command::KeyAttachment {
                animation: self.animate.animation.clone(),
                slot: slot.to_string(),
                time_s,
                attachment: attachment.clone(),
            }) {
                if let Some(shown) = &mut self.animate.shown {
                    part(shown);
                }
                self.message = Some(format!(
                    "keyed '{slot}' showing {} at {time_s:.3} s",
                    attachment.as_deref().unwrap_or("nothing")
                ));
            }
        } else {
            let mut pose = self.doc.state().pose.clone();
            part(&mut pose);
            self.apply(Command::SetPose(pose));
        }
    }

    /// `pose` with the parts hidden in the tree made invisible, for the canvas's picture.
    pub(super) fn with_hidden_parts(&self, pose: &crate::rig::Pose) -> crate::rig::Pose {
        let mut pose = pose.clone();
        for part in &self.tree.hidden_parts {
            pose.parts.entry(part.clone()).or_default().visible = false;
        }
        pose
    }
}

/// Scrolls the tree (the scroll area `ui` is in) while a handle is dragged with the pointer near
/// its visible top or bottom edge: [`AUTOSCROLL_BAND_PT`], [`AUTOSCROLL_SPEED_PT_PER_S`].
fn scroll_while_dragging(ui: &egui::Ui) {
    if !egui::DragAndDrop::has_payload_of_type::<DraggedHandle>(ui.ctx()) {
        return;
    }
    let Some(at) = ui.ctx().pointer_latest_pos() else {
        return;
    };
    let visible = ui.clip_rect();
    let band = AUTOSCROLL_BAND_PT;
    if !visible.x_range().contains(at.x)
        || at.y < visible.top() - band
        || at.y > visible.bottom() + band
    {
        return;
    }
    // How far into the band, 0 at its inner side, 1 at the edge and beyond.
    let up = ((visible.top() + band - at.y) / band).clamp(0.0, 1.0);
    let down = ((at.y - (visible.bottom() - band)) / band).clamp(0.0, 1.0);
    if up == 0.0 && down == 0.0 {
        return;
    }
    let dt_s = ui.input(|i| i.stable_dt).min(0.1);
    // Positive y moves the content down, showing rows above.
    let delta_pt = (up - down) * AUTOSCROLL_SPEED_PT_PER_S * dt_s;
    ui.scroll_with_delta_animation(
        egui::vec2(0.0, delta_pt),
        egui::style::ScrollAnimation::none(),
    );
    // Keep scrolling while the pointer rests there: no input event arrives to draw a frame.
    ui.ctx().request_repaint();
}
