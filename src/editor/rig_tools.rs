//! Rig-mode tools beyond bones and points: cage and region polygons, the automatic rig, and the
//! tracing and meshing parameters with a live preview of the mesh they make.
//!
//! In: clicks on the canvas (polygon vertices), the side panel's fields. Out: document
//! commands ([`Command::AddCage`], [`Command::AddRegion`], [`Command::Propose`] with the
//! automatic rig's proposal and the template it followed, [`Command::SetOptions`] once per
//! slider gesture) and shapes to draw. The automatic rig and the preview mesh run on background
//! threads; the newest request wins and the UI never waits for them.

use super::canvas::{self, Placed};
use super::identity::Identity;
use super::number_field::{number_field, slider};
use super::{EditorApp, Gesture};
use crate::autorig::{AutorigOptions, Proposal, Template, TemplateChoice};
use crate::document::Command;
use crate::geom::Point;
use crate::io::{AutorigRecord, BuildOptions, MeshDoc, RecordedTemplate};
use crate::pipeline::Layer;
use crate::rig::{Cage, Handles, Region};
use eframe::egui::{self, Color32, Pos2, Shape, Stroke};
use std::sync::mpsc::Receiver;

/// A click this close (screen points) to a polygon's first vertex closes it.
pub const CLOSE_RADIUS_PT: f32 = 8.0;
/// The content-aware color scale S offered when the option is switched on (`--content-aware S`).
pub const DEFAULT_CONTENT_AWARE: f64 = 100.0;
/// The influence limit offered when the option is switched on (`--max-influences K`).
pub const DEFAULT_MAX_INFLUENCES: usize = 4;
/// Fewest vertices of a cage or region.
pub const MIN_POLYGON_VERTICES: usize = 3;

/// Which polygon handle a polygon gesture makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PolygonKind {
    Cage,
    Region,
}

/// What the preview mesh was (or is being) built from: the layers (by identity) and the
/// tracing and meshing options, so a change of either starts a new build.
#[derive(Clone, PartialEq)]
struct PreviewKey {
    layers: Vec<Identity<Layer>>,
    trace: crate::trace::TraceOptions,
    mesh: crate::mesh::MeshOptions,
}

/// Traced and meshed parts, or why tracing or meshing failed.
type PreviewMeshes = Result<Vec<MeshDoc>, String>;

/// The live mesh preview: the last meshes built and the build under way.
#[derive(Default)]
pub struct MeshPreview {
    built: Option<(PreviewKey, PreviewMeshes)>,
    running: Option<(PreviewKey, Receiver<PreviewMeshes>)>,
}

/// Rig-mode state the tools keep between frames.
#[derive(Default)]
pub struct RigTools {
    /// Draw the traced mesh in rig mode.
    pub show_mesh: bool,
    /// Slider values while a slider is being dragged; committed as one command on release.
    pub draft: Option<BuildOptions>,
    pub preview: MeshPreview,
    pub autorig: AutorigOptions,
    /// The automatic rig under way.
    autorig_job: Option<Receiver<Result<Proposal, String>>>,
}

impl RigTools {
    /// Rig tools for a document just opened: the automatic rig's Template box shows the
    /// template the document's last proposal followed (the user's choice replaces it).
    pub fn for_document(recorded: Option<AutorigRecord>) -> Self {
        let mut tools = RigTools::default();
        if let Some(record) = recorded {
            tools.autorig.template = template_choice(record.template);
        }
        tools
    }

    /// Whether the automatic rig is running.
    pub fn proposing(&self) -> bool {
        self.autorig_job.is_some()
    }
}

/// How the rig document records the template a proposal followed.
pub fn recorded_template(template: Option<Template>) -> RecordedTemplate {
    match template {
        None => RecordedTemplate::None,
        Some(Template::Humanoid) => RecordedTemplate::Humanoid,
        Some(Template::Quadruped) => RecordedTemplate::Quadruped,
    }
}

/// The Template box's choice for a recorded template.
pub fn template_choice(recorded: RecordedTemplate) -> TemplateChoice {
    match recorded {
        RecordedTemplate::None => TemplateChoice::None,
        RecordedTemplate::Humanoid => TemplateChoice::Humanoid,
        RecordedTemplate::Quadruped => TemplateChoice::Quadruped,
    }
}

/// The status message for an installed proposal: how many handles, the template it followed
/// and why (the proposal's `template: ` note when it chose; else the Template box's choice),
/// then its other notes.
fn proposal_message(proposal: &Proposal, chosen: TemplateChoice) -> String {
    let count = proposal.handles.names().count();
    let template_note = proposal.notes.iter().find(|n| n.starts_with("template: "));
    let template = match template_note {
        Some(note) => note.clone(),
        None => {
            let name = crate::autorig::template_name(proposal.template);
            let why = match chosen {
                TemplateChoice::Auto => "chosen automatically",
                _ => "as chosen in the Template box",
            };
            format!("template: {name} ({why})")
        }
    };
    let mut message = format!("proposed {count} handles; {template}");
    for note in proposal
        .notes
        .iter()
        .filter(|n| !n.starts_with("template: "))
    {
        message.push_str("; ");
        message.push_str(note);
    }
    message
}

impl EditorApp {
    /// A click of the cage or region tool at `at` (canvas px): starts a polygon, adds a vertex,
    /// or closes it on its first vertex.
    pub(super) fn polygon_click(&mut self, kind: PolygonKind, at: Point, placed: &Placed) {
        match &mut self.gesture {
            Some(Gesture::NewPolygon {
                kind: current,
                points,
            }) if *current == kind => {
                let closes = points.len() >= MIN_POLYGON_VERTICES
                    && placed
                        .screen_from_canvas(points[0])
                        .distance(placed.screen_from_canvas(at))
                        <= CLOSE_RADIUS_PT;
                if closes {
                    self.close_polygon();
                } else {
                    points.push(at);
                }
            }
            _ => {
                self.gesture = Some(Gesture::NewPolygon {
                    kind,
                    points: vec![at],
                })
            }
        }
    }

    /// Ends the polygon being drawn: a cage or region when it has enough vertices.
    pub(super) fn close_polygon(&mut self) {
        let Some(Gesture::NewPolygon { kind, points }) = self.gesture.take() else {
            return;
        };
        if points.len() < MIN_POLYGON_VERTICES {
            self.message = Some(format!(
                "a polygon needs at least {MIN_POLYGON_VERTICES} vertices"
            ));
            return;
        }
        let (name, command) = match kind {
            PolygonKind::Cage => {
                let name = self.unique_name("cage");
                let cage = Cage {
                    name: name.clone(),
                    polygon: points,
                };
                (name, Command::AddCage(cage))
            }
            PolygonKind::Region => {
                let name = self.unique_name("region");
                let region = Region {
                    name: name.clone(),
                    polygon: points,
                };
                (name, Command::AddRegion(region))
            }
        };
        if self.apply(command) {
            self.selected = Some(name);
        }
    }

    /// The polygon being drawn, with a rubber band to the pointer.
    pub(super) fn polygon_shapes(&self, placed: &Placed, hover: Option<Pos2>) -> Vec<Shape> {
        let Some(Gesture::NewPolygon { kind, points }) = &self.gesture else {
            return Vec::new();
        };
        let color = match kind {
            PolygonKind::Cage => Color32::from_rgb(120, 255, 140),
            PolygonKind::Region => Color32::from_rgb(255, 140, 220),
        };
        let mut screen: Vec<Pos2> = points
            .iter()
            .map(|p| placed.screen_from_canvas(*p))
            .collect();
        let first = screen[0];
        if let Some(h) = hover {
            screen.push(h);
        }
        let mut shapes = vec![Shape::line(screen, Stroke::new(1.5, color))];
        shapes.push(Shape::circle_stroke(
            first,
            CLOSE_RADIUS_PT,
            Stroke::new(1.0, color),
        ));
        shapes
    }

    /// The side panel's mesh section (tracing and meshing sliders, show mesh) and the
    /// automatic rig's section.
    pub(super) fn rig_tools_panel(&mut self, ui: &mut egui::Ui) {
        ui.separator();
        ui.heading("Mesh and weight options");
        ui.checkbox(&mut self.rig_tools.show_mesh, "Show the traced mesh");
        let current = self.doc.state().options.clone();
        let mut draft = self
            .rig_tools
            .draft
            .clone()
            .unwrap_or_else(|| current.clone());
        let mut responses = Vec::new();
        let mut alpha = f64::from(draft.trace.alpha_threshold);
        responses.push(ui.add(slider(&mut alpha, 1.0..=255.0).text("alpha threshold")));
        draft.trace.alpha_threshold = alpha.round().clamp(1.0, 255.0) as u8;
        responses.push(ui.add(slider(&mut draft.trace.padding_px, 0.0..=16.0).text("padding px")));
        responses.push(
            ui.add(
                slider(&mut draft.trace.simplify_tolerance_px, 0.05..=8.0)
                    .logarithmic(true)
                    .text("simplify px"),
            ),
        );
        responses
            .push(ui.add(slider(&mut draft.mesh.min_angle_deg, 0.0..=30.0).text("min angle °")));
        responses.push(
            ui.add(
                slider(&mut draft.mesh.max_area_fraction, 1e-5..=1e-1)
                    .logarithmic(true)
                    .text("max triangle area (of canvas)"),
            ),
        );
        ui.label("Weight options");
        responses.push(ui.checkbox(
            &mut draft.weights.monotone,
            "monotone (no spurious extrema)",
        ));
        let mut content = draft.weights.content_aware.is_some();
        let mut strength = draft.weights.content_aware.unwrap_or(DEFAULT_CONTENT_AWARE);
        ui.horizontal(|ui| {
            responses.push(ui.checkbox(&mut content, "content-aware, color scale"));
            responses.push(ui.add(number_field(&mut strength).range(0.0..=1000.0)));
        });
        draft.weights.content_aware = content.then_some(strength);
        let mut limit = draft.weights.max_influences.is_some();
        let mut k = draft
            .weights
            .max_influences
            .unwrap_or(DEFAULT_MAX_INFLUENCES);
        ui.horizontal(|ui| {
            responses.push(ui.checkbox(&mut limit, "at most"));
            responses.push(ui.add(number_field(&mut k).range(1..=16)));
            ui.label("influences per vertex");
        });
        draft.weights.max_influences = limit.then_some(k);
        let dragging = responses.iter().any(|r| r.dragged());
        let released = responses.iter().any(|r| r.drag_stopped());
        if draft != current {
            if dragging && !released {
                self.rig_tools.draft = Some(draft);
            } else {
                self.rig_tools.draft = None;
                self.apply(Command::SetOptions(draft));
            }
        } else if !dragging {
            self.rig_tools.draft = None;
        }
        if let Some(Err(e)) = self.rig_tools.preview.built.as_ref().map(|(_, r)| r) {
            ui.colored_label(Color32::from_rgb(255, 120, 100), e);
        }

        ui.separator();
        ui.heading("Automatic rig");
        let options = &mut self.rig_tools.autorig;
        ui.horizontal(|ui| {
            ui.label("Template");
            egui::ComboBox::from_id_salt("autorig template")
                .selected_text(format!("{:?}", options.template))
                .show_ui(ui, |ui| {
                    for t in [
                        TemplateChoice::Auto,
                        TemplateChoice::None,
                        TemplateChoice::Humanoid,
                        TemplateChoice::Quadruped,
                    ] {
                        ui.selectable_value(&mut options.template, t, format!("{t:?}"));
                    }
                });
        });
        let mut limit = options.skeleton.max_bones.is_some();
        ui.horizontal(|ui| {
            ui.checkbox(&mut limit, "at most");
            let mut n = options.skeleton.max_bones.unwrap_or(16);
            ui.add(number_field(&mut n).range(1..=128));
            ui.label("bones");
            options.skeleton.max_bones = limit.then_some(n);
        });
        ui.add(slider(&mut options.point_count, 0..=32).text("points"));
        let mut cage = options.cage_vertices.is_some();
        ui.horizontal(|ui| {
            ui.checkbox(&mut cage, "cage of at most");
            let mut n = options.cage_vertices.unwrap_or(12);
            ui.add(number_field(&mut n).range(3..=64));
            options.cage_vertices = cage.then_some(n);
        });
        if self.rig_tools.proposing() {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label("proposing handles…");
            });
        } else if ui
            .button("Propose handles")
            .on_hover_text("Replaces the handles with the automatic rig's (undo restores them)")
            .clicked()
        {
            let ctx = ui.ctx().clone();
            self.start_autorig(&ctx);
        }
    }

    /// Runs the automatic rig on the current layers on another thread.
    pub fn start_autorig(&mut self, ctx: &egui::Context) {
        let layers = self.doc.state().layers.clone();
        if layers.is_empty() {
            self.message = Some("import a layer first".into());
            return;
        }
        let options = self.rig_tools.autorig.clone();
        let (send, receive) = std::sync::mpsc::channel();
        let ctx = ctx.clone();
        std::thread::spawn(move || {
            let result =
                crate::jobs::propose_handles(&layers, &[], &options).map_err(|e| e.to_string());
            let _ = send.send(result);
            ctx.request_repaint();
        });
        self.rig_tools.autorig_job = Some(receive);
    }

    /// Installs a finished automatic rig; starts and collects preview mesh builds.
    pub(super) fn poll_rig_tools(&mut self, ctx: &egui::Context) {
        if let Some(job) = &self.rig_tools.autorig_job {
            match job.try_recv() {
                Ok(Ok(proposal)) => {
                    self.rig_tools.autorig_job = None;
                    let message = proposal_message(&proposal, self.rig_tools.autorig.template);
                    let command = Command::Propose {
                        record: AutorigRecord {
                            template: recorded_template(proposal.template),
                        },
                        handles: proposal.handles,
                    };
                    if self.apply(command) {
                        self.message = Some(message);
                        self.selected = None;
                    }
                }
                Ok(Err(e)) => {
                    self.rig_tools.autorig_job = None;
                    self.fail(format!("automatic rig: {e}"));
                }
                Err(std::sync::mpsc::TryRecvError::Empty) => {}
                Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                    self.rig_tools.autorig_job = None;
                }
            }
        }
        self.poll_preview(ctx);
    }

    fn wanted_preview(&self) -> Option<PreviewKey> {
        if self.mode != super::Mode::Rig || !self.rig_tools.show_mesh {
            return None;
        }
        let state = self.doc.state();
        if state.layers.is_empty() {
            return None;
        }
        let options = self.rig_tools.draft.as_ref().unwrap_or(&state.options);
        Some(PreviewKey {
            layers: state.layers.iter().map(Identity::of).collect(),
            trace: options.trace.clone(),
            mesh: options.mesh.clone(),
        })
    }

    fn poll_preview(&mut self, ctx: &egui::Context) {
        let preview = &mut self.rig_tools.preview;
        if let Some((key, job)) = &preview.running {
            match job.try_recv() {
                Ok(result) => {
                    preview.built = Some((key.clone(), result));
                    preview.running = None;
                }
                Err(std::sync::mpsc::TryRecvError::Disconnected) => preview.running = None,
                Err(std::sync::mpsc::TryRecvError::Empty) => {}
            }
        }
        let Some(wanted) = self.wanted_preview() else {
            return;
        };
        let preview = &self.rig_tools.preview;
        let have = preview.built.as_ref().is_some_and(|(k, _)| *k == wanted);
        // One build at a time: a newer request waits for the running one, then starts.
        if have || preview.running.is_some() {
            return;
        }
        let layers = self.doc.state().layers.clone();
        let options = BuildOptions {
            trace: wanted.trace.clone(),
            mesh: wanted.mesh.clone(),
            ..Default::default()
        };
        let (send, receive) = std::sync::mpsc::channel();
        let ctx = ctx.clone();
        std::thread::spawn(move || {
            // No handles: trace and mesh only, no weights.
            let result = crate::pipeline::build_rig(
                &layers,
                &std::env::temp_dir(),
                &options,
                &Handles::default(),
            )
            .map(|(doc, _)| doc.parts.into_iter().map(|p| p.mesh).collect())
            .map_err(|e| e.to_string());
            let _ = send.send(result);
            ctx.request_repaint();
        });
        self.rig_tools.preview.running = Some((wanted, receive));
    }

    /// The preview meshes as wireframes (the last ones built while a newer build runs).
    pub(super) fn mesh_shapes(&self, placed: &Placed) -> Vec<Shape> {
        if self.mode != super::Mode::Rig || !self.rig_tools.show_mesh {
            return Vec::new();
        }
        let Some((_, Ok(meshes))) = &self.rig_tools.preview.built else {
            return Vec::new();
        };
        meshes
            .iter()
            .flat_map(|m| canvas::wireframe(placed, &m.vertices, &m.triangles))
            .collect()
    }

    /// The vertex count of the preview meshes, for the status line; `None` before one is built.
    pub fn preview_vertex_count(&self) -> Option<usize> {
        match &self.rig_tools.preview.built {
            Some((_, Ok(meshes))) => Some(meshes.iter().map(|m| m.vertices.len()).sum()),
            _ => None,
        }
    }

    /// Whether a preview mesh build is running.
    pub fn previewing(&self) -> bool {
        self.rig_tools.preview.running.is_some()
    }
}
