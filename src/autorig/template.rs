//! Template fitting: a known topology (humanoid, quadruped) matched to the medial axis, so that
//! limbs get the names and parents an animator expects.
//!
//! In: an [`AxisGraph`] with its [`Shape`] (canvas px, y down), a [`Template`] and the
//! [`SkeletonOptions`]. Out: named [`ProtoBone`]s (parents first), or `None` when no
//! assignment satisfies the template's topology.
//!
//! Matching: the template's extremities (humanoid: head, two hands, two feet; quadruped: head,
//! tail, four feet) are assigned to leaves of the axis tree by exhaustive search over the
//! candidate leaves. The axis is computed without merging nearby junctions, so that limbs
//! leaving a round torso keep their own joints. An assignment fixes the template's inner
//! joints as tree medians: the humanoid's pelvis is where the paths between the feet and the
//! head meet, each arm's shoulder where its hand's path meets the spine (pelvis to head), and
//! the chest is the higher shoulder; shoulders must lie strictly above the pelvis and off the
//! legs' paths. A head drawn apart from the body is no leaf of the body's axis: the highest
//! node of the piece then ends the spine (the head gets its own bone as a separate piece,
//! [`super::budget`]). Among the valid assignments the one with the best score wins:
//! extremities where the template expects them in the drawing's box (head up, feet down, `_l`
//! limbs on the right of the screen: the character's left, facing the viewer) and left/right
//! limbs of similar length. A humanoid's root is not where the legs' paths meet: its hip
//! starts a third of its height below the base of the skull ([`PELVIS_BELOW_SKULL`]; on the
//! spine above a skirt's hem, or between the legs below a wide trunk's junction). Bones then
//! follow the tree paths between the joints: hip and chest along the spine, a neck and a head
//! split where the path widens into the skull, two bones per limb split at the limbs' bends
//! (elbows, knees), a quadruped's tail in up to three bones, all kept straight and inside;
//! axis branches the template does not name (ears, a tail on a humanoid, a held prop) become
//! extra bones hanging from the named bone they leave.

use super::medial::AxisGraph;
use super::shape::Shape;
use super::skeleton::{polyline_length, BoneBuilder, NodeTree, ProtoBone, SkeletonOptions};
use crate::geom::{point_segment_distance, Point};
use serde::{Deserialize, Serialize};

/// A known skeleton topology.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Template {
    /// Spine (hip, chest), head, two arms and two legs of two bones each.
    Humanoid,
    /// Spine (hip, chest), head, a tail of two bones and four legs of two bones each.
    Quadruped,
}

/// Which template a proposal uses: one named, none, or the one the art suggests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TemplateChoice {
    /// Chosen from the layer names, else from the drawing's shape
    /// ([`super::choose_template`]); the proposal says which and why.
    #[default]
    Auto,
    /// No template: bones from the medial axis, or one per layer named after it.
    None,
    Humanoid,
    Quadruped,
}

impl TemplateChoice {
    /// The template fixed by the choice: `Some(None)` for none, `None` for automatic.
    pub fn fixed(self) -> Option<Option<Template>> {
        match self {
            TemplateChoice::Auto => None,
            TemplateChoice::None => Some(None),
            TemplateChoice::Humanoid => Some(Some(Template::Humanoid)),
            TemplateChoice::Quadruped => Some(Some(Template::Quadruped)),
        }
    }
}

impl From<Option<Template>> for TemplateChoice {
    fn from(t: Option<Template>) -> Self {
        match t {
            None => TemplateChoice::None,
            Some(Template::Humanoid) => TemplateChoice::Humanoid,
            Some(Template::Quadruped) => TemplateChoice::Quadruped,
        }
    }
}

/// Candidate leaves kept per search (the most extreme ones); bounds the exhaustive search.
const MAX_CANDIDATE_LEAVES: usize = 14;

/// Lowest-common-ancestor queries on a [`NodeTree`] by binary lifting.
struct Lca {
    depth: Vec<usize>,
    /// Distance from the root along the tree, px.
    dist_px: Vec<f64>,
    up: Vec<Vec<usize>>,
}

impl Lca {
    fn new(tree: &NodeTree, axis: &AxisGraph) -> Lca {
        let n = tree.parent.len();
        let mut depth = vec![0; n];
        let mut dist_px = vec![0.0; n];
        let mut up0: Vec<usize> = (0..n).collect();
        for &v in &tree.order {
            if let Some(p) = tree.parent[v] {
                depth[v] = depth[p] + 1;
                dist_px[v] = dist_px[p] + (axis.nodes[v].pos - axis.nodes[p].pos).norm();
                up0[v] = p;
            }
        }
        let levels = (usize::BITS - n.max(1).leading_zeros()) as usize + 1;
        let mut up = vec![up0];
        for k in 1..levels {
            let prev = &up[k - 1];
            let next: Vec<usize> = (0..n).map(|v| prev[prev[v]]).collect();
            up.push(next);
        }
        Lca { depth, dist_px, up }
    }

    fn lca(&self, mut a: usize, mut b: usize) -> usize {
        if self.depth[a] < self.depth[b] {
            std::mem::swap(&mut a, &mut b);
        }
        let mut diff = self.depth[a] - self.depth[b];
        let mut k = 0;
        while diff > 0 {
            if diff & 1 == 1 {
                a = self.up[k][a];
            }
            diff >>= 1;
            k += 1;
        }
        if a == b {
            return a;
        }
        for k in (0..self.up.len()).rev() {
            if self.up[k][a] != self.up[k][b] {
                a = self.up[k][a];
                b = self.up[k][b];
            }
        }
        self.up[0][a]
    }

    fn dist(&self, a: usize, b: usize) -> f64 {
        self.dist_px[a] + self.dist_px[b] - 2.0 * self.dist_px[self.lca(a, b)]
    }

    /// The node where the paths between three nodes meet.
    fn median(&self, a: usize, b: usize, c: usize) -> usize {
        let (x, y, z) = (self.lca(a, b), self.lca(a, c), self.lca(b, c));
        [x, y, z]
            .into_iter()
            .max_by_key(|&v| self.depth[v])
            .unwrap_or(x)
    }

    /// Whether `x` lies on the tree path between `a` and `b`.
    fn on_path(&self, x: usize, a: usize, b: usize) -> bool {
        (self.dist(a, x) + self.dist(x, b) - self.dist(a, b)).abs() < 1e-6
    }
}

/// The drawing's box, for the position priors.
struct Frame {
    x0: f64,
    y0: f64,
    w: f64,
    h: f64,
}

impl Frame {
    /// (x, y) in [0, 1]² of the box.
    fn unit(&self, p: Point) -> (f64, f64) {
        ((p.x - self.x0) / self.w, (p.y - self.y0) / self.h)
    }
}

/// Which axis nodes may be the template's extremities (head, hands, feet, tail).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extremities {
    /// The axis's own ends (nodes with one neighbour).
    AxisEnds,
    /// The leaves of the spanning tree: the axis's ends and the cuts of its cycles. Fingers
    /// drawn touching, or an outline that nearly meets itself, close small cycles at a hand,
    /// which then has no axis end; the cut leaves a candidate there.
    TreeLeaves,
}

/// Both ways of choosing extremities, the stricter first.
pub const EXTREMITIES: [Extremities; 2] = [Extremities::AxisEnds, Extremities::TreeLeaves];

/// Fits `template` to the largest piece of `axis`: with the axis's ends as extremities, else
/// with the spanning tree's leaves ([`Extremities`]).
pub fn fit_template(
    axis: &AxisGraph,
    shape: &Shape,
    template: Template,
    options: &SkeletonOptions,
) -> Option<Vec<ProtoBone>> {
    EXTREMITIES
        .iter()
        .find_map(|&ends| fit_template_with(axis, shape, template, options, ends))
}

/// Fits `template` to the largest piece of `axis`, its extremities chosen among `ends`.
pub fn fit_template_with(
    axis: &AxisGraph,
    shape: &Shape,
    template: Template,
    options: &SkeletonOptions,
    ends: Extremities,
) -> Option<Vec<ProtoBone>> {
    // The largest piece, rooted at its thickest node.
    let mut done = vec![false; axis.nodes.len()];
    let mut best: Option<(f64, NodeTree)> = None;
    for v in axis.live_nodes() {
        if done[v] {
            continue;
        }
        let tree = NodeTree::new(axis, v);
        tree.order.iter().for_each(|&w| done[w] = true);
        let length = tree.subtree_lengths(axis)[v];
        if best.as_ref().is_none_or(|b| length > b.0) {
            best = Some((length, tree));
        }
    }
    let (_, probe) = best?;
    let root = *probe.order.iter().max_by(|&&a, &&b| {
        axis.nodes[a]
            .radius_px
            .total_cmp(&axis.nodes[b].radius_px)
            .then(b.cmp(&a))
    })?;
    let tree = NodeTree::new(axis, root);
    let lca = Lca::new(&tree, axis);
    let leaves: Vec<usize> = tree
        .order
        .iter()
        .copied()
        .filter(|&v| match ends {
            Extremities::AxisEnds => axis.adjacency[v].len() == 1,
            Extremities::TreeLeaves => v != root && tree.children[v].is_empty(),
        })
        .collect();
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for ring in shape.rings() {
        for p in ring {
            lo = [lo[0].min(p.x), lo[1].min(p.y)];
            hi = [hi[0].max(p.x), hi[1].max(p.y)];
        }
    }
    let frame = Frame {
        x0: lo[0],
        y0: lo[1],
        w: (hi[0] - lo[0]).max(1.0),
        h: (hi[1] - lo[1]).max(1.0),
    };
    let pos = |v: usize| axis.nodes[v].pos;
    let leaves = most_extreme(&leaves, |v| frame.unit(pos(v)), MAX_CANDIDATE_LEAVES);
    match template {
        Template::Humanoid => {
            let fit = fit_humanoid(&leaves, &tree.order, &lca, &frame, &pos)?;
            let chest = fit.chest(&lca);
            Some(build_humanoid(axis, shape, options, &fit, chest, frame.h))
        }
        Template::Quadruped => {
            let thickness: Vec<(usize, f64)> = leaves
                .iter()
                .map(|&v| (v, end_thickness(axis, v, END_WALK_FRACTION * frame.h)))
                .collect();
            let thick = |v: usize| thickness.iter().find(|t| t.0 == v).map_or(0.0, |t| t.1);
            let fit = fit_quadruped(&leaves, &lca, &frame, &pos, &thick)?;
            Some(build_quadruped(axis, shape, options, &fit))
        }
    }
}

/// Up to `keep` leaves, preferring those far from the box center (extremities), in tree order.
fn most_extreme(leaves: &[usize], unit: impl Fn(usize) -> (f64, f64), keep: usize) -> Vec<usize> {
    let mut ranked: Vec<(f64, usize)> = leaves
        .iter()
        .map(|&v| {
            let (x, y) = unit(v);
            (-((x - 0.5).powi(2) + (y - 0.5).powi(2)), v)
        })
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    ranked.truncate(keep);
    let mut kept: Vec<usize> = ranked.into_iter().map(|r| r.1).collect();
    kept.sort_unstable();
    kept
}

/// A humanoid fit (axis nodes): where the legs meet the spine (pelvis), head, hands [l, r],
/// feet [l, r], and where each arm meets the spine (its shoulder joint, in the order of the
/// hands); the chest is the shoulder joint nearer the head.
struct HumanoidFit {
    pelvis: usize,
    head: usize,
    hands: [usize; 2],
    feet: [usize; 2],
    shoulders: [usize; 2],
}

impl HumanoidFit {
    fn chest(&self, lca: &Lca) -> usize {
        let [a, b] = self.shoulders;
        if lca.dist(self.pelvis, a) >= lca.dist(self.pelvis, b) {
            a
        } else {
            b
        }
    }
}

fn fit_humanoid(
    leaves: &[usize],
    nodes: &[usize],
    lca: &Lca,
    frame: &Frame,
    pos: &dyn Fn(usize) -> Point,
) -> Option<HumanoidFit> {
    let mut best: Option<(f64, HumanoidFit)> = None;
    let u = |v: usize| frame.unit(pos(v));
    // The head is a leaf, or (a head drawn apart, rigged as a piece of its own) the highest
    // node of the piece, where the spine then ends.
    let mut heads = leaves.to_vec();
    if let Some(&top) = nodes
        .iter()
        .min_by(|&&a, &&b| pos(a).y.total_cmp(&pos(b).y).then(a.cmp(&b)))
    {
        if !heads.contains(&top) {
            heads.push(top);
        }
    }
    for &head in &heads {
        let head_leaf = leaves.contains(&head);
        for &fl in leaves {
            for &fr in leaves {
                if fl == head || fr == head || fl == fr || pos(fl).x <= pos(fr).x {
                    continue;
                }
                let pelvis = lca.median(fl, fr, head);
                if pelvis == head {
                    continue;
                }
                for &hl in leaves {
                    for &hr in leaves {
                        let distinct = [head, fl, fr].iter().all(|&v| v != hl && v != hr);
                        if !distinct || hl == hr || pos(hl).x <= pos(hr).x {
                            continue;
                        }
                        // Each arm leaves the spine (pelvis to head) strictly above the pelvis
                        // and below the head; no leg passes through a shoulder.
                        let shoulders = [hl, hr].map(|h| lca.median(h, pelvis, head));
                        let valid = shoulders.iter().all(|&s| {
                            s != pelvis
                                && (s != head || !head_leaf)
                                && !lca.on_path(s, pelvis, fl)
                                && !lca.on_path(s, pelvis, fr)
                        });
                        if !valid {
                            continue;
                        }
                        let fit = HumanoidFit {
                            pelvis,
                            head,
                            hands: [hl, hr],
                            feet: [fl, fr],
                            shoulders,
                        };
                        let chest = fit.chest(lca);
                        let (arm_l, arm_r) =
                            (lca.dist(shoulders[0], hl), lca.dist(shoulders[1], hr));
                        let (leg_l, leg_r) = (lca.dist(pelvis, fl), lca.dist(pelvis, fr));
                        let spine = lca.dist(pelvis, chest);
                        let mut score = 2.0 * u(head).1
                            + if head_leaf { 0.0 } else { 1.0 }
                            + 2.0 * (1.0 - u(fl).1)
                            + 2.0 * (1.0 - u(fr).1)
                            + (arm_l - arm_r).abs() / (arm_l + arm_r).max(1e-9)
                            + (leg_l - leg_r).abs() / (leg_l + leg_r).max(1e-9)
                            - 0.5 * (arm_l + arm_r + leg_l + leg_r + spine) / frame.h;
                        // Arms about as long as legs (not ears), hands below the shoulders
                        // (a rest pose), the pelvis below the chest.
                        score += (0.5 * (arm_l + arm_r) / (0.5 * (leg_l + leg_r)).max(1e-9))
                            .ln()
                            .abs();
                        for hand in [hl, hr] {
                            score += ((pos(chest).y - pos(hand).y) / frame.h).max(0.0);
                        }
                        if pos(pelvis).y < pos(chest).y {
                            score += 4.0;
                        }
                        if best.as_ref().is_none_or(|b| score < b.0) {
                            best = Some((score, fit));
                        }
                    }
                }
            }
        }
    }
    best.map(|b| b.1)
}

/// Where a limb path bends (its elbow or knee): the node farthest from the chord when it
/// strays by more than `bend_ratio` of the chord and sits in the middle half of the path (a
/// bend near an end is an ankle or a wrist), else half way. An index into `points`.
fn bend_index(points: &[Point], bend_ratio: f64) -> usize {
    let n = points.len();
    if n < 3 {
        return n.saturating_sub(1);
    }
    let (a, b) = (points[0], points[n - 1]);
    let (k, dev) = (1..n - 1)
        .map(|k| (k, point_segment_distance(points[k], a, b)))
        .fold((1, -1.0), |best, c| if c.1 > best.1 { c } else { best });
    let (lo, hi) = (fraction_index(points, 0.25), fraction_index(points, 0.75));
    if dev > bend_ratio * (b - a).norm() && (lo..=hi).contains(&k) {
        return k;
    }
    half_index(points)
}

/// Where a limb ends (its wrist or ankle): the first node, past the limb's first quarter, whose
/// radius exceeds `WRIST_RADIUS_RATIO` × the thinnest radius before it (a hand, a foot or a
/// held prop is thicker than the forearm or shin); else the path's end.
fn limb_end(radii: &[f64]) -> usize {
    let n = radii.len();
    let mut thinnest = f64::INFINITY;
    for (k, &r) in radii.iter().enumerate() {
        if k >= n / 4 && r > WRIST_RADIUS_RATIO * thinnest {
            return k;
        }
        thinnest = thinnest.min(r);
    }
    n.saturating_sub(1)
}

/// See [`limb_end`].
const WRIST_RADIUS_RATIO: f64 = 1.2;

/// The node at half the path's length.
fn half_index(points: &[Point]) -> usize {
    let total: f64 = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    let mut run = 0.0;
    for k in 1..points.len() {
        run += (points[k] - points[k - 1]).norm();
        if run >= 0.5 * total {
            return k.min(points.len() - 1);
        }
    }
    points.len() - 1
}

/// Named bones along tree paths, then the unnamed rest of the tree as extras.
struct NamedBuilder<'a> {
    builder: BoneBuilder<'a>,
    tree: NodeTree,
    /// Per axis node, the named bone covering it (None: not covered).
    covered: Vec<Option<usize>>,
    /// Where a limb starts: the first node thinner than this fraction of the joint it leaves.
    limb_radius_ratio: f64,
    /// A lower limb is at most this many times as long as its upper limb; the rest of the
    /// path (a foot, a held prop) is left to extra bones.
    lower_limb_ratio: f64,
}

impl<'a> NamedBuilder<'a> {
    fn new(
        axis: &'a AxisGraph,
        shape: &'a Shape,
        options: &'a SkeletonOptions,
        tree: NodeTree,
    ) -> Self {
        let n = axis.nodes.len();
        NamedBuilder {
            builder: BoneBuilder::new(axis, shape, options),
            tree,
            covered: vec![None; n],
            limb_radius_ratio: LIMB_RADIUS_RATIO,
            lower_limb_ratio: LOWER_LIMB_RATIO,
        }
    }

    fn path(&self, from: usize, to: usize) -> Vec<usize> {
        self.tree.path_down(from, to).unwrap_or_default()
    }

    fn points(&self, path: &[usize]) -> Vec<Point> {
        path.iter()
            .map(|&v| self.builder.axis.nodes[v].pos)
            .collect()
    }

    fn cover(&mut self, nodes: &[usize], bone: Option<usize>) {
        for &v in nodes {
            if self.covered[v].is_none() {
                self.covered[v] = bone;
            }
        }
    }

    /// Bones named `names` along `path` from index `start`, the k-th aiming at `ends[k]`
    /// (each stops earlier if its straight segment would leave the shape, and the next starts
    /// where it stopped). Returns the bones and the path index the last one reached.
    fn bones_along(
        &mut self,
        path: &[usize],
        mut start: usize,
        ends: &[usize],
        names: &[&str],
        parent: Option<usize>,
    ) -> (Vec<usize>, usize) {
        let mut last = parent;
        let mut out = Vec::new();
        for (name, &end) in names.iter().zip(ends) {
            if path.len() < 2 || start >= path.len() - 1 {
                break;
            }
            let end = end.max(start + 1).min(path.len() - 1);
            let (bone, reached) = self.builder.straight_bone(path, start, end, last, name);
            self.cover(&path[start..=reached], Some(bone));
            out.push(bone);
            last = Some(bone);
            start = reached;
        }
        (out, start)
    }

    /// Bones named `names` from `from` down to `to`, split at equal lengths.
    fn even_chain(
        &mut self,
        from: usize,
        to: usize,
        names: &[&str],
        parent: Option<usize>,
    ) -> Vec<usize> {
        let path = self.path(from, to);
        let points = self.points(&path);
        let ends: Vec<usize> = (1..=names.len())
            .map(|k| fraction_index(&points, k as f64 / names.len() as f64))
            .collect();
        self.bones_along(&path, 0, &ends, names, parent).0
    }

    /// A neck and a head bone from `from` (the chest joint) to `to` (the head's leaf): the
    /// head starts where the path widens again past its narrowest stretch (the base of the
    /// skull, [`limb_end`]), else half way. A neck shorter than `min_bone_px` makes one head
    /// bone.
    fn neck_and_head(&mut self, from: usize, to: usize, parent: Option<usize>) {
        let path = self.path(from, to);
        if path.len() < 2 {
            return;
        }
        let axis = self.builder.axis;
        let points = self.points(&path);
        let radii: Vec<f64> = path.iter().map(|&v| axis.nodes[v].radius_px).collect();
        let base = limb_end(&radii);
        let base = if base + 1 >= path.len() {
            half_index(&points)
        } else {
            base
        };
        let neck_px = polyline_length(&points[..=base]);
        if neck_px < self.builder.options.min_bone_px || base == 0 {
            self.bones_along(&path, 0, &[path.len() - 1], &["head"], parent);
            return;
        }
        self.bones_along(&path, 0, &[base, path.len() - 1], &["neck", "head"], parent);
    }

    /// The height of the base of the skull, px: the bottom of the head's inscribed disc, the
    /// widest on the path from `chest` to the head's leaf `head` among those wholly above the
    /// chest joint (the discs reaching below it are the trunk's; a big head's may be wider
    /// than the trunk, and its neck need not narrow where a small head's does).
    fn skull_base(&self, chest: usize, head: usize) -> f64 {
        let axis = self.builder.axis;
        let at = axis.nodes[chest].pos;
        let widest = self
            .path(chest, head)
            .into_iter()
            .filter(|&v| axis.nodes[v].pos.y + axis.nodes[v].radius_px < at.y)
            .max_by(|&a, &b| axis.nodes[a].radius_px.total_cmp(&axis.nodes[b].radius_px))
            .unwrap_or(head);
        let node = &axis.nodes[widest];
        node.pos.y + node.radius_px
    }

    /// The height of a standing figure's pelvis, px: [`PELVIS_BELOW_SKULL`] of the drawing's
    /// `height` below the base of its skull. Where the legs' axis paths meet is no pelvis: a
    /// skirt or a coat joins them at its hem, below the hips; a wide trunk joins them half its
    /// width above the crotch (the medial axis of a box branches toward its corners).
    fn pelvis_height(&self, fit: &HumanoidFit, chest: usize, height: f64) -> f64 {
        self.skull_base(chest, fit.head) + PELVIS_BELOW_SKULL * height
    }

    /// The node of the path from `from` up to `to` (the legs' junction to the chest) where it
    /// first rises to height `y`, at most half way along the path (the spine keeps its
    /// length); `from` when the path does not rise that high.
    fn spine_node_at(&self, from: usize, to: usize, y: f64) -> usize {
        let path = self.path(from, to);
        if path.len() < 3 {
            return from;
        }
        let points = self.points(&path);
        let half = half_index(&points);
        path.iter()
            .zip(&points)
            .take(half)
            .find(|(_, p)| p.y <= y)
            .map_or(from, |(&v, _)| v)
    }

    /// Starts the `hip` bone lower, at height `y` between the legs, when the legs' junction
    /// lies above it (a wide trunk): at the middle of the two legs' axis paths at that height,
    /// when the bone stays inside.
    fn lower_hip(&mut self, hip: usize, fit: &HumanoidFit, y: f64) {
        let junction = self.builder.axis.nodes[fit.pelvis].pos;
        if y <= junction.y {
            return;
        }
        let at_height = |points: &[Point]| {
            points.windows(2).find_map(|w| {
                let (a, b) = (w[0], w[1]);
                (a.y < y && b.y >= y).then(|| a.x + (b.x - a.x) * (y - a.y) / (b.y - a.y))
            })
        };
        let xs: Vec<f64> = fit
            .feet
            .iter()
            .filter_map(|&f| at_height(&self.points(&self.path(fit.pelvis, f))))
            .collect();
        let [xl, xr] = xs[..] else { return };
        let head = Point::new(0.5 * (xl + xr), y);
        let tail = self.builder.bones[hip].tail;
        if self.builder.shape.segment_inside(head, tail) {
            self.builder.bones[hip].head = head;
        }
    }

    /// An upper and a lower limb bone from `from` down to `to`: the limb starts where the path
    /// leaves the thick joint (the stretch before belongs to `parent`), bends at its elbow or
    /// knee (the bend, else half way), and the lower bone is at most `lower_limb_ratio` times
    /// the upper one.
    fn limb(&mut self, from: usize, to: usize, names: [&str; 2], parent: Option<usize>) {
        let path = self.path(from, to);
        if path.len() < 2 {
            return;
        }
        let axis = self.builder.axis;
        let joint_radius = axis.nodes[from].radius_px;
        let start = path
            .iter()
            .position(|&v| axis.nodes[v].radius_px < self.limb_radius_ratio * joint_radius)
            .unwrap_or(0)
            .min(path.len() - 2);
        self.cover(&path[..=start], parent);
        let points = self.points(&path);
        let radii: Vec<f64> = path[start..]
            .iter()
            .map(|&v| axis.nodes[v].radius_px)
            .collect();
        let wrist = start + limb_end(&radii);
        let cut = start + bend_index(&points[start..=wrist], self.builder.options.bend_ratio);
        let (upper, reached) = self.bones_along(&path, start, &[cut], &names[..1], parent);
        let Some(&upper) = upper.first() else { return };
        let limit = self.lower_limb_ratio * self.builder.bones[upper].length_px();
        let mut end = reached;
        while end < wrist && (points[end + 1] - points[reached]).norm() <= limit {
            end += 1;
        }
        self.bones_along(&path, reached, &[end], &names[1..], Some(upper));
    }

    /// Every subtree hanging from a covered node into uncovered nodes becomes extra bones.
    fn extras(mut self) -> Vec<ProtoBone> {
        let order = self.tree.order.clone();
        for v in order {
            let Some(bone) = self.covered[v] else {
                continue;
            };
            let hanging: Vec<usize> = self.tree.children[v]
                .iter()
                .copied()
                .filter(|&c| self.covered[c].is_none())
                .collect();
            if !hanging.is_empty() {
                let tree = self.tree.clone();
                self.builder.grow(&tree, v, &hanging, Some(bone));
            }
        }
        let mut bones = self.builder.bones;
        let mut k = 0;
        for b in &mut bones {
            if b.name.is_none() {
                k += 1;
                b.name = Some(format!("extra_{k}"));
            }
        }
        bones
    }
}

/// A quadruped's tail bones, root first.
const TAIL_NAMES: [&str; 3] = ["tail_1", "tail_2", "tail_3"];

/// A standing figure's pelvis lies this fraction of its height below the base of its skull,
/// whatever the size of its head (the real-art set's 18 humanoid references with a pelvis:
/// 0.33 ± 0.07 of the height; a share of the way from the skull to the feet spreads more:
/// 0.35–0.74, big heads lowest).
const PELVIS_BELOW_SKULL: f64 = 0.33;
/// How far (a fraction of the height) the estimate of [`PELVIS_BELOW_SKULL`] strays on the
/// set: within it, the legs' junction stays the root.
const PELVIS_SPREAD: f64 = 0.07;

/// Default for [`NamedBuilder::limb_radius_ratio`].
const LIMB_RADIUS_RATIO: f64 = 0.5;
/// Default for [`NamedBuilder::lower_limb_ratio`].
const LOWER_LIMB_RATIO: f64 = 1.3;

/// The path index at `fraction` of the path's length.
fn fraction_index(points: &[Point], fraction: f64) -> usize {
    let total: f64 = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    let mut run = 0.0;
    for k in 1..points.len() {
        run += (points[k] - points[k - 1]).norm();
        if run >= fraction * total - 1e-9 {
            return k;
        }
    }
    points.len().saturating_sub(1)
}

fn build_humanoid(
    axis: &AxisGraph,
    shape: &Shape,
    options: &SkeletonOptions,
    fit: &HumanoidFit,
    chest: usize,
    height: f64,
) -> Vec<ProtoBone> {
    let tree = NodeTree::new(axis, fit.pelvis);
    let mut nb = NamedBuilder::new(axis, shape, options, tree);
    // The legs' junction is the pelvis unless the estimate is farther from it than the
    // estimate's own spread (a stick figure's legs meet at its pelvis).
    let junction_y = axis.nodes[fit.pelvis].pos.y;
    let pelvis_y = Some(nb.pelvis_height(fit, chest, height))
        .filter(|y| (y - junction_y).abs() > PELVIS_SPREAD * height)
        .unwrap_or(junction_y);
    let root = nb.spine_node_at(fit.pelvis, chest, pelvis_y);
    let spine = nb.even_chain(root, chest, &["hip", "chest"], None);
    let (hip, chest_bone) = (spine.first().copied(), spine.last().copied());
    // Between where the legs meet (a skirt's hem) and the pelvis: the hip's.
    let below = nb.path(fit.pelvis, root);
    nb.cover(&below, hip);
    if let (Some(hip), true) = (hip, root == fit.pelvis) {
        nb.lower_hip(hip, fit, pelvis_y);
    }
    if chest != fit.head {
        nb.neck_and_head(chest, fit.head, chest_bone);
    }
    let [sl, sr] = fit.shoulders;
    nb.limb(sl, fit.hands[0], ["arm_upper_l", "arm_lower_l"], chest_bone);
    nb.limb(sr, fit.hands[1], ["arm_upper_r", "arm_lower_r"], chest_bone);
    nb.limb(fit.pelvis, fit.feet[0], ["leg_upper_l", "leg_lower_l"], hip);
    nb.limb(fit.pelvis, fit.feet[1], ["leg_upper_r", "leg_lower_r"], hip);
    nb.extras()
}

/// A quadruped fit (axis nodes): head, tail, front feet [l, r] and back feet [l, r], and
/// where each leg meets the spine (its attachment), in the same order as the feet.
struct QuadrupedFit {
    head: usize,
    tail: usize,
    feet: [usize; 4],
    attachments: [usize; 4],
}

/// How far from a leaf its end's thickness is measured, as a fraction of the drawing's height.
const END_WALK_FRACTION: f64 = 0.1;

/// The largest radius within `walk_px` (along the axis) of `leaf`: how thick that end is.
fn end_thickness(axis: &AxisGraph, leaf: usize, walk_px: f64) -> f64 {
    let mut best = axis.nodes[leaf].radius_px;
    let mut stack = vec![(leaf, usize::MAX, 0.0)];
    while let Some((v, from, d)) = stack.pop() {
        best = best.max(axis.nodes[v].radius_px);
        for &w in &axis.adjacency[v] {
            let step = (axis.nodes[w].pos - axis.nodes[v].pos).norm();
            if w != from && d + step <= walk_px {
                stack.push((w, v, d + step));
            }
        }
    }
    best
}

fn fit_quadruped(
    leaves: &[usize],
    lca: &Lca,
    frame: &Frame,
    pos: &dyn Fn(usize) -> Point,
    thick: &dyn Fn(usize) -> f64,
) -> Option<QuadrupedFit> {
    let mut best: Option<(f64, QuadrupedFit)> = None;
    let u = |v: usize| frame.unit(pos(v));
    for &head in leaves {
        for &tail in leaves {
            if tail == head {
                continue;
            }
            let spine = lca.dist(head, tail);
            // Where a foot's path meets the spine, and how far along it from the head.
            let attach = |f: usize| {
                let a = lca.median(f, head, tail);
                (a, lca.dist(head, a))
            };
            let others: Vec<usize> = leaves
                .iter()
                .copied()
                .filter(|&v| v != head && v != tail)
                .collect();
            for &fl in &others {
                for &fr in &others {
                    if fl == fr || pos(fl).x <= pos(fr).x {
                        continue;
                    }
                    for &bl in &others {
                        for &br in &others {
                            let feet = [fl, fr, bl, br];
                            let distinct = (0..4).all(|i| (0..i).all(|j| feet[i] != feet[j]));
                            if !distinct || pos(bl).x <= pos(br).x {
                                continue;
                            }
                            let att = feet.map(attach);
                            // Legs leave the spine strictly between head and tail, front legs
                            // nearer the head than back legs.
                            let inner = att
                                .iter()
                                .all(|&(a, d)| a != head && a != tail && d > 0.0 && d < spine);
                            let ordered = att[0].1.max(att[1].1) < att[2].1.min(att[3].1);
                            if !inner || !ordered {
                                continue;
                            }
                            let feet_low: f64 = feet.iter().map(|&f| 1.0 - u(f).1).sum();
                            let leg = |i: usize| lca.dist(att[i].0, feet[i]);
                            let (front_l, front_r, back_l, back_r) =
                                (leg(0), leg(1), leg(2), leg(3));
                            // The head end is thicker than the tail's.
                            let (th, tt) = (thick(head), thick(tail));
                            let score = 2.0 * feet_low
                                - (u(head).0 - u(tail).0).abs()
                                - (th - tt) / (th + tt).max(1e-9)
                                + (front_l - front_r).abs() / (front_l + front_r).max(1e-9)
                                + (back_l - back_r).abs() / (back_l + back_r).max(1e-9)
                                - 0.5 * (front_l + front_r + back_l + back_r) / frame.h;
                            if best.as_ref().is_none_or(|b| score < b.0) {
                                let fit = QuadrupedFit {
                                    head,
                                    tail,
                                    feet,
                                    attachments: att.map(|a| a.0),
                                };
                                best = Some((score, fit));
                            }
                        }
                    }
                }
            }
        }
    }
    best.map(|b| b.1)
}

fn build_quadruped(
    axis: &AxisGraph,
    shape: &Shape,
    options: &SkeletonOptions,
    fit: &QuadrupedFit,
) -> Vec<ProtoBone> {
    let depth = |tree: &NodeTree, v: usize| {
        let mut d = 0;
        let mut at = v;
        while let Some(p) = tree.parent[at] {
            at = p;
            d += 1;
        }
        d
    };
    // The chest is the front attachment nearer the head, the pelvis the back one nearer the
    // tail (legs of one pair may leave the spine at different points in a side view).
    let probe = NodeTree::new(axis, fit.tail);
    let a = fit.attachments;
    let chest = if depth(&probe, a[0]) >= depth(&probe, a[1]) {
        a[0]
    } else {
        a[1]
    };
    let pelvis = if depth(&probe, a[2]) <= depth(&probe, a[3]) {
        a[2]
    } else {
        a[3]
    };
    let tree = NodeTree::new(axis, pelvis);
    let mut nb = NamedBuilder::new(axis, shape, options, tree);
    let spine = nb.even_chain(pelvis, chest, &["hip", "chest"], None);
    let (hip, chest_bone) = (spine.first().copied(), spine.last().copied());
    nb.neck_and_head(chest, fit.head, chest_bone);
    // A tail of up to three bones, each at least twice the shortest bone.
    let tail_px = polyline_length(&nb.points(&nb.path(pelvis, fit.tail)));
    let tail_bones = ((tail_px / (2.0 * options.min_bone_px)) as usize).clamp(1, 3);
    nb.even_chain(pelvis, fit.tail, &TAIL_NAMES[..tail_bones], hip);
    let names = [
        ["leg_front_upper_l", "leg_front_lower_l"],
        ["leg_front_upper_r", "leg_front_lower_r"],
        ["leg_back_upper_l", "leg_back_lower_l"],
        ["leg_back_upper_r", "leg_back_lower_r"],
    ];
    for (i, names) in names.into_iter().enumerate() {
        let parent = if i < 2 { chest_bone } else { hip };
        nb.limb(a[i], fit.feet[i], names, parent);
    }
    nb.extras()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::autorig::medial::AxisNode;

    /// A tree of nodes on a line with a branch: 0-1-2-3 and 1-4-5.
    fn graph() -> AxisGraph {
        let p = [
            (0.0, 0.0),
            (1.0, 0.0),
            (2.0, 0.0),
            (3.0, 0.0),
            (1.0, 1.0),
            (1.0, 2.0),
        ];
        let nodes = p
            .iter()
            .map(|&(x, y)| AxisNode {
                pos: Point::new(x, y),
                radius_px: 1.0,
            })
            .collect();
        let adjacency = vec![
            vec![1],
            vec![0, 2, 4],
            vec![1, 3],
            vec![2],
            vec![1, 5],
            vec![4],
        ];
        AxisGraph { nodes, adjacency }
    }

    #[test]
    fn lca_medians_and_paths_on_a_small_tree() {
        let axis = graph();
        for root in 0..6 {
            let tree = NodeTree::new(&axis, root);
            let lca = Lca::new(&tree, &axis);
            assert_eq!(lca.median(0, 3, 5), 1, "root {root}");
            assert_eq!(lca.median(0, 2, 3), 2, "root {root}");
            assert!((lca.dist(3, 5) - 4.0).abs() < 1e-12);
            assert!(lca.on_path(1, 0, 5) && lca.on_path(2, 0, 3) && !lca.on_path(4, 0, 3));
        }
    }

    /// A figure of `segments` (capsules: end points and radius, px) on a 200 × 420 canvas,
    /// traced.
    fn figure(segments: &[((f64, f64), (f64, f64), f64)]) -> Shape {
        let image = image::RgbaImage::from_fn(200, 420, |x, y| {
            let p = Point::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let inside = segments.iter().any(|&((ax, ay), (bx, by), r)| {
                point_segment_distance(p, Point::new(ax, ay), Point::new(bx, by)) <= r
            });
            image::Rgba([80, 80, 80, if inside { 255 } else { 0 }])
        });
        Shape::trace(&image, &Default::default())
            .expect("traced")
            .expect("a shape")
    }

    fn fitted(shape: &Shape, template: Template) -> Vec<ProtoBone> {
        let medial = crate::autorig::medial::MedialOptions {
            junction_merge_ratio: 0.0,
            ..Default::default()
        };
        let axis = crate::autorig::medial::medial_axis(shape, &medial).expect("an axis");
        fit_template(&axis, shape, template, &SkeletonOptions::default()).expect("a fit")
    }

    fn bone<'a>(bones: &'a [ProtoBone], name: &str) -> &'a ProtoBone {
        bones
            .iter()
            .find(|b| b.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("{name} in {bones:?}"))
    }

    /// A woman in a long, narrow dress: the legs' axis paths meet at its hem (y ≈ 300), far
    /// below her hips (a third of her height below the base of the skull, y ≈ 66 + 130); the
    /// root rises from the hem toward them, at most half way up to the chest joint.
    #[test]
    fn a_dress_roots_the_humanoid_at_the_pelvis_not_at_its_hem() {
        let shape = figure(&[
            ((100.0, 40.0), (100.0, 40.0), 26.0),   // head
            ((100.0, 60.0), (100.0, 90.0), 9.0),    // neck
            ((100.0, 100.0), (100.0, 300.0), 30.0), // dress
            ((80.0, 100.0), (22.0, 220.0), 9.0),    // arms held out
            ((120.0, 100.0), (178.0, 220.0), 9.0),
            ((86.0, 300.0), (80.0, 400.0), 8.0), // legs
            ((114.0, 300.0), (120.0, 400.0), 8.0),
        ]);
        let bones = fitted(&shape, Template::Humanoid);
        let hip = bone(&bones, "hip");
        assert!(
            (190.0..275.0).contains(&hip.head.y),
            "the hip starts at {:?}",
            hip.head
        );
        assert!(bones
            .iter()
            .all(|b| b.parent.is_some() || b.name.as_deref() == Some("hip")));
    }

    /// A squat figure with a big head: its legs join a wide trunk, whose medial axis branches
    /// about half the trunk's width above the crotch (y ≈ 260); the root starts lower, between
    /// the legs (a third of the height below the skull, y ≈ 235).
    #[test]
    fn a_wide_trunk_roots_the_humanoid_between_its_legs() {
        let shape = figure(&[
            ((100.0, 60.0), (100.0, 60.0), 45.0),   // a big head
            ((100.0, 180.0), (100.0, 230.0), 70.0), // a wide trunk
            ((40.0, 150.0), (8.0, 250.0), 9.0),     // arms
            ((160.0, 150.0), (192.0, 250.0), 9.0),
            ((75.0, 250.0), (70.0, 405.0), 12.0), // legs
            ((125.0, 250.0), (130.0, 405.0), 12.0),
        ]);
        let bones = fitted(&shape, Template::Humanoid);
        let hip = bone(&bones, "hip");
        assert!(
            hip.head.y > 220.0 && (hip.head.x - 100.0).abs() < 15.0,
            "the hip starts at {:?}",
            hip.head
        );
    }

    #[test]
    fn limb_joints_split_at_bends_in_the_middle_else_half_way() {
        let straight: Vec<Point> = (0..=10).map(|k| Point::new(k as f64, 0.0)).collect();
        assert_eq!(bend_index(&straight, 0.1), 5);
        // An elbow at 40 % of the length.
        let mut elbow: Vec<Point> = (0..=4).map(|k| Point::new(k as f64, 0.0)).collect();
        elbow.extend((1..=6).map(|k| Point::new(4.0, k as f64)));
        assert_eq!(bend_index(&elbow, 0.1), 4);
        // An ankle at 90 %: not a knee.
        let mut ankle: Vec<Point> = (0..=9).map(|k| Point::new(0.0, k as f64)).collect();
        ankle.push(Point::new(1.0, 9.0));
        assert_eq!(bend_index(&ankle, 0.1), half_index(&ankle));
        // A wrist where the radius grows past the forearm's.
        assert_eq!(limb_end(&[9.0, 8.0, 6.0, 6.0, 6.0, 8.0, 9.0]), 5);
        assert_eq!(limb_end(&[6.0; 8]), 7);
    }
}
