//! Playing an animation into frames.
//!
//! In: a [`Scene`], an [`Animation`], a frame rate and a [`FrameView`] (output size in px, the
//! scale from canvas px to output px, an optional background). Out: one straight-alpha RGBA8
//! image per frame, at times 0, 1/fps, 2/fps, … up to but not including the animation's
//! duration (the loop's end is its start), ready for [`crate::io::sequence`].
//!
//! Frames are posed through [`crate::scene::frames`] (a frame is a function of its time, not of
//! the frame rate or of the frames before it) and drawn in parallel, so the output depends on
//! neither the frame rate's other frames nor the thread count.
//!
//! [`bake`] turns an animation into plain keys (bones, points, cages at every frame time) from
//! the transformations playback solves: what a runtime that knows no skinning IK can play.

use crate::anim::{Animation, SampleOptions};
use crate::pipeline::{PipelineError, Scene};
use crate::render;
use crate::rig::{Handles, Pose};
use crate::scene::{Frame, PlayOptions};
use crate::shown::Shown;
use crate::skin::Blend;
use image::RgbaImage;
use rayon::prelude::*;

mod stream;
pub use stream::{write_animation, AnimationFrames};

/// Frame rates above this are refused: nothing plays them, and a typo (`--fps 2400`) would
/// otherwise render for minutes.
pub const MAX_FPS: f64 = 240.0;
/// Lowest frame rate, frames per second (a frame every 10 s). A choice well above where GIF
/// frame delays overflow (at most 655.35 s, below ~0.0015 fps; at 1e-300 the sweep saw the
/// sheet's duration field overflow too).
pub const MIN_FPS: f64 = 0.1;
/// Most frames one animation may play as (duration × fps): beyond, a typo'd key time (1e6 s)
/// would allocate and render for ever.
pub const MAX_FRAMES: f64 = 100_000.0;
/// Largest output frame side, px. Whether frames of a size may be drawn at all is the memory
/// budget's to say ([`crate::budget`]): [`render_animation`] holds every frame, renders written
/// to files ([`write_animation`]) as many at once as the budget allows.
pub const MAX_FRAME_SIDE_PX: u32 = 16_384;
/// Bytes per px of drawing one pose and saving it as a PNG (`sinew pose -o`): the straight
/// frame (4), the premultiplied pixmap and the coverage scratch while drawing
/// ([`crate::budget::DRAW_BYTES_PER_PX`]), or the encoded PNG (at most about 4) after.
pub const POSE_BYTES_PER_PX: u64 =
    crate::budget::FRAME_BYTES_PER_PX + crate::budget::DRAW_BYTES_PER_PX;

/// Where frames are drawn: an output of `size_px`, the canvas scaled by `scale` about its
/// center and centered in it, over `background` (straight RGBA8; transparent when `None`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameView {
    pub size_px: [u32; 2],
    pub scale: f64,
    pub background: Option<[u8; 4]>,
}

/// How an animation is rendered to frames: the options `sinew render` takes as flags and the
/// editor's File → Render as fields, in one place so both render the same.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderSettings {
    /// Frames per second, in [[`MIN_FPS`], [`MAX_FPS`]]. Default [`DEFAULT_RENDER_FPS`].
    pub fps: f64,
    /// Output px per canvas px, > 0. Default 1.
    pub scale: f64,
    /// Output size, px; the scaled canvas is centered in it. Default `None`: the scaled canvas.
    pub size_px: Option<[u32; 2]>,
    /// Straight RGBA8 background. Default `None`: transparent.
    pub background: Option<[u8; 4]>,
    /// How handle transformations blend. Default linear.
    pub blend: Blend,
    /// Exact curves, or as Spine's runtimes play them. Default exact.
    pub sampling: SampleOptions,
    /// With the Spine runtime's sampling: the export it plays. Default: `sinew spine`'s defaults.
    pub export: crate::export::spine::played::ExportPlayed,
    /// Play as this runtime plays the default export of its format (the export's baked keys,
    /// interpolated as the runtime does); `sampling` then plays no part. Default `None`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baked_runtime: Option<BakedRuntime>,
}

/// A runtime that plays an export's baked keys, reproduced by sinew (`--match-runtime`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BakedRuntime {
    /// The DragonBones runtimes: [`crate::export::dragonbones::played`].
    Dragonbones,
    /// A glTF runtime (three.js, Godot, Bevy…): [`crate::export::gltf::played`].
    Gltf,
}

/// The frame rate of [`RenderSettings::default`], frames per second.
pub const DEFAULT_RENDER_FPS: f64 = 24.0;

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            fps: DEFAULT_RENDER_FPS,
            scale: 1.0,
            size_px: None,
            background: None,
            blend: Blend::Linear,
            sampling: SampleOptions::default(),
            export: Default::default(),
            baked_runtime: None,
        }
    }
}

impl RenderSettings {
    /// These settings playing as `target`'s runtime plays the default export of its format
    /// (the other fields kept): the Spine runtime's curves and the export of that line, or a
    /// baked runtime.
    pub fn playing_as(&self, target: crate::io::RuntimeTarget) -> RenderSettings {
        use crate::export::spine::SpineVersion;
        use crate::io::RuntimeTarget;
        let spine = |version| RenderSettings {
            sampling: SampleOptions {
                curves: crate::anim::CurveEvaluation::SpineRuntime,
            },
            export: crate::export::spine::played::ExportPlayed {
                version,
                ..Default::default()
            },
            baked_runtime: None,
            ..self.clone()
        };
        match target {
            RuntimeTarget::Spine41 => spine(SpineVersion::V4_1),
            RuntimeTarget::Spine42 => spine(SpineVersion::V4_2),
            RuntimeTarget::Spine43 => spine(SpineVersion::V4_3),
            RuntimeTarget::DragonBones => RenderSettings {
                baked_runtime: Some(BakedRuntime::Dragonbones),
                ..self.clone()
            },
            RuntimeTarget::Gltf => RenderSettings {
                baked_runtime: Some(BakedRuntime::Gltf),
                ..self.clone()
            },
        }
    }

    /// The output view for a canvas of `canvas_px`.
    pub fn view(&self, canvas_px: [u32; 2]) -> Result<FrameView, PlaybackError> {
        FrameView::new(canvas_px, self.scale, self.size_px, self.background)
    }
}

/// Plays `animation` (named `name`) on `scene` as `settings` say, all frames in memory: the
/// frames of [`AnimationFrames`] (at [`frame_times`]`(duration, fps)`, posed as [`play`] poses
/// them, so a frame is the same at any frame rate, and drawn by [`draw_pose`]). `on_frame` is
/// called once per frame drawn (progress). To write a render to files, [`write_animation`]
/// streams it instead.
pub fn render_animation(
    scene: &Scene,
    name: &str,
    animation: &Animation,
    settings: &RenderSettings,
    on_frame: &(dyn Fn() + Sync),
) -> Result<Vec<RgbaImage>, RenderAnimationError> {
    let frames = AnimationFrames::new(scene, name, animation, settings, on_frame)?;
    let count = frames.times_s().len();
    check_render_memory(count, &settings.view(scene.doc.canvas)?)?;
    frames.render(0..count)
}

/// The events each frame of [`render_animation`] fires, one list per frame
/// ([`crate::anim::frame_events`] at its frame times, payloads from the rig's definitions; key
/// times stored as the runtime stores them when `settings` match it).
pub fn render_events(
    scene: &Scene,
    animation: &Animation,
    settings: &RenderSettings,
) -> Result<Vec<Vec<crate::anim::FiredEvent>>, PlaybackError> {
    let times = frame_times(animation.duration_s(), settings.fps)?;
    Ok(crate::anim::frame_events(
        animation,
        &times,
        &scene.doc.events,
        settings.sampling.curves,
    ))
}

/// The frames of `animation` (named `name`) at `times_s`, played as `settings` say (only their
/// `sampling`, `export` and `baked_runtime` matter here): with exact curves, through the one
/// pose path ([`crate::scene::frames`]); with [`crate::anim::CurveEvaluation::SpineRuntime`], as Spine's
/// runtime plays the Spine export made with `export` ([`crate::export::spine::played`]: its
/// curve evaluation, and the baked keys interpolated as it does); with a `baked_runtime`, as
/// that runtime plays the default export of its format ([`crate::export::dragonbones::played`],
/// [`crate::export::gltf::played`]).
pub fn play(
    scene: &Scene,
    name: &str,
    animation: &Animation,
    times_s: &[f64],
    looping: bool,
    settings: &RenderSettings,
) -> Result<Vec<Frame>, RenderAnimationError> {
    stream::Player::new(
        scene,
        name,
        animation,
        &settings.sampling,
        &settings.export,
        settings.baked_runtime,
        looping,
    )?
    .frames(times_s)
}

/// Why [`render_animation`] failed: its settings, or posing and drawing the rig.
#[derive(Debug, thiserror::Error)]
pub enum RenderAnimationError {
    #[error(transparent)]
    Settings(#[from] PlaybackError),
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    #[error(transparent)]
    Runtime(#[from] crate::export::spine::SpineError),
    #[error(transparent)]
    Gltf(#[from] crate::export::gltf::GltfError),
    #[error(transparent)]
    DragonBones(#[from] crate::export::dragonbones::DragonBonesError),
    #[error(transparent)]
    Sequence(#[from] crate::io::sequence::SequenceError),
}

/// The smallest side the scaled canvas may have, px: a scale that draws it smaller renders
/// nothing recognisable (a 1×1 px frame).
pub const MIN_SCALED_SIDE_PX: f64 = 1.0;

/// What is wrong with a playback request.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PlaybackError {
    #[error(
        "the frame rate must be a number in [{MIN_FPS}, {MAX_FPS}] frames per second, not {}",
        Shown(*.0)
    )]
    Fps(f64),
    #[error("the scale must be a positive number, not {}", Shown(*.0))]
    Scale(f64),
    #[error(
        "the scale {} draws the {}×{} px canvas smaller than {MIN_SCALED_SIDE_PX} px a side: \
         use a scale of at least {}",
        Shown(*scale), canvas[0], canvas[1], Shown(*min_scale)
    )]
    ScaleTooSmall {
        scale: f64,
        canvas: [u32; 2],
        min_scale: f64,
    },
    #[error("the output size must be at least 1×1 px")]
    Size,
    #[error(
        "the output frames would be {0:.0}×{1:.0} px: at most {MAX_FRAME_SIDE_PX} px a side \
         (lower the scale or the size)"
    )]
    TooLarge(f64, f64),
    #[error(
        "the animation would play as {} frames (duration × frame rate): at most {MAX_FRAMES}",
        Shown(*.0)
    )]
    TooManyFrames(f64),
    /// More than the memory budget would be allocated ([`crate::budget`]).
    #[error(transparent)]
    Budget(#[from] crate::budget::BudgetError),
}

impl FrameView {
    /// The canvas at `scale`, in an output of `size_px` (default: the scaled canvas, rounded
    /// up).
    pub fn new(
        canvas_px: [u32; 2],
        scale: f64,
        size_px: Option<[u32; 2]>,
        background: Option<[u8; 4]>,
    ) -> Result<Self, PlaybackError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(PlaybackError::Scale(scale));
        }
        let shortest = canvas_px.iter().copied().min().unwrap_or(0).max(1);
        if f64::from(shortest) * scale < MIN_SCALED_SIDE_PX {
            return Err(PlaybackError::ScaleTooSmall {
                scale,
                canvas: canvas_px,
                min_scale: MIN_SCALED_SIDE_PX / f64::from(shortest),
            });
        }
        let size = size_px.map_or_else(
            || canvas_px.map(|c| (f64::from(c) * scale).ceil().max(1.0)),
            |s| s.map(f64::from),
        );
        if size.contains(&0.0) {
            return Err(PlaybackError::Size);
        }
        if size.iter().any(|&side| side > f64::from(MAX_FRAME_SIDE_PX)) {
            return Err(PlaybackError::TooLarge(size[0], size[1]));
        }
        let size_px = size.map(|side| side as u32);
        Ok(FrameView {
            size_px,
            scale,
            background,
        })
    }

    /// Output px from canvas px: scale about the canvas center, then center in the output.
    pub fn output_from_canvas(&self, canvas_px: [u32; 2]) -> tiny_skia::Transform {
        let s = self.scale as f32;
        let half = |c: u32| c as f32 / 2.0;
        let tx = half(self.size_px[0]) - s * half(canvas_px[0]);
        let ty = half(self.size_px[1]) - s * half(canvas_px[1]);
        tiny_skia::Transform::from_row(s, 0.0, 0.0, s, tx, ty)
    }
}

/// Frame times (s) of an animation lasting `duration_s` played at `fps`: 0, 1/fps, … while
/// below the duration; a single frame at 0 for an animation without duration.
pub fn frame_times(duration_s: f64, fps: f64) -> Result<Vec<f64>, PlaybackError> {
    if !(MIN_FPS..=MAX_FPS).contains(&fps) {
        return Err(PlaybackError::Fps(fps));
    }
    // A frame that lands on the duration up to rounding is the loop's start again.
    let count = ((duration_s * fps) - FRAME_TIME_SLACK).ceil().max(1.0);
    if count.is_nan() || count > MAX_FRAMES {
        return Err(PlaybackError::TooManyFrames(count));
    }
    Ok((0..count as usize).map(|i| i as f64 / fps).collect())
}

/// Fails when holding `frames` frames of `view`'s size, while the pool's threads draw them
/// ([`render_animation`]), is over the memory budget in force ([`crate::budget`]).
pub fn check_render_memory(frames: usize, view: &FrameView) -> Result<(), PlaybackError> {
    use crate::budget::{px_bytes, FrameCost, DRAW_BYTES_PER_PX, FRAME_BYTES_PER_PX};
    let size = (view.size_px[0], view.size_px[1]);
    let cost = FrameCost {
        fixed_bytes: 0,
        per_frame_bytes: px_bytes(size, FRAME_BYTES_PER_PX),
        per_thread_bytes: px_bytes(size, DRAW_BYTES_PER_PX),
        threads: rayon::current_num_threads(),
    };
    crate::budget::memory_budget().check(cost.peak_bytes(frames), || {
        format!(
            "a render holding {frames} frames of {}×{} px (lower the frame rate, the scale or \
             the duration)",
            size.0, size.1
        )
    })?;
    Ok(())
}

/// Fails when drawing one frame of `size_px` and saving it as a PNG ([`POSE_BYTES_PER_PX`];
/// `sinew pose -o`) is over the memory budget in force.
pub fn check_pose_memory(size_px: [u32; 2]) -> Result<(), PlaybackError> {
    let size = (size_px[0], size_px[1]);
    let need = crate::budget::px_bytes(size, POSE_BYTES_PER_PX);
    crate::budget::memory_budget().check(need, || {
        format!("a {}×{} px pose drawn and saved", size.0, size.1)
    })?;
    Ok(())
}

/// How far below a whole frame count `duration · fps` may fall and still count as it.
const FRAME_TIME_SLACK: f64 = 1e-9;

/// Renders one pose through `view`.
pub fn render_pose(
    scene: &Scene,
    pose: &Pose,
    blend: Blend,
    view: &FrameView,
) -> Result<RgbaImage, PipelineError> {
    let positions = scene.pose_positions_with(pose, blend)?;
    render_positions(scene, &positions, pose, view)
}

/// Draws the parts at `positions` as `pose` shows them on a transparent canvas of the rig's size
/// (what `sinew pose -o` writes).
pub fn render_posed(
    scene: &Scene,
    positions: &[Vec<crate::geom::Point>],
    pose: &Pose,
) -> Result<RgbaImage, PipelineError> {
    let view = FrameView::new(scene.doc.canvas, 1.0, None, None)
        .map_err(|_| PipelineError::Canvas(scene.doc.canvas))?;
    render_positions(scene, positions, pose, &view)
}

/// Renders parts at `positions` (one list per part, canvas px) as `pose` shows them.
fn render_positions(
    scene: &Scene,
    positions: &[Vec<crate::geom::Point>],
    pose: &Pose,
    view: &FrameView,
) -> Result<RgbaImage, PipelineError> {
    let [w, h] = view.size_px;
    let mut canvas = tiny_skia::Pixmap::new(w, h).ok_or(PipelineError::Canvas(view.size_px))?;
    if let Some([r, g, b, a]) = view.background {
        canvas.fill(tiny_skia::Color::from_rgba8(r, g, b, a));
    }
    draw_pose(
        scene,
        &mut canvas,
        positions,
        pose,
        view.output_from_canvas(scene.doc.canvas),
    )?;
    Ok(render::rgba_from_pixmap(&canvas))
}

/// Draws the parts at `positions` as `pose` shows them: its draw order (the document's
/// otherwise), each part's tint and visibility ([`pose_draws`]).
pub fn draw_pose(
    scene: &Scene,
    canvas: &mut tiny_skia::Pixmap,
    positions: &[Vec<crate::geom::Point>],
    pose: &Pose,
    output_from_canvas: tiny_skia::Transform,
) -> Result<(), PipelineError> {
    let draws = pose_draws(scene, positions, pose);
    scene.draw_parts(canvas, &draws, output_from_canvas)
}

/// The parts at `positions` (one list per part, canvas px) as `pose` shows them, back to
/// front: its draw order of slots (the document's otherwise), each slot's tint and visibility,
/// and the part each slot shows (its attachment, through the scene's skins). What
/// [`draw_pose`] draws, for every consumer that draws a pose (the editor's canvas too).
pub fn pose_draws<'a>(
    scene: &Scene,
    positions: &'a [Vec<crate::geom::Point>],
    pose: &Pose,
) -> Vec<render::PartDraw<'a>> {
    let doc = &scene.doc;
    // Slots back to front; each draws the part its attachment and the skins choose.
    let slots: Vec<&str> = match &pose.draw_order {
        Some(names) => names
            .iter()
            .map(String::as_str)
            .filter(|n| doc.parts.iter().any(|p| p.slot.is_none() && p.name == *n))
            .collect(),
        None => doc.slot_names(),
    };
    slots
        .into_iter()
        .filter_map(|slot| {
            let state = pose.parts.get(slot);
            let attachment = state.and_then(|s| s.attachment.as_deref());
            let i = doc.shown_part(slot, attachment, scene.skins())?;
            let mut draw =
                render::PartDraw::new(i, positions.get(i).map(Vec::as_slice).unwrap_or_default());
            if let Some(state) = state {
                let [r, g, b, a] = state.color.map(|c| c as f32);
                draw.tint = render::Tint { r, g, b, a };
                draw.visible = state.visible;
            }
            Some(draw)
        })
        .collect()
}

/// Draws every frame through `view`, in parallel; `on_frame` is called once per finished frame
/// (for a progress bar).
pub fn render_frames(
    scene: &Scene,
    frames: &[Frame],
    blend: Blend,
    view: &FrameView,
    on_frame: &(dyn Fn() + Sync),
) -> Result<Vec<RgbaImage>, PipelineError> {
    frames
        .par_iter()
        .map(|frame| {
            let image = scene
                .positions_from_transforms(&frame.transforms, &frame.pose, blend)
                .and_then(|positions| render_positions(scene, &positions, &frame.pose, view));
            on_frame();
            image
        })
        .collect()
}

/// How far (px, at the corners of the rig's rest bounding box) playing a baked frame on the rig
/// may move a handle away from the transformation that was baked.
pub const BAKE_REPLAY_TOLERANCE_PX: f64 = 1e-3;

/// Bakes `animation` at `times_s` (ascending; the caller includes the end time if the loop
/// must close) into an animation with linear keys for every bone, point and cage, computed from
/// the skinning transformations playback solves — skinning IK included — and no `ik`
/// timelines. Part looks, draw order and events are kept as authored. Rotations are unwrapped (each key
/// within 180° of the previous), since runtimes interpolate plain numbers.
///
/// Bone IK constraints stay in the rig and solve again when the baked keys play, so the bones of
/// their chains are baked with the keys the constraints solve from (the animation's own), not
/// with the solved rotations, which a constraint with mix < 1 would blend a second time. Every
/// baked frame is played back on the rig and compared with what was baked; when a constraint
/// would not reproduce it (skinning IK moved a chain, which then follows its ancestor without
/// solving again), the bake is refused.
pub fn bake(
    scene: &Scene,
    animation: &Animation,
    times_s: &[f64],
) -> Result<Animation, PipelineError> {
    let handles = &scene.doc.handles;
    let frames = crate::scene::frames(scene, animation, times_s, PlayOptions::default())?;
    let (poses, transforms): (Vec<Pose>, Vec<Vec<crate::rig::Affine>>) = frames
        .into_iter()
        .map(|frame| (frame.pose, frame.transforms))
        .unzip();
    let mut baked: Vec<Pose> = transforms
        .iter()
        .map(|t| crate::rig::pose::pose_from_transforms(handles, t))
        .collect::<Result<_, _>>()?;
    if !handles.ik.is_empty() {
        let constrained: std::collections::BTreeSet<&String> =
            handles.ik.iter().flat_map(|c| &c.bones).collect();
        let corners = rest_corners(&scene.doc);
        for ((frame, keyed), solved) in baked.iter_mut().zip(&poses).zip(&transforms) {
            for &bone in &constrained {
                let input = keyed.bones.get(bone).cloned().unwrap_or_default();
                frame.bones.insert(bone.clone(), input);
            }
            // Bones only: constraints move nothing else.
            let replayed = crate::rig::handle_transforms(handles, frame)?;
            let apart = replayed
                .iter()
                .zip(solved)
                .take(handles.bones.len())
                .flat_map(|(a, b)| {
                    corners
                        .iter()
                        .map(move |&p| (a.apply(p) - b.apply(p)).norm())
                })
                .fold(0.0, f64::max);
            if apart.is_nan() || apart > BAKE_REPLAY_TOLERANCE_PX {
                let names: Vec<&str> = handles.ik.iter().map(|c| c.name.as_str()).collect();
                return Err(PipelineError::BakeBoneIk(names.join(", ")));
            }
        }
    }
    let mut out = keyed_animation(handles, times_s, &baked);
    out.parts = animation.parts.clone();
    out.draw_order = animation.draw_order.clone();
    out.events = animation.events.clone();
    Ok(out)
}

/// An animation with one linear key per time in `times_s` for every bone, point and cage of
/// `handles`, from `poses` (one per time; every handle posed, as
/// [`crate::rig::pose::pose_from_transforms`] gives them). Rotations are unwrapped (each key
/// within 180° of the one before), since runtimes interpolate plain numbers.
pub fn keyed_animation(handles: &Handles, times_s: &[f64], poses: &[Pose]) -> Animation {
    use crate::anim::timeline::{BoneTimelines, Key, PointTimelines};
    let baked = poses;
    // One linear key per frame time.
    let keys = |values: &mut dyn Iterator<Item = [f64; 2]>| -> Option<Vec<Key<[f64; 2]>>> {
        Some(
            times_s
                .iter()
                .zip(values)
                .map(|(&t, v)| linear_key(t, v))
                .collect(),
        )
    };
    // Rotations unwrapped: each key within 180° of the one before.
    let rotations = |values: &mut dyn Iterator<Item = f64>| -> Option<Vec<Key<f64>>> {
        let mut previous: Option<f64> = None;
        Some(
            times_s
                .iter()
                .zip(values)
                .map(|(&t, v)| {
                    let v = match previous {
                        Some(p) => p + ((v - p + 180.0).rem_euclid(360.0) - 180.0),
                        None => v,
                    };
                    previous = Some(v);
                    linear_key(t, v)
                })
                .collect(),
        )
    };
    let mut out = Animation::default();
    for bone in &handles.bones {
        let pose = |k: usize| &baked[k].bones[&bone.name];
        let frames = 0..baked.len();
        out.bones.insert(
            bone.name.clone(),
            BoneTimelines {
                rotate: rotations(&mut frames.clone().map(|k| pose(k).rotate)),
                translate: keys(&mut frames.clone().map(|k| pose(k).translate)),
                scale: keys(&mut frames.clone().map(|k| pose(k).scale)),
                shear: keys(&mut frames.map(|k| pose(k).shear)),
            },
        );
    }
    for point in &handles.points {
        let pose = |k: usize| &baked[k].points[&point.name];
        let frames = 0..baked.len();
        out.points.insert(
            point.name.clone(),
            PointTimelines {
                translate: keys(&mut frames.clone().map(|k| pose(k).translate)),
                rotate: rotations(&mut frames.clone().map(|k| pose(k).rotate)),
                scale: keys(&mut frames.clone().map(|k| pose(k).scale)),
                shear: keys(&mut frames.map(|k| pose(k).shear)),
            },
        );
    }
    for cage in &handles.cages {
        out.cages.insert(
            cage.name.clone(),
            times_s
                .iter()
                .zip(baked)
                .map(|(&t, pose)| linear_key(t, pose.cages[&cage.name].polygon.clone()))
                .collect(),
        );
    }
    out
}

/// The corners of the box around every part's rest mesh (canvas px); the origin alone for a
/// document without vertices.
pub fn rest_corners(doc: &crate::io::RigDocument) -> Vec<crate::geom::Point> {
    use crate::geom::Point;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in doc.parts.iter().flat_map(|p| &p.mesh.vertices) {
        lo = [lo[0].min(v[0]), lo[1].min(v[1])];
        hi = [hi[0].max(v[0]), hi[1].max(v[1])];
    }
    if !lo[0].is_finite() {
        return vec![Point::origin()];
    }
    vec![
        Point::new(lo[0], lo[1]),
        Point::new(hi[0], lo[1]),
        Point::new(hi[0], hi[1]),
        Point::new(lo[0], hi[1]),
    ]
}

fn linear_key<V>(time: f64, value: V) -> crate::anim::timeline::Key<V> {
    crate::anim::timeline::Key {
        time,
        value,
        curve: crate::anim::Curve::Linear,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_durations_and_sizes_are_refused_before_anything_is_allocated() {
        assert_eq!(
            frame_times(1e300, 24.0),
            Err(PlaybackError::TooManyFrames(2.4e301))
        );
        assert!(frame_times(100_000.0 / 24.0, 24.0).is_ok());
        assert!(matches!(
            FrameView::new([64, 64], 1000.0, None, None),
            Err(PlaybackError::TooLarge(..))
        ));
        assert!(matches!(
            FrameView::new([64, 64], 1.0, Some([100_000, 10]), None),
            Err(PlaybackError::TooLarge(..))
        ));
        let view = FrameView::new([64, 64], 1.0, Some([4096, 4096]), None).unwrap();
        // 64 MiB frames, 144 MiB per drawing thread: 20 frames and 4 threads take 1856 MiB.
        let budget = crate::budget::MemoryBudget {
            bytes: 1856 * crate::budget::MIB,
        };
        let four = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        four.install(|| {
            crate::budget::with_memory_budget(budget, || {
                assert!(check_render_memory(20, &view).is_ok());
                let err = check_render_memory(21, &view).unwrap_err();
                assert!(
                    matches!(
                        err,
                        PlaybackError::Budget(crate::budget::BudgetError::OverBudget { .. })
                    ),
                    "{err}"
                );
                assert!(err.to_string().contains("--memory-budget"), "{err}");
            })
        });
        let small = crate::budget::MemoryBudget {
            bytes: 64 * crate::budget::MIB,
        };
        crate::budget::with_memory_budget(small, || {
            assert!(check_pose_memory([4096, 4096]).is_err());
            assert!(check_pose_memory([2048, 2048]).is_ok());
        });
    }

    #[test]
    fn frame_times_stop_before_the_loop_end() {
        let t = frame_times(1.0, 4.0).unwrap();
        assert_eq!(t, vec![0.0, 0.25, 0.5, 0.75]);
        // 1.05 s at 10 fps: the frame at 1.0 s is still inside.
        assert_eq!(frame_times(1.05, 10.0).unwrap().len(), 11);
        // Rounding in duration · fps does not add a frame at the end.
        assert_eq!(frame_times(0.7, 30.0).unwrap().len(), 21);
        assert_eq!(frame_times(0.0, 24.0).unwrap(), vec![0.0]);
        assert_eq!(frame_times(1.0, 0.0), Err(PlaybackError::Fps(0.0)));
        assert!(frame_times(1.0, f64::NAN).is_err());
    }

    #[test]
    fn the_view_centers_the_scaled_canvas() {
        let view = FrameView::new([100, 50], 2.0, None, None).unwrap();
        assert_eq!(view.size_px, [200, 100]);
        let t = view.output_from_canvas([100, 50]);
        let mut p = [tiny_skia::Point::from_xy(50.0, 25.0)];
        t.map_points(&mut p);
        assert_eq!((p[0].x, p[0].y), (100.0, 50.0));
        let padded = FrameView::new([100, 50], 1.0, Some([300, 300]), None).unwrap();
        let mut q = [tiny_skia::Point::from_xy(0.0, 0.0)];
        padded.output_from_canvas([100, 50]).map_points(&mut q);
        assert_eq!((q[0].x, q[0].y), (100.0, 125.0));
        assert_eq!(
            FrameView::new([10, 10], 0.0, None, None),
            Err(PlaybackError::Scale(0.0))
        );
    }
}
