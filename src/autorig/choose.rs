//! Which template a drawing is: humanoid, quadruped or neither, from its shape alone.
//!
//! In: the drawing's medial axis (unmerged junctions, as [`super::template`] fits on), its
//! [`Shape`] and the [`SkeletonOptions`]. Out: the template, the fitted bones and a reason
//! for the person, or `None` when no template is plausible (then the caller rigs the medial
//! axis, and no limb names land on props).
//!
//! Each template is fitted ([`fit_template`]) and its fit judged by what its named bones say
//! of the body in the drawing's box (y down, heights as fractions of the box):
//! - humanoid: the head above the hips; each leg reaches the lowest [`FOOT_BAND`] of the
//!   box and is at least [`MIN_LEG_FRACTION`] of the height long; legs long enough for a
//!   body and not arms alone. A bust (head and shoulders, nothing reaching the bottom as
//!   legs do) is no humanoid here: its arms and head stay on the medial axis.
//! - quadruped: a spine more level than upright, four legs reaching the lowest
//!   [`FOOT_BAND`], the box wider than tall.
//!
//! When both are plausible, the box's aspect decides (wider than tall: quadruped).

use super::medial::AxisGraph;
use super::shape::Shape;
use super::skeleton::{ProtoBone, SkeletonOptions};
use super::template::{fit_template, Template};
use crate::geom::Point;

/// A foot must end in the lowest this fraction of the box.
pub const FOOT_BAND: f64 = 0.25;
/// A humanoid's leg (thigh and shin) spans at least this fraction of the box's height.
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

/// Why a humanoid fit is implausible, or `None` when it is plausible.
fn humanoid_doubt(bones: &[ProtoBone], frame: &Frame) -> Option<String> {
    let hip = named(bones, "hip")?;
    let head = named(bones, "head").or_else(|| named(bones, "neck"))?;
    if frame.v(head.tail) >= frame.v(hip.head) {
        return Some("its head is not above its hips".into());
    }
    for side in ["l", "r"] {
        let (Some(upper), Some(lower)) = (
            named(bones, &format!("leg_upper_{side}")),
            named(bones, &format!("leg_lower_{side}")),
        ) else {
            return Some("a leg is missing".into());
        };
        if frame.v(lower.tail) < 1.0 - FOOT_BAND {
            return Some("its legs do not reach the ground".into());
        }
        if (upper.length_px() + lower.length_px()) < MIN_LEG_FRACTION * frame.h {
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

/// The plausible template for the drawing, its fitted bones and why; or, when neither fits
/// plausibly, why not (each template's first doubt).
pub fn choose_template(
    axis: &AxisGraph,
    shape: &Shape,
    options: &SkeletonOptions,
) -> Result<(Template, Vec<ProtoBone>, String), String> {
    let frame = Frame::of(shape);
    let judge = |t: Template, doubt: fn(&[ProtoBone], &Frame) -> Option<String>| {
        match fit_template(axis, shape, t, options) {
            None => Err("no assignment of its limbs to the drawing's extremities".to_string()),
            Some(bones) => match doubt(&bones, &frame) {
                Some(why) => Err(why),
                None => Ok(bones),
            },
        }
    };
    let humanoid = judge(Template::Humanoid, humanoid_doubt);
    let quadruped = judge(Template::Quadruped, quadruped_doubt);
    let aspect = frame.w / frame.h;
    match (humanoid, quadruped) {
        (Ok(h), Ok(q)) => Ok(if aspect > 1.0 {
            (
                Template::Quadruped,
                q,
                format!("both fit; the drawing is {aspect:.2} times wider than tall"),
            )
        } else {
            (
                Template::Humanoid,
                h,
                format!("both fit; the drawing is taller than wide ({aspect:.2})"),
            )
        }),
        (Ok(h), Err(_)) => Ok((
            Template::Humanoid,
            h,
            "two arms, two legs standing on the ground and a head above the hips".into(),
        )),
        (Err(_), Ok(q)) => Ok((
            Template::Quadruped,
            q,
            "four legs standing on the ground under a level spine".into(),
        )),
        (Err(h), Err(q)) => Err(format!("humanoid: {h}; quadruped: {q}")),
    }
}
