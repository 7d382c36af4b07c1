//! `sinew target RIG.json [RUNTIME|none]`: the runtime a rig is made for. Without a runtime it
//! prints the rig's; with one it records it in the rig document, so `sinew pose`, `sinew
//! render` and the editor play its animations as that runtime plays the export.

use anyhow::{bail, Result};
use clap::Args;
use sinew::io::{RigDocument, RuntimeTarget};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct TargetArgs {
    /// The rig document.
    pub rig: PathBuf,
    /// spine-4.1, spine-4.2, spine-4.3, dragonbones, gltf, or none (play exactly). Omitted: print
    /// the rig's target.
    pub runtime: Option<String>,
}

pub fn run(args: &TargetArgs) -> Result<()> {
    let mut doc = RigDocument::load(&args.rig)?;
    let Some(name) = &args.runtime else {
        println!("{}", doc.target.map_or("none", RuntimeTarget::name));
        return Ok(());
    };
    let target = match name.as_str() {
        "none" => None,
        other => match RuntimeTarget::parse(other) {
            Some(t) => Some(t),
            None => bail!(
                "unknown runtime '{other}': use one of {}, or none",
                RuntimeTarget::ALL.map(RuntimeTarget::name).join(", ")
            ),
        },
    };
    if doc.target != target {
        doc.target = target;
        doc.save(&args.rig)?;
    }
    match target {
        Some(t) => super::out::report!(
            "{}: pose, render and the editor play as {} plays the export",
            args.rig.display(),
            t.label()
        ),
        None => super::out::report!("{}: animations play exactly", args.rig.display()),
    }
    Ok(())
}
