//! The handles file: what the animator placed on the canvas.
//!
//! In: JSON as in `docs/formats.md` (`bones`, `points`, `cages`, `regions`, `bind`, `ik`;
//! positions in canvas px).
//! Out: [`Handles`], checked by [`Handles::validate`]: names unique across all handles, parents
//! known and acyclic, bones of non-zero length, polygons of at least three points, every
//! coordinate finite.

use crate::geom::Point;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, HashMap, HashSet};

/// A bone: rest geometry `head` → `tail` in canvas px; it rotates about its head in its
/// parent's frame. A bone without a parent starts its own skeleton.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Bone {
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parent: Option<String>,
    #[schemars(with = "[f64; 2]")]
    pub head: Point,
    #[schemars(with = "[f64; 2]")]
    pub tail: Point,
}

/// A point handle at `at` (canvas px): loose, or carried by a bone.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointHandle {
    pub name: String,
    #[schemars(with = "[f64; 2]")]
    pub at: Point,
    /// The bone that carries the point: posed, the point moves as that bone does, then by its
    /// own pose (as a Spine point attachment or a child bone would). `None`: a loose point,
    /// posed on its own in canvas axes. Default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parent: Option<String>,
}

/// A cage: a closed polygon (canvas px) whose vertices are handles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Cage {
    pub name: String,
    #[schemars(with = "Vec<[f64; 2]>")]
    pub polygon: Vec<Point>,
}

/// A region: a closed polygon (canvas px) whose inside moves rigidly together.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Region {
    pub name: String,
    #[schemars(with = "Vec<[f64; 2]>")]
    pub polygon: Vec<Point>,
}

/// Every handle of a rig, in file order.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Handles {
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bones: Vec<Bone>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<PointHandle>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub cages: Vec<Cage>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub regions: Vec<Region>,
    /// Handle name → the parts (layer names) it may weigh. A handle not listed weighs every
    /// part it touches; a listed one is left out of the others' meshes and weights (a tail
    /// bone that passes behind a leg layer must not drag the leg).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub bind: BTreeMap<String, Vec<String>>,
    /// Classic bone IK constraints (see [`super::bone_ik`]), applied in order during forward
    /// kinematics.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ik: Vec<BoneIk>,
    /// Bone physics constraints (see [`super::physics`]), applied in order after the IK
    /// constraints while animations play; static poses leave them out.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub physics: Vec<super::physics::PhysicsConstraint>,
}

/// An IK constraint of the handles file (solved by [`super::bone_ik`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BoneIk {
    pub name: String,
    /// The chain, root first; each bone the parent of the next.
    pub bones: Vec<String>,
    /// The bone whose head the chain's end reaches for.
    pub target: String,
    /// Two bones: the child's local rotation comes out positive (counter-clockwise on screen),
    /// Spine's `bendPositive`. Default true.
    #[serde(default = "default_true")]
    pub bend_positive: bool,
    /// 0: forward kinematics only; 1: fully solved. Values outside [0, 1] are clamped. Default 1.
    #[serde(default = "default_one")]
    pub mix: f64,
    /// Distance before full extension over which a two-bone chain eases, px (in the frame of the
    /// chain root's parent, see the module doc). Default 0.
    #[serde(default)]
    pub softness_px: f64,
}

impl BoneIk {
    /// The mix as applied: clamped to [0, 1] (what an exporter must write).
    pub fn applied_mix(&self) -> f64 {
        self.mix.clamp(0.0, 1.0)
    }
}

fn default_true() -> bool {
    true
}

fn default_one() -> f64 {
    1.0
}

/// What is wrong with a set of handles.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum HandleError {
    #[error("two handles are named '{0}'")]
    DuplicateName(String),
    #[error("handle names must not be empty")]
    EmptyName,
    #[error(
        "bone '{bone}' has unknown parent '{parent}'{}",
        crate::names::did_you_mean(.suggestion)
    )]
    UnknownParent {
        bone: String,
        parent: String,
        /// The bone most like `parent` ([`crate::names::closest`]).
        suggestion: Option<String>,
    },
    #[error(
        "point '{point}' has unknown parent bone '{parent}'{}",
        crate::names::did_you_mean(.suggestion)
    )]
    UnknownPointParent {
        point: String,
        parent: String,
        suggestion: Option<String>,
    },
    #[error("bone '{0}' is its own ancestor (cyclic parents)")]
    CyclicParents(String),
    #[error("bone '{0}' has zero length (head = tail)")]
    DegenerateBone(String),
    #[error("{kind} '{name}' needs at least 3 distinct points")]
    DegeneratePolygon { kind: &'static str, name: String },
    #[error("handle '{0}' has a coordinate that is not a finite number")]
    NonFinite(String),
    #[error(
        "'bind' names handle '{name}', which does not exist{}",
        crate::names::did_you_mean(.suggestion)
    )]
    UnknownBindHandle {
        name: String,
        /// The handle most like `name`.
        suggestion: Option<String>,
    },
    #[error("'bind' lists no part for handle '{0}'")]
    EmptyBind(String),
    #[error("ik constraint '{name}': {problem}")]
    BadIkConstraint { name: String, problem: String },
    #[error("physics constraint '{name}': {problem}")]
    BadPhysicsConstraint { name: String, problem: String },
    #[error("handle '{name}' has a coordinate beyond ±{MAX_COORDINATE_PX} px: {}", crate::shown::Shown(*.value))]
    TooFar { name: String, value: f64 },
    #[error("{kind} '{name}': {problem}")]
    BadPolygon {
        kind: &'static str,
        name: String,
        problem: String,
    },
    #[error(
        "the handles make {columns} weight columns (one per bone, point, cage vertex and \
         region): at most {MAX_WEIGHT_COLUMNS}; use fewer handles or cages of fewer vertices"
    )]
    TooManyColumns { columns: usize },
}

/// Handle coordinates beyond this (px, either sign) are refused: no canvas is that large, and a
/// bone that long overflows its length (and the Spine export's `length`). Also the limit of a
/// rig document's mesh vertices ([`crate::io::document::MAX_COORDINATE_PX`] is this).
pub const MAX_COORDINATE_PX: f64 = 1e6;
/// The most weight columns a set of handles may make: each column is one weight solve over the
/// mesh, and each a skinning-IK unknown (a 1000-bone chain takes most of a minute).
pub const MAX_WEIGHT_COLUMNS: usize = 256;
/// A cage or region encloses at least this area, px²: less is a line (collinear points).
pub const MIN_POLYGON_AREA_PX2: f64 = 1e-6;

/// What is wrong with a cage's or region's outline: a repeated vertex, edges that cross or
/// double back, or no area. `None` for a simple polygon.
pub fn polygon_problem(p: &[Point]) -> Option<String> {
    use crate::geom::{segments_touch, triangle_area2};
    let n = p.len();
    for i in 0..n {
        if p[i] == p[(i + 1) % n] {
            return Some(format!("vertex {} repeats vertex {i}", (i + 1) % n));
        }
    }
    for i in 0..n {
        let (a, b, c) = (p[i], p[(i + 1) % n], p[(i + 2) % n]);
        if n > 3 && triangle_area2(a, b, c) == 0.0 && (a - b).dot(&(c - b)) > 0.0 {
            return Some(format!(
                "edges {i} and {} double back on each other at vertex {}",
                (i + 1) % n,
                (i + 1) % n
            ));
        }
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through the closing edge
            }
            if segments_touch(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]) {
                return Some(format!(
                    "edge {i} (vertices {i}–{}) crosses edge {j} (vertices {j}–{}): the outline \
                     must not cross itself (a bow tie); reorder the vertices",
                    (i + 1) % n,
                    (j + 1) % n
                ));
            }
        }
    }
    let area2: f64 = (0..n)
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % n]);
            a.x * b.y - a.y * b.x
        })
        .sum();
    if area2.abs() / 2.0 < MIN_POLYGON_AREA_PX2 {
        return Some("it has no area: its vertices lie on one line".into());
    }
    None
}

/// Every coordinate of handle `name` within ±[`MAX_COORDINATE_PX`].
fn check_reach<'a>(
    name: &str,
    mut values: impl Iterator<Item = &'a f64>,
) -> Result<(), HandleError> {
    match values.find(|v| v.abs() > MAX_COORDINATE_PX) {
        Some(&value) => Err(HandleError::TooFar {
            name: name.to_string(),
            value,
        }),
        None => Ok(()),
    }
}

/// Bones shorter than this (px) are degenerate: they have no direction.
pub const MIN_BONE_LENGTH_PX: f64 = 1e-6;

impl Handles {
    /// The parent of bone or point `name` (a bone's parent bone, a point's carrying bone):
    /// `Some(None)` for a root bone or a loose point, `None` when no bone or point has that name.
    pub fn parent_of(&self, name: &str) -> Option<Option<&str>> {
        let bone = self.bones.iter().find(|b| b.name == name);
        bone.map(|b| b.parent.as_deref()).or_else(|| {
            let point = self.points.iter().find(|p| p.name == name)?;
            Some(point.parent.as_deref())
        })
    }

    /// The index in `bones` of the bone carrying point `points[i]`, if it has one (a parent
    /// named but missing, as in [`Handles::for_part`]'s subsets, counts as none).
    pub fn point_parent(&self, i: usize) -> Option<usize> {
        let parent = self.points.get(i)?.parent.as_deref()?;
        self.bones.iter().position(|b| b.name == parent)
    }

    /// The root of bone `name`'s skeleton: the ancestor with no parent (the bone itself when
    /// it has none). `None` when no bone has that name or the parents loop (an invalid rig).
    pub fn root_bone(&self, name: &str) -> Option<&Bone> {
        let mut bone = self.bones.iter().find(|b| b.name == name)?;
        for _ in 0..self.bones.len() {
            match &bone.parent {
                None => return Some(bone),
                Some(parent) => bone = self.bones.iter().find(|b| &b.name == parent)?,
            }
        }
        None
    }

    pub fn is_empty(&self) -> bool {
        self.bones.is_empty()
            && self.points.is_empty()
            && self.cages.is_empty()
            && self.regions.is_empty()
    }

    /// Renames handle `from` to `to` wherever it is named: the handle itself, bone parents,
    /// bindings and bone IK constraints. (Call [`Handles::validate`] afterwards: `to` may clash.)
    pub fn rename(&mut self, from: &str, to: &str) {
        let fix = |name: &mut String| {
            if name == from {
                *name = to.to_string();
            }
        };
        for b in &mut self.bones {
            fix(&mut b.name);
            if let Some(parent) = &mut b.parent {
                fix(parent);
            }
        }
        for p in &mut self.points {
            fix(&mut p.name);
            if let Some(parent) = &mut p.parent {
                fix(parent);
            }
        }
        self.cages.iter_mut().for_each(|c| fix(&mut c.name));
        self.regions.iter_mut().for_each(|r| fix(&mut r.name));
        if let Some(parts) = self.bind.remove(from) {
            self.bind.insert(to.to_string(), parts);
        }
        for constraint in &mut self.ik {
            constraint.bones.iter_mut().for_each(fix);
            fix(&mut constraint.target);
        }
        self.physics.iter_mut().for_each(|c| fix(&mut c.bone));
    }

    /// Removes handle `name`. A removed bone's children (bones and points) move up to its
    /// parent, and the bone IK constraints that name it go with it.
    pub fn delete(&mut self, name: &str) {
        if let Some(index) = self.bones.iter().position(|b| b.name == name) {
            let removed = self.bones.remove(index);
            for b in &mut self.bones {
                if b.parent.as_deref() == Some(name) {
                    b.parent = removed.parent.clone();
                }
            }
            for p in &mut self.points {
                if p.parent.as_deref() == Some(name) {
                    p.parent = removed.parent.clone();
                }
            }
        }
        self.points.retain(|p| p.name != name);
        self.cages.retain(|c| c.name != name);
        self.regions.retain(|r| r.name != name);
        self.bind.remove(name);
        self.ik
            .retain(|c| c.target != name && !c.bones.iter().any(|b| b == name));
        self.physics.retain(|c| c.bone != name);
    }

    /// Every handle's name, in the order weights columns use: bones, points, cages, regions.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        let bones = self.bones.iter().map(|b| b.name.as_str());
        let points = self.points.iter().map(|p| p.name.as_str());
        let cages = self.cages.iter().map(|c| c.name.as_str());
        let regions = self.regions.iter().map(|r| r.name.as_str());
        bones.chain(points).chain(cages).chain(regions)
    }

    /// Whether the handle `name` may weigh the part named `part` (see [`Handles::bind`]).
    pub fn binds(&self, name: &str, part: &str) -> bool {
        self.bind
            .get(name)
            .is_none_or(|parts| parts.iter().any(|p| p == part))
    }

    /// The same handles less those that may not weigh `part` (see [`Handles::bind`]): what
    /// that part's mesh must carry.
    pub fn for_part(&self, part: &str) -> Handles {
        Handles {
            ik: Vec::new(),
            physics: Vec::new(),
            bones: self
                .bones
                .iter()
                .filter(|h| self.binds(&h.name, part))
                .cloned()
                .collect(),
            points: self
                .points
                .iter()
                .filter(|h| self.binds(&h.name, part))
                .cloned()
                .collect(),
            cages: self
                .cages
                .iter()
                .filter(|h| self.binds(&h.name, part))
                .cloned()
                .collect(),
            regions: self
                .regions
                .iter()
                .filter(|h| self.binds(&h.name, part))
                .cloned()
                .collect(),
            bind: BTreeMap::new(),
        }
    }

    /// Per weight column (see [`crate::rig::handle_columns`]: bones, points, one per cage
    /// vertex, regions), whether it may weigh `part`.
    pub fn columns_binding(&self, part: &str) -> Vec<bool> {
        let bones = self.bones.iter().map(|b| self.binds(&b.name, part));
        let points = self.points.iter().map(|p| self.binds(&p.name, part));
        let cages = self
            .cages
            .iter()
            .flat_map(|c| std::iter::repeat_n(self.binds(&c.name, part), c.polygon.len()));
        let regions = self.regions.iter().map(|r| self.binds(&r.name, part));
        bones.chain(points).chain(cages).chain(regions).collect()
    }

    /// Checks names, parents, lengths, polygons and numbers. (Part names in [`Handles::bind`]
    /// are checked against the layers by whoever knows them.)
    pub fn validate(&self) -> Result<(), HandleError> {
        let mut seen = HashSet::new();
        for name in self.names() {
            if name.is_empty() {
                return Err(HandleError::EmptyName);
            }
            if !seen.insert(name) {
                return Err(HandleError::DuplicateName(name.to_string()));
            }
        }
        for (name, parts) in &self.bind {
            if !seen.contains(name.as_str()) {
                return Err(HandleError::UnknownBindHandle {
                    name: name.clone(),
                    suggestion: crate::names::closest(name, self.names()),
                });
            }
            if parts.is_empty() {
                return Err(HandleError::EmptyBind(name.clone()));
            }
        }
        for b in &self.bones {
            if !b.head.iter().chain(b.tail.iter()).all(|v| v.is_finite()) {
                return Err(HandleError::NonFinite(b.name.clone()));
            }
            check_reach(&b.name, b.head.iter().chain(b.tail.iter()))?;
            if (b.tail - b.head).norm() < MIN_BONE_LENGTH_PX {
                return Err(HandleError::DegenerateBone(b.name.clone()));
            }
        }
        for p in &self.points {
            if !p.at.iter().all(|v| v.is_finite()) {
                return Err(HandleError::NonFinite(p.name.clone()));
            }
            check_reach(&p.name, p.at.iter())?;
        }
        let polygons = self.cages.iter().map(|c| ("cage", &c.name, &c.polygon));
        for (kind, name, polygon) in
            polygons.chain(self.regions.iter().map(|r| ("region", &r.name, &r.polygon)))
        {
            if !polygon.iter().flat_map(|p| p.iter()).all(|v| v.is_finite()) {
                return Err(HandleError::NonFinite(name.clone()));
            }
            let distinct: HashSet<(u64, u64)> = polygon
                .iter()
                .map(|p| (p[0].to_bits(), p[1].to_bits()))
                .collect();
            if distinct.len() < 3 {
                return Err(HandleError::DegeneratePolygon {
                    kind,
                    name: name.clone(),
                });
            }
            check_reach(name, polygon.iter().flat_map(|p| p.iter()))?;
            if let Some(problem) = polygon_problem(polygon) {
                return Err(HandleError::BadPolygon {
                    kind,
                    name: name.clone(),
                    problem,
                });
            }
        }
        let columns = self.bones.len()
            + self.points.len()
            + self.cages.iter().map(|c| c.polygon.len()).sum::<usize>()
            + self.regions.len();
        if columns > MAX_WEIGHT_COLUMNS {
            return Err(HandleError::TooManyColumns { columns });
        }
        self.check_parents()?;
        self.check_ik()?;
        self.check_physics()
    }

    /// Every physics constraint names a known bone, has a name no IK or physics constraint
    /// shares, and parameters as [`super::physics::PhysicsConstraint::check`] wants.
    fn check_physics(&self) -> Result<(), HandleError> {
        let mut names: HashSet<&str> = self.ik.iter().map(|c| c.name.as_str()).collect();
        for c in &self.physics {
            let bad = |problem: String| HandleError::BadPhysicsConstraint {
                name: c.name.clone(),
                problem,
            };
            if c.name.is_empty() {
                return Err(bad("its name is empty".into()));
            }
            if !names.insert(c.name.as_str()) {
                return Err(bad("another constraint has this name".into()));
            }
            let Some(bone) = self.bones.iter().find(|b| b.name == c.bone) else {
                return Err(bad(format!(
                    "bone '{}' does not exist{}",
                    c.bone,
                    self.did_you_mean_bone(&c.bone)
                )));
            };
            c.check_on_bone((bone.tail - bone.head).norm())
                .map_err(bad)?;
        }
        Ok(())
    }

    /// Every IK chain is a parent-linked run of known bones whose target is a known bone that the
    /// chain does not move.
    fn check_ik(&self) -> Result<(), HandleError> {
        let bad = |c: &BoneIk, problem: String| HandleError::BadIkConstraint {
            name: c.name.clone(),
            problem,
        };
        let find = |name: &str| self.bones.iter().find(|b| b.name == name);
        let mut names = HashSet::new();
        for c in &self.ik {
            if !names.insert(c.name.as_str()) {
                return Err(bad(c, "two ik constraints have this name".into()));
            }
            if c.bones.is_empty() {
                return Err(bad(c, "names no bones".into()));
            }
            // A mix outside [0, 1] is clamped (see `BoneIk::mix`), only NaN is meaningless.
            if !(c.mix.is_finite() && c.softness_px.is_finite() && c.softness_px >= 0.0) {
                return Err(bad(
                    c,
                    "mix and softness_px must be finite, softness_px ≥ 0".into(),
                ));
            }
            for (k, name) in c.bones.iter().enumerate() {
                let bone = find(name).ok_or_else(|| {
                    let guess = self.did_you_mean_bone(name);
                    bad(c, format!("unknown bone '{name}'{guess}"))
                })?;
                if k > 0 && bone.parent.as_deref() != Some(c.bones[k - 1].as_str()) {
                    return Err(bad(
                        c,
                        format!("'{name}' is not a child of '{}'", c.bones[k - 1]),
                    ));
                }
            }
            find(&c.target).ok_or_else(|| {
                let guess = self.did_you_mean_bone(&c.target);
                bad(c, format!("unknown target bone '{}'{guess}", c.target))
            })?;
            // The target must not hang below the chain, or solving would move its own goal.
            let mut at = Some(c.target.as_str());
            while let Some(name) = at {
                if c.bones.iter().any(|b| b == name) {
                    return Err(bad(
                        c,
                        format!("target '{}' moves with the chain", c.target),
                    ));
                }
                at = find(name).and_then(|b| b.parent.as_deref());
            }
        }
        self.check_ik_cycles()
    }

    /// No ik constraint may (through others) move its own target: a constraint depends on each
    /// one whose chain its target hangs from, and those dependencies must not form a cycle.
    fn check_ik_cycles(&self) -> Result<(), HandleError> {
        let parent = |name: &str| {
            self.bones
                .iter()
                .find(|b| b.name == name)
                .and_then(|b| b.parent.as_deref())
        };
        // Constraint i depends on j when j's chain holds the target of i or one of its ancestors.
        let depends: Vec<Vec<usize>> = self
            .ik
            .iter()
            .map(|c| {
                let mut up = Vec::new();
                let mut at = Some(c.target.as_str());
                while let Some(name) = at {
                    up.push(name);
                    at = parent(name);
                }
                (0..self.ik.len())
                    .filter(|&j| self.ik[j].bones.iter().any(|b| up.contains(&b.as_str())))
                    .collect()
            })
            .collect();
        // Depth-first search; 1 = on the current path, 2 = done.
        fn visit(i: usize, depends: &[Vec<usize>], state: &mut [u8]) -> Option<usize> {
            state[i] = 1;
            for &j in &depends[i] {
                match state[j] {
                    1 => return Some(j),
                    0 => {
                        if let Some(found) = visit(j, depends, state) {
                            return Some(found);
                        }
                    }
                    _ => {}
                }
            }
            state[i] = 2;
            None
        }
        let mut state = vec![0u8; self.ik.len()];
        for i in 0..self.ik.len() {
            if state[i] == 0 {
                if let Some(j) = visit(i, &depends, &mut state) {
                    return Err(HandleError::BadIkConstraint {
                        name: self.ik[j].name.clone(),
                        problem: "its target is moved, through other ik constraints, by its own \
                                  chain"
                            .into(),
                    });
                }
            }
        }
        Ok(())
    }

    /// The bone most like `name` ([`crate::names::closest`]).
    fn closest_bone(&self, name: &str) -> Option<String> {
        crate::names::closest(name, self.bones.iter().map(|b| &b.name))
    }

    /// `; did you mean 'BONE'?` for the bone most like `name`, or nothing.
    fn did_you_mean_bone(&self, name: &str) -> String {
        crate::names::did_you_mean(&self.closest_bone(name))
    }

    fn check_parents(&self) -> Result<(), HandleError> {
        let index: HashMap<&str, usize> = self
            .bones
            .iter()
            .enumerate()
            .map(|(i, b)| (b.name.as_str(), i))
            .collect();
        let mut parent = vec![None; self.bones.len()];
        for (i, b) in self.bones.iter().enumerate() {
            if let Some(p) = &b.parent {
                match index.get(p.as_str()) {
                    Some(&j) => parent[i] = Some(j),
                    None => {
                        return Err(HandleError::UnknownParent {
                            bone: b.name.clone(),
                            parent: p.clone(),
                            suggestion: self.closest_bone(p),
                        })
                    }
                }
            }
        }
        for p in &self.points {
            if let Some(parent) = p
                .parent
                .as_ref()
                .filter(|n| !index.contains_key(n.as_str()))
            {
                return Err(HandleError::UnknownPointParent {
                    point: p.name.clone(),
                    parent: parent.clone(),
                    suggestion: self.closest_bone(parent),
                });
            }
        }
        for start in 0..self.bones.len() {
            // A chain longer than the bone count must revisit a bone.
            let (mut at, mut steps) = (parent[start], 0);
            while let Some(j) = at {
                steps += 1;
                if steps > self.bones.len() {
                    return Err(HandleError::CyclicParents(self.bones[start].name.clone()));
                }
                at = parent[j];
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bone(name: &str, parent: Option<&str>) -> Bone {
        Bone {
            name: name.into(),
            parent: parent.map(Into::into),
            head: Point::new(0.0, 0.0),
            tail: Point::new(0.0, 10.0),
        }
    }

    #[test]
    fn parses_the_design_example_and_validates() {
        let json = r#"{
          "bones": [
            {"name": "hip",   "head": [256, 300], "tail": [256, 240]},
            {"name": "chest", "parent": "hip", "head": [256, 240], "tail": [256, 160]},
            {"name": "arm_l", "head": [220, 170], "tail": [170, 230]}
          ],
          "points":  [{"name": "nose", "at": [262, 110]}],
          "cages":   [{"name": "belly", "polygon": [[200, 200], [310, 200], [310, 300], [200, 300]]}],
          "regions": [{"name": "hand", "polygon": [[160, 220], [180, 220], [180, 240], [160, 240]]}]
        }"#;
        let h: Handles = serde_json::from_str(json).unwrap();
        h.validate().unwrap();
        assert_eq!(
            h.names().collect::<Vec<_>>(),
            ["hip", "chest", "arm_l", "nose", "belly", "hand"]
        );
    }

    #[test]
    fn a_bones_root_is_its_first_ancestor_without_parent() {
        let mut h = Handles {
            bones: vec![
                bone("hip", None),
                bone("chest", Some("hip")),
                bone("arm", Some("chest")),
                bone("prop", None),
            ],
            ..Default::default()
        };
        let root = |h: &Handles, name: &str| h.root_bone(name).map(|b| b.name.clone());
        assert_eq!(root(&h, "arm").as_deref(), Some("hip"));
        assert_eq!(root(&h, "hip").as_deref(), Some("hip"));
        assert_eq!(root(&h, "prop").as_deref(), Some("prop"));
        assert_eq!(root(&h, "nose"), None);
        h.bones[0].parent = Some("arm".into());
        assert_eq!(root(&h, "arm"), None, "a parent loop has no root");
    }

    #[test]
    fn rejects_bad_handles() {
        let dup = Handles {
            bones: vec![bone("a", None)],
            points: vec![PointHandle {
                name: "a".into(),
                at: Point::new(1.0, 1.0),
                parent: None,
            }],
            ..Default::default()
        };
        assert_eq!(dup.validate(), Err(HandleError::DuplicateName("a".into())));
        let unknown = Handles {
            bones: vec![bone("a", Some("zz"))],
            ..Default::default()
        };
        let misspelt = Handles {
            bones: vec![bone("shoulder", None), bone("arm", Some("sholder"))],
            ..Default::default()
        };
        assert_eq!(
            misspelt.validate().unwrap_err().to_string(),
            "bone 'arm' has unknown parent 'sholder'; did you mean 'shoulder'?"
        );
        assert!(matches!(
            unknown.validate(),
            Err(HandleError::UnknownParent {
                suggestion: None,
                ..
            })
        ));
        let cyclic = Handles {
            bones: vec![bone("a", Some("b")), bone("b", Some("a"))],
            ..Default::default()
        };
        assert!(matches!(
            cyclic.validate(),
            Err(HandleError::CyclicParents(_))
        ));
        let mut short = bone("a", None);
        short.tail = short.head;
        assert_eq!(
            Handles {
                bones: vec![short],
                ..Default::default()
            }
            .validate(),
            Err(HandleError::DegenerateBone("a".into()))
        );
        let nan = Handles {
            points: vec![PointHandle {
                name: "p".into(),
                at: Point::new(f64::NAN, 0.0),
                parent: None,
            }],
            ..Default::default()
        };
        assert_eq!(nan.validate(), Err(HandleError::NonFinite("p".into())));
        let flat = Handles {
            cages: vec![Cage {
                name: "c".into(),
                polygon: vec![
                    Point::new(0.0, 0.0),
                    Point::new(1.0, 1.0),
                    Point::new(0.0, 0.0),
                ],
            }],
            ..Default::default()
        };
        assert!(matches!(
            flat.validate(),
            Err(HandleError::DegeneratePolygon { .. })
        ));
    }

    #[test]
    fn a_points_parent_is_a_bone_kept_through_renames_and_deletes() {
        let point = |parent: &str| PointHandle {
            name: "p".into(),
            at: Point::new(1.0, 1.0),
            parent: Some(parent.into()),
        };
        let mut h = Handles {
            bones: vec![bone("a", None), bone("b", Some("a"))],
            points: vec![point("zz")],
            ..Default::default()
        };
        assert_eq!(
            h.validate(),
            Err(HandleError::UnknownPointParent {
                point: "p".into(),
                parent: "zz".into(),
                suggestion: None
            })
        );
        h.points[0] = point("b");
        assert_eq!(h.validate(), Ok(()));
        assert_eq!(h.point_parent(0), Some(1));
        h.rename("b", "fore");
        assert_eq!(h.points[0].parent.as_deref(), Some("fore"));
        // The deleted bone's point moves up to its parent, as its child bones do.
        h.delete("fore");
        assert_eq!(h.points[0].parent.as_deref(), Some("a"));
        h.delete("a");
        assert_eq!(h.points[0].parent, None);
        assert_eq!(h.validate(), Ok(()));
    }

    #[test]
    fn bind_names_known_handles_and_expands_to_columns() {
        let mut h = Handles {
            points: vec![PointHandle {
                name: "p".into(),
                at: Point::new(0.0, 0.0),
                parent: None,
            }],
            cages: vec![Cage {
                name: "c".into(),
                polygon: vec![
                    Point::new(0.0, 0.0),
                    Point::new(9.0, 0.0),
                    Point::new(0.0, 9.0),
                ],
            }],
            ..Default::default()
        };
        h.bind.insert("c".into(), vec!["body".into()]);
        assert_eq!(h.validate(), Ok(()));
        assert_eq!(h.columns_binding("body"), vec![true; 4]);
        assert_eq!(h.columns_binding("arm"), vec![true, false, false, false]);
        assert!(h.for_part("arm").cages.is_empty());
        h.bind.insert("ghost".into(), vec!["body".into()]);
        assert_eq!(
            h.validate(),
            Err(HandleError::UnknownBindHandle {
                name: "ghost".into(),
                suggestion: None
            })
        );
        h.bind.remove("ghost");
        h.bind.insert("p".into(), vec![]);
        assert_eq!(h.validate(), Err(HandleError::EmptyBind("p".into())));
    }

    #[test]
    fn ik_constraints_have_distinct_names_and_do_not_chase_each_other() {
        let bone = |name: &str, x: f64| Bone {
            name: name.into(),
            parent: None,
            head: Point::new(x, 0.0),
            tail: Point::new(x, 10.0),
        };
        let ik = |name: &str, chain: &str, target: &str| BoneIk {
            name: name.into(),
            bones: vec![chain.into()],
            target: target.into(),
            bend_positive: true,
            mix: 1.0,
            softness_px: 0.0,
        };
        let mut h = Handles {
            bones: vec![bone("a", 0.0), bone("b", 20.0), bone("c", 40.0)],
            ik: vec![ik("k", "a", "b"), ik("m", "c", "b")],
            ..Default::default()
        };
        assert_eq!(h.validate(), Ok(()));
        h.ik[1].name = "k".into();
        assert!(matches!(
            h.validate(),
            Err(HandleError::BadIkConstraint { .. })
        ));
        // k moves a toward b while m moves b toward a.
        h.ik[1] = ik("m", "b", "a");
        let e = h.validate().unwrap_err().to_string();
        assert!(e.contains("through other ik constraints"), "{e}");
    }
}
