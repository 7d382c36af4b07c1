//! Unit tests of the layered readers on small files built here byte by byte (what the art
//! tools of tests/layered.rs do not write: masks, clipping, deep nesting, zip bombs).

use super::*;
use std::io::Write;

/// A test layer mask: rectangle (top, left, bottom, right), value per mask pixel, default
/// outside.
type TestMask = ([i32; 4], fn(u32, u32) -> u8, u8);

/// A layer of a test PSD: raw channels.
struct L {
    name: &'static str,
    /// top, left, bottom, right.
    rect: [i32; 4],
    pixel: fn(u32, u32) -> [u8; 4],
    mask: Option<TestMask>,
    clipped: bool,
    hidden: bool,
    /// `lsct` divider type (1 group start, 3 group end).
    section: Option<u32>,
}

fn layer(name: &'static str, rect: [i32; 4], pixel: fn(u32, u32) -> [u8; 4]) -> L {
    L {
        name,
        rect,
        pixel,
        mask: None,
        clipped: false,
        hidden: false,
        section: None,
    }
}

fn divider(name: &'static str, kind: u32) -> L {
    L {
        section: Some(kind),
        ..layer(name, [0, 0, 0, 0], |_, _| [0; 4])
    }
}

fn be32(v: &mut Vec<u8>, x: u32) {
    v.extend_from_slice(&x.to_be_bytes());
}

fn size(rect: [i32; 4]) -> (u32, u32) {
    ((rect[3] - rect[1]) as u32, (rect[2] - rect[0]) as u32)
}

/// An 8-bit RGB PSD of `w`×`h` with `layers` bottom first, all channels raw.
fn psd(w: u32, h: u32, layers: &[L]) -> Vec<u8> {
    let mut info = Vec::new();
    info.extend_from_slice(&(layers.len() as i16).to_be_bytes());
    let mut data = Vec::new();
    for l in layers {
        for v in l.rect {
            info.extend_from_slice(&v.to_be_bytes());
        }
        let (lw, lh) = size(l.rect);
        let mut channels: Vec<(i16, Vec<u8>)> = (0..4)
            .map(|c| {
                let id = if c == 3 { -1 } else { c as i16 };
                let mut plane = Vec::new();
                for y in 0..lh {
                    for x in 0..lw {
                        plane.push((l.pixel)(x, y)[c]);
                    }
                }
                (id, plane)
            })
            .collect();
        if let Some((rect, value, _)) = l.mask {
            let (mw, mh) = size(rect);
            let plane = (0..mh)
                .flat_map(|y| (0..mw).map(move |x| value(x, y)))
                .collect();
            channels.push((-2, plane));
        }
        info.extend_from_slice(&(channels.len() as u16).to_be_bytes());
        for (id, plane) in &channels {
            info.extend_from_slice(&id.to_be_bytes());
            be32(&mut info, plane.len() as u32 + 2);
            data.extend_from_slice(&[0, 0]);
            data.extend_from_slice(plane);
        }
        info.extend_from_slice(b"8BIMnorm");
        info.extend_from_slice(&[255, l.clipped as u8, if l.hidden { 2 } else { 0 }, 0]);
        let mut extra = Vec::new();
        match l.mask {
            Some((rect, _, default)) => {
                be32(&mut extra, 20);
                for v in rect {
                    extra.extend_from_slice(&v.to_be_bytes());
                }
                extra.extend_from_slice(&[default, 0, 0, 0]);
            }
            None => be32(&mut extra, 0),
        }
        be32(&mut extra, 0);
        let name = l.name.as_bytes();
        extra.push(name.len() as u8);
        extra.extend_from_slice(name);
        extra.extend(std::iter::repeat_n(0u8, (4 - (name.len() + 1) % 4) % 4));
        if let Some(kind) = l.section {
            extra.extend_from_slice(b"8BIMlsct");
            be32(&mut extra, 4);
            be32(&mut extra, kind);
        }
        be32(&mut info, extra.len() as u32);
        info.extend_from_slice(&extra);
    }
    info.extend_from_slice(&data);
    let mut out = Vec::new();
    out.extend_from_slice(b"8BPS\0\x01\0\0\0\0\0\0\0\x03");
    be32(&mut out, h);
    be32(&mut out, w);
    out.extend_from_slice(&[0, 8, 0, 3]);
    be32(&mut out, 0);
    be32(&mut out, 0);
    be32(&mut out, info.len() as u32 + 8);
    be32(&mut out, info.len() as u32);
    out.extend_from_slice(&info);
    be32(&mut out, 0);
    out.extend_from_slice(&[0, 0]);
    out.extend(std::iter::repeat_n(0u8, (w * h * 3) as usize));
    out
}

const RED: fn(u32, u32) -> [u8; 4] = |_, _| [255, 0, 0, 255];
const BLUE: fn(u32, u32) -> [u8; 4] = |_, _| [0, 0, 255, 255];

#[test]
fn psd_masks_clipping_and_trimming() {
    let left_half: fn(u32, u32) -> [u8; 4] = |x, _| [255, 0, 0, if x < 4 { 255 } else { 0 }];
    let masked = L {
        mask: Some(([0, 0, 8, 8], |_, y| if y < 4 { 0 } else { 255 }, 0)),
        ..layer("masked", [0, 0, 8, 8], BLUE)
    };
    let shade = L {
        clipped: true,
        ..layer("shade", [0, 0, 8, 8], BLUE)
    };
    let bytes = psd(
        8,
        8,
        &[layer("base", [0, 0, 8, 8], left_half), shade, masked],
    );
    let img = psd::parse(&bytes, &LayeredLimits::default()).unwrap();
    let names: Vec<_> = img.layers.iter().map(|l| l.path.as_str()).collect();
    assert_eq!(names, ["base", "shade", "masked"]);
    // Trimmed to the opaque half; the clipped layer to its base's pixels; the mask to its rows.
    assert_eq!(img.layers[0].image.dimensions(), (4, 8));
    assert_eq!(img.layers[1].image.dimensions(), (4, 8));
    assert_eq!(img.layers[2].image.dimensions(), (8, 4));
    assert_eq!(img.layers[2].offset_px, [0, 4]);
}

#[test]
fn psd_groups_give_paths_and_deep_nesting_is_refused() {
    let groups = |depth: usize| {
        let mut layers = Vec::new();
        for _ in 0..depth {
            layers.push(divider("</Layer group>", 3));
        }
        layers.push(layer("leaf", [1, 1, 5, 5], RED));
        layers.push(L {
            hidden: true,
            ..layer("ghost", [1, 1, 5, 5], RED)
        });
        for _ in 0..depth {
            layers.push(divider("g", 1));
        }
        psd(8, 8, &layers)
    };
    let img = psd::parse(&groups(3), &LayeredLimits::default()).unwrap();
    assert_eq!(img.layers[0].path, "g/g/g/leaf");
    assert!(img.layers[0].visible && !img.layers[1].visible);
    let e = psd::parse(&groups(64), &LayeredLimits::default()).unwrap_err();
    assert!(matches!(e, LayeredError::TooDeep { .. }), "{e}");
}

#[test]
fn psd_empty_and_off_canvas_layers() {
    let bytes = psd(
        8,
        8,
        &[
            layer("empty", [0, 0, 0, 0], RED),
            layer("away", [100, 100, 104, 104], RED),
            layer("body", [0, 0, 4, 4], RED),
        ],
    );
    let img = psd::parse(&bytes, &LayeredLimits::default()).unwrap();
    assert_eq!(img.warnings, ["layer 'empty': empty layer; skipped"]);
    // Off the canvas but kept, at its place: the caller decides (sinew rig drops it).
    assert_eq!(img.layers[0].offset_px, [100, 100]);
    let only_empty = psd(8, 8, &[layer("empty", [0, 0, 0, 0], RED)]);
    assert!(matches!(
        psd::parse(&only_empty, &LayeredLimits::default()),
        Err(LayeredError::NoLayers)
    ));
}

/// An ORA zip of `entries` (deflated).
fn ora_zip(entries: &[(&str, &[u8])]) -> Vec<u8> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    for (name, bytes) in entries {
        zip.start_file(*name, options).unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

fn png(w: u32, h: u32) -> Vec<u8> {
    crate::io::image::encode_png(&image::RgbaImage::from_pixel(
        w,
        h,
        image::Rgba([9, 9, 9, 255]),
    ))
    .unwrap()
}

#[test]
fn ora_stacks_merge_and_refusals() {
    let dot = png(2, 2);
    let stack = br#"<image w="10" h="10"><stack>
        <stack name="arm [merge]" x="1" y="1">
          <layer name="a" src="a.png" x="0" y="0"/>
          <layer name="b" src="a.png" x="3" y="3" opacity="0.5"/>
        </stack>
        <layer name="body" src="a.png" x="5" y="6" visibility="hidden"/>
      </stack></image>"#;
    let bytes = ora_zip(&[
        ("mimetype", b"image/openraster"),
        ("stack.xml", stack),
        ("a.png", &dot),
    ]);
    let img = ora::parse(&bytes, &LayeredLimits::default()).unwrap();
    let names: Vec<_> = img
        .layers
        .iter()
        .map(|l| (l.path.as_str(), l.visible))
        .collect();
    // First in stack.xml is the top: back to front it comes last.
    assert_eq!(names, [("body", false), ("arm", true)]);
    // The merged group spans both children, offset by the stack's x/y.
    assert_eq!(img.layers[1].offset_px, [1, 1]);
    assert_eq!(img.layers[1].image.dimensions(), (5, 5));

    let e = ora::parse(&ora_zip(&[("a.png", &dot)]), &LayeredLimits::default()).unwrap_err();
    assert!(e.to_string().contains("stack.xml: missing"), "{e}");

    let deep = format!(
        r#"<image w="4" h="4">{}<layer src="a.png"/>{}</image>"#,
        "<stack>".repeat(65),
        "</stack>".repeat(65)
    );
    let e = ora::parse(
        &ora_zip(&[("stack.xml", deep.as_bytes()), ("a.png", &dot)]),
        &LayeredLimits::default(),
    )
    .unwrap_err();
    assert!(matches!(e, LayeredError::TooDeep { .. }), "{e}");

    // A zip bomb: 8 MiB of zeros deflate to a few kB; the entry limit stops the read.
    let zeros = vec![0u8; 8 << 20];
    let bomb = ora_zip(&[("stack.xml", &zeros)]);
    assert!(bomb.len() < 100_000);
    let limits = LayeredLimits {
        max_entry_bytes: 1 << 20,
        ..LayeredLimits::default()
    };
    let e = ora::parse(&bomb, &limits).unwrap_err();
    assert!(
        e.to_string().contains("stack.xml") && e.to_string().contains("at most 1048576 bytes"),
        "{e}"
    );
    assert!(matches!(
        ora::parse(b"PK\x03\x04garbage", &limits),
        Err(LayeredError::Zip(_))
    ));
}

#[test]
fn a_part_image_is_the_layers_pixels_on_the_canvas_trimmed_and_placed() {
    // A 6×4 layer at (-2, 1) on a 10×10 canvas: columns 0–1 lie off the canvas; the last
    // column is transparent; half opacity rounds alpha 1 to 1 and alpha 255 to 128.
    let mut image = RgbaImage::new(6, 4);
    for (x, y, p) in image.enumerate_pixels_mut() {
        let alpha = match (x, y) {
            (5, _) => 0,
            (_, 0) => 1,
            _ => 255,
        };
        *p = image::Rgba([x as u8, y as u8, 7, alpha]);
    }
    let layer = ArtLayer {
        name: "l".into(),
        path: "l".into(),
        offset_px: [-2, 1],
        image,
        opacity: 0.5,
        visible: true,
        blend: BlendMode::Normal,
    };
    let (part, offset_px) = part_image(&layer, [10, 10]).expect("pixels left");
    assert_eq!(offset_px, [0, 1]);
    assert_eq!(part.dimensions(), (3, 4));
    assert_eq!(part.get_pixel(0, 0).0, [2, 0, 7, 1]);
    assert_eq!(part.get_pixel(2, 3).0, [4, 3, 7, 128]);
    // Wholly off the canvas: nothing.
    let off = ArtLayer {
        offset_px: [10, 0],
        ..layer
    };
    assert!(part_image(&off, [10, 10]).is_none());
}

// Found by the review that wrote the fuzz targets of the layered readers (fuzz/,
// docs/fuzzing.md): each of these panicked (an overflow) or asked for gigabytes before the fix,
// but the last, whose refusal was right but named a canvas computed from saturated numbers.

/// A PSD of no layers whose merged image is `planes` channels of `w`×`h`, compressed as
/// `method` with `data` after the compression code.
fn merged_psd(w: u32, h: u32, planes: u16, method: u16, data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(b"8BPS\0\x01\0\0\0\0\0\0");
    out.extend_from_slice(&planes.to_be_bytes());
    be32(&mut out, h);
    be32(&mut out, w);
    out.extend_from_slice(&[0, 8, 0, 3]);
    for _ in 0..3 {
        be32(&mut out, 0);
    }
    out.extend_from_slice(&method.to_be_bytes());
    out.extend_from_slice(data);
    out
}

#[test]
fn psd_merged_image_keeps_only_its_colour_channels() {
    // 56 channels (the most a document has): the colour planes are read, the other 53
    // checked to be there and dropped.
    let data: Vec<u8> = (0..56u8).flat_map(|c| [c; 4]).collect();
    let img = psd::parse(&merged_psd(2, 2, 56, 0, &data), &LayeredLimits::default()).unwrap();
    assert_eq!(img.layers[0].image.get_pixel(1, 1).0, [0, 1, 2, 255]);
    assert_eq!(
        psd::merged_image(&merged_psd(2, 2, 56, 0, &data), true)
            .unwrap()
            .get_pixel(0, 0)
            .0,
        [0, 1, 2, 3]
    );
    // Cut inside a channel it does not keep: still truncated.
    let e = psd::parse(
        &merged_psd(2, 2, 56, 0, &data[..200]),
        &LayeredLimits::default(),
    )
    .unwrap_err();
    assert!(matches!(e, LayeredError::Truncated { .. }), "{e}");
    let e = psd::parse(&merged_psd(2, 2, 57, 0, &data), &LayeredLimits::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "malformed: 57 channels (a document has 1 to 56)"
    );
    // 65,535 channels were accepted: a 16384² canvas (at the pixel limit) of them asked for
    // 16 TiB up front, and the process aborted.
    let e = psd::parse(
        &merged_psd(16384, 16384, u16::MAX, 2, &[]),
        &LayeredLimits::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("65535 channels"), "{e}");
    // Of 56 ZIP channels in a 44-byte file: 14 GiB reserved up front; now what it decodes.
    let e = psd::parse(
        &merged_psd(16384, 16384, 56, 2, &[0x78, 0x9c, 0x03, 0x00]),
        &LayeredLimits::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("merged image: ZIP data"), "{e}");
    // The same for RLE: 56 × 16384 row counts of zero bytes, every row then too short.
    let counts = vec![0u8; 2 * 56 * 16384];
    let e = psd::parse(
        &merged_psd(16384, 16384, 56, 1, &counts),
        &LayeredLimits::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("RLE row: ends early"), "{e}");
}

#[test]
fn a_merged_group_of_layers_far_apart_is_refused_not_overflowed() {
    // Two 1-px layers at the ends of i32 in a `[merge]` group: their span overflowed i32
    // (a panic), and a span within it allocated the whole merged rectangle unchecked.
    for (a, b, what) in [
        (
            [i32::MIN, i32::MIN],
            [i32::MAX - 1, i32::MAX - 1],
            "4294967295 px a side",
        ),
        (
            [0, 0],
            [29_000, 29_000],
            "(841058001 px); sinew reads at most 268435456 px",
        ),
    ] {
        let dot = |at: [i32; 2]| [at[1], at[0], at[1] + 1, at[0] + 1];
        let bytes = psd(
            8,
            8,
            &[
                divider("</g>", 3),
                layer("a", dot(a), RED),
                layer("b", dot(b), BLUE),
                divider("g [merge]", 1),
            ],
        );
        let e = psd::parse(&bytes, &LayeredLimits::default()).unwrap_err();
        assert!(
            matches!(e, LayeredError::TooLarge { .. }) && e.to_string().contains(what),
            "{e}"
        );
        assert!(e.to_string().contains("merged group 'g [merge]'"), "{e}");
    }
}

#[test]
fn ora_positions_past_i32_and_opacities_not_numbers_are_refused() {
    let dot = png(2, 2);
    let read = |stack: &str| {
        ora::parse(
            &ora_zip(&[("stack.xml", stack.as_bytes()), ("a.png", &dot)]),
            &LayeredLimits::default(),
        )
    };
    // A stack's x plus its layer's overflowed i32 (a panic).
    let e = read(
        r#"<image w="4" h="4"><stack><stack x="1073741824"><layer src="a.png" x="1073741824"/></stack></stack></image>"#,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "stack.xml: x = 2147483648 px with its stacks': sinew reads positions within ±1073741824 px"
    );
    // Far, but within the range: kept at its place (off the canvas).
    let img = read(
        r#"<image w="4" h="4"><stack><layer src="a.png" x="1073741822" y="-1073741824"/></stack></image>"#,
    )
    .unwrap();
    assert_eq!(img.layers[0].offset_px, [1_073_741_822, -1_073_741_824]);
    // `nan` parsed as a number and stayed NaN through the clamp.
    for opacity in ["nan", "inf", "-inf"] {
        let e = read(&format!(
            r#"<image w="4" h="4"><stack><layer src="a.png" opacity="{opacity}"/></stack></image>"#
        ))
        .unwrap_err();
        assert!(e.to_string().contains("is not a finite number"), "{e}");
    }
    let e = read(r#"<image w="4" h="4"><stack opacity="NaN"><layer src="a.png"/></stack></image>"#)
        .unwrap_err();
    assert!(e.to_string().contains("opacity=\"NaN\""), "{e}");
}

#[test]
fn spine_script_positions_too_far_apart_are_refused_not_overflowed() {
    let tmp = crate::test_scratch::scratch("layered-spine-far");
    let dir = tmp.path();
    std::fs::write(dir.join("a.png"), png(2, 2)).unwrap();
    let skeleton = |x: &str, bone_x: &str| {
        format!(
            r#"{{"bones": [{{"name": "root"}}, {{"name": "far", "parent": "root", "x": {bone_x}}}],
               "slots": [{{"name": "s", "bone": "root", "attachment": "a"}},
                         {{"name": "t", "bone": "far", "attachment": "a"}}],
               "skins": {{"default": {{"s": {{"a": {{}}}}, "t": {{"a": {{"x": {x}}}}}}}}}}}"#
        )
    };
    let read = |x: &str, bone_x: &str| {
        spine_json::parse(
            skeleton(x, bone_x).as_bytes(),
            dir,
            &LayeredLimits::default(),
        )
    };
    assert_eq!(read("10", "0").unwrap().canvas_px, [12, 2]);
    // A canvas wider than i32: refused by its width, checked before any offset is made.
    let e = read("3e9", "0").unwrap_err();
    assert!(matches!(e, LayeredError::TooLarge { .. }), "{e}");
    // Past what an f64 holds, with the bone's: said so (was "too large" with a made-up size).
    let e = read("1.5e308", "1.5e308").unwrap_err();
    assert_eq!(
        e.to_string(),
        "malformed: attachment positions (with their bones') are too large to place"
    );
}
