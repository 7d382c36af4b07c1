//! From what a format parser read (a raw tree of groups and untrimmed pixel layers) to the
//! [`LayeredImage`] every format gives: tags applied, clipping applied, layers trimmed, name
//! paths and effective visibility and opacity computed, `[merge]` groups flattened.

use super::composite::{bounds, over};
use super::tags::{self, Tagged};
use super::{ArtLayer, BlendMode, LayeredError, LayeredImage, LayeredLimits, Pivot, TreeNode};
use image::RgbaImage;
use std::collections::HashSet;

/// A pixel layer as a parser read it (not trimmed, mask applied).
#[derive(Clone, Debug)]
pub struct RawLayer {
    /// The name in the file, tags included.
    pub name: String,
    pub offset_px: [i32; 2],
    pub image: RgbaImage,
    /// Own opacity in [0, 1].
    pub opacity: f32,
    /// Own visibility.
    pub visible: bool,
    pub blend: BlendMode,
    /// Photoshop's clipping mask: drawn only where the layer below it (in its group) is.
    pub clipped: bool,
}

/// A node of the raw tree, back to front within its group.
#[derive(Clone, Debug)]
pub enum RawNode {
    Group {
        /// The name in the file, tags included.
        name: String,
        visible: bool,
        opacity: f32,
        children: Vec<RawNode>,
    },
    Layer(RawLayer),
}

/// The [`LayeredImage`] of a raw tree; `warnings` are the parser's own so far.
pub fn build_layers(
    canvas_px: [u32; 2],
    nodes: Vec<RawNode>,
    warnings: Vec<String>,
    limits: &LayeredLimits,
) -> Result<LayeredImage, LayeredError> {
    let mut b = Builder {
        out: LayeredImage {
            canvas_px,
            layers: Vec::new(),
            tree: Vec::new(),
            pivots: Vec::new(),
            warnings,
        },
        paths: HashSet::new(),
        limits,
    };
    let at = Context {
        prefix: String::new(),
        visible: true,
        opacity: 1.0,
        depth: 0,
    };
    let tree = b.walk(nodes, &at)?;
    b.out.tree = tree;
    if b.out.layers.is_empty() {
        return Err(LayeredError::NoLayers);
    }
    Ok(b.out)
}

struct Builder<'a> {
    out: LayeredImage,
    paths: HashSet<String>,
    limits: &'a LayeredLimits,
}

/// Where in the tree a walk is: the group path and the groups' combined visibility/opacity.
struct Context {
    prefix: String,
    visible: bool,
    opacity: f32,
    depth: usize,
}

impl Context {
    fn path(&self, name: &str) -> String {
        if self.prefix.is_empty() {
            name.to_string()
        } else {
            format!("{}/{name}", self.prefix)
        }
    }
}

impl Builder<'_> {
    fn warn(&mut self, line: String) {
        self.out.warnings.push(line);
    }

    /// Warns once per tag that sinew does not act on.
    fn report_tags(&mut self, raw: &str, tagged: &Tagged) {
        for tag in &tagged.tags {
            if !tags::ACTED_ON.contains(&tag.kind.as_str()) {
                self.warn(format!(
                    "'{raw}': tag [{}] has no meaning in sinew; ignored",
                    tag.kind
                ));
            }
        }
    }

    fn walk(&mut self, nodes: Vec<RawNode>, at: &Context) -> Result<Vec<TreeNode>, LayeredError> {
        let mut tree = Vec::new();
        // The last unclipped layer of this group: what clipped layers above it clip to.
        let mut clip_base: Option<(RgbaImage, [i32; 2])> = None;
        // `[overlay]`: the layer clips every layer below it in its group (Spine's scripts).
        let mut nodes = nodes;
        if let Some(i) = nodes.iter().rposition(|n| match n {
            RawNode::Layer(l) => tags::parse(&l.name).has("overlay"),
            _ => false,
        }) {
            self.apply_overlay(&mut nodes, i);
        }
        for node in nodes {
            match node {
                RawNode::Group {
                    name,
                    visible,
                    opacity,
                    children,
                } => {
                    clip_base = None;
                    let tagged = tags::parse(&name);
                    if tagged.has("ignore") {
                        continue;
                    }
                    self.report_tags(&name, &tagged);
                    let depth = at.depth + 1;
                    if depth > self.limits.max_depth {
                        return Err(LayeredError::TooDeep {
                            got: depth,
                            limit: self.limits.max_depth,
                        });
                    }
                    let inner = Context {
                        prefix: at.path(&tagged.name),
                        visible: at.visible && visible,
                        opacity: at.opacity * opacity,
                        depth,
                    };
                    if tagged.has("merge") {
                        if let Some(layer) =
                            self.merge(&name, &tagged, children, visible, opacity, &inner)?
                        {
                            let index = self.push(layer, at);
                            tree.extend(index.map(TreeNode::Layer));
                        }
                        continue;
                    }
                    let children = self.walk(children, &inner)?;
                    tree.push(TreeNode::Group {
                        name: tagged.name,
                        visible,
                        opacity,
                        children,
                    });
                }
                RawNode::Layer(mut layer) => {
                    if layer.clipped {
                        match &clip_base {
                            Some((base, base_px)) => clip_alpha(&mut layer, base, *base_px),
                            None => self.warn(format!(
                                "layer '{}': clipping mask with no layer below; drawn unclipped",
                                layer.name
                            )),
                        }
                    } else {
                        clip_base = Some((layer.image.clone(), layer.offset_px));
                    }
                    let tagged = tags::parse(&layer.name);
                    if tagged.has("ignore") || tagged.has("overlay") {
                        continue;
                    }
                    if tagged.has("origin") || tagged.has("pivot") {
                        self.pivot(&layer, at);
                        continue;
                    }
                    let index = self.push(layer, at);
                    tree.extend(index.map(TreeNode::Layer));
                }
            }
        }
        Ok(tree)
    }

    /// Clips every layer below the `[overlay]` layer at `i` (same group) to its alpha.
    fn apply_overlay(&mut self, nodes: &mut [RawNode], i: usize) {
        let RawNode::Layer(overlay) = &nodes[i] else {
            return;
        };
        let (base, base_px) = (overlay.image.clone(), overlay.offset_px);
        for node in &mut nodes[..i] {
            if let RawNode::Layer(l) = node {
                clip_alpha(l, &base, base_px);
            }
        }
    }

    fn pivot(&mut self, layer: &RawLayer, at: &Context) {
        let (mut n, mut sx, mut sy) = (0.0, 0.0, 0.0);
        for (x, y, p) in layer.image.enumerate_pixels() {
            if p[3] > 0 {
                n += 1.0;
                sx += x as f64 + 0.5;
                sy += y as f64 + 0.5;
            }
        }
        if n == 0.0 {
            self.warn(format!("pivot layer '{}' is empty; ignored", layer.name));
            return;
        }
        self.out.pivots.push(Pivot {
            group: at.prefix.clone(),
            at_px: crate::geom::Point::new(
                layer.offset_px[0] as f64 + sx / n,
                layer.offset_px[1] as f64 + sy / n,
            ),
        });
    }

    /// Flattens a `[merge]` group into one raw layer named after it.
    fn merge(
        &mut self,
        raw_name: &str,
        tagged: &Tagged,
        children: Vec<RawNode>,
        visible: bool,
        opacity: f32,
        inner: &Context,
    ) -> Result<Option<RawLayer>, LayeredError> {
        let mut sub = Builder {
            out: LayeredImage {
                canvas_px: self.out.canvas_px,
                layers: Vec::new(),
                tree: Vec::new(),
                pivots: Vec::new(),
                warnings: Vec::new(),
            },
            paths: HashSet::new(),
            limits: self.limits,
        };
        let local = Context {
            prefix: inner.prefix.clone(),
            visible: true,
            opacity: 1.0,
            depth: inner.depth,
        };
        sub.walk(children, &local)?;
        self.out.warnings.append(&mut sub.out.warnings);
        self.out.pivots.append(&mut sub.out.pivots);
        let Some((origin, size)) = bounds(&sub.out.layers) else {
            self.warn(format!(
                "merged group '{raw_name}' has no visible pixels; skipped"
            ));
            return Ok(None);
        };
        // The merged layer spans its layers, however far apart: checked as a layer of its own.
        let what = format!("merged group '{raw_name}'");
        let [w, h] = size.map(u64::from);
        super::check_limit(&what, w.max(h), self.limits.max_side_px.into(), "px a side")?;
        super::check_limit(&what, w * h, self.limits.max_total_px, "px")?;
        let mut image = RgbaImage::new(size[0], size[1]);
        for l in sub.out.layers.iter().filter(|l| l.visible) {
            over(&mut image, origin, &l.image, l.offset_px, l.opacity);
        }
        // The merged layer keeps the group's path (its tags removed, `[path]` honoured).
        let name = match tagged.value("path") {
            Some(p) => format!("[path:{p}]"),
            None => String::new(),
        };
        Ok(Some(RawLayer {
            name: format!("{} {name}", tagged.name),
            offset_px: origin,
            image,
            opacity,
            visible,
            blend: BlendMode::Normal,
            clipped: false,
        }))
    }

    /// Trims and adds a layer; None when it has no pixels (with a warning).
    fn push(&mut self, layer: RawLayer, at: &Context) -> Option<usize> {
        let tagged = tags::parse(&layer.name);
        self.report_tags(&layer.name, &tagged);
        let Some((image, offset_px)) = trim(&layer.image, layer.offset_px) else {
            self.warn(format!("layer '{}' has no pixels; skipped", layer.name));
            return None;
        };
        let name = if tagged.name.is_empty() {
            "layer".to_string()
        } else {
            tagged.name.clone()
        };
        let mut path = match tagged.value("path") {
            // Spine's `[path:name]`; a leading `/` ignores the groups.
            Some(p) => match p.strip_prefix('/') {
                Some(abs) => abs.to_string(),
                None => at.path(p),
            },
            None => at.path(&name),
        };
        if !self.paths.insert(path.clone()) {
            let base = path.clone();
            let mut k = 2;
            while !self.paths.insert(format!("{base} {k}")) {
                k += 1;
            }
            path = format!("{base} {k}");
            self.warn(format!(
                "layer '{}': name repeated; renamed '{path}'",
                layer.name
            ));
        }
        if !matches!(layer.blend, BlendMode::Normal | BlendMode::PassThrough) {
            self.warn(format!(
                "layer '{}': blend mode {:?} drawn as normal",
                layer.name, layer.blend
            ));
        }
        self.out.layers.push(ArtLayer {
            name,
            path,
            offset_px,
            image,
            opacity: (layer.opacity * at.opacity).clamp(0.0, 1.0),
            visible: layer.visible && at.visible,
            blend: layer.blend,
        });
        Some(self.out.layers.len() - 1)
    }
}

/// Multiplies `layer`'s alpha by `base`'s (top-left at canvas `base_px`) where they overlap;
/// zero elsewhere.
fn clip_alpha(layer: &mut RawLayer, base: &RgbaImage, base_px: [i32; 2]) {
    let (ox, oy) = (
        layer.offset_px[0] as i64 - base_px[0] as i64,
        layer.offset_px[1] as i64 - base_px[1] as i64,
    );
    for (x, y, p) in layer.image.enumerate_pixels_mut() {
        let (bx, by) = (x as i64 + ox, y as i64 + oy);
        let a = if bx >= 0 && by >= 0 && bx < base.width() as i64 && by < base.height() as i64 {
            base.get_pixel(bx as u32, by as u32)[3] as u32
        } else {
            0
        };
        p[3] = ((p[3] as u32 * a + 127) / 255) as u8;
    }
}

/// The smallest sub-image holding every pixel with alpha > 0, and its canvas offset.
pub fn trim(image: &RgbaImage, offset_px: [i32; 2]) -> Option<(RgbaImage, [i32; 2])> {
    let (w, h) = image.dimensions();
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for (x, y, p) in image.enumerate_pixels() {
        if p[3] > 0 {
            x0 = x0.min(x);
            y0 = y0.min(y);
            x1 = x1.max(x + 1);
            y1 = y1.max(y + 1);
        }
    }
    if x1 <= x0 || y1 <= y0 {
        return None;
    }
    let sub = image::imageops::crop_imm(image, x0, y0, x1 - x0, y1 - y0).to_image();
    Some((sub, [offset_px[0] + x0 as i32, offset_px[1] + y0 as i32]))
}
