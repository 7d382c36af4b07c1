//! OpenRaster (`.ora`, written by Krita, GIMP and MyPaint): a zip of `stack.xml` and one PNG
//! per layer.
//!
//! In: the file's bytes. Out: the raw layer tree for [`build_layers`]: `<stack>`s become
//! groups, `<layer>`s pixel layers at their `x`/`y` (canvas px; a nested stack's `x`/`y` are
//! added to its children's), with `opacity`, `visibility` and `composite-op`. In `stack.xml`
//! the first child is the topmost; the tree built is back to front. Zip entries are read only
//! up to [`LayeredLimits::max_entry_bytes`] whatever they declare, and PNG sizes are checked
//! before decoding. Specification: <https://www.openraster.org/baseline/file-layout-spec.html>.

use super::tree::{build_layers, RawLayer, RawNode};
use super::{
    check_limit, check_size, BlendMode, LayeredError, LayeredImage, LayeredLimits, MAX_OFFSET_PX,
};
use image::codecs::png::PngDecoder;
use image::{DynamicImage, ImageDecoder, RgbaImage};
use quick_xml::events::{BytesStart, Event};
use std::io::{Cursor, Read};

type Archive<'a> = zip::ZipArchive<Cursor<&'a [u8]>>;

/// Reads an OpenRaster file.
pub fn parse(bytes: &[u8], limits: &LayeredLimits) -> Result<LayeredImage, LayeredError> {
    let mut zip = open(bytes, limits)?;
    let xml = entry(&mut zip, "stack.xml", limits)?;
    let mut warnings = Vec::new();
    let mut total_px = 0;
    let (canvas, nodes) = read_stack(&xml, &mut zip, limits, &mut total_px, &mut warnings)?;
    build_layers(canvas, nodes, warnings, limits)
}

/// The file's own flattened image, `mergedimage.png` (what the writing tool composited).
pub fn merged_image(bytes: &[u8]) -> Result<RgbaImage, LayeredError> {
    let limits = LayeredLimits::default();
    let mut zip = open(bytes, &limits)?;
    let png = entry(&mut zip, "mergedimage.png", &limits)?;
    decode_png(&png, "mergedimage.png", &limits, &mut 0)
}

fn open<'a>(bytes: &'a [u8], limits: &LayeredLimits) -> Result<Archive<'a>, LayeredError> {
    if !bytes.starts_with(b"PK") {
        return Err(LayeredError::NotFormat {
            expected: "an OpenRaster file (a zip archive)",
        });
    }
    let zip =
        zip::ZipArchive::new(Cursor::new(bytes)).map_err(|e| LayeredError::Zip(e.to_string()))?;
    check_limit(
        "the zip",
        zip.len() as u64,
        limits.max_layers as u64 + 16,
        "entries",
    )?;
    Ok(zip)
}

/// The bytes of entry `name`, at most [`LayeredLimits::max_entry_bytes`] of them.
fn entry(zip: &mut Archive, name: &str, limits: &LayeredLimits) -> Result<Vec<u8>, LayeredError> {
    let bad = |reason: String| LayeredError::Entry {
        entry: name.to_string(),
        reason,
    };
    let mut file = zip.by_name(name).map_err(|e| match e {
        zip::result::ZipError::FileNotFound => bad("missing: not an OpenRaster file".into()),
        e => bad(e.to_string()),
    })?;
    let limit = limits.max_entry_bytes;
    check_limit(&format!("entry {name}"), file.size(), limit, "bytes")?;
    // The declared size is only a claim: reserve at most 1 MiB for it (a 100-byte zip may
    // declare 1 GiB), and let the buffer grow with what is really there.
    let mut out = Vec::with_capacity(file.size().min(1 << 20) as usize);
    (&mut file)
        .take(limit + 1)
        .read_to_end(&mut out)
        .map_err(|e| bad(e.to_string()))?;
    check_limit(&format!("entry {name}"), out.len() as u64, limit, "bytes")?;
    Ok(out)
}

fn decode_png(
    bytes: &[u8],
    name: &str,
    limits: &LayeredLimits,
    total_px: &mut u64,
) -> Result<RgbaImage, LayeredError> {
    let bad = |e: image::ImageError| LayeredError::Entry {
        entry: name.to_string(),
        reason: format!("cannot decode PNG: {e}"),
    };
    let decoder = PngDecoder::new(Cursor::new(bytes)).map_err(bad)?;
    let (w, h) = decoder.dimensions();
    check_size(name, [w as u64, h as u64], total_px, limits)?;
    Ok(DynamicImage::from_decoder(decoder)
        .map_err(bad)?
        .into_rgba8())
}

/// A `<stack>` being read: its attributes and children so far (top first, as in the file).
struct Frame {
    name: String,
    visible: bool,
    opacity: f32,
    offset_px: [i32; 2],
    children: Vec<RawNode>,
}

fn xml_error(e: impl std::fmt::Display) -> LayeredError {
    LayeredError::Entry {
        entry: "stack.xml".into(),
        reason: e.to_string(),
    }
}

/// The attributes of an element as (name, unescaped value) pairs.
fn attributes(e: &BytesStart) -> Result<Vec<(String, String)>, LayeredError> {
    e.attributes()
        .map(|a| {
            let a = a.map_err(xml_error)?;
            let value = a
                .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                .map_err(xml_error)?
                .into_owned();
            Ok((String::from_utf8_lossy(a.key.as_ref()).into_owned(), value))
        })
        .collect()
}

fn attr<'a>(attrs: &'a [(String, String)], key: &str) -> Option<&'a str> {
    attrs
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

fn number<T: std::str::FromStr>(
    attrs: &[(String, String)],
    key: &str,
    default: T,
) -> Result<T, LayeredError> {
    match attr(attrs, key) {
        None => Ok(default),
        Some(v) => v
            .trim()
            .parse()
            .map_err(|_| xml_error(format!("attribute {key}=\"{v}\" is not a number"))),
    }
}

fn blend(op: Option<&str>) -> BlendMode {
    match op.unwrap_or("svg:src-over") {
        "svg:src-over" => BlendMode::Normal,
        "svg:multiply" => BlendMode::Multiply,
        "svg:screen" => BlendMode::Screen,
        "svg:overlay" => BlendMode::Overlay,
        "svg:darken" => BlendMode::Darken,
        "svg:lighten" => BlendMode::Lighten,
        "svg:plus" => BlendMode::Add,
        other => BlendMode::Other(other.to_string()),
    }
}

/// The `opacity` attribute, in [0, 1] (`nan` and infinities refused).
fn opacity(attrs: &[(String, String)]) -> Result<f32, LayeredError> {
    let v: f32 = number(attrs, "opacity", 1.0)?;
    if !v.is_finite() {
        return Err(xml_error(format!(
            "attribute opacity=\"{v}\" is not a finite number"
        )));
    }
    Ok(v.clamp(0.0, 1.0))
}

/// The `x`, `y` attributes added to the enclosing stack's position: canvas px, within
/// ±[`MAX_OFFSET_PX`] (far past any canvas, so sizes added to it stay in range).
fn position(attrs: &[(String, String)], base: [i32; 2]) -> Result<[i32; 2], LayeredError> {
    let mut at = base;
    for (i, key) in ["x", "y"].into_iter().enumerate() {
        let v = i64::from(base[i]) + i64::from(number(attrs, key, 0i32)?);
        if v.abs() > i64::from(MAX_OFFSET_PX) {
            return Err(xml_error(format!(
                "{key} = {v} px with its stacks': sinew reads positions within ±{MAX_OFFSET_PX} px"
            )));
        }
        at[i] = v as i32;
    }
    Ok(at)
}

fn frame(attrs: &[(String, String)], parent: Option<&Frame>) -> Result<Frame, LayeredError> {
    let base = parent.map_or([0, 0], |p| p.offset_px);
    Ok(Frame {
        name: attr(attrs, "name").unwrap_or("group").to_string(),
        visible: attr(attrs, "visibility") != Some("hidden"),
        opacity: opacity(attrs)?,
        offset_px: position(attrs, base)?,
        children: Vec::new(),
    })
}

/// Parses `stack.xml`, reading each layer's PNG from `zip`: the canvas size and the tree.
fn read_stack(
    xml: &[u8],
    zip: &mut Archive,
    limits: &LayeredLimits,
    total_px: &mut u64,
    warnings: &mut Vec<String>,
) -> Result<([u32; 2], Vec<RawNode>), LayeredError> {
    let mut reader = quick_xml::Reader::from_reader(xml);
    let mut canvas: Option<[u32; 2]> = None;
    let mut stack: Vec<Frame> = Vec::new();
    let mut root: Option<Vec<RawNode>> = None;
    let mut count = 0usize;
    let mut buf = Vec::new();
    loop {
        let event = reader.read_event_into(&mut buf).map_err(xml_error)?;
        let (element, empty) = match &event {
            Event::Start(e) => (Some(e), false),
            Event::Empty(e) => (Some(e), true),
            Event::End(e) if e.name().as_ref() == b"stack" => {
                let mut done = stack
                    .pop()
                    .ok_or_else(|| xml_error("unbalanced </stack>"))?;
                done.children.reverse();
                match stack.last_mut() {
                    Some(parent) => parent.children.push(RawNode::Group {
                        name: done.name,
                        visible: done.visible,
                        opacity: done.opacity,
                        children: done.children,
                    }),
                    None => root = Some(done.children),
                }
                (None, false)
            }
            Event::Eof => break,
            _ => (None, false),
        };
        let Some(e) = element else {
            buf.clear();
            continue;
        };
        let attrs = attributes(e)?;
        match e.name().as_ref() {
            b"image" => {
                let (w, h) = (number(&attrs, "w", 0u32)?, number(&attrs, "h", 0u32)?);
                if w == 0 || h == 0 {
                    return Err(xml_error(format!("<image> canvas {w}×{h} px is empty")));
                }
                check_size("the canvas", [w as u64, h as u64], &mut 0, limits)?;
                canvas = Some([w, h]);
            }
            b"stack" => {
                count += 1;
                check_limit(
                    "the file",
                    count as u64,
                    limits.max_layers as u64,
                    "layers and groups",
                )?;
                // The outermost stack is the image itself, not a group.
                if stack.len() > limits.max_depth {
                    return Err(LayeredError::TooDeep {
                        got: stack.len(),
                        limit: limits.max_depth,
                    });
                }
                let f = frame(&attrs, stack.last())?;
                if empty {
                    if let Some(parent) = stack.last_mut() {
                        parent.children.push(RawNode::Group {
                            name: f.name,
                            visible: f.visible,
                            opacity: f.opacity,
                            children: Vec::new(),
                        });
                    }
                } else {
                    stack.push(f);
                }
            }
            b"layer" => {
                count += 1;
                check_limit(
                    "the file",
                    count as u64,
                    limits.max_layers as u64,
                    "layers and groups",
                )?;
                let parent = stack
                    .last_mut()
                    .ok_or_else(|| xml_error("<layer> outside any <stack>"))?;
                let name = attr(&attrs, "name").unwrap_or("layer").to_string();
                let Some(src) = attr(&attrs, "src") else {
                    warnings.push(format!("layer '{name}': no pixels (no src); skipped"));
                    continue;
                };
                if !src.to_ascii_lowercase().ends_with(".png") {
                    warnings.push(format!("layer '{name}': {src} is not a PNG; skipped"));
                    continue;
                }
                let png = entry(zip, src, limits)?;
                let image = decode_png(&png, src, limits, total_px)?;
                parent.children.push(RawNode::Layer(RawLayer {
                    offset_px: position(&attrs, parent.offset_px)?,
                    image,
                    opacity: opacity(&attrs)?,
                    visible: attr(&attrs, "visibility") != Some("hidden"),
                    blend: blend(attr(&attrs, "composite-op")),
                    clipped: false,
                    name,
                }));
            }
            _ => {}
        }
        buf.clear();
    }
    let canvas = canvas.ok_or_else(|| xml_error("no <image w= h=> element"))?;
    let root = root.ok_or_else(|| xml_error("no <stack> element"))?;
    Ok((canvas, root))
}
