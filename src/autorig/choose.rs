//! Which template a drawing is: humanoid, quadruped or neither, from its shape alone, and
//! whether a template's fit is plausible.
//!
//! In: the drawing's [`Shape`] (canvas px, y down); for a fit, its medial axis (unmerged
//! junctions, as [`super::template`] fits on) and the [`SkeletonOptions`].
//!
//! [`classify`] reads the silhouette's box and the runs of pixels across its rows (legs
//! below, a body across the middle). [`fit_plausibly`] fits a template ([`fit_template`])
//! and judges the fit by what its named bones say of the body in the drawing's box (heights
//! as fractions of the box; the axis's ends as extremities first, then the cuts of its
//! cycles, [`super::template::Extremities`]), so that a fit that would put limb names on props is refused
//! (the caller then rigs the medial axis):
//! - humanoid: the head above the hips; each leg's chain (its named bones and the bones
//!   hanging below them: a foot, a shoe) reaches the lowest [`FOOT_BAND`] of the box and ends
//!   at least [`MIN_LEG_FRACTION`] of the height from the hips (or the thigh's start, when
//!   higher); legs long enough for a body and not arms alone. A bust (head and shoulders,
//!   nothing reaching the bottom as legs do) is no humanoid here: its arms and head stay on
//!   the medial axis.
//! - quadruped: a spine more level than upright, four legs reaching the lowest
//!   [`FOOT_BAND`], the box wider than tall.

use super::medial::AxisGraph;
use super::shape::Shape;
use super::skeleton::{ProtoBone, SkeletonOptions};
use super::template::{fit_template_with, Template, EXTREMITIES};
use crate::geom::Point;

/// A foot must end in the lowest this fraction of the box.
pub const FOOT_BAND: f64 = 0.25;
/// A humanoid's leg (from the hips to the lowest end of its chain) spans at least this
/// fraction of the box's height.
pub const MIN_LEG_FRACTION: f64 = 0.2;
/// A quadruped's box is at least this much wider than tall (width / height).
pub const QUADRUPED_MIN_ASPECT: f64 = 0.9;

/// The drawing's box: top-left and size, px.
struct Frame {
    lo: Point,
    w: f64,
    h: f64,
}

impl Frame {
    fn of(shape: &Shape) -> Frame {
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in shape.rings().flatten() {
            lo = [lo[0].min(p.x), lo[1].min(p.y)];
            hi = [hi[0].max(p.x), hi[1].max(p.y)];
        }
        Frame {
            lo: Point::new(lo[0], lo[1]),
            w: (hi[0] - lo[0]).max(1.0),
            h: (hi[1] - lo[1]).max(1.0),
        }
    }

    /// Height in the box, 0 at the top and 1 at the bottom.
    fn v(&self, p: Point) -> f64 {
        (p.y - self.lo.y) / self.h
    }
}

fn named<'a>(bones: &'a [ProtoBone], name: &str) -> Option<&'a ProtoBone> {
    bones.iter().find(|b| b.name.as_deref() == Some(name))
}

/// The lowest point (largest y) of bone `b` and the bones hanging below it: where a limb's
/// chain ends, past the named lower bone (a foot, a shoe left to extra bones).
fn chain_bottom(bones: &[ProtoBone], b: usize) -> Point {
    let mut below = vec![false; bones.len()];
    below[b] = true;
    let mut bottom = bones[b].tail;
    // Parents come before their children.
    for k in b + 1..bones.len() {
        if bones[k].parent.is_some_and(|p| below[p]) {
            below[k] = true;
            if bones[k].tail.y > bottom.y {
                bottom = bones[k].tail;
            }
        }
    }
    bottom
}

/// Why a humanoid fit is implausible, or `None` when it is plausible. A leg is measured from
/// the hips to the lowest end of its chain (a thigh hidden under a skirt or a coat is drawn
/// short, and the foot may hang below the named shin as an extra bone).
fn humanoid_doubt(bones: &[ProtoBone], frame: &Frame) -> Option<String> {
    let hip = named(bones, "hip")?;
    let head = named(bones, "head").or_else(|| named(bones, "neck"))?;
    if frame.v(head.tail) >= frame.v(hip.head) {
        return Some("its head is not above its hips".into());
    }
    for side in ["l", "r"] {
        let lower = bones
            .iter()
            .position(|b| b.name.as_deref() == Some(&format!("leg_lower_{side}")));
        let (Some(upper), Some(lower)) = (named(bones, &format!("leg_upper_{side}")), lower) else {
            return Some("a leg is missing".into());
        };
        let foot = chain_bottom(bones, lower);
        if frame.v(foot) < 1.0 - FOOT_BAND {
            return Some("its legs do not reach the ground".into());
        }
        // From the higher of the hips and the thigh's start (the root may sit between the
        // legs, below where their axis paths meet).
        let top = if upper.head.y < hip.head.y {
            upper.head
        } else {
            hip.head
        };
        if (foot - top).norm() < MIN_LEG_FRACTION * frame.h {
            return Some("its legs are too short for a body".into());
        }
    }
    None
}

/// Why a quadruped fit is implausible, or `None` when it is plausible.
fn quadruped_doubt(bones: &[ProtoBone], frame: &Frame) -> Option<String> {
    if frame.w / frame.h < QUADRUPED_MIN_ASPECT {
        return Some("it is taller than wide".into());
    }
    let hip = named(bones, "hip")?;
    let chest = named(bones, "chest")?;
    let spine = chest.tail - hip.head;
    if spine.y.abs() > spine.x.abs() {
        return Some("its spine is upright".into());
    }
    for end in ["front", "back"] {
        for side in ["l", "r"] {
            let Some(lower) = named(bones, &format!("leg_{end}_lower_{side}")) else {
                return Some("a leg is missing".into());
            };
            if frame.v(lower.tail) < 1.0 - FOOT_BAND {
                return Some("its legs do not reach the ground".into());
            }
        }
    }
    None
}

/// Rows (fractions of the box's height from the top) where legs are counted.
const LEG_ROWS: [f64; 2] = [0.88, 0.94];
/// A run of opaque pixels narrower than this fraction of the box's width is noise, not a leg.
const MIN_RUN_FRACTION: f64 = 0.015;
/// A leg's run is at most this fraction of the box's width (wider: a bust's shoulders, a
/// dress's hem, a belly).
const MAX_LEG_FRACTION: f64 = 0.3;
/// Wider than tall by this much (width / height): drawn lying or walking on four legs.
const WIDE_ASPECT: f64 = 1.0;
/// Rows across the body's middle (fractions of the height from the top): a quadruped's
/// trunk fills at least [`MIN_TRUNK_FRACTION`] of the width on one of them.
const TRUNK_ROWS: [f64; 3] = [0.4, 0.5, 0.6];
const MIN_TRUNK_FRACTION: f64 = 0.45;

/// The runs of inside pixels along the row at height `v` of the box (fractions of the width).
fn runs(shape: &Shape, frame: &Frame, v: f64) -> Vec<f64> {
    let y = (frame.lo.y + v * frame.h).floor();
    if y < 0.0 || y >= f64::from(shape.height) {
        return Vec::new();
    }
    let (w, row) = (shape.width as usize, y as usize);
    let x0 = frame.lo.x.max(0.0) as usize;
    let x1 = ((frame.lo.x + frame.w).ceil() as usize + 1).min(w);
    let mut out = Vec::new();
    let mut run = 0usize;
    for x in x0..=x1 {
        if x < x1 && shape.inside[row * w + x] {
            run += 1;
        } else if run > 0 {
            out.push(run as f64 / frame.w);
            run = 0;
        }
    }
    out.retain(|&r| r >= MIN_RUN_FRACTION);
    out
}

/// The top of the drawing whose centre tells where the head is (fraction of the height).
const HEAD_BAND: f64 = 0.12;
/// A head this far (fraction of the width) to one side of the drawing's centre is carried
/// ahead of the body, as a standing animal carries it; a person's head sits above the middle.
const HEAD_ASIDE_FRACTION: f64 = 0.12;
/// Wider than tall by more than this, with no legs and the head above the middle, is a
/// long body (a fish, a snake), not a figure holding something out.
const FIGURE_MAX_ASPECT: f64 = 1.5;

/// How far the top [`HEAD_BAND`] of the drawing lies to one side of the whole drawing's
/// centre, as a fraction of the width (centroids of the inside pixels).
fn head_offset(shape: &Shape, frame: &Frame) -> f64 {
    let w = shape.width as usize;
    let head_rows = frame.lo.y + HEAD_BAND * frame.h;
    let (mut all, mut top) = ((0.0, 0usize), (0.0, 0usize));
    for (k, _) in shape.inside.iter().enumerate().filter(|(_, &i)| i) {
        let (x, y) = ((k % w) as f64 + 0.5, (k / w) as f64 + 0.5);
        all = (all.0 + x, all.1 + 1);
        if y <= head_rows {
            top = (top.0 + x, top.1 + 1);
        }
    }
    if all.1 == 0 || top.1 == 0 {
        return 0.0;
    }
    (top.0 / top.1 as f64 - all.0 / all.1 as f64) / frame.w
}

/// What the drawing's shape says it is, and why, from its box, the narrow runs of pixels
/// across its lowest rows (legs) and where its top lies (the head):
/// - standing on three or more legs and wider than tall, or on two or more with the head
///   carried to one side ([`HEAD_ASIDE_FRACTION`]): a quadruped;
/// - wider than tall with nothing standing under it: no template (a fish, a bird in flight),
///   unless its head sits above its middle and it is not long ([`FIGURE_MAX_ASPECT`]): a
///   figure holding something out; on a wide base: a bust;
/// - upright on three or more strands with the head above the middle: no template (a kite
///   and its tails, a tassel); anything else upright: a humanoid.
pub fn classify(shape: &Shape) -> (Option<Template>, String) {
    let frame = Frame::of(shape);
    let aspect = frame.w / frame.h;
    // Legs: narrow runs on every leg row (the fewest); a wide run is a base, not legs.
    let (legs, wide) = LEG_ROWS
        .iter()
        .map(|&v| {
            let r = runs(shape, &frame, v);
            let legs = r.iter().filter(|&&x| x <= MAX_LEG_FRACTION).count();
            let wide = r.iter().any(|&x| x > MAX_LEG_FRACTION);
            (legs, wide)
        })
        .fold((usize::MAX, false), |(l, w), (l2, w2)| (l.min(l2), w || w2));
    let trunk = TRUNK_ROWS
        .iter()
        .flat_map(|&v| runs(shape, &frame, v))
        .fold(0.0f64, f64::max);
    let offset = head_offset(shape, &frame);
    let aside = offset.abs() >= HEAD_ASIDE_FRACTION;
    let head = if aside {
        format!(
            "the head {:.0} % of the width to one side",
            100.0 * offset.abs()
        )
    } else {
        "the head above the middle".to_string()
    };
    if legs >= 2 && (aside || (aspect >= WIDE_ASPECT && legs >= 3 && trunk >= MIN_TRUNK_FRACTION)) {
        return (
            Some(Template::Quadruped),
            format!("{aspect:.2} as wide as tall, standing on {legs} legs, {head}"),
        );
    }
    if aspect >= WIDE_ASPECT {
        if wide && !aside {
            return (
                Some(Template::Humanoid),
                format!("{aspect:.2} times wider than tall, on a wide base: a bust"),
            );
        }
        if legs < 2 && (aside || aspect > FIGURE_MAX_ASPECT) {
            return (
                None,
                format!("{aspect:.2} times wider than tall with no legs under it"),
            );
        }
    }
    if legs >= 3 {
        return (
            None,
            format!("upright on {legs} thin strands with {head}: no body a template knows"),
        );
    }
    (
        Some(Template::Humanoid),
        format!("upright ({aspect:.2} as wide as tall) on {legs} legs or a base, {head}"),
    )
}

/// `template` fitted to the drawing, or why it does not fit plausibly.
pub fn fit_plausibly(
    axis: &AxisGraph,
    shape: &Shape,
    template: Template,
    options: &SkeletonOptions,
) -> Result<Vec<ProtoBone>, String> {
    let frame = Frame::of(shape);
    let mut first_doubt = None;
    for ends in EXTREMITIES {
        let Some(bones) = fit_template_with(axis, shape, template, options, ends) else {
            continue;
        };
        let doubt = match template {
            Template::Humanoid => humanoid_doubt(&bones, &frame),
            Template::Quadruped => quadruped_doubt(&bones, &frame),
        };
        match doubt {
            None => return Ok(bones),
            Some(why) => {
                first_doubt.get_or_insert(why);
            }
        }
    }
    Err(first_doubt
        .unwrap_or_else(|| "no assignment of its limbs to the drawing's extremities".to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bone(
        name: Option<&str>,
        head: (f64, f64),
        tail: (f64, f64),
        parent: Option<usize>,
    ) -> ProtoBone {
        ProtoBone {
            head: Point::new(head.0, head.1),
            tail: Point::new(tail.0, tail.1),
            parent,
            name: name.map(str::to_string),
        }
    }

    /// A figure 400 px tall whose coat hides its thighs: the legs' axis paths meet at the
    /// hem (y 300), the named leg bones are short (40 px) and the shoes hang below them as
    /// extra bones. The leg runs from the hips to the shoe's end: plausible.
    #[test]
    fn a_leg_is_measured_from_the_hips_to_the_end_of_its_chain() {
        let frame = Frame {
            lo: Point::new(0.0, 0.0),
            w: 160.0,
            h: 400.0,
        };
        let mut bones = vec![
            bone(Some("hip"), (80.0, 300.0), (80.0, 200.0), None),
            bone(Some("chest"), (80.0, 200.0), (80.0, 100.0), Some(0)),
            bone(Some("head"), (80.0, 70.0), (80.0, 10.0), Some(1)),
        ];
        for (side, x) in [("l", 100.0), ("r", 60.0)] {
            let upper = bones.len();
            bones.push(bone(
                Some(&format!("leg_upper_{side}")),
                (x, 310.0),
                (x, 330.0),
                Some(0),
            ));
            bones.push(bone(
                Some(&format!("leg_lower_{side}")),
                (x, 330.0),
                (x, 350.0),
                Some(upper),
            ));
            bones.push(bone(None, (x, 350.0), (x + 5.0, 395.0), Some(upper + 1)));
        }
        assert_eq!(humanoid_doubt(&bones, &frame), None);
        // Without the shoes the chain ends 50 px below the hips: too short for a body.
        let mut barefoot = bones.clone();
        barefoot.retain(|b| b.name.is_some());
        barefoot[6].parent = Some(5);
        assert_eq!(
            humanoid_doubt(&barefoot, &frame).as_deref(),
            Some("its legs are too short for a body")
        );
        // Arms hanging from a bust's shoulders are no legs: they start low and end near it.
        let mut short = bones.clone();
        short[0].head = Point::new(80.0, 340.0);
        for b in short.iter_mut() {
            if b.name
                .as_deref()
                .is_some_and(|n| n.starts_with("leg_upper"))
            {
                b.head.y = 345.0;
            }
        }
        assert_eq!(
            humanoid_doubt(&short, &frame).as_deref(),
            Some("its legs are too short for a body")
        );
        // The root between the legs, below where their paths meet: the thighs' start counts.
        let mut between = bones.clone();
        between[0].head = Point::new(80.0, 340.0);
        assert_eq!(humanoid_doubt(&between, &frame), None);
    }
}
