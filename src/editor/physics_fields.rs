//! Physics constraints in the tree view: listed under the bone they move; the one selected shows
//! its parameters as numbers to type into or drag.
//!
//! In: the document's physics constraints ([`crate::rig::physics`]), clicks on their rows,
//! typed or dragged numbers. Out: one `SetPhysics` command per changed number (undoable),
//! checked by the document as the handles file is: an infinity (a typed `NaN` reaches it as
//! one: egui's field clamps it), a mass ≤ 0, a negative limit, steps per second out of range
//! are refused with its one-line message and the constraint stays as it was. The rig stays
//! posable: constraints move no weights.

use super::number_field::number_field;
use super::EditorApp;
use crate::document::Command;
use crate::rig::PhysicsConstraint;
use eframe::egui;

/// A parameter's field: its label, drag speed, and where it lives in the constraint.
struct Field {
    label: &'static str,
    speed: f64,
    get: fn(&mut PhysicsConstraint) -> &mut f64,
}

/// The fields, in Spine's order: the spring, the forces, the limit and mix, what it moves.
const FIELDS: [Field; 14] = [
    Field {
        label: "Physics inertia",
        speed: 0.01,
        get: |c| &mut c.inertia,
    },
    Field {
        label: "Physics strength",
        speed: 1.0,
        get: |c| &mut c.strength,
    },
    Field {
        label: "Physics damping",
        speed: 0.01,
        get: |c| &mut c.damping,
    },
    Field {
        label: "Physics mass",
        speed: 0.01,
        get: |c| &mut c.mass,
    },
    Field {
        label: "Physics wind",
        speed: 0.1,
        get: |c| &mut c.wind,
    },
    Field {
        label: "Physics gravity",
        speed: 0.1,
        get: |c| &mut c.gravity,
    },
    Field {
        label: "Physics limit",
        speed: 10.0,
        get: |c| &mut c.limit,
    },
    Field {
        label: "Physics mix",
        speed: 0.01,
        get: |c| &mut c.mix,
    },
    Field {
        label: "Physics steps per second",
        speed: 1.0,
        get: |c| &mut c.fps,
    },
    Field {
        label: "Moves x",
        speed: 0.01,
        get: |c| &mut c.x,
    },
    Field {
        label: "Moves y",
        speed: 0.01,
        get: |c| &mut c.y,
    },
    Field {
        label: "Moves rotate",
        speed: 0.01,
        get: |c| &mut c.rotate,
    },
    Field {
        label: "Moves scale",
        speed: 0.01,
        get: |c| &mut c.scale_x,
    },
    Field {
        label: "Moves shear",
        speed: 0.01,
        get: |c| &mut c.shear_x,
    },
];

impl EditorApp {
    /// The physics constraints on `bone`, one row each; the selected one's fields below it.
    pub(super) fn physics_rows(&mut self, ui: &mut egui::Ui, bone: &str, depth: usize) {
        let constraints: Vec<PhysicsConstraint> = self
            .doc
            .state()
            .handles
            .physics
            .iter()
            .filter(|c| c.bone == bone)
            .cloned()
            .collect();
        for constraint in constraints {
            let selected = self.tree.physics.as_deref() == Some(constraint.name.as_str());
            let row = ui.horizontal(|ui| {
                ui.add_space(12.0 * (depth + 1) as f32);
                ui.selectable_label(selected, format!("physics {}", constraint.name))
            });
            if row.inner.clicked() {
                self.tree.physics = (!selected).then(|| constraint.name.clone());
            }
            if selected {
                ui.indent(("physics fields", &constraint.name), |ui| {
                    self.physics_fields(ui, &constraint)
                });
            }
        }
    }

    /// The parameters of `constraint`; a changed number is a `SetPhysics`.
    fn physics_fields(&mut self, ui: &mut egui::Ui, constraint: &PhysicsConstraint) {
        let mut edited = None;
        egui::Grid::new(("physics", &constraint.name)).show(ui, |ui| {
            for field in &FIELDS {
                let mut c = constraint.clone();
                let shown = *(field.get)(&mut c);
                let mut value = shown;
                let label = ui.label(field.label);
                let response = ui
                    .add(
                        number_field(&mut value)
                            .speed(field.speed)
                            .max_decimals(4)
                            .update_while_editing(false),
                    )
                    .labelled_by(label.id);
                // A press reports a change without one.
                if response.changed() && value.to_bits() != shown.to_bits() {
                    *(field.get)(&mut c) = value;
                    edited = Some(c);
                }
                ui.end_row();
            }
        });
        if let Some(c) = edited {
            if self.apply(Command::SetPhysics(c)) {
                self.message = Some(format!("physics '{}' updated", constraint.name));
            }
        }
    }
}
