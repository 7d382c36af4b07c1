//! Bone trees from the medial axis: junctions become joints, long curved branches split where
//! they bend, the root sits at the thickest part.
//!
//! In: an [`AxisGraph`] (canvas px), the [`Shape`] it came from and [`SkeletonOptions`]. Out:
//! [`ProtoBone`]s (head → tail in canvas px, parent index, optional name), parents listed
//! before their children; every bone is a straight segment that lies inside the shape's
//! outlines.
//!
//! Each connected piece of the axis becomes one skeleton. It is rooted at its node of largest
//! inscribed radius and turned into a tree by breadth-first search (a loop around a hole is
//! cut where the search meets itself). Maximal unbranched paths of the tree are split into
//! straight bones by Douglas–Peucker: a path is split at its point farthest from the chord
//! while that point is farther than `bend_ratio` × the chord, or while the chord leaves the
//! shape. Paths shorter than `min_bone_px` make no bone (their subtrees hang from the bone
//! before them); at the root, the path with the longest subtree makes the root bone and the
//! other paths leaving the root hang from it.

use super::medial::AxisGraph;
use super::shape::Shape;
use crate::geom::{point_segment_distance, Point};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// How axis paths become bones.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkeletonOptions {
    /// A path is split where it strays from its chord by more than this fraction of the
    /// chord's length. Default 0.12.
    pub bend_ratio: f64,
    /// Paths and bones shorter than this make no bone of their own, px. Default 6.
    pub min_bone_px: f64,
    /// ... nor those shorter than this fraction of the character's size (the larger side of
    /// its box), whichever is longer: no junk bones at junctions. Default 0.03.
    pub min_bone_fraction: f64,
    /// At most this many bones (bends are merged first, then the shortest leaf bones
    /// dropped). Default: the template's budget (humanoid 20, quadruped 25; 25 without a
    /// template, see [`super::budget`]).
    pub max_bones: Option<usize>,
    /// Without a template, a piece whose axis has no side branch longer than this fraction
    /// of its longest path is a prop (a sword, a bottle, a flag): bones along that path
    /// only, at most `prop_max_bones`. Default 0.25.
    pub prop_branch_fraction: f64,
    /// At most this many bones for a prop. Default 3.
    pub prop_max_bones: usize,
}

impl Default for SkeletonOptions {
    fn default() -> Self {
        SkeletonOptions {
            bend_ratio: 0.12,
            min_bone_px: 6.0,
            min_bone_fraction: 0.03,
            max_bones: None,
            prop_branch_fraction: 0.25,
            prop_max_bones: 3,
        }
    }
}

/// A bone before it is named and written: canvas px.
#[derive(Clone, Debug, PartialEq)]
pub struct ProtoBone {
    pub head: Point,
    pub tail: Point,
    /// Index of the parent bone in the same list (always smaller).
    pub parent: Option<usize>,
    pub name: Option<String>,
}

impl ProtoBone {
    pub fn length_px(&self) -> f64 {
        (self.tail - self.head).norm()
    }
}

/// A spanning tree of one connected piece of the axis.
#[derive(Clone, Debug)]
pub struct NodeTree {
    pub root: usize,
    /// Per axis node: its parent (None for the root and for nodes outside this tree).
    pub parent: Vec<Option<usize>>,
    /// Per axis node: its children, in axis-node order.
    pub children: Vec<Vec<usize>>,
    /// The tree's nodes in breadth-first order from the root.
    pub order: Vec<usize>,
}

impl NodeTree {
    /// Breadth-first spanning tree of the piece of `axis` containing `root`.
    pub fn new(axis: &AxisGraph, root: usize) -> NodeTree {
        let n = axis.nodes.len();
        let mut parent = vec![None; n];
        let mut children = vec![Vec::new(); n];
        let mut seen = vec![false; n];
        let mut order = Vec::new();
        let mut queue = VecDeque::from([root]);
        seen[root] = true;
        while let Some(v) = queue.pop_front() {
            order.push(v);
            for &w in &axis.adjacency[v] {
                if !seen[w] {
                    seen[w] = true;
                    parent[w] = Some(v);
                    children[v].push(w);
                    queue.push_back(w);
                }
            }
        }
        NodeTree {
            root,
            parent,
            children,
            order,
        }
    }

    /// Per node, the total edge length (px) of the subtree below it.
    pub fn subtree_lengths(&self, axis: &AxisGraph) -> Vec<f64> {
        let mut total = vec![0.0; self.parent.len()];
        for &v in self.order.iter().rev() {
            if let Some(p) = self.parent[v] {
                total[p] += total[v] + (axis.nodes[v].pos - axis.nodes[p].pos).norm();
            }
        }
        total
    }

    /// The path from `from` down to its descendant `to`, both included (None when `to` is not
    /// below `from`).
    pub fn path_down(&self, from: usize, to: usize) -> Option<Vec<usize>> {
        let mut path = vec![to];
        let mut at = to;
        while at != from {
            at = self.parent[at]?;
            path.push(at);
        }
        path.reverse();
        Some(path)
    }
}

/// Accumulates bones, growing them along subtrees of a [`NodeTree`].
pub struct BoneBuilder<'a> {
    pub axis: &'a AxisGraph,
    pub shape: &'a Shape,
    pub options: &'a SkeletonOptions,
    pub bones: Vec<ProtoBone>,
}

impl<'a> BoneBuilder<'a> {
    pub fn new(axis: &'a AxisGraph, shape: &'a Shape, options: &'a SkeletonOptions) -> Self {
        BoneBuilder {
            axis,
            shape,
            options,
            bones: Vec::new(),
        }
    }

    fn pos(&self, v: usize) -> Point {
        self.axis.nodes[v].pos
    }

    /// Grows bones along the subtrees of `from`'s children `first` (in `tree`), hanging them
    /// from `parent`. With no parent, the path of longest subtree makes the root bone and the
    /// others hang from it.
    pub fn grow(&mut self, tree: &NodeTree, from: usize, first: &[usize], parent: Option<usize>) {
        let lengths = tree.subtree_lengths(self.axis);
        let mut starts: Vec<usize> = first.to_vec();
        if parent.is_none() {
            // Longest first (stable: ties keep axis order).
            starts.sort_by(|&a, &b| lengths[b].total_cmp(&lengths[a]));
        }
        let mut root_bone = parent;
        for (k, &c) in starts.iter().enumerate() {
            let mut queue = VecDeque::from([(from, c, root_bone)]);
            while let Some((s, c, pb)) = queue.pop_front() {
                let mut path = vec![s, c];
                let mut end = c;
                while tree.children[end].len() == 1 {
                    end = tree.children[end][0];
                    path.push(end);
                }
                let last = self.path_bones(&path, pb);
                for &child in &tree.children[end] {
                    queue.push_back((end, child, last));
                }
                if k == 0 && root_bone.is_none() {
                    // The first path's first bone is the root bone.
                    root_bone = pb.or(last.map(|l| self.first_bone_of_chain(l, pb)));
                }
            }
        }
    }

    /// The first bone on the chain of parents from `bone` up to (not including) `stop`.
    fn first_bone_of_chain(&self, mut bone: usize, stop: Option<usize>) -> usize {
        while let Some(p) = self.bones[bone].parent {
            if Some(p) == stop {
                break;
            }
            bone = p;
        }
        bone
    }

    /// Bones along one unbranched path (axis nodes), chained from `parent`. Returns the last
    /// bone (or `parent` when the path is too short for one).
    fn path_bones(&mut self, path: &[usize], parent: Option<usize>) -> Option<usize> {
        let points: Vec<Point> = path.iter().map(|&v| self.pos(v)).collect();
        if polyline_length(&points) < self.options.min_bone_px {
            return parent;
        }
        let mut joints = vec![0];
        split_polyline(
            &points,
            0,
            points.len() - 1,
            self.shape,
            self.options,
            &mut joints,
        );
        joints.push(points.len() - 1);
        let mut last = parent;
        for w in joints.windows(2) {
            let (head, tail) = (points[w[0]], points[w[1]]);
            if (tail - head).norm() < 1e-9 {
                continue;
            }
            self.bones.push(ProtoBone {
                head,
                tail,
                parent: last,
                name: None,
            });
            last = Some(self.bones.len() - 1);
        }
        last
    }

    /// One named bone from `path[start]` to the farthest `path[t]`, t ≤ `end`, whose segment
    /// stays inside the shape. Returns (bone index, t).
    pub fn straight_bone(
        &mut self,
        path: &[usize],
        start: usize,
        end: usize,
        parent: Option<usize>,
        name: &str,
    ) -> (usize, usize) {
        let head = self.pos(path[start]);
        let mut t = end;
        while t > start + 1 && !self.shape.segment_inside(head, self.pos(path[t])) {
            t -= 1;
        }
        let t = t.max((start + 1).min(path.len() - 1));
        self.bones.push(ProtoBone {
            head,
            tail: self.pos(path[t]),
            parent,
            name: Some(name.to_string()),
        });
        (self.bones.len() - 1, t)
    }
}

/// Appends to `joints` the interior split indices of `points[i..=j]`, in order.
fn split_polyline(
    points: &[Point],
    i: usize,
    j: usize,
    shape: &Shape,
    options: &SkeletonOptions,
    joints: &mut Vec<usize>,
) {
    if j <= i + 1 {
        return;
    }
    let (a, b) = (points[i], points[j]);
    let chord = (b - a).norm();
    let (k, deviation) = ((i + 1)..j)
        .map(|k| (k, point_segment_distance(points[k], a, b)))
        .fold((i + 1, -1.0), |best, c| if c.1 > best.1 { c } else { best });
    let bent = deviation > options.bend_ratio * chord && chord >= 2.0 * options.min_bone_px;
    if bent || !shape.segment_inside(a, b) {
        split_polyline(points, i, k, shape, options, joints);
        joints.push(k);
        split_polyline(points, k, j, shape, options, joints);
    }
}

pub fn polyline_length(points: &[Point]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Skeletons for every piece of the axis: one per connected piece of at least `min_bone_px`,
/// rooted at its thickest node.
pub fn medial_skeleton(
    axis: &AxisGraph,
    shape: &Shape,
    options: &SkeletonOptions,
) -> Vec<ProtoBone> {
    let mut builder = BoneBuilder::new(axis, shape, options);
    let mut done = vec![false; axis.nodes.len()];
    // Pieces in the order of their thickest node's radius (largest first), then node index.
    let mut pieces: Vec<(usize, NodeTree)> = Vec::new();
    for v in axis.live_nodes() {
        if done[v] {
            continue;
        }
        let probe = NodeTree::new(axis, v);
        probe.order.iter().for_each(|&w| done[w] = true);
        let root = *probe
            .order
            .iter()
            .max_by(|&&a, &&b| {
                axis.nodes[a]
                    .radius_px
                    .total_cmp(&axis.nodes[b].radius_px)
                    .then(b.cmp(&a))
            })
            .unwrap_or(&v);
        pieces.push((root, NodeTree::new(axis, root)));
    }
    pieces.sort_by(|a, b| {
        axis.nodes[b.0]
            .radius_px
            .total_cmp(&axis.nodes[a.0].radius_px)
            .then(a.0.cmp(&b.0))
    });
    for (root, tree) in &pieces {
        match prop_path(axis, tree, options.prop_branch_fraction) {
            Some(path) => {
                let first = builder.bones.len();
                builder.path_bones(&path, None);
                let mut prop: Vec<ProtoBone> = builder.bones.split_off(first);
                for b in &mut prop {
                    b.parent = b.parent.map(|p| p - first);
                }
                limit_bones(&mut prop, Some(options.prop_max_bones), shape);
                for mut b in prop {
                    b.parent = b.parent.map(|p| p + first);
                    builder.bones.push(b);
                }
            }
            None => builder.grow(tree, *root, &tree.children[*root], None),
        }
    }
    builder.bones
}

/// The longest path of a piece of the axis (from its lower end, larger y, to the other) when
/// no side branch is longer than `fraction` of it: the piece is a prop. None otherwise.
fn prop_path(axis: &AxisGraph, piece: &NodeTree, fraction: f64) -> Option<Vec<usize>> {
    let far = |tree: &NodeTree| {
        let mut dist = vec![0.0; axis.nodes.len()];
        for &v in &tree.order {
            if let Some(p) = tree.parent[v] {
                dist[v] = dist[p] + (axis.nodes[v].pos - axis.nodes[p].pos).norm();
            }
        }
        let end = *tree
            .order
            .iter()
            .max_by(|&&a, &&b| dist[a].total_cmp(&dist[b]).then(b.cmp(&a)))?;
        Some((end, dist))
    };
    let (a, _) = far(piece)?;
    let from_a = NodeTree::new(axis, a);
    let (b, dist) = far(&from_a)?;
    let main = from_a.path_down(a, b)?;
    if main.len() < 2 {
        return None;
    }
    let mut on_main = vec![false; axis.nodes.len()];
    main.iter().for_each(|&v| on_main[v] = true);
    let mut side = vec![0.0f64; axis.nodes.len()];
    let mut longest_side = 0.0f64;
    for &v in &from_a.order {
        if let (Some(p), false) = (from_a.parent[v], on_main[v]) {
            side[v] = side[p] + (axis.nodes[v].pos - axis.nodes[p].pos).norm();
            longest_side = longest_side.max(side[v]);
        }
    }
    if longest_side >= fraction * dist[b] {
        return None;
    }
    let mut path = main;
    if axis.nodes[path[0]].pos.y < axis.nodes[path[path.len() - 1]].pos.y {
        path.reverse();
    }
    Some(path)
}

/// Reduces `bones` to at most `max` (if given): first merges a bone into its only child where
/// the merged bone stays inside (least bent joint first), then drops the shortest leaf bones.
/// Never drops the last bone.
pub fn limit_bones(bones: &mut Vec<ProtoBone>, max: Option<usize>, shape: &Shape) {
    let Some(max) = max else { return };
    let max = max.max(1);
    while bones.len() > max {
        let child_count =
            |bones: &[ProtoBone], b: usize| bones.iter().filter(|c| c.parent == Some(b)).count();
        let merge = (0..bones.len())
            .filter_map(|c| {
                let p = bones[c].parent?;
                let joined = (bones[p].tail - bones[c].head).norm() < 1e-9;
                if !joined || child_count(bones, p) != 1 || bones[c].name.is_some() {
                    return None;
                }
                if !shape.segment_inside(bones[p].head, bones[c].tail) {
                    return None;
                }
                Some((
                    c,
                    point_segment_distance(bones[c].head, bones[p].head, bones[c].tail),
                ))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        let remove = match merge {
            Some((c, _)) => {
                let p = bones[c].parent.unwrap_or(c);
                bones[p].tail = bones[c].tail;
                c
            }
            None => {
                let leaf = (0..bones.len())
                    .filter(|&b| child_count(bones, b) == 0 && bones[b].name.is_none())
                    .min_by(|&a, &b| bones[a].length_px().total_cmp(&bones[b].length_px()));
                let Some(leaf) = leaf.or_else(|| {
                    (0..bones.len())
                        .filter(|&b| child_count(bones, b) == 0)
                        .min_by(|&a, &b| bones[a].length_px().total_cmp(&bones[b].length_px()))
                }) else {
                    return;
                };
                leaf
            }
        };
        remove_bone(bones, remove);
    }
}

/// Removes bone `r`, hanging its children from its parent and renumbering.
fn remove_bone(bones: &mut Vec<ProtoBone>, r: usize) {
    let parent = bones[r].parent;
    bones.remove(r);
    for b in bones.iter_mut() {
        b.parent = match b.parent {
            Some(p) if p == r => parent,
            Some(p) if p > r => Some(p - 1),
            other => other,
        };
    }
}
