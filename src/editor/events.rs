//! Animate mode's events: the payload of the event key selected in the dopesheet's events row,
//! adding an event at the playhead, and defining new events.
//!
//! In: the document's event definitions and the animation edited, the dopesheet's selection
//! (one time of the events row), typed names and numbers. Out: [`EventEdit`] commands, one per
//! change (undoable; refused with the document's message): `Set` when a field of the selected
//! key changes (its name picked from the definitions; int, float, string; volume and balance
//! for an event with audio), `Redefine` when its audio path changes (the definition's: every key
//! of that event plays it), `Add` at the playhead (on its frame), `Define` from the *Define
//! event* window. Moving, copying and deleting event keys are the dopesheet's.

use super::number_field::number_field;
use super::EditorApp;
use crate::anim::edit::{KeyRef, TimelineId};
use crate::anim::{EventDef, EventKey};
use crate::document::events::events_at;
use crate::document::{Command, EventEdit};
use eframe::egui;

/// The events panel's own state: which of several events at one time is shown, the text being
/// typed, the event *Add event* adds and the *Define event* window's fields.
#[derive(Default)]
pub struct EventsPanel {
    /// Which event at the selected time the fields show (0: the first).
    pub index: usize,
    /// The string and audio path fields while typed, with the key they were read from.
    string: TextBuffer,
    audio: TextBuffer,
    /// The defined event *Add event* adds.
    pub to_add: String,
    /// The *Define event* window: open, and its fields.
    pub define_open: bool,
    pub new_name: String,
    pub new_def: EventDef,
    new_audio: String,
}

/// A text field's contents while it is typed into (otherwise the document's text).
#[derive(Default)]
struct TextBuffer {
    text: String,
}

/// A single-line text field labelled `label` showing `current`; true when Enter (or leaving the
/// field) commits other text (in `buffer`).
fn text_field(ui: &mut egui::Ui, label: &str, buffer: &mut TextBuffer, current: &str) -> bool {
    let id = ui.make_persistent_id(label);
    let editing = ui.memory(|m| m.has_focus(id));
    if !editing {
        buffer.text = current.to_string();
    }
    let label = ui.label(label);
    let field = ui
        .add(
            egui::TextEdit::singleline(&mut buffer.text)
                .id(id)
                .desired_width(140.0),
        )
        .labelled_by(label.id);
    field.lost_focus() && buffer.text != current
}

impl EditorApp {
    /// The time of the events row selected in the dopesheet, when the selection is one.
    fn selected_event_time(&self) -> Option<f64> {
        match self.timeline.selection.as_slice() {
            [KeyRef {
                timeline: TimelineId::Events,
                time_s,
            }] => Some(*time_s),
            _ => None,
        }
    }

    /// Whether the dopesheet's selection is one time of the events row (the panel beside the
    /// dopesheet then shows [`EditorApp::event_key_panel`] instead of the curve editor).
    pub(super) fn event_selected(&self) -> bool {
        self.selected_event_time().is_some()
    }

    /// Animate mode's side panel row: *Add event* (the event picked) at the playhead, and
    /// *Define event…*.
    pub(super) fn add_event_row(&mut self, ui: &mut egui::Ui) {
        let names: Vec<String> = self.doc.state().events.keys().cloned().collect();
        if !names.contains(&self.events.to_add) {
            self.events.to_add = names.first().cloned().unwrap_or_default();
        }
        egui::ComboBox::from_label("Event to add")
            .selected_text(if names.is_empty() {
                "(none defined)".to_string()
            } else {
                self.events.to_add.clone()
            })
            .show_ui(ui, |ui| {
                for name in &names {
                    ui.selectable_value(&mut self.events.to_add, name.clone(), name);
                }
            });
        if ui
            .add_enabled(!names.is_empty(), egui::Button::new("Add event"))
            .on_hover_text("key the event picked at the playhead")
            .clicked()
        {
            self.add_event();
        }
        if ui.button("Define event…").clicked() {
            self.events.define_open = true;
        }
    }

    /// Adds the event picked at the playhead (on its frame) and selects it.
    pub fn add_event(&mut self) {
        let time = self.snap_to_frame(self.animate.time_s).max(0.0);
        let key = EventKey {
            time,
            name: self.events.to_add.clone(),
            int: None,
            float: None,
            string: None,
            volume: None,
            balance: None,
        };
        if self.apply(Command::Events(EventEdit::Add {
            animation: self.animate.animation.clone(),
            key,
        })) {
            let animation =
                crate::document::animation_named(self.doc.state(), &self.animate.animation);
            self.events.index = events_at(&animation.events, time).len().saturating_sub(1);
            self.timeline.selection = vec![KeyRef {
                timeline: TimelineId::Events,
                time_s: time,
            }];
            self.message = Some(format!(
                "keyed event '{}' at {time:.3} s",
                self.events.to_add
            ));
        }
    }

    /// The payload of the selected event key: its name, int, float and string (and volume,
    /// balance for an event with audio), and its definition's audio path.
    pub(super) fn event_key_panel(&mut self, ui: &mut egui::Ui) {
        let Some(time_s) = self.selected_event_time() else {
            return;
        };
        let animation = crate::document::animation_named(self.doc.state(), &self.animate.animation);
        let at = events_at(&animation.events, time_s);
        if at.is_empty() {
            return;
        }
        ui.label(format!("Events at {time_s:.3} s"));
        self.events.index = self.events.index.min(at.len() - 1);
        if at.len() > 1 {
            ui.horizontal(|ui| {
                for (n, &i) in at.iter().enumerate() {
                    let label = format!("{}: {}", n + 1, animation.events[i].name);
                    if ui.selectable_label(self.events.index == n, label).clicked() {
                        self.events.index = n;
                    }
                }
            });
        }
        let index = self.events.index;
        let key = animation.events[at[index]].clone();
        let defs = self.doc.state().events.clone();
        let def = defs.get(&key.name).cloned().unwrap_or_default();
        let mut edited = key.clone();
        let mut redefined = None;
        egui::Grid::new("event key").show(ui, |ui| {
            ui.label("Name");
            egui::ComboBox::from_label("Event name")
                .selected_text(&key.name)
                .show_ui(ui, |ui| {
                    for name in defs.keys() {
                        ui.selectable_value(&mut edited.name, name.clone(), name);
                    }
                });
            ui.end_row();
            // A press on a field reports a change without one: only other numbers count.
            let shown = key.int.unwrap_or(def.int);
            let mut int = shown;
            let label = ui.label("Event int");
            let field = ui.add(number_field(&mut int).update_while_editing(false));
            if field.labelled_by(label.id).changed() && int != shown {
                edited.int = Some(int);
            }
            ui.end_row();
            let shown = key.float.unwrap_or(def.float);
            let mut float = shown;
            let label = ui.label("Event float");
            let field = ui.add(
                number_field(&mut float)
                    .speed(0.01)
                    .max_decimals(6)
                    .update_while_editing(false),
            );
            if field.labelled_by(label.id).changed() && float != shown {
                edited.float = Some(float);
            }
            ui.end_row();
            let string = key.string.clone().unwrap_or_else(|| def.string.clone());
            if text_field(ui, "Event string", &mut self.events.string, &string) {
                edited.string = Some(self.events.string.text.clone());
            }
            ui.end_row();
            if def.audio.is_some() {
                for (name, value, default, range) in [
                    ("Volume", &mut edited.volume, def.volume, 0.0..=1.0),
                    ("Balance", &mut edited.balance, def.balance, -1.0..=1.0),
                ] {
                    let shown = value.unwrap_or(default);
                    let mut v = shown;
                    let label = ui.label(name);
                    let field = ui.add(
                        number_field(&mut v)
                            .speed(0.01)
                            .range(range)
                            .update_while_editing(false),
                    );
                    if field.labelled_by(label.id).changed() && v != shown {
                        *value = Some(v);
                    }
                    ui.end_row();
                }
            }
            let audio = def.audio.clone().unwrap_or_default();
            if text_field(ui, "Audio path", &mut self.events.audio, &audio) {
                let text = self.events.audio.text.trim().to_string();
                redefined = Some(EventDef {
                    audio: (!text.is_empty()).then_some(text),
                    ..def.clone()
                });
            }
            ui.end_row();
        });
        ui.label(format!(
            "(the audio path is the definition's: every '{}' key plays it)",
            key.name
        ));
        if edited != key {
            self.apply(Command::Events(EventEdit::Set {
                animation: self.animate.animation.clone(),
                time_s,
                index,
                key: edited,
            }));
        }
        if let Some(def) = redefined {
            self.apply(Command::Events(EventEdit::Redefine {
                name: key.name.clone(),
                def,
            }));
        }
    }

    /// The *Define event* window: a name and the default payload.
    pub(super) fn define_event_window(&mut self, ctx: &egui::Context) {
        if !self.events.define_open {
            return;
        }
        let mut open = true;
        let mut define = false;
        egui::Window::new("Define event")
            .open(&mut open)
            .collapsible(false)
            .show(ctx, |ui| {
                let panel = &mut self.events;
                egui::Grid::new("define event").show(ui, |ui| {
                    let label = ui.label("New event name:");
                    ui.add(egui::TextEdit::singleline(&mut panel.new_name))
                        .labelled_by(label.id);
                    ui.end_row();
                    let label = ui.label("Default int");
                    ui.add(number_field(&mut panel.new_def.int))
                        .labelled_by(label.id);
                    ui.end_row();
                    let label = ui.label("Default float");
                    ui.add(number_field(&mut panel.new_def.float).speed(0.01))
                        .labelled_by(label.id);
                    ui.end_row();
                    let label = ui.label("Default string");
                    ui.add(egui::TextEdit::singleline(&mut panel.new_def.string))
                        .labelled_by(label.id);
                    ui.end_row();
                    let label = ui.label("Default audio path");
                    ui.add(egui::TextEdit::singleline(&mut panel.new_audio))
                        .labelled_by(label.id);
                    ui.end_row();
                });
                define = ui.button("Define").clicked();
            });
        self.events.define_open = open;
        if define {
            let name = self.events.new_name.trim().to_string();
            let audio = self.events.new_audio.trim().to_string();
            let def = EventDef {
                audio: (!audio.is_empty()).then_some(audio),
                ..self.events.new_def.clone()
            };
            if self.apply(Command::Events(EventEdit::Define {
                name: name.clone(),
                def,
            })) {
                self.events.to_add = name.clone();
                self.events.define_open = false;
                self.events.new_name.clear();
                self.events.new_def = EventDef::default();
                self.events.new_audio.clear();
                self.message = Some(format!("defined event '{name}'"));
            }
        }
    }
}
