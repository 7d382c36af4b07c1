//! Trace + mesh on the generated sprites and the bundled character, checked against the alpha:
//! coverage, how far the mesh strays, angle quality, and the rest pose rendering the sprite back.

mod common;

use image::RgbaImage;
use sinew::geom::{triangle_area2, Point};
use sinew::io::{BuildOptions, RigDocument};
use sinew::mesh::{triangle_min_angle_deg, triangulate, Mesh, MeshOptions};
use sinew::pipeline::{self, Scene};
use sinew::render::{psnr_premultiplied, psnr_rgba, rgba_from_pixmap};
use sinew::trace::{trace, TraceOptions};
use std::collections::HashMap;

/// Slack for points that lie on a triangle edge.
const INSIDE_EPS_PX: f64 = 1e-9;

fn mesh_of(image: &RgbaImage, trace_options: &TraceOptions, mesh_options: &MeshOptions) -> Mesh {
    let outlines = trace(image, trace_options).expect("trace");
    triangulate(
        &outlines,
        (image.width() * image.height()) as f64,
        mesh_options,
    )
    .expect("mesh")
}

/// Which of the grid points (x0 + i·step, y0 + j·step) lie in some triangle.
struct Coverage {
    w: usize,
    h: usize,
    x0: f64,
    y0: f64,
    step: f64,
    covered: Vec<bool>,
}

impl Coverage {
    fn new(mesh: &Mesh, w: usize, h: usize, x0: f64, y0: f64, step: f64) -> Self {
        let mut covered = vec![false; w * h];
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
            let area2 = triangle_area2(a, b, c);
            let (lo_x, hi_x) = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
            let (lo_y, hi_y) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
            let i0 = (((lo_x - x0) / step).floor().max(0.0)) as usize;
            let j0 = (((lo_y - y0) / step).floor().max(0.0)) as usize;
            let i1 = ((((hi_x - x0) / step).ceil()) as usize).min(w.saturating_sub(1));
            let j1 = ((((hi_y - y0) / step).ceil()) as usize).min(h.saturating_sub(1));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let p = Point::new(x0 + i as f64 * step, y0 + j as f64 * step);
                    let eps = INSIDE_EPS_PX * area2.abs().max(1.0);
                    if triangle_area2(a, b, p) >= -eps
                        && triangle_area2(b, c, p) >= -eps
                        && triangle_area2(c, a, p) >= -eps
                    {
                        covered[j * w + i] = true;
                    }
                }
            }
        }
        Coverage {
            w,
            h,
            x0,
            y0,
            step,
            covered,
        }
    }

    fn at(&self, p: Point) -> bool {
        let i = ((p.x - self.x0) / self.step).round();
        let j = ((p.y - self.y0) / self.step).round();
        i >= 0.0
            && j >= 0.0
            && (i as usize) < self.w
            && (j as usize) < self.h
            && self.covered[j as usize * self.w + i as usize]
    }
}

/// Distance from `p` to the nearest pixel square with alpha ≥ threshold, searched within `radius`.
fn distance_to_alpha(image: &RgbaImage, threshold: u8, p: Point, radius: f64) -> f64 {
    let r = radius.ceil() as i64 + 1;
    let (cx, cy) = (p.x.floor() as i64, p.y.floor() as i64);
    let mut best = f64::INFINITY;
    for y in cy - r..=cy + r {
        for x in cx - r..=cx + r {
            if x < 0 || y < 0 || x >= image.width() as i64 || y >= image.height() as i64 {
                continue;
            }
            if image.get_pixel(x as u32, y as u32)[3] < threshold {
                continue;
            }
            let dx = (x as f64 - p.x).max(p.x - (x + 1) as f64).max(0.0);
            let dy = (y as f64 - p.y).max(p.y - (y + 1) as f64).max(0.0);
            best = best.min(dx.hypot(dy));
        }
    }
    best
}

fn check_mesh_against_alpha(name: &str, image: &RgbaImage, mesh: &Mesh, options: &TraceOptions) {
    let (w, h) = (image.width() as usize, image.height() as usize);
    // Every opaque pixel: its whole square (its four corners and its center) inside the mesh.
    let corners = Coverage::new(mesh, w + 1, h + 1, 0.0, 0.0, 1.0);
    let centers = Coverage::new(mesh, w, h, 0.5, 0.5, 1.0);
    for (x, y, px) in image.enumerate_pixels() {
        if px[3] < options.alpha_threshold {
            continue;
        }
        let (x, y) = (x as f64, y as f64);
        for q in [
            Point::new(x, y),
            Point::new(x + 1.0, y),
            Point::new(x, y + 1.0),
            Point::new(x + 1.0, y + 1.0),
        ] {
            assert!(
                corners.at(q),
                "{name}: corner {q:?} of an opaque pixel is outside the mesh"
            );
        }
        assert!(
            centers.at(Point::new(x + 0.5, y + 0.5)),
            "{name}: opaque pixel ({x}, {y}) outside the mesh"
        );
    }
    // No triangle strays more than padding + 1 px from the opaque pixels (at the default
    // simplification tolerance of 0.5 px; a coarser tolerance may cut corners by that much).
    let limit = options.padding_px + options.simplify_tolerance_px.max(0.5) + 0.5;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        let samples = [
            a,
            b,
            c,
            Point::from((a.coords + b.coords) / 2.0),
            Point::from((b.coords + c.coords) / 2.0),
            Point::from((c.coords + a.coords) / 2.0),
            Point::from((a.coords + b.coords + c.coords) / 3.0),
        ];
        for p in samples {
            let d = distance_to_alpha(image, options.alpha_threshold, p, limit);
            assert!(
                d <= limit,
                "{name}: mesh point {p:?} is {d:.2} px from the alpha (limit {limit})"
            );
        }
    }
}

/// Boundary edges (used by one triangle) and, per boundary vertex, its two boundary neighbours.
fn outline_corner_angles(mesh: &Mesh) -> HashMap<u32, f64> {
    let mut count: HashMap<[u32; 2], u32> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    let mut neighbours: HashMap<u32, Vec<u32>> = HashMap::new();
    for (&[a, b], &n) in &count {
        if n == 1 {
            neighbours.entry(a).or_default().push(b);
            neighbours.entry(b).or_default().push(a);
        }
    }
    neighbours
        .into_iter()
        .map(|(v, nb)| {
            let p = mesh.vertices[v as usize];
            // The sharpest angle between any two boundary edges at v (≥ 2 of them).
            let mut sharpest = 180.0f64;
            for i in 0..nb.len() {
                for j in i + 1..nb.len() {
                    let (u, w) = (
                        mesh.vertices[nb[i] as usize] - p,
                        mesh.vertices[nb[j] as usize] - p,
                    );
                    sharpest = sharpest.min(
                        (u.dot(&w) / (u.norm() * w.norm()))
                            .clamp(-1.0, 1.0)
                            .acos()
                            .to_degrees(),
                    );
                }
            }
            (v, sharpest)
        })
        .collect()
}

/// Every angle below 20° sits at an outline corner sharp enough to force it (below 60°, where
/// Delaunay refinement cannot help).
fn check_angles(name: &str, mesh: &Mesh) {
    const REQUIRED_DEG: f64 = 20.0;
    const FORCING_CORNER_DEG: f64 = 60.0;
    let corners = outline_corner_angles(mesh);
    let mut small = 0;
    for t in &mesh.triangles {
        let p = t.map(|i| mesh.vertices[i as usize]);
        if triangle_min_angle_deg(p) >= REQUIRED_DEG {
            continue;
        }
        small += 1;
        let forced = (0..3).any(|k| {
            let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let angle = ((b - a).dot(&(c - a)) / ((b - a).norm() * (c - a).norm()))
                .acos()
                .to_degrees();
            angle < REQUIRED_DEG
                && corners
                    .get(&t[k])
                    .is_some_and(|&corner| corner < FORCING_CORNER_DEG)
        });
        assert!(forced, "{name}: triangle {p:?} has an angle below {REQUIRED_DEG}° away from a sharp outline corner");
    }
    eprintln!(
        "{name}: {} vertices, {} triangles, {small} with a forced angle below 20°",
        mesh.vertices.len(),
        mesh.triangles.len()
    );
}

#[test]
fn meshes_cover_the_alpha_and_stay_close_with_good_angles() {
    let options = TraceOptions::default();
    for (name, image) in common::sprites() {
        let mesh = mesh_of(&image, &options, &MeshOptions::default());
        check_mesh_against_alpha(name, &image, &mesh, &options);
        check_angles(name, &mesh);
    }
}

#[test]
fn holes_stay_holes() {
    let sprites = common::sprites();
    let (_, donut) = sprites.iter().find(|(n, _)| *n == "donut").unwrap();
    let mesh = mesh_of(donut, &TraceOptions::default(), &MeshOptions::default());
    let centers = Coverage::new(&mesh, 96, 96, 0.5, 0.5, 1.0);
    assert!(
        !centers.at(Point::new(48.5, 48.5)),
        "the donut's hole is meshed"
    );
    assert!(centers.at(Point::new(48.5, 18.5)));
}

#[test]
fn coarse_meshes_are_much_smaller_and_still_cover() {
    let image = common::critter(256);
    let trace_options = TraceOptions::coarse();
    let fine = mesh_of(&image, &TraceOptions::default(), &MeshOptions::default());
    let coarse = mesh_of(&image, &trace_options, &MeshOptions::coarse());
    assert!(
        coarse.vertices.len() * 4 <= fine.vertices.len(),
        "coarse {} vs fine {}",
        coarse.vertices.len(),
        fine.vertices.len()
    );
    check_mesh_against_alpha("critter coarse", &image, &coarse, &trace_options);
}

/// Renders the freshly rigged sprite in its rest pose.
fn rest_render(image: &RgbaImage) -> RgbaImage {
    let dir = std::env::temp_dir();
    let layer = pipeline::Layer::whole("sprite", dir.join("sprite.png"), image.clone());
    let (doc, _) = pipeline::build_rig(
        std::slice::from_ref(&layer),
        &dir,
        &BuildOptions::default(),
        &Default::default(),
    )
    .unwrap();
    let scene = Scene::new(doc, std::slice::from_ref(image)).unwrap();
    rgba_from_pixmap(&scene.render(&scene.rest_positions()).unwrap())
}

#[test]
fn rest_pose_renders_the_sprite_back() {
    const MIN_PSNR_DB: f64 = 45.0;
    for (name, image) in common::sprites() {
        let rendered = rest_render(&image);
        // Premultiplied: the color of a transparent pixel is not part of the picture.
        let psnr = psnr_premultiplied(&image, &rendered);
        eprintln!(
            "{name}: rest pose PSNR {psnr:.1} dB (premultiplied RGBA), {:.1} dB (straight RGBA)",
            psnr_rgba(&image, &rendered)
        );
        assert!(
            psnr >= MIN_PSNR_DB,
            "{name}: rest pose PSNR {psnr:.1} dB < {MIN_PSNR_DB}"
        );
        // No seams: wherever the sprite is opaque, so is the render, and the colors agree.
        for (x, y, src) in image.enumerate_pixels() {
            if src[3] == 255 {
                let out = rendered.get_pixel(x, y);
                let diff = (0..4)
                    .map(|c| (src[c] as i32 - out[c] as i32).abs())
                    .max()
                    .unwrap();
                assert!(
                    diff <= 1,
                    "{name}: pixel ({x}, {y}) rendered {out:?}, sprite {src:?}"
                );
            }
        }
    }
}

#[test]
fn bundled_character_rigs_and_renders_back() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/character");
    let list: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("layers.json")).unwrap()).unwrap();
    let paths: Vec<_> = list["layers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| dir.join(format!("{}.png", n.as_str().unwrap())))
        .collect();
    let layers = pipeline::load_layers(&paths).unwrap();
    let options = BuildOptions::default();
    let (doc, _) = pipeline::build_rig(&layers, &dir, &options, &Default::default()).unwrap();
    for (layer, part) in layers.iter().zip(&doc.parts) {
        let mesh = part.mesh.to_mesh();
        check_mesh_against_alpha(&layer.name, &layer.image, &mesh, &options.trace);
        check_angles(&layer.name, &mesh);
        assert_eq!(
            RigDocument::image_path(&dir.join("x.json"), part),
            layer.path
        );
    }
    let images: Vec<_> = layers.iter().map(|l| l.image.clone()).collect();
    let scene = Scene::new(doc, &images).unwrap();
    let rendered = rgba_from_pixmap(&scene.render(&scene.rest_positions()).unwrap());
    let flat = sinew::io::load_png(&dir.join("flat.png")).unwrap();
    let psnr = psnr_rgba(&flat, &rendered);
    eprintln!("character: rest pose PSNR against flat.png {psnr:.1} dB");
    assert!(psnr >= 45.0, "character rest pose PSNR {psnr:.1} dB");
}
