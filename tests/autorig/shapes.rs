//! The generated test shapes of the autorig tests, drawn with tiny-skia on a 256² canvas (y
//! down, px): a stick figure, a five-pointed star, a letter "P" with a hole, a blob, a
//! quadruped, each (where it has noise) also with a jittered outline, and their limb tips.

use image::RgbaImage;
use sinew::geom::Point;
use std::f32::consts::PI;
use tiny_skia::{Color, FillRule, LineCap, Paint, PathBuilder, Pixmap, Stroke, Transform};

pub fn to_rgba(p: &Pixmap) -> RgbaImage {
    let mut img = RgbaImage::new(p.width(), p.height());
    for (dst, src) in img.pixels_mut().zip(p.pixels()) {
        let c = src.demultiply();
        *dst = image::Rgba([c.red(), c.green(), c.blue(), c.alpha()]);
    }
    img
}

fn paint() -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(200, 90, 40, 255));
    p.anti_alias = true;
    p
}

/// A deterministic pseudo-random sequence in [0, 1) (an LCG), for noise.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// A segment (from, to), canvas px.
pub type Segment = ((f32, f32), (f32, f32));

/// Small round bumps (radius `r`) along the outline of `capsule`s: outline noise.
fn bumps(p: &mut Pixmap, segments: &[Segment], half_width: f32, r: f32) {
    let mut rng = Lcg(7);
    for &((ax, ay), (bx, by)) in segments {
        let (dx, dy) = (bx - ax, by - ay);
        let len = (dx * dx + dy * dy).sqrt();
        let (nx, ny) = (-dy / len, dx / len);
        let mut t = 6.0;
        while t < len - 6.0 {
            let side = if rng.next() < 0.5 { -1.0 } else { 1.0 };
            let (cx, cy) = (ax + dx * t / len, ay + dy * t / len);
            let (x, y) = (cx + side * nx * half_width, cy + side * ny * half_width);
            if let Some(c) = PathBuilder::from_circle(x, y, r) {
                p.fill_path(&c, &paint(), FillRule::Winding, Transform::identity(), None);
            }
            t += 5.0 + 6.0 * rng.next();
        }
    }
}

pub fn capsules(p: &mut Pixmap, segments: &[Segment], width: f32) {
    for &(a, b) in segments {
        let mut pb = PathBuilder::new();
        pb.move_to(a.0, a.1);
        pb.line_to(b.0, b.1);
        let stroke = Stroke {
            width,
            line_cap: LineCap::Round,
            ..Stroke::default()
        };
        if let Some(path) = pb.finish() {
            p.stroke_path(&path, &paint(), &stroke, Transform::identity(), None);
        }
    }
}

/// The stick figure's limbs: spine, two arms, two legs (canvas 256², y down).
const STICK: [((f32, f32), (f32, f32)); 5] = [
    ((128.0, 60.0), (128.0, 150.0)),
    ((128.0, 85.0), (70.0, 140.0)),
    ((128.0, 85.0), (186.0, 140.0)),
    ((128.0, 150.0), (95.0, 232.0)),
    ((128.0, 150.0), (161.0, 232.0)),
];
const STICK_HALF_WIDTH: f32 = 8.0;
const HEAD: (f32, f32, f32) = (128.0, 40.0, 22.0);

/// A stick figure: a round head and capsule limbs; with `noise`, bumps along the limbs.
pub fn stick_figure(noise: bool) -> RgbaImage {
    let mut p = Pixmap::new(256, 256).unwrap();
    capsules(&mut p, &STICK, 2.0 * STICK_HALF_WIDTH);
    if let Some(c) = PathBuilder::from_circle(HEAD.0, HEAD.1, HEAD.2) {
        p.fill_path(&c, &paint(), FillRule::Winding, Transform::identity(), None);
    }
    if noise {
        bumps(&mut p, &STICK[1..], STICK_HALF_WIDTH, 2.5);
    }
    to_rgba(&p)
}

/// The stick figure's limb tips (hands, feet), canvas px.
pub fn stick_tips() -> Vec<Point> {
    STICK[1..]
        .iter()
        .map(|s| Point::new(s.1 .0 as f64, s.1 .1 as f64))
        .collect()
}

/// A five-pointed star centered on a 256² canvas; with `noise`, its outline jittered.
pub fn star(noise: bool) -> (RgbaImage, Vec<Point>) {
    let (cx, cy, outer, inner) = (128.0f32, 132.0f32, 110.0f32, 42.0f32);
    let mut rng = Lcg(3);
    let mut pb = PathBuilder::new();
    let mut tips = Vec::new();
    let steps = 10 * 12;
    for k in 0..steps {
        // Between the 10 star vertices, 12 points along each edge (jittered with noise).
        let (e, f) = (k / 12, (k % 12) as f32 / 12.0);
        let vertex = |e: usize| {
            let a = -PI / 2.0 + e as f32 * PI / 5.0;
            let r = if e.is_multiple_of(2) { outer } else { inner };
            (cx + r * a.cos(), cy + r * a.sin())
        };
        let (a, b) = (vertex(e), vertex((e + 1) % 10));
        let mut x = a.0 + (b.0 - a.0) * f;
        let mut y = a.1 + (b.1 - a.1) * f;
        if noise && f > 0.0 {
            x += 3.0 * (rng.next() - 0.5);
            y += 3.0 * (rng.next() - 0.5);
        }
        if k == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
        if e.is_multiple_of(2) && k % 12 == 0 {
            tips.push(Point::new(a.0 as f64, a.1 as f64));
        }
    }
    pb.close();
    let mut p = Pixmap::new(256, 256).unwrap();
    p.fill_path(
        &pb.finish().unwrap(),
        &paint(),
        FillRule::Winding,
        Transform::identity(),
        None,
    );
    (to_rgba(&p), tips)
}

/// A letter-like "P": a stem with a ring-shaped bowl (a hole).
pub fn letter_p() -> (RgbaImage, Vec<Point>) {
    let mut p = Pixmap::new(256, 256).unwrap();
    capsules(&mut p, &[((80.0, 40.0), (80.0, 220.0))], 32.0);
    let mut ring = PathBuilder::new();
    ring.push_circle(120.0, 95.0, 58.0);
    ring.push_circle(120.0, 95.0, 28.0);
    p.fill_path(
        &ring.finish().unwrap(),
        &paint(),
        FillRule::EvenOdd,
        Transform::identity(),
        None,
    );
    // The stem's foot is the one limb tip.
    (to_rgba(&p), vec![Point::new(80.0, 220.0)])
}

/// An ellipse-like blob; with `noise`, a jittered outline.
pub fn blob(noise: bool) -> RgbaImage {
    let mut rng = Lcg(11);
    let mut pb = PathBuilder::new();
    let n = 180;
    for k in 0..n {
        let a = k as f32 * 2.0 * PI / n as f32;
        let jitter = if noise { 4.0 * (rng.next() - 0.5) } else { 0.0 };
        let (x, y) = (
            128.0 + (95.0 + jitter) * a.cos(),
            128.0 + (60.0 + jitter) * a.sin(),
        );
        if k == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
    }
    pb.close();
    let mut p = Pixmap::new(256, 256).unwrap();
    p.fill_path(
        &pb.finish().unwrap(),
        &paint(),
        FillRule::Winding,
        Transform::identity(),
        None,
    );
    to_rgba(&p)
}

/// A quadruped seen from the side: a horizontal body, a head up front (left), a tail at the
/// back, four legs.
pub fn quadruped() -> RgbaImage {
    let mut p = Pixmap::new(256, 256).unwrap();
    capsules(&mut p, &[((80.0, 110.0), (180.0, 110.0))], 44.0);
    capsules(
        &mut p,
        &[
            ((70.0, 100.0), (45.0, 60.0)),
            ((185.0, 100.0), (235.0, 70.0)),
            ((75.0, 120.0), (70.0, 215.0)),
            ((95.0, 120.0), (100.0, 215.0)),
            ((165.0, 120.0), (160.0, 215.0)),
            ((185.0, 120.0), (192.0, 215.0)),
        ],
        14.0,
    );
    if let Some(c) = PathBuilder::from_circle(40.0, 50.0, 22.0) {
        p.fill_path(&c, &paint(), FillRule::Winding, Transform::identity(), None);
    }
    to_rgba(&p)
}
