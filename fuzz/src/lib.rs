//! One function per fuzz target: bytes in, anything but a panic out. Each reader must turn any
//! input into a value or an error; whatever it accepts is then used the way the commands use it
//! (checked against a rig, posed, sampled, traced and meshed), so a value that passes the
//! checks but breaks a later stage is found too. The bins under `src/bin/` feed these to AFL++;
//! `tests/replay.rs` runs them over the seed corpus with plain `cargo test`.

use sinew::anim;
use sinew::io::RigDocument;
use sinew::rig::{handle_transforms, Handles, Pose};
use std::path::Path;

/// The bundled character's handles: the rig poses and animations are checked against.
pub const CHARACTER_HANDLES: &str = include_str!("../../assets/character/handles.json");

/// Largest image the PNG target traces, px (width × height): bigger inputs only cost time.
pub const MAX_FUZZ_IMAGE_PX: u64 = 512 * 512;

fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

fn character() -> Handles {
    serde_json::from_str(CHARACTER_HANDLES).expect("the bundled handles parse")
}

/// A rig document: read, checked, its animations checked against it and sampled.
pub fn rig_document(data: &[u8]) {
    let Some(text) = text(data) else { return };
    let Ok(doc) = RigDocument::from_json(text, Path::new("fuzz.json")) else {
        return;
    };
    let _ = doc.validate();
    if doc.check_animations().is_ok() {
        for animation in doc.animations.values() {
            sample(&doc.handles, animation);
        }
    }
    let _ = handle_transforms(&doc.handles, &Pose::default());
}

/// A handles file: parsed, validated, posed at rest.
pub fn handles(data: &[u8]) {
    let Ok(h) = serde_json::from_slice::<Handles>(data) else {
        return;
    };
    if h.validate().is_ok() {
        let _ = handle_transforms(&h, &Pose::default());
        let _ = sinew::rig::handle_columns(&h);
    }
}

/// A pose file: parsed and posed on the bundled character's handles.
pub fn pose(data: &[u8]) {
    let Ok(pose) = serde_json::from_slice::<Pose>(data) else {
        return;
    };
    let _ = pose.check_values();
    let _ = handle_transforms(&character(), &pose);
}

/// An animations file (name → animation): parsed, checked against the character, sampled.
pub fn animations(data: &[u8]) {
    let Ok(value) = serde_json::from_slice::<serde_json::Value>(data) else {
        return;
    };
    let Ok(animations) = anim::animations_from_json(&value) else {
        return;
    };
    let handles = character();
    let parts: Vec<&str> = Vec::new();
    let _ = anim::check_animations(&animations, &handles, &parts, &Default::default());
    for animation in animations.values() {
        sample(&handles, animation);
    }
}

/// Samples an animation at its start, middle, end and past it, and poses what it gives.
fn sample(handles: &Handles, animation: &anim::Animation) {
    let d = animation.duration_s();
    for t in [0.0, d * 0.37, d, d * 1.5 + 0.1] {
        let pose = animation.sample(t, true);
        let _ = handle_transforms(handles, &pose);
    }
}

/// A scribble file rasterized on a 64 × 64 canvas.
pub fn scribbles(data: &[u8]) {
    let Some(text) = text(data) else { return };
    let _ = sinew::colorize::Scribbles::from_json(text, 64, 64, &Default::default());
}

/// A PNG: decoded, traced and meshed, as `sinew rig` does with a layer.
pub fn png_trace_mesh(data: &[u8]) {
    let Ok(reader) = image::ImageReader::with_format(std::io::Cursor::new(data), image::ImageFormat::Png)
        .into_dimensions()
    else {
        return;
    };
    if u64::from(reader.0) * u64::from(reader.1) > MAX_FUZZ_IMAGE_PX {
        return;
    }
    let Ok(img) = image::load_from_memory_with_format(data, image::ImageFormat::Png) else {
        return;
    };
    let img = img.into_rgba8();
    let Ok(outlines) = sinew::trace::trace(&img, &Default::default()) else {
        return;
    };
    let area = f64::from(img.width()) * f64::from(img.height());
    let _ = sinew::mesh::triangulate(&outlines, area, &Default::default());
}

/// A BVH motion-capture file: parsed with the default limits; what parses is posed by forward
/// kinematics at rest and at its first, middle and last frames.
pub fn bvh(data: &[u8]) {
    let Ok(clip) = sinew::motion::parse(data, &Default::default()) else {
        return;
    };
    let _ = sinew::motion::rest_positions(&clip);
    let last = clip.frame_count().saturating_sub(1);
    for f in [0, last / 2, last, last + 1] {
        let _ = sinew::motion::frame_positions(&clip, f);
    }
}

/// Every target by name, for the replay test and the run script.
pub const TARGETS: [(&str, fn(&[u8])); 7] = [
    ("rig_document", rig_document),
    ("handles", handles),
    ("pose", pose),
    ("animations", animations),
    ("scribbles", scribbles),
    ("png_trace_mesh", png_trace_mesh),
    ("bvh", bvh),
];
