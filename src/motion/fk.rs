//! Forward kinematics of a BVH [`Clip`]: world-space joint positions per frame.
//!
//! In: a clip and a frame index. Out: each joint's world transform ([`JointPose`]: rotation
//! and origin) and, from them, [`FramePositions`]: the world position of every joint's origin
//! and of every end site, in the file's units and frame (BVH: y-up, right-handed; nothing is
//! converted).
//!
//! The conventions (those of the Biovision format as Meredith and Maddock, "Motion Capture
//! File Formats Explained", 2001, describe it, and of the CMU conversions):
//!
//! - A joint's local transform is a translation by `OFFSET` plus its position channels (a
//!   missing axis adds 0; in practice only roots have position channels, with a zero OFFSET),
//!   then its rotation.
//! - Rotation channels are degrees and are applied in the order written in the file as
//!   intrinsic rotations: for `CHANNELS 3 Zrotation Xrotation Yrotation` with values a, b, c,
//!   the local rotation is R = Rz(a) · Rx(b) · Ry(c), applied to column vectors (so a child
//!   offset v becomes R v). R_axis(θ) turns counter-clockwise by θ looking down the axis
//!   towards the origin (right-handed). Position channels may stand anywhere in the list; they
//!   only translate.
//! - World: W_joint = W_parent · T(offset + position) · R; the joint's position is W's
//!   translation, an end site's is W_joint applied to its OFFSET.

use super::bvh::{Channel, Clip, JointId};
use nalgebra::{Point3, Rotation3, Vector3};

/// A joint's world transform in one frame: x_world = rotation · x_local + origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointPose {
    pub rotation: Rotation3<f64>,
    /// The joint's world position (the origin of its frame), file units.
    pub origin: Point3<f64>,
}

/// World positions of one frame, file units.
#[derive(Clone, Debug, PartialEq)]
pub struct FramePositions {
    /// Indexed like [`Clip::joints`] (see [`FramePositions::joint`]).
    pub joints: Vec<Point3<f64>>,
    /// The end site of each joint that has one, indexed like [`Clip::joints`].
    pub end_sites: Vec<Option<Point3<f64>>>,
}

impl FramePositions {
    /// The joint's position.
    pub fn joint(&self, id: JointId) -> Option<Point3<f64>> {
        self.joints.get(id.index()).copied()
    }

    /// The joint's end site's position, if it has one.
    pub fn end_site(&self, id: JointId) -> Option<Point3<f64>> {
        self.end_sites.get(id.index()).copied().flatten()
    }
}

/// The rotation of one axis by `degrees` (right-handed).
pub fn axis_rotation(axis: usize, degrees: f64) -> Rotation3<f64> {
    let radians = degrees.to_radians();
    match axis {
        0 => Rotation3::from_axis_angle(&Vector3::x_axis(), radians),
        1 => Rotation3::from_axis_angle(&Vector3::y_axis(), radians),
        _ => Rotation3::from_axis_angle(&Vector3::z_axis(), radians),
    }
}

/// A joint's local rotation and translation from its channels' `values` (as many as it has
/// channels, in its order): R = R_first · R_second · R_third over the rotation channels as
/// written; translation = `offset` + the position channels.
pub fn local_transform(
    channels: &[Channel],
    values: &[f64],
    offset: &Vector3<f64>,
) -> (Rotation3<f64>, Vector3<f64>) {
    let mut rotation = Rotation3::identity();
    let mut translation = *offset;
    for (&channel, &value) in channels.iter().zip(values) {
        if channel.is_rotation() {
            rotation *= axis_rotation(channel.axis(), value);
        } else {
            translation[channel.axis()] += value;
        }
    }
    (rotation, translation)
}

/// Every joint's world transform in frame `frame`, indexed like [`Clip::joints`]; `None` past
/// the last frame.
pub fn joint_poses(clip: &Clip, frame: usize) -> Option<Vec<JointPose>> {
    let row = clip.frame(frame)?;
    poses_from_row(clip, |first, n| row.get(first..first + n))
}

/// The rest pose: every channel 0 (offsets only).
pub fn rest_poses(clip: &Clip) -> Vec<JointPose> {
    let zeros = [0.0; 6];
    poses_from_row(clip, |_, n| zeros.get(..n)).unwrap_or_default()
}

fn poses_from_row<'r>(
    clip: &Clip,
    values: impl Fn(usize, usize) -> Option<&'r [f64]>,
) -> Option<Vec<JointPose>> {
    let mut poses: Vec<JointPose> = Vec::with_capacity(clip.joints.len());
    for joint in &clip.joints {
        let v = values(joint.first_channel, joint.channels.len())?;
        let (r, t) = local_transform(&joint.channels, v, &joint.offset);
        // Parents come before their children (the parser builds them so).
        let pose = match joint.parent.and_then(|p| poses.get(p.index())) {
            Some(parent) => JointPose {
                rotation: parent.rotation * r,
                origin: parent.origin + parent.rotation * t,
            },
            None => JointPose {
                rotation: r,
                origin: Point3::from(t),
            },
        };
        poses.push(pose);
    }
    Some(poses)
}

/// World positions of joints and end sites from their transforms.
pub fn positions_from_poses(clip: &Clip, poses: &[JointPose]) -> FramePositions {
    FramePositions {
        joints: poses.iter().map(|p| p.origin).collect(),
        end_sites: clip
            .joints
            .iter()
            .zip(poses)
            .map(|(j, p)| j.end_site.map(|e| p.origin + p.rotation * e))
            .collect(),
    }
}

/// World positions in frame `frame`; `None` past the last frame.
pub fn frame_positions(clip: &Clip, frame: usize) -> Option<FramePositions> {
    joint_poses(clip, frame).map(|poses| positions_from_poses(clip, &poses))
}

/// World positions in the rest pose (every channel 0).
pub fn rest_positions(clip: &Clip) -> FramePositions {
    positions_from_poses(clip, &rest_poses(clip))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::bvh::{parse, BvhLimits};

    fn clip(text: &str) -> Clip {
        parse(text.as_bytes(), &BvhLimits::default()).unwrap()
    }

    fn close(a: Point3<f64>, b: [f64; 3]) {
        assert!((a - Point3::from(b)).norm() < 1e-9, "{a} != {b:?}");
    }

    /// The tiny clip of the parser's tests, positions worked out by hand.
    #[test]
    fn hand_computed_positions() {
        let clip = clip(crate::motion::bvh::tests::TINY);
        let id = |n| clip.find(n).unwrap();
        // Frame 0: all zero, the rest pose.
        let p = frame_positions(&clip, 0).unwrap();
        assert_eq!(p, rest_positions(&clip));
        close(p.joint(id("Hips")).unwrap(), [0.0, 0.0, 0.0]);
        close(p.joint(id("Spine")).unwrap(), [0.0, 10.0, 0.0]);
        close(p.end_site(id("Spine")).unwrap(), [0.0, 15.0, 0.0]);
        close(p.end_site(id("Leg")).unwrap(), [2.0, -8.0, 0.0]);
        assert_eq!(p.end_site(id("Hips")), None);
        // Frame 1: root at (1, 2, 3) turned 90° about z, which takes (x, y, z) to (−y, x, z).
        // Spine: (1,2,3) + Rz90 (0,10,0) = (1,2,3) + (−10,0,0) = (−9, 2, 3).
        // Its end: Spine turns 90° about x ((x,y,z) → (x,−z,y)): (0,5,0) → (0,0,5), then
        // Rz90 leaves (0,0,5): (−9, 2, 8).
        // Leg: (1,2,3) + Rz90 (2,0,0) = (1, 4, 3); its end: Rx90 (0,−8,0) = (0,0,−8), Rz90
        // leaves it: (1, 4, −5).
        let p = frame_positions(&clip, 1).unwrap();
        close(p.joint(id("Hips")).unwrap(), [1.0, 2.0, 3.0]);
        close(p.joint(id("Spine")).unwrap(), [-9.0, 2.0, 3.0]);
        close(p.end_site(id("Spine")).unwrap(), [-9.0, 2.0, 8.0]);
        close(p.joint(id("Leg")).unwrap(), [1.0, 4.0, 3.0]);
        close(p.end_site(id("Leg")).unwrap(), [1.0, 4.0, -5.0]);
        assert_eq!(frame_positions(&clip, 2), None);
    }

    fn one_bone(order: &str, values: &str) -> Point3<f64> {
        let text = format!(
            "HIERARCHY\nROOT a\n{{\nOFFSET 0 0 0\nCHANNELS 3 {order}\nEnd Site\n{{\nOFFSET 0 1 0\n}}\n}}\nMOTION\nFrames: 1\nFrame Time: 0.1\n{values}\n"
        );
        let clip = clip(&text);
        frame_positions(&clip, 0).unwrap().end_sites[0].unwrap()
    }

    /// The same angles (z 90°, x 90°, y 0°) in two channel orders: different, each as worked
    /// out by hand.
    #[test]
    fn channel_order_is_the_written_order() {
        // ZXY: Rz(90) · Rx(90) · (0,1,0): Rx takes it to (0,0,1), Rz leaves it.
        close(
            one_bone("Zrotation Xrotation Yrotation", "90 90 0"),
            [0.0, 0.0, 1.0],
        );
        // XYZ: Rx(90) · Ry(0) · Rz(90) · (0,1,0): Rz takes it to (−1,0,0), Rx leaves it.
        close(
            one_bone("Xrotation Yrotation Zrotation", "90 0 90"),
            [-1.0, 0.0, 0.0],
        );
        // Three angles: ZYX with z 90, y 90, x 90 on (0,1,0): Rx → (0,0,1); Ry(90) takes
        // (x,y,z) to (z,y,−x): (1,0,0); Rz → (0,1,0).
        close(
            one_bone("Zrotation Yrotation Xrotation", "90 90 90"),
            [0.0, 1.0, 0.0],
        );
        // XYZ with the same three: Rz → (−1,0,0); Ry → (0,0,1); Rx → (0,−1,0).
        close(
            one_bone("Xrotation Yrotation Zrotation", "90 90 90"),
            [0.0, -1.0, 0.0],
        );
        // Position channels between rotations only translate.
        close(
            one_bone("Zrotation Yposition Xrotation", "90 5 90"),
            [0.0, 5.0, 1.0],
        );
    }

    /// Joint positions match composing the local transforms along the chain, for any angles.
    #[test]
    fn chain_composition() {
        let clip = clip(crate::motion::bvh::tests::TINY);
        let row = [
            0.5, -1.0, 2.0, 30.0, -20.0, 10.0, 5.0, 15.0, -25.0, 40.0, -35.0, 12.0,
        ];
        let mut c = clip.clone();
        c.frames = row.to_vec();
        let p = frame_positions(&c, 0).unwrap();
        let rz = |a: f64| axis_rotation(2, a);
        let rx = |a: f64| axis_rotation(0, a);
        let ry = |a: f64| axis_rotation(1, a);
        let root = rz(30.0) * rx(-20.0) * ry(10.0);
        let spine = rz(5.0) * rx(15.0) * ry(-25.0);
        let t = Vector3::new(0.5, -1.0, 2.0);
        let expected =
            t + root * (Vector3::new(0.0, 10.0, 0.0) + spine * Vector3::new(0.0, 5.0, 0.0));
        assert!((p.end_sites[1].unwrap().coords - expected).norm() < 1e-12);
        let leg = rx(40.0) * ry(-35.0) * rz(12.0);
        let expected =
            t + root * (Vector3::new(2.0, 0.0, 0.0) + leg * Vector3::new(0.0, -8.0, 0.0));
        assert!((p.end_sites[2].unwrap().coords - expected).norm() < 1e-12);
    }
}
