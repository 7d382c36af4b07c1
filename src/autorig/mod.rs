//! Automatic rigging: skeletons, cages and point handles proposed from the drawing.
//!
//! In: one or more straight-alpha RGBA layers on one canvas (with their part names) and
//! [`AutorigOptions`]. Out: a [`Proposal`]: a [`Handles`] value (the handles file of
//! `docs/formats.md`, canvas px, validated) that a person can edit and pass to `sinew rig --handles`, plus notes
//! for the person.
//!
//! - One image, or any images with a template: the union silhouette is traced as `sinew rig`
//!   traces it ([`shape`]), its medial axis is computed and pruned ([`medial`]) and turned into
//!   a bone tree ([`skeleton`]) or fitted to a humanoid/quadruped template ([`template`]).
//! - Several images without a template: one bone per part along its principal axis, parented
//!   through overlaps ([`layers`]); each part's bones are bound to that part (`bind`), as in
//!   cutout animation.
//! - `cage_vertices`: a containing cage of the union ([`cage`]); `point_count`: point handles by
//!   geodesic farthest-point sampling ([`points`]), each carried by its nearest bone among those
//!   that may weigh the layer under it.
//!   [`preview`] draws the result.

pub mod attach;
pub mod budget;
pub mod cage;
pub mod choose;
pub mod labels;
pub mod layers;
pub mod medial;
pub mod points;
pub mod preview;
pub mod shape;
pub mod skeleton;
pub mod template;

pub use cage::{CageError, CageOptions};
pub use medial::{MedialError, MedialOptions};
pub use points::PointOptions;
pub use preview::draw_preview;
pub use skeleton::{ProtoBone, SkeletonOptions};
pub use template::{Template, TemplateChoice};

use crate::geom::Point;
use crate::rig::{Bone, Cage, HandleError, Handles, PointHandle};
use crate::trace::{TraceError, TraceOptions};
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use shape::Shape;
use std::collections::{BTreeMap, HashSet};

/// Everything autorig can be asked for. Defaults: bones only, traced as `sinew rig` traces.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AutorigOptions {
    /// Tracing, as the rig will be traced (default: the rig's defaults), so that proposed
    /// handles lie inside the rig's meshes.
    pub trace: TraceOptions,
    pub medial: MedialOptions,
    /// Bone splitting and the bone budget (`max_bones`).
    pub skeleton: SkeletonOptions,
    /// The template: one named, none, or (default) the one the layer names or the drawing
    /// suggest.
    pub template: TemplateChoice,
    /// Propose a cage of at most this many vertices. Default: none.
    pub cage_vertices: Option<usize>,
    pub cage: CageOptions,
    /// Propose this many point handles. Default 0.
    pub point_count: usize,
    pub points: PointOptions,
}

/// One input layer.
#[derive(Clone, Copy, Debug)]
pub struct LayerRef<'a> {
    pub name: &'a str,
    pub image: &'a RgbaImage,
    /// Canvas position of the image's top-left pixel, px.
    pub offset_px: [i32; 2],
    /// The canvas the layer lies on, px.
    pub canvas_px: [u32; 2],
}

impl<'a> LayerRef<'a> {
    /// A layer whose image is the whole canvas.
    pub fn whole(name: &'a str, image: &'a RgbaImage) -> Self {
        LayerRef {
            name,
            image,
            offset_px: [0, 0],
            canvas_px: [image.width(), image.height()],
        }
    }
}

/// What autorig proposes.
#[derive(Clone, Debug, PartialEq)]
pub struct Proposal {
    pub handles: Handles,
    /// The template the proposal follows (`None`: none).
    pub template: Option<Template>,
    /// Remarks for the person (a part with nothing to trace, a fallback taken).
    pub notes: Vec<String>,
}

/// What went wrong.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AutorigError {
    #[error("no input images")]
    NoLayers,
    #[error("layer '{0}' is not the size of the first layer")]
    SizeMismatch(String),
    #[error(transparent)]
    Trace(#[from] TraceError),
    #[error("no opaque region of at least {0} px² to rig")]
    NoShape(f64),
    #[error(transparent)]
    Medial(#[from] MedialError),
    #[error("cage: {0}")]
    Cage(#[from] CageError),
    #[error("the proposed handles are invalid: {0}")]
    Handles(#[from] HandleError),
    #[error("invalid autorig option: {0}")]
    InvalidOptions(String),
    #[error(
        "{parts} layers to rig, each a body part with bones of its own: at most {max} \
         (a rig's weight columns); merge the layers that move together, or hide those that \
         are not body parts"
    )]
    TooManyParts { parts: usize, max: usize },
}

/// Proposes handles for `layers` (back to front, one canvas). `pivots` are bone origins the
/// artist marked in a layered file (see [`crate::io::layered::Pivot`]): with several layers,
/// the bone of a group's first part (the one joined to a part outside the group, or a root)
/// starts at the group's pivot; a pivot outside any group starts the skeleton's root bone.
pub fn autorig(
    layers: &[LayerRef],
    pivots: &[crate::io::layered::Pivot],
    options: &AutorigOptions,
) -> Result<Proposal, AutorigError> {
    let first = layers.first().ok_or(AutorigError::NoLayers)?;
    if let Some(l) = layers.iter().find(|l| l.canvas_px != first.canvas_px) {
        return Err(AutorigError::SizeMismatch(l.name.to_string()));
    }
    check_options(&options.skeleton)?;
    if layers.len() > 1 {
        check_part_count(layers, &options.trace)?;
    }
    let union = shape::union_alpha(layers);
    let silhouette = Shape::trace(&union, &options.trace)?
        .ok_or(AutorigError::NoShape(options.trace.min_area_px2))?;
    let mut notes = Vec::new();
    let min_bone_px = budget::min_bone_length_px(&options.skeleton, &silhouette);
    let so = &SkeletonOptions {
        min_bone_px,
        ..options.skeleton.clone()
    };
    let (bones, bind, template) = if layers.len() > 1 {
        layered_bones(layers, pivots, &silhouette, options, so, &mut notes)?
    } else {
        let (bones, template) = drawing_bones(&silhouette, options, so, &mut notes)?;
        (bones, BTreeMap::new(), template)
    };
    let points = points::propose_points(&silhouette, options.point_count, &options.points)
        .into_iter()
        .enumerate()
        .map(|(k, p)| PointHandle {
            name: format!("point_{}", k + 1),
            at: p,
            parent: carrier(&bones, &bind, layers, options.trace.alpha_threshold, p),
        })
        .collect();
    let cages = match options.cage_vertices {
        Some(n) => {
            let ring = cage::propose_cage(&union, options.trace.alpha_threshold, n, &options.cage)?;
            vec![Cage {
                name: "cage".into(),
                polygon: ring,
            }]
        }
        None => Vec::new(),
    };
    let handles = Handles {
        bones,
        points,
        cages,
        regions: Vec::new(),
        bind,
        ik: Vec::new(),
        physics: Vec::new(),
    };
    handles.validate()?;
    Ok(Proposal {
        handles,
        template,
        notes,
    })
}

fn check_options(so: &SkeletonOptions) -> Result<(), AutorigError> {
    let positive = so.bend_ratio.is_finite() && so.bend_ratio > 0.0;
    let fraction_ok = |f: f64| f.is_finite() && (0.0..=1.0).contains(&f);
    if !(positive && so.min_bone_px.is_finite() && so.min_bone_px >= 0.0) {
        return Err(AutorigError::InvalidOptions(
            "bend_ratio must be positive and min_bone_px at least 0".into(),
        ));
    }
    if !(fraction_ok(so.min_bone_fraction) && fraction_ok(so.prop_branch_fraction)) {
        return Err(AutorigError::InvalidOptions(
            "min_bone_fraction and prop_branch_fraction must lie in [0, 1]".into(),
        ));
    }
    if so.prop_max_bones == 0 {
        return Err(AutorigError::InvalidOptions(
            "prop_max_bones must be at least 1".into(),
        ));
    }
    if so.max_bones == Some(0) {
        return Err(AutorigError::InvalidOptions(
            "the bone budget must be at least 1".into(),
        ));
    }
    Ok(())
}

/// The bones of one drawing (a single image: its union silhouette), fitted to the chosen
/// template, with the budget applied; and the template used.
fn drawing_bones(
    silhouette: &Shape,
    options: &AutorigOptions,
    so: &SkeletonOptions,
    notes: &mut Vec<String>,
) -> Result<(Vec<Bone>, Option<Template>), AutorigError> {
    let min_bone_px = so.min_bone_px;
    // Limbs leaving a round torso meet within its radius: merged, the arms' and the legs'
    // junctions would be one, and a template could not tell chest from pelvis.
    let unmerged = MedialOptions {
        junction_merge_ratio: 0.0,
        ..options.medial.clone()
    };
    let (mut bones, template) = match options.template.fixed() {
        Some(Some(t)) => {
            let axis = medial::medial_axis(silhouette, &unmerged)?;
            match template::fit_template(&axis, silhouette, t, so) {
                Some(bones) => (bones, Some(t)),
                None => {
                    notes.push(format!(
                        "the drawing does not match the {} template (no assignment of its \
                         limbs to the shape's extremities fits): bones from the medial axis",
                        template_name(Some(t))
                    ));
                    let axis = medial::medial_axis(silhouette, &options.medial)?;
                    (skeleton::medial_skeleton(&axis, silhouette, so), Some(t))
                }
            }
        }
        Some(None) => {
            let axis = medial::medial_axis(silhouette, &options.medial)?;
            (skeleton::medial_skeleton(&axis, silhouette, so), None)
        }
        None => {
            let (class, why) = choose::classify(silhouette);
            notes.push(format!("template: {} ({why})", template_name(class)));
            let axis = medial::medial_axis(silhouette, &unmerged)?;
            match class.map(|t| (t, choose::fit_plausibly(&axis, silhouette, t, so))) {
                Some((t, Ok(bones))) => (bones, Some(t)),
                Some((t, Err(doubt))) => {
                    // No limb names on what may be a prop: a clean generic skeleton.
                    notes.push(format!(
                        "the drawing does not match the {} template ({doubt}): bones from the \
                         medial axis",
                        template_name(Some(t))
                    ));
                    let axis = medial::medial_axis(silhouette, &options.medial)?;
                    (skeleton::medial_skeleton(&axis, silhouette, so), Some(t))
                }
                None => {
                    let axis = medial::medial_axis(silhouette, &options.medial)?;
                    (skeleton::medial_skeleton(&axis, silhouette, so), None)
                }
            }
        }
    };
    if bones.is_empty() {
        // A round blob has no significant axis: one bone along its principal axis.
        if let Some(b) = principal_bone(silhouette) {
            notes.push("no significant medial axis: one bone along the principal axis".into());
            bones.push(b);
        }
    }
    let added = budget::rig_free_pieces(&mut bones, silhouette, min_bone_px);
    if added > 0 {
        notes.push(format!(
            "{added} separate pieces got a bone each (piece_N), parented to the nearest bone"
        ));
    }
    budget::keep_inside(&mut bones, silhouette, min_bone_px);
    budget::drop_short_bones(&mut bones, silhouette, min_bone_px);
    let max_bones = budget::bone_budget(so, template);
    skeleton::limit_bones(&mut bones, Some(max_bones), silhouette);
    let min_bones = budget::bone_minimum(so, template);
    budget::reach_minimum(&mut bones, min_bones.min(max_bones), min_bone_px);
    Ok((name_bones(bones), template))
}

/// Refuses layered input with more drawn layers (any pixel at least the trace's alpha
/// threshold) than a rig has weight columns: every part gets a bone. Counted before anything is
/// traced: each traced part holds a canvas-sized grid (10,000 small layers on a 1200² canvas
/// took 13 s and 1.5 GB only to be refused at the end).
fn check_part_count(layers: &[LayerRef], trace: &TraceOptions) -> Result<(), AutorigError> {
    let max = crate::rig::handles::MAX_WEIGHT_COLUMNS;
    let drawn = layers
        .iter()
        .filter(|l| l.image.pixels().any(|p| p[3] >= trace.alpha_threshold))
        .count();
    if drawn > max {
        return Err(AutorigError::TooManyParts { parts: drawn, max });
    }
    Ok(())
}

/// The bones of a layered character: every layer a body part with its own bones
/// ([`layers::layered_skeleton`]), each bone bound to its part; the template from the
/// option, else from the layer names ([`labels::template_from_labels`]), else from the
/// drawing's shape.
#[allow(clippy::type_complexity)]
fn layered_bones(
    layers: &[LayerRef],
    pivots: &[crate::io::layered::Pivot],
    silhouette: &Shape,
    options: &AutorigOptions,
    so: &SkeletonOptions,
    notes: &mut Vec<String>,
) -> Result<(Vec<Bone>, BTreeMap<String, Vec<String>>, Option<Template>), AutorigError> {
    let mut shapes = Vec::new();
    for layer in layers {
        match Shape::trace_placed(layer, &options.trace) {
            Ok(Some(s)) => shapes.push((layer.name, s)),
            Ok(None) | Err(TraceError::NoOpaquePixels { .. }) => notes.push(format!(
                "layer '{}' has nothing to trace: no bone",
                layer.name
            )),
            Err(e) => return Err(e.into()),
        }
    }
    let mut part_labels: Vec<labels::Label> =
        shapes.iter().map(|(name, _)| labels::label(name)).collect();
    let axes: Vec<Option<layers::PrincipalAxis>> = shapes
        .iter()
        .map(|(_, s)| layers::principal_axis(s))
        .collect();
    let centroids: Vec<Point> = axes
        .iter()
        .map(|a| a.map_or(Point::origin(), |a| a.centroid))
        .collect();
    attach::complete_sides(&mut part_labels, &centroids);
    let template = match options.template.fixed() {
        Some(t) => t,
        None => match labels::template_from_labels(&part_labels) {
            Some((t, why)) => {
                notes.push(format!("template: {} ({why})", template_name(t)));
                t
            }
            None => {
                let (class, why) = choose::classify(silhouette);
                notes.push(format!(
                    "template: {} ({why}; the layer names tell no body parts, so bones are \
                     named after the layers)",
                    template_name(class)
                ));
                class
            }
        },
    };
    let parts: Vec<layers::Part> = shapes
        .iter()
        .zip(part_labels.iter().zip(&axes))
        .map(|((name, shape), (&label, &axis))| layers::Part {
            name,
            shape,
            label,
            axis,
        })
        .collect();
    let skeleton = layers::layered_skeleton(&parts, pivots, template, &options.medial, so)?;
    // Each bone weighs only its own part.
    let mut bind: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for (b, &p) in skeleton.bones.iter().zip(&skeleton.bone_part) {
        if let Some(name) = &b.name {
            bind.entry(name.clone())
                .or_default()
                .push(parts[p].name.to_string());
        }
    }
    let mut bones = skeleton.bones;
    if let Some(max) = options.skeleton.max_bones {
        skeleton::limit_bones(&mut bones, Some(max), silhouette);
    }
    let bones = name_bones(bones);
    bind.retain(|name, _| bones.iter().any(|b| &b.name == name));
    Ok((bones, bind, template))
}

/// A template's name as the person writes it (`humanoid`, `quadruped`, `none`).
pub fn template_name(t: Option<Template>) -> &'static str {
    match t {
        None => "none",
        Some(Template::Humanoid) => "humanoid",
        Some(Template::Quadruped) => "quadruped",
    }
}

/// The bone that carries a proposed point at `p` (canvas px), so that the point turns with the
/// limb it sits on: the nearest (distance to its head–tail segment; the first of equals) among
/// the bones that may weigh a layer opaque at `p` (alpha at least `alpha_threshold`; a bone
/// `bind` does not list weighs every layer), or among all bones when none may.
fn carrier(
    bones: &[Bone],
    bind: &BTreeMap<String, Vec<String>>,
    layers: &[LayerRef],
    alpha_threshold: u8,
    p: Point,
) -> Option<String> {
    let under: Vec<&str> = layers
        .iter()
        .filter(|l| {
            let (x, y) = (
                (p.x - f64::from(l.offset_px[0])).floor(),
                (p.y - f64::from(l.offset_px[1])).floor(),
            );
            let inside = x >= 0.0
                && y >= 0.0
                && x < f64::from(l.image.width())
                && y < f64::from(l.image.height());
            inside && l.image.get_pixel(x as u32, y as u32)[3] >= alpha_threshold
        })
        .map(|l| l.name)
        .collect();
    let weighs_under = |b: &&Bone| {
        bind.get(&b.name)
            .is_none_or(|parts| parts.iter().any(|part| under.contains(&part.as_str())))
    };
    let distance = |b: &&Bone| crate::geom::segment_distance(p, b.head, b.tail).0;
    let nearest = |candidates: Vec<&Bone>| {
        candidates
            .into_iter()
            .min_by(|a, b| distance(a).total_cmp(&distance(b)))
            .map(|b| b.name.clone())
    };
    let allowed: Vec<&Bone> = bones.iter().filter(weighs_under).collect();
    if allowed.is_empty() {
        nearest(bones.iter().collect())
    } else {
        nearest(allowed)
    }
}

/// One bone along the principal axis of `shape`, through its centroid, shortened to stay
/// inside.
fn principal_bone(shape: &Shape) -> Option<ProtoBone> {
    let axis = layers::principal_axis(shape)?;
    let [t0, t1] = axis.extent;
    // Shrink both ends toward the centroid until the segment lies inside.
    let mut scale = 0.9;
    while scale > 0.05 {
        let (a, b) = (axis.at(scale * t0), axis.at(scale * t1));
        if (b - a).norm() > 1e-6 && shape.segment_inside(a, b) {
            let (head, tail) = if a.y >= b.y { (a, b) } else { (b, a) };
            return Some(ProtoBone {
                head,
                tail,
                parent: None,
                name: None,
            });
        }
        scale *= 0.8;
    }
    None
}

/// Gives unnamed bones `bone_N` names (unique) and resolves parents to names.
fn name_bones(bones: Vec<ProtoBone>) -> Vec<Bone> {
    let mut used: HashSet<String> = bones.iter().filter_map(|b| b.name.clone()).collect();
    let mut counter = 0;
    let names: Vec<String> = bones
        .iter()
        .map(|b| match &b.name {
            Some(n) => n.clone(),
            None => loop {
                counter += 1;
                let candidate = format!("bone_{counter}");
                if used.insert(candidate.clone()) {
                    break candidate;
                }
            },
        })
        .collect();
    bones
        .iter()
        .zip(&names)
        .map(|(b, name)| Bone {
            name: name.clone(),
            parent: b.parent.map(|p| names[p].clone()),
            head: round_px(b.head),
            tail: round_px(b.tail),
        })
        .collect()
}

/// Coordinates rounded to 1/1000 px, so files stay readable (and stay inside: the rounding is
/// far below the distance of any axis point to the outline).
fn round_px(p: Point) -> Point {
    p.map(|v| (v * 1000.0).round() / 1000.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn more_parts_than_weight_columns_are_refused_before_the_part_tree() {
        let max = crate::rig::handles::MAX_WEIGHT_COLUMNS;
        // One 12 × 12 blob per layer on a grid; each placed at its own cell of the canvas.
        let blob = RgbaImage::from_fn(12, 12, |x, y| {
            let inside = (2..10).contains(&x) && (2..10).contains(&y);
            image::Rgba([90, 60, 30, if inside { 255 } else { 0 }])
        });
        let cols = 20;
        let names: Vec<String> = (0..=max).map(|i| format!("part {i}")).collect();
        let rigged = |n: usize| {
            let canvas_px = [cols as u32 * 16, (n.div_ceil(cols) as u32) * 16];
            let layers: Vec<LayerRef> = names[..n]
                .iter()
                .enumerate()
                .map(|(i, name)| LayerRef {
                    name,
                    image: &blob,
                    offset_px: [(i % cols) as i32 * 16, (i / cols) as i32 * 16],
                    canvas_px,
                })
                .collect();
            autorig(&layers, &[], &AutorigOptions::default())
        };
        assert_eq!(
            rigged(max + 1).map(|_| ()),
            Err(AutorigError::TooManyParts {
                parts: max + 1,
                max
            })
        );
        // At the limit the parts are rigged (or refused for another reason, never this one).
        assert!(!matches!(
            rigged(max),
            Err(AutorigError::TooManyParts { .. })
        ));
    }

    #[test]
    fn a_point_is_carried_by_the_nearest_bone_that_weighs_the_layer_under_it() {
        // "body" opaque over x < 100, "arm" over x ≥ 100 (two 200 × 100 layers).
        let layer = |opaque: std::ops::Range<u32>| {
            RgbaImage::from_fn(200, 100, |x, _| {
                image::Rgba([0, 0, 0, if opaque.contains(&x) { 255 } else { 0 }])
            })
        };
        let (body, arm) = (layer(0..100), layer(100..200));
        let layers = [LayerRef::whole("body", &body), LayerRef::whole("arm", &arm)];
        let bone = |name: &str, head: [f64; 2], tail: [f64; 2]| Bone {
            name: name.into(),
            parent: None,
            head: head.into(),
            tail: tail.into(),
        };
        let bones = [
            bone("spine", [10.0, 20.0], [10.0, 80.0]),
            bone("upper_arm", [100.0, 50.0], [190.0, 50.0]),
        ];
        let mut bind = BTreeMap::new();
        bind.insert("spine".to_string(), vec!["body".to_string()]);
        bind.insert("upper_arm".to_string(), vec!["arm".to_string()]);
        let carrier_at = |bind: &BTreeMap<String, Vec<String>>, x: f64| {
            carrier(&bones, bind, &layers, 1, Point::new(x, 50.0))
        };
        // On the body, 5 px from the arm's bone and 85 px from the spine: the spine carries it.
        assert_eq!(carrier_at(&bind, 95.0).as_deref(), Some("spine"));
        assert_eq!(carrier_at(&bind, 105.0).as_deref(), Some("upper_arm"));
        // Unbound bones weigh every layer: then the nearest wins.
        assert_eq!(
            carrier_at(&BTreeMap::new(), 95.0).as_deref(),
            Some("upper_arm")
        );
        // Under no layer (beyond the canvas), the nearest of all.
        assert_eq!(carrier_at(&bind, 250.0).as_deref(), Some("upper_arm"));
    }
}
