//! Exports of a rig for other tools' runtimes: [`spine`] (Spine 4.2 JSON + atlas + pages),
//! [`dragonbones`] (DragonBones 5.5 JSON + atlas + page) and [`gltf`] (binary glTF 2.0: skinned
//! meshes, textures, baked animations). [`joints`] is the skeleton the last two share.

pub mod dragonbones;
pub mod gltf;
pub mod joints;
pub mod spine;
