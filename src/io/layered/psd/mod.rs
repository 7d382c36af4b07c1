//! Photoshop documents (PSD, and PSB, its large-document variant): 8-bit RGB and grayscale,
//! channels raw, RLE or ZIP compressed, with groups, layer masks and clipping masks.
//!
//! In: the file's bytes. Out: the raw layer tree for [`build_layers`] (see the module above).
//! 16- and 32-bit documents and colour modes other than RGB and grayscale (CMYK, Lab, indexed,
//! bitmap, duotone, multichannel) are refused, naming what is unsupported. Adjustment and fill
//! layers are skipped with a warning; text layers and smart objects are read as the pixels the
//! file carries for them (skipped with a warning when it carries none). A document saved
//! without layers is one layer, its merged image. Specification: Adobe's "Photoshop File
//! Formats Specification".

mod read;

use super::tree::{build_layers, RawLayer, RawNode};
use super::{check_limit, check_size, BlendMode, LayeredError, LayeredImage, LayeredLimits};
use image::RgbaImage;
use read::{decode_planes, Compression, Reader};

/// Reads a PSD or PSB document.
pub fn parse(bytes: &[u8], limits: &LayeredLimits) -> Result<LayeredImage, LayeredError> {
    let mut r = Reader::new(bytes);
    let header = Header::read(&mut r, limits)?;
    let len = r.u32("color mode data length")?;
    r.skip(len as u64, "color mode data")?;
    let len = r.u32("image resources length")?;
    r.skip(len as u64, "image resources")?;
    let len = r.length(header.psb, "layer and mask section length")?;
    let mut section = r.sub(len, "layer and mask section")?;
    let mut warnings = Vec::new();
    let records = if len > 0 {
        read_layers(&mut section, &header, limits, &mut warnings)?
    } else {
        Vec::new()
    };
    let nodes = if records.is_empty() {
        // No layers: the document is its merged image.
        let mut total = 0;
        check_size("the merged image", header.size_u64(), &mut total, limits)?;
        vec![RawNode::Layer(RawLayer {
            name: "Background".into(),
            offset_px: [0, 0],
            image: merged(&mut r, &header, false)?,
            opacity: 1.0,
            visible: true,
            blend: BlendMode::Normal,
            clipped: false,
        })]
    } else {
        group_tree(records, limits)?
    };
    build_layers(header.size, nodes, warnings, limits)
}

/// The document's own flattened image (the "maximize compatibility" composite Photoshop and
/// psd-tools store after the layers), alpha from the first extra channel when `alpha`.
pub fn merged_image(bytes: &[u8], alpha: bool) -> Result<RgbaImage, LayeredError> {
    let limits = LayeredLimits::default();
    let mut r = Reader::new(bytes);
    let header = Header::read(&mut r, &limits)?;
    for what in ["color mode data", "image resources"] {
        let len = r.u32(what)?;
        r.skip(len as u64, what)?;
    }
    let len = r.length(header.psb, "layer and mask section length")?;
    r.skip(len, "layer and mask section")?;
    merged(&mut r, &header, alpha)
}

struct Header {
    psb: bool,
    channels: usize,
    size: [u32; 2],
    gray: bool,
}

impl Header {
    fn read(r: &mut Reader, limits: &LayeredLimits) -> Result<Self, LayeredError> {
        if r.peek(4) != Some(b"8BPS") {
            return Err(LayeredError::NotFormat {
                expected: "a Photoshop file (PSD/PSB)",
            });
        }
        r.skip(4, "signature")?;
        let psb = match r.u16("version")? {
            1 => false,
            2 => true,
            v => {
                return Err(LayeredError::Malformed(format!(
                    "version {v} (1 is PSD, 2 PSB)"
                )))
            }
        };
        r.skip(6, "header")?;
        let channels = r.u16("channel count")? as usize;
        let h = r.u32("height")?;
        let w = r.u32("width")?;
        let depth = r.u16("depth")?;
        let mode = r.u16("color mode")?;
        if depth != 8 {
            return Err(LayeredError::Unsupported(format!(
                "{depth}-bit channels: sinew reads 8-bit PSD/PSB only (Image → Mode → 8 Bits/Channel)"
            )));
        }
        let gray = match mode {
            1 => true,
            3 => false,
            _ => {
                let name = match mode {
                    0 => "bitmap",
                    2 => "indexed",
                    4 => "CMYK",
                    7 => "multichannel",
                    8 => "duotone",
                    9 => "Lab",
                    _ => "unknown",
                };
                return Err(LayeredError::Unsupported(format!(
                    "{name} color mode ({mode}): sinew reads RGB and grayscale documents only (Image → Mode → RGB Color)"
                )));
            }
        };
        if channels < if gray { 1 } else { 3 } || channels > 56 {
            return Err(LayeredError::Malformed(format!(
                "{channels} channels (a document has 1 to 56)"
            )));
        }
        if w == 0 || h == 0 {
            return Err(LayeredError::Malformed(format!(
                "canvas {w}×{h} px is empty"
            )));
        }
        let header = Self {
            psb,
            channels,
            size: [w, h],
            gray,
        };
        let mut total = 0;
        check_size("the canvas", header.size_u64(), &mut total, limits)?;
        Ok(header)
    }

    fn size_u64(&self) -> [u64; 2] {
        [self.size[0] as u64, self.size[1] as u64]
    }
}

/// The merged image data section, as RGBA.
fn merged(r: &mut Reader, header: &Header, alpha: bool) -> Result<RgbaImage, LayeredError> {
    let method = Compression::from_code(r.u16("merged image compression")?, "merged image")?;
    let [w, h] = header.size.map(|v| v as usize);
    let color = if header.gray { 1 } else { 3 };
    let with_alpha = alpha && header.channels > color;
    // Only the colour channels and alpha are decoded (of up to 56).
    let planes = decode_planes(
        r,
        method,
        [w, h],
        [header.channels, color + with_alpha as usize],
        header.psb,
        "merged image",
    )?;
    let plane = |c: usize| &planes[c * w * h..(c + 1) * w * h];
    let a = with_alpha.then(|| plane(color));
    let mut image = RgbaImage::new(w as u32, h as u32);
    for (i, p) in image.pixels_mut().enumerate() {
        for c in 0..3 {
            p[c] = plane(if header.gray { 0 } else { c })[i];
        }
        p[3] = a.map_or(255, |a| a[i]);
    }
    Ok(image)
}

/// What a layer record is, from its tagged blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Pixels,
    Text,
    SmartObject,
    /// An adjustment or fill layer, with the block key naming which.
    Adjustment(&'static str),
    /// A group's start (open or closed folder) or its end marker.
    GroupStart,
    GroupEnd,
}

struct Mask {
    rect: [i32; 4],
    default: u8,
    disabled: bool,
}

struct Record {
    name: String,
    rect: [i32; 4],
    channels: Vec<(i16, u64)>,
    blend: BlendMode,
    opacity: f32,
    clipped: bool,
    hidden: bool,
    kind: Kind,
    mask: Option<Mask>,
    real_mask: Option<Mask>,
    vector_mask: bool,
}

/// Tagged blocks whose length is 8 bytes in PSB.
const LONG_KEYS: [&[u8; 4]; 13] = [
    b"LMsk", b"Lr16", b"Lr32", b"Layr", b"Mt16", b"Mt32", b"Mtrn", b"Alph", b"FMsk", b"lnk2",
    b"FEid", b"FXid", b"PxSD",
];

const ADJUSTMENTS: [(&[u8; 4], &str); 20] = [
    (b"brit", "brightness/contrast"),
    (b"levl", "levels"),
    (b"curv", "curves"),
    (b"expA", "exposure"),
    (b"vibA", "vibrance"),
    (b"hue ", "hue/saturation"),
    (b"hue2", "hue/saturation"),
    (b"blnc", "color balance"),
    (b"blwh", "black & white"),
    (b"phfl", "photo filter"),
    (b"mixr", "channel mixer"),
    (b"clrL", "color lookup"),
    (b"nvrt", "invert"),
    (b"post", "posterize"),
    (b"thrs", "threshold"),
    (b"grdm", "gradient map"),
    (b"selc", "selective color"),
    (b"SoCo", "solid color fill"),
    (b"GdFl", "gradient fill"),
    (b"PtFl", "pattern fill"),
];

fn blend_mode(key: &[u8]) -> BlendMode {
    match key {
        b"norm" => BlendMode::Normal,
        b"pass" => BlendMode::PassThrough,
        b"mul " => BlendMode::Multiply,
        b"scrn" => BlendMode::Screen,
        b"over" => BlendMode::Overlay,
        b"dark" => BlendMode::Darken,
        b"lite" => BlendMode::Lighten,
        b"lddg" => BlendMode::Add,
        other => BlendMode::Other(String::from_utf8_lossy(other).trim().to_string()),
    }
}

/// The layer records and their pixels, bottom (back) first.
fn read_layers(
    section: &mut Reader,
    header: &Header,
    limits: &LayeredLimits,
    warnings: &mut Vec<String>,
) -> Result<Vec<(Record, Option<RawLayer>)>, LayeredError> {
    let len = section.length(header.psb, "layer info length")?;
    if len == 0 {
        return Ok(Vec::new());
    }
    let mut r = section.sub(len, "layer info")?;
    let count = r.i16("layer count")?.unsigned_abs() as usize;
    check_limit(
        "the file",
        count as u64,
        limits.max_layers as u64,
        "layers and groups",
    )?;
    let mut records = Vec::with_capacity(count);
    for i in 0..count {
        records.push(read_record(&mut r, header.psb, i)?);
    }
    let mut total_px = 0;
    let mut out = Vec::with_capacity(count);
    for record in records {
        let layer = read_pixels(&mut r, &record, header, limits, &mut total_px, warnings)?;
        out.push((record, layer));
    }
    Ok(out)
}

fn read_rect(r: &mut Reader, what: &str) -> Result<[i32; 4], LayeredError> {
    let (top, left, bottom, right) = (r.i32(what)?, r.i32(what)?, r.i32(what)?, r.i32(what)?);
    if bottom < top || right < left {
        return Err(LayeredError::Malformed(format!(
            "{what}: rectangle top {top} left {left} bottom {bottom} right {right}"
        )));
    }
    Ok([top, left, bottom, right])
}

fn rect_size(rect: &[i32; 4]) -> [u64; 2] {
    [
        (rect[3] as i64 - rect[1] as i64) as u64,
        (rect[2] as i64 - rect[0] as i64) as u64,
    ]
}

fn read_record(r: &mut Reader, psb: bool, index: usize) -> Result<Record, LayeredError> {
    let what = format!("layer record {index}");
    let rect = read_rect(r, &what)?;
    let n = r.u16(&what)? as usize;
    if n > 56 {
        return Err(LayeredError::Malformed(format!("{what}: {n} channels")));
    }
    let mut channels = Vec::with_capacity(n);
    for _ in 0..n {
        let id = r.i16(&what)?;
        channels.push((id, r.length(psb, &what)?));
    }
    if r.take(4, &what)? != b"8BIM" {
        return Err(LayeredError::Malformed(format!(
            "{what}: no blend mode signature"
        )));
    }
    let blend = blend_mode(r.take(4, &what)?);
    let opacity = r.u8(&what)? as f32 / 255.0;
    let clipped = r.u8(&what)? != 0;
    let flags = r.u8(&what)?;
    r.skip(1, &what)?;
    let extra_len = r.u32(&what)?;
    let mut extra = r.sub(extra_len as u64, &what)?;
    let (mask, real_mask) = read_mask(&mut extra, &what)?;
    let len = extra.u32(&what)?;
    extra.skip(len as u64, &what)?;
    let len = extra.u8(&what)? as u64;
    let pascal = extra.take(len, &what)?;
    let mut name: String = pascal.iter().map(|&b| b as char).collect();
    extra.skip((4 - (len + 1) % 4) % 4, &what).ok();
    let mut kind = Kind::Pixels;
    let mut vector_mask = false;
    let mut blend = blend;
    while extra.remaining() >= 12 {
        // Blocks are padded to 2 or 4 bytes depending on the writer: find the next signature.
        let Some(sig) = extra.peek(4) else { break };
        if sig != b"8BIM" && sig != b"8B64" {
            extra.skip(1, &what)?;
            continue;
        }
        extra.skip(4, &what)?;
        let key: [u8; 4] = extra.take(4, &what)?.try_into().unwrap_or([0; 4]);
        let long = psb && LONG_KEYS.contains(&&key);
        let len = extra.length(long, &what)?;
        let mut data = extra.sub(
            len,
            &format!("{what}: block {}", String::from_utf8_lossy(&key)),
        )?;
        match &key {
            b"luni" => {
                let chars = data.u32(&what)? as u64;
                let units = data.take(chars.saturating_mul(2), &what)?;
                let utf16: Vec<u16> = units
                    .chunks_exact(2)
                    .map(|c| u16::from_be_bytes([c[0], c[1]]))
                    .collect();
                name = String::from_utf16_lossy(&utf16)
                    .trim_end_matches('\0')
                    .to_string();
            }
            b"lsct" | b"lsdk" => {
                kind = match data.u32(&what)? {
                    1 | 2 => Kind::GroupStart,
                    3 => Kind::GroupEnd,
                    _ => kind,
                };
                if data.remaining() >= 8 && data.take(4, &what)? == b"8BIM" {
                    blend = blend_mode(data.take(4, &what)?);
                }
            }
            b"TySh" | b"tySh" => kind = Kind::Text,
            b"SoLd" | b"PlLd" | b"SoLE" => kind = Kind::SmartObject,
            b"vmsk" | b"vsms" => vector_mask = true,
            _ => {
                if let Some((_, what)) = ADJUSTMENTS.iter().find(|(k, _)| *k == &key) {
                    kind = Kind::Adjustment(what);
                }
            }
        }
    }
    Ok(Record {
        name,
        rect,
        channels,
        blend,
        opacity,
        clipped,
        hidden: flags & 0x02 != 0,
        kind,
        mask,
        real_mask,
        vector_mask,
    })
}

/// The layer mask data: the user mask and, when a vector mask is present too, the "real" one.
fn read_mask(r: &mut Reader, what: &str) -> Result<(Option<Mask>, Option<Mask>), LayeredError> {
    let len = r.u32(what)?;
    let mut m = r.sub(len as u64, what)?;
    if len < 20 {
        return Ok((None, None));
    }
    let rect = read_rect(&mut m, what)?;
    let default = m.u8(what)?;
    let flags = m.u8(what)?;
    let mask = Mask {
        rect,
        default,
        disabled: flags & 0x02 != 0,
    };
    if len < 36 {
        return Ok((Some(mask), None));
    }
    if flags & 0x10 != 0 {
        let params = m.u8(what)?;
        for (bit, size) in [(0x01, 1), (0x02, 8), (0x04, 1), (0x08, 8)] {
            if params & bit != 0 {
                m.skip(size, what)?;
            }
        }
    }
    let real = (|| -> Result<Mask, LayeredError> {
        let flags = m.u8(what)?;
        let default = m.u8(what)?;
        Ok(Mask {
            rect: read_rect(&mut m, what)?,
            default,
            disabled: flags & 0x02 != 0,
        })
    })()
    .ok();
    Ok((Some(mask), real))
}

/// Reads (or skips) a record's channel data; the raw layer when it has pixels to show.
fn read_pixels(
    r: &mut Reader,
    rec: &Record,
    header: &Header,
    limits: &LayeredLimits,
    total_px: &mut u64,
    warnings: &mut Vec<String>,
) -> Result<Option<RawLayer>, LayeredError> {
    let size = rect_size(&rec.rect);
    let wanted = matches!(rec.kind, Kind::Pixels | Kind::Text | Kind::SmartObject);
    if wanted {
        check_size(&format!("layer '{}'", rec.name), size, total_px, limits)?;
    }
    let [w, h] = size.map(|v| v as usize);
    let mut planes: [Option<Vec<u8>>; 4] = [None, None, None, None];
    let mut mask: Option<(Vec<u8>, &Mask)> = None;
    for &(id, len) in &rec.channels {
        let what = format!("layer '{}' channel {id}", rec.name);
        let mut data = r.sub(len, &what)?;
        if !wanted || len < 2 {
            continue;
        }
        let method = Compression::from_code(data.u16(&what)?, &what)?;
        let slot = match (id, header.gray) {
            (0..=2, false) => Some(id as usize),
            (0, true) => Some(0),
            (-1, _) => Some(3),
            _ => None,
        };
        if let Some(slot) = slot {
            planes[slot] = Some(decode_planes(
                &mut data,
                method,
                [w, h],
                [1, 1],
                header.psb,
                &what,
            )?);
            continue;
        }
        let m = match id {
            -2 if rec.real_mask.is_none() || !rec.channels.iter().any(|c| c.0 == -3) => {
                rec.mask.as_ref()
            }
            -3 => rec.real_mask.as_ref(),
            _ => None,
        };
        if let Some(m) = m.filter(|m| !m.disabled) {
            let ms = rect_size(&m.rect);
            check_size(&format!("layer '{}' mask", rec.name), ms, total_px, limits)?;
            let ms = ms.map(|v| v as usize);
            mask = Some((
                decode_planes(&mut data, method, ms, [1, 1], header.psb, &what)?,
                m,
            ));
        }
    }
    let name = &rec.name;
    match rec.kind {
        Kind::GroupStart | Kind::GroupEnd => return Ok(None),
        Kind::Adjustment(what) => {
            warnings.push(format!("layer '{name}': {what} layer not applied; skipped"));
            return Ok(None);
        }
        _ => {}
    }
    if w == 0 || h == 0 {
        let what = match rec.kind {
            Kind::Text => "text layer without rendered pixels",
            Kind::SmartObject => "smart object without rendered pixels",
            _ => "empty layer",
        };
        warnings.push(format!("layer '{name}': {what}; skipped"));
        return Ok(None);
    }
    if rec.vector_mask {
        warnings.push(format!("layer '{name}': vector mask not applied"));
    }
    let mut image = RgbaImage::new(w as u32, h as u32);
    let color = |c: usize| if header.gray { 0 } else { c };
    for (i, p) in image.pixels_mut().enumerate() {
        for c in 0..3 {
            p[c] = planes[color(c)].as_ref().map_or(0, |v| v[i]);
        }
        p[3] = planes[3].as_ref().map_or(255, |v| v[i]);
    }
    if let Some((values, m)) = mask {
        apply_mask(&mut image, rec.rect, &values, m);
    }
    Ok(Some(RawLayer {
        name: rec.name.clone(),
        offset_px: [rec.rect[1], rec.rect[0]],
        image,
        opacity: rec.opacity,
        visible: !rec.hidden,
        blend: rec.blend.clone(),
        clipped: rec.clipped,
    }))
}

/// Multiplies alpha by the mask (its `default` outside the mask's rectangle).
fn apply_mask(image: &mut RgbaImage, rect: [i32; 4], values: &[u8], m: &Mask) {
    let [mw, mh] = rect_size(&m.rect).map(|v| v as i64);
    for (x, y, p) in image.enumerate_pixels_mut() {
        let mx = rect[1] as i64 + x as i64 - m.rect[1] as i64;
        let my = rect[0] as i64 + y as i64 - m.rect[0] as i64;
        let v = if mx >= 0 && my >= 0 && mx < mw && my < mh {
            values[(my * mw + mx) as usize]
        } else {
            m.default
        };
        p[3] = ((p[3] as u32 * v as u32 + 127) / 255) as u8;
    }
}

/// Records bottom-first → the raw group tree: a group's end marker comes first (below its
/// children), the group's own record last.
fn group_tree(
    records: Vec<(Record, Option<RawLayer>)>,
    limits: &LayeredLimits,
) -> Result<Vec<RawNode>, LayeredError> {
    let mut stack: Vec<Vec<RawNode>> = vec![Vec::new()];
    for (rec, layer) in records {
        match rec.kind {
            Kind::GroupEnd => {
                if stack.len() > limits.max_depth {
                    return Err(LayeredError::TooDeep {
                        got: stack.len(),
                        limit: limits.max_depth,
                    });
                }
                stack.push(Vec::new());
            }
            Kind::GroupStart => {
                if stack.len() < 2 {
                    return Err(LayeredError::Malformed(format!(
                        "group '{}' has no end marker",
                        rec.name
                    )));
                }
                let children = stack.pop().unwrap_or_default();
                let group = RawNode::Group {
                    name: rec.name,
                    visible: !rec.hidden,
                    opacity: rec.opacity,
                    children,
                };
                if let Some(top) = stack.last_mut() {
                    top.push(group);
                }
            }
            _ => {
                if let (Some(layer), Some(top)) = (layer, stack.last_mut()) {
                    top.push(RawNode::Layer(layer));
                }
            }
        }
    }
    if stack.len() != 1 {
        return Err(LayeredError::Malformed("a group is not closed".into()));
    }
    Ok(stack.pop().unwrap_or_default())
}
