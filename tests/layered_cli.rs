//! `sinew rig` and `sinew autorig` on layered files written by real tools
//! (tests/fixtures/layered, see tools/layered-fixtures/run.sh): the rest pose of the rig
//! renders the tool's own flattened image; bad files are refused with one line, exit code 2,
//! and nothing written.

mod command;

use command::{assert_bad_input, s, scratch, sinew};
use image::RgbaImage;
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/layered")
        .join(name)
}

fn ok(args: &[&str]) -> String {
    let out = sinew(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// PSNR (dB) of premultiplied RGBA over the canvas.
fn psnr(a: &RgbaImage, b: &RgbaImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let pre = |p: &image::Rgba<u8>, c: usize| {
        if c == 3 {
            p[3] as f64
        } else {
            p[c] as f64 * p[3] as f64 / 255.0
        }
    };
    let (mut se, mut n) = (0.0, 0.0);
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..4 {
            se += (pre(p, c) - pre(q, c)).powi(2);
            n += 1.0;
        }
    }
    10.0 * (255.0f64.powi(2) / (se / n).max(1e-12)).log10()
}

/// Autorig, rig with the proposed handles, draw the rest pose: it is the tool's flattening.
fn rest_pose_matches(file: &str, reference: &RgbaImage, name: &str) {
    let tmp = scratch(name);
    let dir = tmp.path();
    let (handles, rig, rest) = (
        dir.join("handles.json"),
        dir.join("rig.json"),
        dir.join("rest.png"),
    );
    let art = fixture(file);
    ok(&["autorig", s(&art), "-o", s(&handles)]);
    let report = ok(&["rig", s(&art), "--handles", s(&handles), "-o", s(&rig)]);
    assert!(
        report.contains("layer 'sketch' is hidden; not a part"),
        "{report}"
    );
    ok(&["pose", s(&rig), "-o", s(&rest)]);
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rig).unwrap()).unwrap();
    let parts: Vec<&str> = doc["parts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        parts,
        ["torso", "arm_l/upper", "arm_l/hand", "head", "leaf"]
    );
    assert!(dir.join("rig.parts/arm_l/hand.png").is_file());
    parts_keep_their_layers_bounds(&art, dir, &doc);
    let rest = image::open(&rest).unwrap().into_rgba8();
    let db = psnr(&rest, reference);
    println!("{file}: rest pose vs the tool's flattened image: PSNR {db:.1} dB");
    assert!(db >= 40.0, "{file}: PSNR {db:.1} dB");
}

/// Each part's image is its layer's opaque pixels, no larger than the layer's bounds, placed at
/// their offset on the canvas (a trimmed layer does not become a canvas-sized texture).
fn parts_keep_their_layers_bounds(art: &Path, dir: &Path, doc: &serde_json::Value) {
    let file = sinew::io::layered::load_layered(art, &Default::default()).unwrap();
    let canvas = file.canvas_px;
    for part in doc["parts"].as_array().unwrap() {
        let name = part["name"].as_str().unwrap();
        let image_path = part["image"].as_str().unwrap();
        assert!(
            image_path.starts_with("rig.parts/"),
            "{name}: image '{image_path}' is not relative to the document's folder"
        );
        let layer = file.layers.iter().find(|l| l.path == name).unwrap();
        let image = image::open(dir.join(part["image"].as_str().unwrap()))
            .unwrap()
            .into_rgba8();
        let (w, h) = image.dimensions();
        let bounds = layer.image.dimensions();
        assert!(
            w <= bounds.0 && h <= bounds.1,
            "{name}: {w}×{h} px image for a layer of {bounds:?} px"
        );
        assert!(
            w < canvas[0] || h < canvas[1],
            "{name}: its image is the whole canvas"
        );
        let offset: Vec<i64> = match part.get("offset_px") {
            Some(o) => o
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_i64().unwrap())
                .collect(),
            None => vec![0, 0],
        };
        assert!(
            offset[0] >= i64::from(layer.offset_px[0])
                && offset[1] >= i64::from(layer.offset_px[1]),
            "{name}: placed at {offset:?}, left of or above its layer at {:?}",
            layer.offset_px
        );
        // Its opaque pixels touch every side of the image: it is trimmed.
        let opaque = |x: u32, y: u32| image.get_pixel(x, y)[3] > 0;
        assert!((0..h).any(|y| opaque(0, y)) && (0..h).any(|y| opaque(w - 1, y)));
        assert!((0..w).any(|x| opaque(x, 0)) && (0..w).any(|x| opaque(x, h - 1)));
    }
}

#[test]
fn psd_rig_rest_pose_renders_psd_tools_composite() {
    let reference = image::open(fixture("character.composite.png"))
        .unwrap()
        .into_rgba8();
    rest_pose_matches("character.psd", &reference, "psd");
}

#[test]
fn krita_ora_rig_rest_pose_renders_kritas_merged_image() {
    let bytes = std::fs::read(fixture("krita.ora")).unwrap();
    let reference = sinew::io::layered::ora::merged_image(&bytes).unwrap();
    rest_pose_matches("krita.ora", &reference, "ora");
}

/// A group's pivot layer (`shoulder [origin]` in `arm_l`) starts the bone of the group's first
/// part there; the next part of the group joins it where they overlap, as without pivots. The
/// group's name gives the side, so the bones take the template's names (`arm_l/upper` is
/// `arm_upper_l`, `arm_l/forearm` is `arm_lower_l`).
#[test]
fn a_groups_pivot_layer_is_where_its_first_bone_starts() {
    let tmp = scratch("pivots");
    let dir = tmp.path();
    let handles = dir.join("handles.json");
    ok(&["autorig", s(&fixture("pivots.psd")), "-o", s(&handles)]);
    let proposal: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&handles).unwrap()).unwrap();
    let head = |name: &str| -> [f64; 2] {
        let bone = proposal["bones"]
            .as_array()
            .unwrap()
            .iter()
            .find(|b| b["name"] == name)
            .unwrap_or_else(|| panic!("no bone '{name}' in {proposal}"));
        [0, 1].map(|k| bone["head"][k].as_f64().unwrap())
    };
    let distance = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    // The dot's centre: pixels 74..78 × 49..53.
    let pivot = [76.0, 51.0];
    let upper = head("arm_upper_l");
    assert!(
        distance(upper, pivot) < 1.0,
        "the upper arm starts at {upper:?}, not at the pivot {pivot:?}"
    );
    // The forearm hangs from the upper arm where they overlap (x 100..112, y 50..58).
    let forearm = head("arm_lower_l");
    assert!(
        distance(forearm, pivot) > 20.0 && (99.0..=113.0).contains(&forearm[0]),
        "the forearm starts at {forearm:?}"
    );
}

#[test]
fn bad_layered_files_are_refused_and_nothing_is_written() {
    let tmp = scratch("bad");
    let dir = tmp.path();
    let rig = dir.join("rig.json");
    let cut = dir.join("cut.psd");
    let bytes = std::fs::read(fixture("character.psd")).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).unwrap();
    assert_bad_input(&["rig", s(&cut), "-o", s(&rig)], "truncated");
    assert_bad_input(&["rig", s(&fixture("deep16.psd")), "-o", s(&rig)], "16-bit");
    assert_bad_input(&["rig", s(&fixture("cmyk.psd")), "-o", s(&rig)], "CMYK");
    let no_stack = dir.join("empty.ora");
    std::fs::write(&no_stack, b"PK\x05\x06\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0").unwrap();
    assert_bad_input(&["autorig", s(&no_stack), "-o", s(&rig)], "stack.xml");
    let entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(entries.len(), 2, "{entries:?}");
}
