//! One function per fuzz target: bytes in, anything but a panic out. Each reader must turn any
//! input into a value or an error; whatever it accepts is then used the way the commands use it
//! (checked against a rig, posed, sampled, traced and meshed; a layered file's layers cut into
//! part images; a manifest planned), so a value that passes the checks but breaks a later stage
//! is found too. The bins under `src/bin/` feed these to AFL++;
//! `tests/replay.rs` runs them over the seed corpus with plain `cargo test`.

use sinew::anim;
use sinew::io::layered::{self, LayeredImage, LayeredLimits};
use sinew::io::RigDocument;
use sinew::rig::{handle_transforms, Handles, Pose};
use std::io::{Read, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::OnceLock;

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
    let Ok(reader) =
        image::ImageReader::with_format(std::io::Cursor::new(data), image::ImageFormat::Png)
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

/// The limits the layered targets read with: small, so one execution stays fast (the seeds
/// are at most 160 × 120 px).
pub fn fuzz_limits() -> LayeredLimits {
    LayeredLimits {
        max_side_px: 2048,
        max_total_px: 1 << 22,
        max_layers: 256,
        max_depth: 32,
        max_file_bytes: 1 << 20,
        max_entry_bytes: 1 << 22,
    }
}

/// A layered file as `sinew rig` uses it: every visible layer cut to the canvas as a part
/// image, whose file under `RIG.parts/` must stay inside that folder; the visible layers
/// flattened (as the preview and the tests do).
fn use_layered(image: &LayeredImage) {
    let parts = Path::new("parts");
    for layer in &image.layers {
        let file = sinew::art::part_image_path(parts, &layer.path);
        assert!(
            file.strip_prefix(parts)
                .is_ok_and(|rest| rest.components().all(|c| matches!(c, Component::Normal(_)))),
            "layer '{}': part image {} leaves its folder",
            layer.path,
            file.display()
        );
        assert!(
            layer.opacity.is_finite(),
            "layer '{}': opacity {}",
            layer.path,
            layer.opacity
        );
        if !layer.visible {
            continue;
        }
        if let Some((part, offset)) = layered::part_image(layer, image.canvas_px) {
            let [w, h] = image.canvas_px.map(i64::from);
            assert!(
                offset[0] >= 0
                    && offset[1] >= 0
                    && i64::from(offset[0]) + i64::from(part.width()) <= w
                    && i64::from(offset[1]) + i64::from(part.height()) <= h,
                "layer '{}': part image {}×{} at {offset:?} is not on the {w}×{h} canvas",
                layer.path,
                part.width(),
                part.height()
            );
        }
    }
    let _ = layered::composite(image);
    let _ = image.warnings.join("\n");
}

/// A Photoshop document (PSD or PSB): read with [`fuzz_limits`], then used as
/// [`use_layered`] says.
pub fn psd(data: &[u8]) {
    psd_read(data);
}

/// [`psd`], saying whether the input was read (and used).
pub fn psd_read(data: &[u8]) -> bool {
    let read = layered::psd::parse(data, &fuzz_limits());
    read.as_ref().map(use_layered).is_ok()
}

/// The layers of the OpenRaster target's zip when the input is its `stack.xml`: the PNGs of
/// tests/fixtures/layered/krita.ora (`data/layer0.png` … `data/layer6.png`).
const ORA_FIXTURE: &[u8] = include_bytes!("../../tests/fixtures/layered/krita.ora");

fn ora_layers() -> &'static [(String, Vec<u8>)] {
    static LAYERS: OnceLock<Vec<(String, Vec<u8>)>> = OnceLock::new();
    LAYERS.get_or_init(|| {
        let mut zip = zip::ZipArchive::new(std::io::Cursor::new(ORA_FIXTURE))
            .expect("the ORA fixture is a zip");
        let mut out = Vec::new();
        for i in 0..zip.len() {
            let mut entry = zip.by_index(i).expect("the ORA fixture's entries read");
            let name = entry.name().map(|n| n.to_string()).unwrap_or_default();
            if name.ends_with(".png") && name.starts_with("data/") {
                let mut bytes = Vec::new();
                entry
                    .read_to_end(&mut bytes)
                    .expect("the ORA fixture's PNGs read");
                out.push((name, bytes));
            }
        }
        out
    })
}

/// An OpenRaster file. An input that starts as a zip (`PK`) is the file itself; any other
/// input is its `stack.xml`, zipped (stored, with correct CRCs) with the PNG layers of
/// krita.ora, so the mutations reach the stack's reading instead of failing the zip's
/// checksums. Read with [`fuzz_limits`], then used as [`use_layered`] says.
pub fn ora(data: &[u8]) {
    ora_read(data);
}

/// [`ora`], saying whether the input was read (and used).
pub fn ora_read(data: &[u8]) -> bool {
    let zipped;
    let bytes = if data.starts_with(b"PK") {
        data
    } else {
        zipped = ora_zip(data);
        &zipped
    };
    let read = layered::ora::parse(bytes, &fuzz_limits());
    read.as_ref().map(use_layered).is_ok()
}

/// An ORA zip of `stack` and the fixture's PNG layers, entries stored.
pub fn ora_zip(stack: &[u8]) -> Vec<u8> {
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let stored =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let mut add = |name: &str, bytes: &[u8]| {
        out.start_file(name, stored).expect("a zip entry starts");
        out.write_all(bytes).expect("a zip entry is written");
    };
    add("mimetype", b"image/openraster");
    add("stack.xml", stack);
    for (name, png) in ora_layers() {
        add(name, png);
    }
    out.finish().expect("the zip is finished").into_inner()
}

/// A folder of its own for a target that reads or plans files (under `fuzz/out/scratch/`),
/// made once with `files` (path, bytes) in it.
fn scratch(name: &str, files: &[(&str, &[u8])]) -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("out/scratch")
        .join(name);
    for (path, bytes) in files {
        let path = dir.join(path);
        std::fs::create_dir_all(path.parent().expect("a file in a folder"))
            .expect("the scratch folder is made");
        if std::fs::read(&path).ok().as_deref() != Some(*bytes) {
            std::fs::write(&path, bytes).expect("a scratch file is written");
        }
    }
    std::fs::canonicalize(&dir).expect("the scratch folder exists")
}

/// The Spine-script target's folder: the trimmed PNGs of tests/fixtures/layered/spine
/// (`torso`, `upper`, `hand`, `head`, `leaf`).
pub fn spine_folder() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        macro_rules! png {
            ($name:literal) => {
                (
                    concat!($name, ".png"),
                    &include_bytes!(concat!(
                        "../../tests/fixtures/layered/spine/",
                        $name,
                        ".png"
                    ))[..],
                )
            };
        }
        scratch(
            "spine_script",
            &[
                png!("torso"),
                png!("upper"),
                png!("hand"),
                png!("head"),
                png!("leaf"),
            ],
        )
    })
}

/// A Spine-script skeleton JSON in a folder of trimmed PNGs ([`spine_folder`]): read with
/// [`fuzz_limits`], then used as [`use_layered`] says.
pub fn spine_script(data: &[u8]) {
    spine_script_read(data);
}

/// [`spine_script`], saying whether the input was read (and used).
pub fn spine_script_read(data: &[u8]) -> bool {
    let read = layered::spine_json::parse(data, spine_folder(), &fuzz_limits());
    read.as_ref().map(use_layered).is_ok()
}

/// A rig document naming part images: the one of docs/formats.md.
const MANIFEST_RIG: &str = r#"{"format": "sinew-rig", "version": 1, "canvas": [64, 64],
 "parts": [{"name": "arm", "image": "arm.png",
   "mesh": {"vertices": [[8, 24], [56, 24], [56, 40]], "triangles": [[0, 1, 2]]},
   "weights": {"handles": ["upper"], "rows": [[[0, 1.0]], [[0, 1.0]], [[0, 1.0]]]}}],
 "handles": {"bones": [{"name": "upper", "head": [8, 32], "tail": [56, 32]}]}}"#;

/// The batch target's folder: the inputs the manifest example of docs/formats.md names
/// (`art/torso.png`, `art/head.png`, `art/handles.json`, `rigs/hero.json`, `ink/001.png`,
/// `ink/001.json`), and the manifest itself, `manifest.PID.json`, rewritten by each execution
/// (named by the process that made the folder, which AFL++ forks: a replay test beside a fuzz
/// run writes its own).
pub fn batch_folder() -> &'static Path {
    batch_paths().0.as_path()
}

fn batch_paths() -> &'static (PathBuf, PathBuf) {
    static PATHS: OnceLock<(PathBuf, PathBuf)> = OnceLock::new();
    PATHS.get_or_init(|| {
        let png: &[u8] = include_bytes!("../../tests/fixtures/layered/spine/hand.png");
        let dir = scratch(
            "batch_manifest",
            &[
                ("art/torso.png", png),
                ("art/head.png", png),
                ("art/handles.json", CHARACTER_HANDLES.as_bytes()),
                ("rigs/hero.json", MANIFEST_RIG.as_bytes()),
                ("rigs/arm.png", png),
                ("ink/001.png", png),
                ("ink/001.json", b"{}"),
            ],
        );
        let manifest = dir.join(format!("manifest.{}.json", std::process::id()));
        (dir, manifest)
    })
}

/// A batch manifest, as `sinew batch` reads it: written as `manifest.json` in
/// [`batch_folder`] and loaded (parsed, every path confined, planned). A plan's every input and
/// output must lie inside the folder, and every job's options must give the library's.
pub fn batch_manifest(data: &[u8]) {
    batch_manifest_read(data);
}

/// [`batch_manifest`], saying whether the manifest was planned.
pub fn batch_manifest_read(data: &[u8]) -> bool {
    let (dir, path) = batch_paths();
    std::fs::write(path, data).expect("the manifest is written");
    let Ok(plan) = sinew::batch::load(path) else {
        return false;
    };
    for job in &plan.jobs {
        let paths = job
            .inputs()
            .into_iter()
            .chain(job.outputs().into_iter().map(|o| o.path));
        for p in paths {
            let file = sinew::batch::plan::absolute(&plan.root, &p);
            assert!(
                file.starts_with(dir) && file.as_path() != dir.as_path(),
                "job '{}': {} is not inside the manifest's folder {}",
                job.name(),
                p.display(),
                dir.display()
            );
        }
        match job {
            sinew::batch::Job::Render(j) => {
                j.options.settings().expect("a planned render's settings");
            }
            sinew::batch::Job::Export(j) => {
                j.options.spine().expect("a planned export's options");
            }
            _ => {}
        }
    }
    true
}

/// The targets whose seeds the replay test checks are read, by name: each says whether the
/// input was read.
pub const READERS: [(&str, fn(&[u8]) -> bool); 4] = [
    ("psd", psd_read),
    ("ora", ora_read),
    ("spine_script", spine_script_read),
    ("batch_manifest", batch_manifest_read),
];

/// Every target by name, for the replay test and the run script.
pub const TARGETS: [(&str, fn(&[u8])); 11] = [
    ("rig_document", rig_document),
    ("handles", handles),
    ("pose", pose),
    ("animations", animations),
    ("scribbles", scribbles),
    ("png_trace_mesh", png_trace_mesh),
    ("bvh", bvh),
    ("psd", psd),
    ("ora", ora),
    ("spine_script", spine_script),
    ("batch_manifest", batch_manifest),
];
