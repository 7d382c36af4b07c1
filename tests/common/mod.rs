//! Sprites generated in code for the integration tests and benchmarks: the shapes tracing and
//! meshing must get right (holes, several pieces, thin parts, 1-px features, a fully opaque
//! image, soft alpha), drawn antialiased with tiny-skia.
#![allow(dead_code)]

pub mod document;
pub mod golden;
pub mod sprite_meshes;

use image::RgbaImage;
use tiny_skia::{
    Color, FillRule, GradientStop, Paint, PathBuilder, Pixmap, Point, RadialGradient, Shader,
    SpreadMode, Stroke, Transform,
};

pub fn to_rgba(p: &Pixmap) -> RgbaImage {
    let mut img = RgbaImage::new(p.width(), p.height());
    for (dst, src) in img.pixels_mut().zip(p.pixels()) {
        let c = src.demultiply();
        *dst = image::Rgba([c.red(), c.green(), c.blue(), c.alpha()]);
    }
    img
}

fn paint(r: u8, g: u8, b: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(r, g, b, 255);
    p.anti_alias = true;
    p
}

fn circle(p: &mut Pixmap, cx: f32, cy: f32, r: f32, paint: &Paint) {
    if let Some(path) = PathBuilder::from_circle(cx, cy, r) {
        p.fill_path(&path, paint, FillRule::Winding, Transform::identity(), None);
    }
}

fn stroke_line(p: &mut Pixmap, a: (f32, f32), b: (f32, f32), width: f32, paint: &Paint) {
    let mut pb = PathBuilder::new();
    pb.move_to(a.0, a.1);
    pb.line_to(b.0, b.1);
    if let Some(path) = pb.finish() {
        let stroke = Stroke {
            width,
            ..Stroke::default()
        };
        p.stroke_path(&path, paint, &stroke, Transform::identity(), None);
    }
}

/// A colorful body with a ring-shaped handle (a hole), a thin antenna and a separate blob.
pub fn critter(size: u32) -> RgbaImage {
    let s = size as f32 / 256.0;
    let mut p = Pixmap::new(size, size).unwrap();
    circle(&mut p, 128.0 * s, 150.0 * s, 60.0 * s, &paint(230, 120, 40));
    circle(&mut p, 128.0 * s, 80.0 * s, 35.0 * s, &paint(240, 200, 80));
    circle(&mut p, 115.0 * s, 75.0 * s, 6.0 * s, &paint(20, 20, 30));
    // Handle: a thick ring, its inside transparent.
    let mut ring = PathBuilder::new();
    ring.push_circle(205.0 * s, 150.0 * s, 25.0 * s);
    ring.push_circle(205.0 * s, 150.0 * s, 14.0 * s);
    p.fill_path(
        &ring.finish().unwrap(),
        &paint(60, 120, 220),
        FillRule::EvenOdd,
        Transform::identity(),
        None,
    );
    stroke_line(
        &mut p,
        (128.0 * s, 45.0 * s),
        (150.0 * s, 10.0 * s),
        2.0,
        &paint(40, 40, 40),
    );
    circle(&mut p, 40.0 * s, 230.0 * s, 14.0 * s, &paint(90, 200, 90));
    to_rgba(&p)
}

/// Every test sprite with its name.
pub fn sprites() -> Vec<(&'static str, RgbaImage)> {
    let mut out = vec![("critter", critter(256))];

    let mut donut = Pixmap::new(96, 96).unwrap();
    let mut ring = PathBuilder::new();
    ring.push_circle(48.0, 48.0, 40.0);
    ring.push_circle(48.0, 48.0, 18.0);
    donut.fill_path(
        &ring.finish().unwrap(),
        &paint(200, 60, 120),
        FillRule::EvenOdd,
        Transform::identity(),
        None,
    );
    out.push(("donut", to_rgba(&donut)));

    let mut pieces = Pixmap::new(120, 80).unwrap();
    for (i, x) in [20.0, 60.0, 100.0].into_iter().enumerate() {
        circle(
            &mut pieces,
            x,
            40.0,
            12.0 + 3.0 * i as f32,
            &paint(50 + 60 * i as u8, 100, 200),
        );
    }
    out.push(("pieces", to_rgba(&pieces)));

    let mut thin = Pixmap::new(100, 100).unwrap();
    stroke_line(
        &mut thin,
        (10.0, 90.0),
        (90.0, 12.0),
        1.0,
        &paint(10, 10, 10),
    );
    stroke_line(
        &mut thin,
        (10.5, 10.5),
        (60.5, 10.5),
        1.0,
        &paint(200, 10, 10),
    );
    out.push(("thin", to_rgba(&thin)));

    // Isolated single opaque pixels and a 1-px-wide column.
    let mut dots = RgbaImage::new(40, 40);
    for (x, y) in [(5, 5), (20, 8), (33, 30)] {
        dots.put_pixel(x, y, image::Rgba([255, 255, 0, 255]));
    }
    for y in 10..35 {
        dots.put_pixel(12, y, image::Rgba([0, 200, 255, 255]));
    }
    out.push(("one_px", dots));

    out.push((
        "opaque",
        RgbaImage::from_fn(64, 48, |x, y| {
            image::Rgba([(x * 4) as u8, (y * 5) as u8, 128, 255])
        }),
    ));

    let mut soft = Pixmap::new(80, 80).unwrap();
    let stops = vec![
        GradientStop::new(0.0, Color::from_rgba8(30, 160, 90, 255)),
        GradientStop::new(1.0, Color::from_rgba8(30, 160, 90, 0)),
    ];
    let shader: Shader = RadialGradient::new(
        Point::from_xy(40.0, 40.0),
        0.0,
        Point::from_xy(40.0, 40.0),
        36.0,
        stops,
        SpreadMode::Pad,
        Transform::identity(),
    )
    .unwrap();
    let sp = Paint {
        shader,
        ..Paint::default()
    };
    soft.fill_rect(
        tiny_skia::Rect::from_xywh(0.0, 0.0, 80.0, 80.0).unwrap(),
        &sp,
        Transform::identity(),
        None,
    );
    out.push(("soft", to_rgba(&soft)));
    out.push(("painted", painted(90, 70)));
    out
}

/// Straight-alpha pixels as a paint program saves them: colors that do not survive a round trip
/// through premultiplied 8-bit values, on an ellipse with a soft 6-px edge.
pub fn painted(w: u32, h: u32) -> RgbaImage {
    let mut state = 0x2545_f491_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    };
    RgbaImage::from_fn(w, h, |x, y| {
        let (dx, dy) = (
            (x as f64 + 0.5 - w as f64 / 2.0) / (w as f64 * 0.4),
            (y as f64 + 0.5 - h as f64 / 2.0) / (h as f64 * 0.4),
        );
        let edge = (1.0 - (dx * dx + dy * dy).sqrt()) * (w as f64 * 0.4) / 6.0;
        let alpha = (edge.clamp(0.0, 1.0) * 255.0).round() as u8;
        let n = next();
        image::Rgba([n as u8, (n >> 8) as u8, (n >> 16) as u8, alpha])
    })
}

/// The bundled character (`assets/character`), rigged from its layers and handles with default
/// options.
pub fn character_scene() -> sinew::pipeline::Scene {
    let (doc, images) = character_rig();
    sinew::pipeline::Scene::new(doc, &images).expect("a scene")
}

/// The bundled character's layers and handles, as the assets hold them.
pub fn character_layers() -> (Vec<sinew::pipeline::Layer>, sinew::rig::Handles) {
    use sinew::pipeline;
    let assets = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/character");
    let list: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(assets.join("layers.json")).expect("layers.json"),
    )
    .expect("layers.json parses");
    let paths: Vec<std::path::PathBuf> = list["layers"]
        .as_array()
        .expect("a layer list")
        .iter()
        .map(|n| assets.join(format!("{}.png", n.as_str().expect("a layer name"))))
        .collect();
    let layers = pipeline::load_layers(&paths).expect("layers load");
    let handles: sinew::rig::Handles = serde_json::from_str(
        &std::fs::read_to_string(assets.join("handles.json")).expect("handles.json"),
    )
    .expect("handles.json parses");
    (layers, handles)
}

/// The bundled character's rig document (no animations) and its part images, as
/// [`character_scene`] builds them.
pub fn character_rig() -> (sinew::io::RigDocument, Vec<RgbaImage>) {
    let assets = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/character");
    let (mut layers, handles) = character_layers();
    // The other attachments of its slots (after the layers) and its skins, as `sinew demo` rigs them.
    let list: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(assets.join("layers.json")).expect("layers.json"),
    )
    .expect("layers.json parses");
    let attachments: std::collections::BTreeMap<String, String> =
        serde_json::from_value(list["attachments"].clone()).unwrap_or_default();
    let skins: sinew::io::Skins = serde_json::from_value(list["skins"].clone()).unwrap_or_default();
    let paths: Vec<std::path::PathBuf> = attachments
        .keys()
        .map(|n| assets.join(format!("{n}.png")))
        .collect();
    layers.extend(sinew::pipeline::load_layers(&paths).expect("attachments load"));
    let (mut doc, _) = sinew::pipeline::build_rig(
        &layers,
        &assets,
        &sinew::io::BuildOptions::default(),
        &handles,
    )
    .expect("the character rigs");
    doc.set_slots(&attachments, skins)
        .expect("the character's slots and skins");
    let images: Vec<RgbaImage> = layers.into_iter().map(|l| l.image).collect();
    (doc, images)
}
