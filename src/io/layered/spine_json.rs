//! Trimmed PNGs with their positions, as Spine's export scripts write them (PhotoshopToSpine,
//! GimpToSpine, the Krita and Affinity scripts): a skeleton JSON whose slots hold region
//! attachments (centre `x`, `y` and `width`, `height`, Spine units = px, y up, relative to
//! their bone) next to a folder of trimmed PNGs.
//!
//! In: the JSON's path (the PNGs are found under `skeleton.images`, relative to the JSON's
//! folder, named after each attachment's `path` or name). Out: the raw layers for
//! [`build_layers`], back to front in slot order, on the canvas that bounds them all (the
//! scripts do not record the document's size). Slots with no setup attachment are hidden
//! layers. Bones may translate; bones or attachments that rotate or scale are refused, as are
//! attachments other than regions (skipped with a warning).

use super::tree::{build_layers, RawLayer, RawNode};
use super::{check_size, read_limited, BlendMode, LayeredError, LayeredImage, LayeredLimits};
use crate::geom::{Point, Vec2};
use image::codecs::png::PngDecoder;
use image::{DynamicImage, ImageDecoder};
use serde_json::Value;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::Path;

fn bad(reason: impl Into<String>) -> LayeredError {
    LayeredError::Malformed(reason.into())
}

/// Reads a Spine skeleton JSON of region attachments and the PNGs it names.
pub fn load(path: &Path, limits: &LayeredLimits) -> Result<LayeredImage, LayeredError> {
    let bytes = read_limited(path, limits)?;
    parse(&bytes, path.parent().unwrap_or(Path::new("")), limits)
}

/// Reads the bytes of a Spine skeleton JSON whose file lies in `dir`, and the PNGs it names
/// (confined to `dir`).
pub fn parse(
    bytes: &[u8],
    dir: &Path,
    limits: &LayeredLimits,
) -> Result<LayeredImage, LayeredError> {
    let json: Value = serde_json::from_slice(bytes)
        .map_err(|e| bad(format!("not a Spine skeleton JSON: {e}")))?;
    // The PNGs lie in the JSON's folder: `skeleton.images` and every attachment's file name
    // are confined to it (a script's JSON from a stranger reads nothing outside).
    let images = Path::new(
        json.pointer("/skeleton/images")
            .and_then(Value::as_str)
            .unwrap_or(""),
    )
    .to_path_buf();
    let confine = |field: String, file: &Path| {
        crate::io::confine::confined_from(dir_or_dot(dir), &images, file).map_err(|problem| {
            LayeredError::Entry {
                entry: field,
                reason: problem.to_string(),
            }
        })
    };
    if !images.as_os_str().is_empty() {
        crate::io::confine::confined(dir_or_dot(dir), &images).map_err(|problem| {
            LayeredError::Entry {
                entry: "\"skeleton\".\"images\"".into(),
                reason: problem.to_string(),
            }
        })?;
    }
    let bones = bone_positions(&json)?;
    let skin = default_skin(&json)?;
    let slots = json
        .get("slots")
        .and_then(Value::as_array)
        .ok_or_else(|| bad("no \"slots\" array: not a Spine skeleton"))?;
    let mut warnings = Vec::new();
    struct Placed {
        name: String,
        visible: bool,
        center: Point,
        image: image::RgbaImage,
    }
    let mut placed = Vec::new();
    let mut total_px = 0;
    for slot in slots {
        let slot_name = slot.get("name").and_then(Value::as_str).unwrap_or("");
        let bone = slot.get("bone").and_then(Value::as_str).unwrap_or("root");
        let bone_at = *bones
            .get(bone)
            .ok_or_else(|| bad(format!("slot '{slot_name}': unknown bone '{bone}'")))?;
        let Some(attachments) = skin.get(slot_name).and_then(Value::as_object) else {
            continue;
        };
        let setup = slot.get("attachment").and_then(Value::as_str);
        let (name, att) = match setup.and_then(|s| attachments.get_key_value(s)) {
            Some(found) => found,
            None => match attachments.iter().next() {
                Some(first) => first,
                None => continue,
            },
        };
        let visible = setup == Some(name.as_str());
        let kind = att.get("type").and_then(Value::as_str).unwrap_or("region");
        if kind != "region" {
            warnings.push(format!(
                "attachment '{name}': {kind} attachments are not read; skipped"
            ));
            continue;
        }
        let f = |k: &str, default: f64| att.get(k).and_then(Value::as_f64).unwrap_or(default);
        if f("rotation", 0.0) != 0.0 || f("scaleX", 1.0) != 1.0 || f("scaleY", 1.0) != 1.0 {
            return Err(LayeredError::Unsupported(format!(
                "attachment '{name}' is rotated or scaled; sinew reads unrotated, unscaled regions"
            )));
        }
        let file = att.get("path").and_then(Value::as_str).unwrap_or(name);
        let png = confine(
            match att.get("path") {
                Some(_) => format!("attachment '{name}' (slot '{slot_name}'): \"path\""),
                None => format!("attachment '{name}' (slot '{slot_name}'): its name"),
            },
            Path::new(&format!("{file}.png")),
        )?;
        let image = load_png(&png, limits, &mut total_px)?;
        let (w, h) = (
            f("width", image.width() as f64),
            f("height", image.height() as f64),
        );
        if (w - image.width() as f64).abs() > 0.5 || (h - image.height() as f64).abs() > 0.5 {
            warnings.push(format!(
                "attachment '{name}': {w}×{h} in the JSON but {}×{} px in {}; placed by its centre",
                image.width(),
                image.height(),
                png.display()
            ));
        }
        placed.push(Placed {
            name: name.clone(),
            visible,
            center: bone_at + Vec2::new(f("x", 0.0), f("y", 0.0)),
            image,
        });
    }
    // Top-left corners in y-down px: the scripts write centres either exactly (Photoshop:
    // `left + width / 2`) or floored (GIMP: `left + floor(width / 2)`); flooring the corner
    // plus half a pixel recovers the integer corner from both.
    let corner = |p: &Placed| {
        let (w, h) = (p.image.width() as f64, p.image.height() as f64);
        [
            (p.center.x - w / 2.0 + 0.5).floor(),
            (-p.center.y - h / 2.0 + 0.5).floor(),
        ]
    };
    if placed.is_empty() {
        return Err(LayeredError::NoLayers);
    }
    let extent = |axis: usize, size: fn(&Placed) -> u32| {
        let from = placed
            .iter()
            .map(|p| corner(p)[axis])
            .fold(f64::INFINITY, f64::min);
        let to = placed
            .iter()
            .map(|p| corner(p)[axis] + f64::from(size(p)))
            .fold(f64::NEG_INFINITY, f64::max);
        (from, to - from)
    };
    let (left, width) = extent(0, |p| p.image.width());
    let (top, height) = extent(1, |p| p.image.height());
    // The canvas is checked before any position becomes an integer: bones and attachments
    // far apart (or past what an f64 holds) make a canvas too large, not a wrong one.
    if !(width.is_finite() && height.is_finite()) {
        return Err(bad(
            "attachment positions (with their bones') are too large to place",
        ));
    }
    let canvas = [width, height].map(|v| v.min(u64::MAX as f64) as u64);
    check_size("the canvas", canvas, &mut 0, limits)?;
    let size = canvas.map(|v| v as u32);
    let mut nodes = Vec::new();
    for p in placed {
        let [l, t] = corner(&p);
        // Within [0, the canvas's side]: checked above.
        let offset_px = [(l - left) as i32, (t - top) as i32];
        nodes.push(RawNode::Layer(RawLayer {
            name: p.name,
            offset_px,
            image: p.image,
            opacity: 1.0,
            visible: p.visible,
            blend: BlendMode::Normal,
            clipped: false,
        }));
    }
    build_layers(size, nodes, warnings, limits)
}

/// The folder a path without one names: `.`.
fn dir_or_dot(dir: &Path) -> &Path {
    if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    }
}

/// Each bone's world position (the sum of its and its parents' `x`, `y`).
fn bone_positions(json: &Value) -> Result<HashMap<String, Point>, LayeredError> {
    let mut at: HashMap<String, Point> = HashMap::new();
    let bones = json
        .get("bones")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    // Spine lists parents before children.
    for bone in &bones {
        let name = bone
            .get("name")
            .and_then(Value::as_str)
            .ok_or_else(|| bad("a bone without a name"))?;
        let f = |k: &str, d: f64| bone.get(k).and_then(Value::as_f64).unwrap_or(d);
        if f("rotation", 0.0) != 0.0 || f("scaleX", 1.0) != 1.0 || f("scaleY", 1.0) != 1.0 {
            return Err(LayeredError::Unsupported(format!(
                "bone '{name}' is rotated or scaled; sinew reads bones that only translate"
            )));
        }
        let base = match bone.get("parent").and_then(Value::as_str) {
            Some(p) => *at
                .get(p)
                .ok_or_else(|| bad(format!("bone '{name}': parent '{p}' not listed before it")))?,
            None => Point::origin(),
        };
        at.insert(name.to_string(), base + Vec2::new(f("x", 0.0), f("y", 0.0)));
    }
    at.entry("root".into()).or_insert_with(Point::origin);
    Ok(at)
}

/// The default skin's slot → attachments map (Spine 3.8+'s array of skins or the older
/// object of skins).
fn default_skin(json: &Value) -> Result<serde_json::Map<String, Value>, LayeredError> {
    let skins = json
        .get("skins")
        .ok_or_else(|| bad("no \"skins\": not a Spine skeleton"))?;
    let found = match skins {
        Value::Array(list) => list
            .iter()
            .find(|s| s.get("name").and_then(Value::as_str) == Some("default"))
            .or(list.first())
            .and_then(|s| s.get("attachments")),
        Value::Object(map) => map.get("default").or(map.values().next()),
        _ => None,
    };
    found
        .and_then(Value::as_object)
        .cloned()
        .ok_or_else(|| bad("no skin with attachments"))
}

fn load_png(
    path: &Path,
    limits: &LayeredLimits,
    total_px: &mut u64,
) -> Result<image::RgbaImage, LayeredError> {
    let entry = |reason: String| LayeredError::Entry {
        entry: path.display().to_string(),
        reason,
    };
    let bytes = read_limited(path, limits).map_err(|e| entry(e.to_string()))?;
    let decoder = PngDecoder::new(Cursor::new(&bytes))
        .map_err(|e| entry(format!("cannot decode PNG: {e}")))?;
    let (w, h) = decoder.dimensions();
    check_size(
        &path.display().to_string(),
        [w as u64, h as u64],
        total_px,
        limits,
    )?;
    Ok(DynamicImage::from_decoder(decoder)
        .map_err(|e| entry(format!("cannot decode PNG: {e}")))?
        .into_rgba8())
}
