//! From a rig and a pose to a skinning-IK [`Problem`], and the solver that keeps its state.
//!
//! In: validated [`Handles`], the rig's skinned meshes (parts in draw order, weights over
//! [`handle_columns`]) and a [`Pose`] with `ik` drags. Out: per-column skinning transforms.
//!
//! Which handles the solver may move: a bone or point or cage the pose names is *keyed* and
//! keeps what the pose gives it — relative to its nearest unkeyed ancestor bone if it has one
//! (a keyed forearm under a free upper arm turns with it, and so does a keyed point it
//! carries), absolutely otherwise. An unkeyed point is free under drags whether a bone carries
//! it or not, as an unkeyed child bone is: its freedom is what lets the shape around it bend. Every other
//! handle is free: bones rigid (rotation and translation, [`IkOptions::bones`]), regions
//! near-rigid,
//! points and cage vertices as
//! [`IkOptions::points`] and [`IkOptions::cage_vertices`] say. A free bone's head stays on its
//! parent ([`IkOptions::connect_joints`]). Disjoint skeletons are coupled only through the
//! shape they skin.

use super::fast::{ColumnDofs, DragRow, FastIk, IkSolution, Joint, Problem};
use super::subspace::{add_skinning_row, SkinnedMesh};
use super::{BoneDofs, HandleDofs, IkError, IkOptions, MAX_MOMENTUM_STEP_S, MIN_MOMENTUM_STEP_S};
use crate::geom::Point;
use crate::rig::handles::Handles;
use crate::rig::pose::{handle_columns, handle_transforms, Affine, IkDrag, Pose};
use nalgebra::Matrix2;
use std::collections::BTreeMap;

/// The skinning-IK solver of one rig, with its precomputation and warm start.
#[derive(Clone, Debug)]
pub struct RigIk {
    pub handles: Handles,
    /// Shared between clones: solvers of one rig differ only in their warm start.
    pub meshes: std::sync::Arc<Vec<SkinnedMesh>>,
    pub solver: FastIk,
    /// Per column: inertia from [`IkOptions::momentum`], s (0: none).
    inertia_s: Vec<f64>,
    /// The last two results of [`RigIk::step`], oldest first: the momentum handles' motion.
    history: Vec<Vec<Affine>>,
    /// The time between the two results in `history`, s: their difference over it is the
    /// momentum handles' velocity.
    history_step_s: f64,
    /// Skinning rows of the points drags have gripped, by their rest position's bits: finding
    /// the triangle under a point scans every triangle, and a dragged point stays the same
    /// while only its target moves.
    gripped: BTreeMap<[u64; 2], Vec<f64>>,
}

impl RigIk {
    /// Precomputes the reduced energy for `meshes` (parts back to front, weights over the
    /// columns of [`handle_columns`]`(handles)`).
    pub fn precompute(
        handles: &Handles,
        meshes: Vec<SkinnedMesh>,
        options: IkOptions,
    ) -> Result<Self, IkError> {
        let names = handle_columns(handles);
        let mut inertia_s = vec![0.0; names.len()];
        for (name, &tau) in &options.momentum {
            let j = names
                .iter()
                .position(|c| c == name)
                .ok_or_else(|| IkError::UnknownMomentumHandle(name.clone()))?;
            if !(tau.is_finite() && tau >= 0.0) {
                return Err(IkError::BadMomentum(name.clone()));
            }
            inertia_s[j] = tau;
        }
        let step_s = options.momentum_step_s;
        if !options.momentum.is_empty()
            && !(MIN_MOMENTUM_STEP_S..=MAX_MOMENTUM_STEP_S).contains(&step_s)
        {
            return Err(IkError::BadMomentumStep(step_s));
        }
        if let Some(name) = options
            .stretch
            .iter()
            .find(|name| !handles.bones.iter().any(|b| &b.name == *name))
        {
            return Err(IkError::UnknownStretchBone(name.clone()));
        }
        let solver = FastIk::precompute(&meshes, names.len(), options)?;
        Ok(RigIk {
            handles: handles.clone(),
            meshes: std::sync::Arc::new(meshes),
            solver,
            inertia_s,
            history: Vec::new(),
            history_step_s: 0.0,
            gripped: BTreeMap::new(),
        })
    }

    /// Forgets the warm start and the momentum handles' motion (the sequence jumps).
    pub fn reset(&mut self) {
        self.solver.reset();
        self.history.clear();
    }

    /// One frame of a sequence, `frame_time_s` after the previous one: [`RigIk::transforms`]
    /// plus secondary motion — handles with momentum are solved even when the pose has no
    /// drags, pulled toward where their motion over the last frames carries them.
    pub fn step(&mut self, pose: &Pose, frame_time_s: f64) -> Result<IkSolution, IkError> {
        let dynamic = self.inertia_s.iter().any(|&t| t > 0.0)
            && frame_time_s > 0.0
            && frame_time_s.is_finite();
        let drags = self.cached_drag_rows(pose)?;
        let problem = self.problem_with(pose, dynamic.then_some(frame_time_s), drags)?;
        let solution = if problem.drags.is_empty() && problem.inertia.is_empty() {
            // Not solved: the next solved frame must not start from a stale result.
            self.solver.reset();
            IkSolution {
                transforms: problem.anchor,
                iterations: 0,
                drag_error_px: 0.0,
                energy: f64::NAN,
            }
        } else if problem.inertia.is_empty() {
            self.solver.solve(&problem)?
        } else {
            let limit = self.solver.options.momentum_iterations;
            self.solver.solve_limited(&problem, Some(limit))?
        };
        self.history.push(solution.transforms.clone());
        if self.history.len() > 2 {
            self.history.remove(0);
        }
        self.history_step_s = frame_time_s;
        Ok(solution)
    }

    /// The skinning transformations of the static pose `pose`, as a fresh solver finds them:
    /// its drags taken in order from the forward-kinematics pose ([`FastIk::solve_static`]),
    /// with no warm start and no guarded triangles carried over, so the answer depends on the
    /// pose alone, and a pin added where a point already is moves nothing. The last
    /// factorization is reused when the problem's structure is the same, which changes the
    /// cost, never the answer.
    pub fn solve_pose(&mut self, pose: &Pose) -> Result<IkSolution, IkError> {
        let drags = self.cached_drag_rows(pose)?;
        let problem = self.problem_with(pose, None, drags)?;
        if problem.drags.is_empty() {
            self.solver.reset();
            return Ok(IkSolution {
                transforms: problem.anchor,
                iterations: 0,
                drag_error_px: 0.0,
                energy: f64::NAN,
            });
        }
        self.solver.solve_static(&problem)
    }

    /// The skinning transformations for `pose`: forward kinematics if it has no drags, the
    /// skinning IK otherwise (warm-started from the previous call: a speed device for
    /// interactive use; [`RigIk::solve_pose`] is the answer of record).
    pub fn transforms(&mut self, pose: &Pose) -> Result<IkSolution, IkError> {
        let drags = self.cached_drag_rows(pose)?;
        let problem = self.problem_with(pose, None, drags)?;
        if problem.drags.is_empty() {
            return Ok(IkSolution {
                transforms: problem.anchor,
                iterations: 0,
                drag_error_px: 0.0,
                energy: f64::NAN,
            });
        }
        self.solver.solve(&problem)
    }

    /// The problem `pose` poses (see the module doc).
    pub fn problem(&self, pose: &Pose) -> Result<Problem, IkError> {
        let drags = pose
            .ik
            .iter()
            .map(|d| self.drag_row(d))
            .collect::<Result<Vec<_>, _>>()?;
        self.problem_with(pose, None, drags)
    }

    /// The pose's drags as rows, gripping each rest point once per solver (see `gripped`).
    fn cached_drag_rows(&mut self, pose: &Pose) -> Result<Vec<DragRow>, IkError> {
        pose.ik
            .iter()
            .map(|drag| {
                let key = [drag.at.x.to_bits(), drag.at.y.to_bits()];
                // The same check as an uncached drag's: a cached grip is no licence.
                check_drag(drag)?;
                match self.gripped.get(&key) {
                    Some(row) => Ok(DragRow {
                        row: row.clone(),
                        target: drag.to,
                        weight: drag.weight,
                    }),
                    _ => {
                        let row = self.drag_row(drag)?;
                        self.gripped.insert(key, row.row.clone());
                        Ok(row)
                    }
                }
            })
            .collect()
    }

    /// [`RigIk::problem`] with the drags' rows given; with a frame time, handles with momentum
    /// are free and carry it.
    fn problem_with(
        &self,
        pose: &Pose,
        frame_time_s: Option<f64>,
        drags: Vec<DragRow>,
    ) -> Result<Problem, IkError> {
        let handles = &self.handles;
        let dragged = !pose.ik.is_empty();
        // A handle the solver may move: unkeyed, and either drags move everything free or it
        // carries momentum in this frame.
        let movable = |j: usize| dragged || (frame_time_s.is_some() && self.inertia_s[j] > 0.0);
        let options = &self.solver.options;
        // Forward kinematics applies the bone IK constraints itself; the constrained pose only
        // says which bones they decide (like keyed ones), so they are not applied twice.
        let fk = handle_transforms(handles, pose)?;
        let pose = &crate::rig::bone_ik::constrained_pose(handles, pose)?;
        let mut columns: Vec<ColumnDofs> = Vec::with_capacity(fk.len());
        let mut joints = Vec::new();
        let bone_index = |name: &str| handles.bones.iter().position(|b| b.name == name);
        // A bone is decided (by the pose or by forward kinematics) unless it may move.
        let keyed = |i: usize| pose.bones.contains_key(&handles.bones[i].name) || !movable(i);
        // A decided column `j` under bone `parent`: it follows the nearest unkeyed ancestor,
        // if any (validated parents are acyclic), or stays where forward kinematics puts it.
        let decided = |j: usize, parent: Option<usize>| -> Result<ColumnDofs, IkError> {
            let mut ancestor = parent;
            while let Some(a) = ancestor {
                if !keyed(a) {
                    break;
                }
                ancestor = handles.bones[a].parent.as_deref().and_then(bone_index);
            }
            Ok(match ancestor {
                Some(a) => {
                    let world_from_ancestor = fk[a].inverse().ok_or(IkError::Singular)?;
                    ColumnDofs::Follows {
                        parent: a,
                        local: world_from_ancestor.then_after(&fk[j]),
                    }
                }
                None => ColumnDofs::Fixed(fk[j]),
            })
        };
        for (i, bone) in handles.bones.iter().enumerate() {
            let parent = bone.parent.as_deref().and_then(bone_index);
            if !keyed(i) {
                columns.push(match options.bones {
                    BoneDofs::Rigid | BoneDofs::Uniform => ColumnDofs::Rigid {
                        pivot: bone.head,
                        scale: options.bones == BoneDofs::Uniform
                            || options.stretch.contains(&bone.name),
                    },
                    BoneDofs::Affine => ColumnDofs::Affine {
                        rigidity: options.rigidity,
                    },
                });
                if let (Some(p), true) = (parent, options.connect_joints) {
                    joints.push(Joint {
                        child: i,
                        parent: p,
                        at: bone.head,
                    });
                }
                continue;
            }
            columns.push(decided(i, parent)?);
        }
        let free = |dofs: HandleDofs| match dofs {
            HandleDofs::Affine => ColumnDofs::Affine { rigidity: 0.0 },
            HandleDofs::Rigid => ColumnDofs::Affine {
                rigidity: options.region_rigidity,
            },
            HandleDofs::Translation => ColumnDofs::Translation {
                linear: Matrix2::identity(),
            },
        };
        for (i, point) in handles.points.iter().enumerate() {
            let j = columns.len();
            columns.push(if pose.points.contains_key(&point.name) || !movable(j) {
                decided(j, handles.point_parent(i))?
            } else {
                free(options.points)
            });
        }
        for cage in &handles.cages {
            let posed = pose.cages.contains_key(&cage.name);
            for _ in &cage.polygon {
                let j = columns.len();
                columns.push(if posed || !movable(j) {
                    ColumnDofs::Fixed(fk[j])
                } else {
                    free(options.cage_vertices)
                });
            }
        }
        for _ in &handles.regions {
            let j = columns.len();
            columns.push(if movable(j) {
                ColumnDofs::Affine {
                    rigidity: options.region_rigidity,
                }
            } else {
                ColumnDofs::Fixed(fk[j])
            });
        }
        let mut inertia = Vec::new();
        if let (Some(h), Some(now)) = (frame_time_s, self.history.last()) {
            let before = self
                .history
                .first()
                .filter(|_| self.history.len() == 2)
                .unwrap_or(now);
            // Velocity per second (the last step over its own duration), carried over this
            // frame's h and decayed by exp(−rate · h): the motion does not depend on the frame
            // rate, only the time stepping's accuracy does.
            let velocity_per_s = if self.history.len() == 2
                && self.history_step_s > 0.0
                && self.history_step_s.is_finite()
            {
                1.0 / self.history_step_s
            } else {
                0.0
            };
            let rate = options.momentum_damping_per_s.max(0.0);
            let carry = h * velocity_per_s * (-rate * h).exp();
            for (j, c) in columns.iter().enumerate() {
                let tau = self.inertia_s[j];
                if tau <= 0.0
                    || !matches!(
                        c,
                        ColumnDofs::Affine { .. }
                            | ColumnDofs::Translation { .. }
                            | ColumnDofs::Rigid { .. }
                    )
                {
                    continue;
                }
                let predicted = Affine {
                    linear: now[j].linear + (now[j].linear - before[j].linear) * carry,
                    translation: now[j].translation
                        + (now[j].translation - before[j].translation) * carry,
                };
                inertia.push((j, (tau / h).powi(2), predicted));
            }
        }
        Ok(Problem {
            columns,
            joints,
            drags,
            anchor: fk,
            inertia,
        })
    }

    /// The skinning row of the material point a drag grips, and its target.
    pub fn drag_row(&self, drag: &IkDrag) -> Result<DragRow, IkError> {
        check_drag(drag)?;
        let at = drag.at;
        let (mesh, triangle, barycentric) =
            grip(&self.meshes, at, self.solver.options.grip_tolerance_px)
                .ok_or(IkError::DragOutside(at.x, at.y))?;
        let mesh = &self.meshes[mesh];
        let mut row = vec![0.0; 3 * self.solver.subspace.column_count];
        for (k, &v) in mesh.triangles[triangle].iter().enumerate() {
            add_skinning_row(
                mesh.rest[v as usize],
                &mesh.weights[v as usize],
                barycentric[k],
                &mut row,
            );
        }
        Ok(DragRow {
            row,
            target: drag.to,
            weight: drag.weight,
        })
    }
}

/// The topmost mesh triangle under `p` (parts drawn later win), with barycentric coordinates;
/// failing that, the nearest triangle within `tolerance_px`, gripped at its nearest point.
pub fn grip(
    meshes: &[SkinnedMesh],
    p: Point,
    tolerance_px: f64,
) -> Option<(usize, usize, [f64; 3])> {
    let mut nearest: Option<(f64, usize, usize, [f64; 3])> = None;
    for (m, mesh) in meshes.iter().enumerate().rev() {
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|v| mesh.rest[v as usize]);
            let Some(bary) = crate::geom::barycentric(p, a, b, c) else {
                continue;
            };
            if bary.iter().all(|&x| x >= -1e-12) {
                return Some((m, t, bary));
            }
            // Outside: the closest point of the triangle lies on one of its edges.
            for (u, v) in [(0usize, 1usize), (1, 2), (2, 0)] {
                let (pu, pv) = ([a, b, c][u], [a, b, c][v]);
                let e = pv - pu;
                let s = ((p - pu).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
                let d = (pu + e * s - p).norm();
                if d <= tolerance_px && nearest.as_ref().is_none_or(|n| d < n.0) {
                    let mut w = [0.0; 3];
                    w[u] = 1.0 - s;
                    w[v] = s;
                    nearest = Some((d, m, t, w));
                }
            }
        }
    }
    nearest.map(|(_, m, t, w)| (m, t, w))
}

/// Applies per-column transforms to a rest point through its skinning row (for checks).
pub fn skinned_position(row: &[f64], transforms: &[Affine]) -> Point {
    let (mut x, mut y) = (0.0, 0.0);
    for (j, t) in transforms.iter().enumerate() {
        let (a, b, c) = (row[3 * j], row[3 * j + 1], row[3 * j + 2]);
        x += a * t.linear[(0, 0)] + b * t.linear[(0, 1)] + c * t.translation.x;
        y += a * t.linear[(1, 0)] + b * t.linear[(1, 1)] + c * t.translation.y;
    }
    Point::new(x, y)
}

/// A drag's one check ([`IkDrag::check`]), in the IK's own terms where it has them.
fn check_drag(drag: &IkDrag) -> Result<(), IkError> {
    let values = [drag.at[0], drag.at[1], drag.to[0], drag.to[1]];
    if values.iter().any(|v| !v.is_finite())
        || drag.weight.is_some_and(|w| !(w.is_finite() && w >= 0.0))
    {
        return Err(IkError::NonFinite);
    }
    if drag
        .to
        .iter()
        .any(|v| v.abs() > crate::rig::pose::MAX_POSED_PX)
    {
        return Err(IkError::TargetTooFar(drag.to[0], drag.to[1]));
    }
    Ok(drag.check()?)
}
