//! Exports of a rig for other tools' runtimes: [`spine`] (Spine 4.2 JSON + atlas + pages).

pub mod spine;
