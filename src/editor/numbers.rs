//! The numbers panel (pose and animate modes): the selected bone's or point's rotation,
//! translation, scale and shear as labelled fields to type into or drag.
//!
//! In: the selected handle, the pose edited ([`EditorApp::edited_pose`]), typed numbers and
//! drags of the fields. Out: the pose with the new numbers, committed as every pose edit is
//! ([`EditorApp::commit_pose`]: `SetPose` in pose mode; animate mode's pose, keyed at once when
//! auto-key is on). A typed number commits on Enter; a drag shows its pose live and commits
//! once, on release (one undo step).

use super::number_field::number_field;
use super::{EditorApp, Gesture};
use crate::rig::Pose;
use eframe::egui;

/// What the panel says with nothing selected (no fields shown: their labels would suggest
/// values).
pub const NOTHING_SELECTED: &str = "Nothing selected. Click a bone or point to edit its numbers.";

/// One field: its label, its drag speed (per point moved) and unit suffix.
struct Field {
    label: &'static str,
    speed: f64,
    suffix: &'static str,
}

/// The fields, in the order of [`channels`]' numbers.
const FIELDS: [Field; 7] = [
    Field {
        label: "Rotation",
        speed: 0.5,
        suffix: "°",
    },
    Field {
        label: "Translation x",
        speed: 0.5,
        suffix: " px",
    },
    Field {
        label: "Translation y",
        speed: 0.5,
        suffix: " px",
    },
    Field {
        label: "Scale x",
        speed: 0.01,
        suffix: "",
    },
    Field {
        label: "Scale y",
        speed: 0.01,
        suffix: "",
    },
    Field {
        label: "Shear x",
        speed: 0.5,
        suffix: "°",
    },
    Field {
        label: "Shear y",
        speed: 0.5,
        suffix: "°",
    },
];

/// Whether `name` is a bone (`Some(true)`), a point (`Some(false)`) or neither.
fn kind(handles: &crate::rig::Handles, name: &str) -> Option<bool> {
    if handles.bones.iter().any(|b| b.name == name) {
        Some(true)
    } else if handles.points.iter().any(|p| p.name == name) {
        Some(false)
    } else {
        None
    }
}

/// The seven numbers of `name` in `pose`: rotation (degrees), translation (px), scale, shear
/// (degrees); the rest pose's when the pose does not name it.
pub fn channels(pose: &Pose, name: &str, bone: bool) -> [f64; 7] {
    let (r, t, s, h) = if bone {
        let b = pose.bones.get(name).cloned().unwrap_or_default();
        (b.rotate, b.translate, b.scale, b.shear)
    } else {
        let p = pose.points.get(name).cloned().unwrap_or_default();
        (p.rotate, p.translate, p.scale, p.shear)
    };
    [r, t[0], t[1], s[0], s[1], h[0], h[1]]
}

/// `pose` with `name`'s numbers set to `n` (see [`channels`]).
fn with_channels(mut pose: Pose, name: &str, bone: bool, n: [f64; 7]) -> Pose {
    if bone {
        let b = pose.bones.entry(name.to_string()).or_default();
        (b.rotate, b.translate, b.scale, b.shear) =
            (n[0], [n[1], n[2]], [n[3], n[4]], [n[5], n[6]]);
    } else {
        let p = pose.points.entry(name.to_string()).or_default();
        (p.rotate, p.translate, p.scale, p.shear) =
            (n[0], [n[1], n[2]], [n[3], n[4]], [n[5], n[6]]);
    }
    pose
}

/// The seven labelled fields of `numbers`; whether one is being dragged, and whether a drag
/// ended this frame.
fn numbers_grid(ui: &mut egui::Ui, numbers: &mut [f64; 7]) -> (bool, bool) {
    let (mut dragging, mut released) = (false, false);
    // Rotation on its own row, then x and y side by side: four rows, not seven (the tree
    // below gets the height).
    egui::Grid::new("numbers").show(ui, |ui| {
        for (k, (field, value)) in FIELDS.iter().zip(numbers.iter_mut()).enumerate() {
            let label = ui.label(field.label);
            let response = ui
                .add(
                    number_field(value)
                        .speed(field.speed)
                        .suffix(field.suffix)
                        .max_decimals(3)
                        // A typed number counts when entered, not at each keystroke.
                        .update_while_editing(false),
                )
                .labelled_by(label.id);
            dragging |= response.dragged();
            released |= response.drag_stopped();
            if k % 2 == 0 {
                ui.end_row();
            }
        }
    });
    (dragging, released)
}

impl EditorApp {
    /// The numbers of the selected bone or point. The panel is as tall whatever is selected
    /// (one truncated line, then the fields; with nothing to pose, only the line, the fields'
    /// room kept empty), so a click in the tree below it never moves the tree under the
    /// pointer.
    pub(super) fn numbers_panel(&mut self, ui: &mut egui::Ui) {
        ui.separator();
        ui.heading("Numbers");
        let target = match self.selected.clone() {
            None => Err(NOTHING_SELECTED.to_string()),
            Some(name) => match kind(&self.doc.state().handles, &name) {
                Some(bone) => Ok((name, bone)),
                None => Err(format!(
                    "'{name}' has no numbers to pose (a cage or region)."
                )),
            },
        };
        let line = match &target {
            Ok((name, bone)) => format!("{} '{name}'", if *bone { "Bone" } else { "Point" }),
            Err(why) => why.clone(),
        };
        ui.add(egui::Label::new(line).truncate());
        let Ok((name, bone)) = target else {
            // The fields' room kept empty: the tree below stays where it is.
            let rows = FIELDS.len().div_ceil(2) as f32;
            let spacing = ui.spacing();
            let height = rows * spacing.interact_size.y + (rows - 1.0) * spacing.item_spacing.y;
            ui.allocate_space(egui::vec2(ui.available_width(), height));
            return;
        };
        let base = match &self.gesture {
            Some(Gesture::Numbers(pose)) => pose.clone(),
            _ => self.edited_pose(),
        };
        let before = channels(&base, &name, bone);
        let mut numbers = before;
        let (dragging, released) = numbers_grid(ui, &mut numbers);
        if numbers != before {
            let pose = with_channels(base, &name, bone, numbers);
            if dragging && !released {
                self.gesture = Some(Gesture::Numbers(pose));
            } else {
                self.gesture = None;
                self.commit_pose(pose);
            }
        } else if released {
            if let Some(Gesture::Numbers(pose)) = self.gesture.take() {
                self.commit_pose(pose);
            }
        }
    }
}
