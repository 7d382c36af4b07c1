//! A motion added to a rig document: the one path from a clip to a keyed animation that the
//! command line (`sinew animate`, `sinew auto`) and the editor (*Apply motion…*) share.
//!
//! In: a [`RigDocument`], a [`Clip`], an optional user [`MapFile`], the animation's name and
//! the [`RetargetOptions`]. Out: the document with the animation added (or replaced), checked
//! against the rig as any animation the document holds, and what retargeting chose. A clip
//! made to loop ([`RetargetReport::looped`]) is stored flagged `loop` as retargeting made it (a
//! cycle, [`crate::anim::Animation::looping`]).

use super::bvh::Clip;
use super::map::{JointMap, MapError, MapFile};
use super::retarget::{retarget, RetargetError, RetargetOptions, RetargetReport};
use crate::anim::AnimError;
use crate::io::RigDocument;

/// What went wrong.
#[derive(Debug, thiserror::Error)]
pub enum ApplyError {
    #[error(transparent)]
    Map(#[from] MapError),
    #[error(transparent)]
    Retarget(#[from] RetargetError),
    #[error("the retargeted animation does not fit the rig: {0}")]
    Check(#[from] AnimError),
    #[error("an animation needs a name")]
    NoName,
}

/// Retargets `clip` onto the rig of `doc` and stores it as animation `name` (replacing one of
/// that name). The document is unchanged when this fails.
pub fn apply_motion(
    doc: &mut RigDocument,
    clip: &Clip,
    map: Option<&MapFile>,
    name: &str,
    options: &RetargetOptions,
) -> Result<RetargetReport, ApplyError> {
    if name.trim().is_empty() {
        return Err(ApplyError::NoName);
    }
    let bones: Vec<&str> = doc.handles.bones.iter().map(|b| b.name.as_str()).collect();
    let joint_map = match map {
        Some(file) => JointMap::from_file(file, clip, &bones)?,
        None => JointMap::for_rig(clip, &bones)?,
    };
    let retargeted = retarget(&doc.handles, clip, &joint_map, options)?;
    let previous = doc
        .animations
        .insert(name.to_string(), retargeted.animation);
    if let Err(e) = doc.check_animations() {
        match previous {
            Some(old) => doc.animations.insert(name.to_string(), old),
            None => doc.animations.remove(name),
        };
        return Err(e.into());
    }
    Ok(retargeted.report)
}
