//! Exports of a rig for other tools' runtimes: [`spine`] (Spine 4.2 JSON + atlas + pages) and
//! [`gltf`] (binary glTF 2.0: skinned meshes, textures, baked animations).

pub mod gltf;
pub mod spine;
