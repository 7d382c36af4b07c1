//! The bundled character, built into the binary: `sinew demo` reads it from here unless
//! `--assets DIR` names a folder, so an installed `sinew` needs no checkout (issue 45). The
//! files are those of `assets/character/` that the demo reads; a unit test holds the list to
//! `layers.json` and the bytes to the files.

use anyhow::{anyhow, Context, Result};
use std::borrow::Cow;
use std::path::Path;

/// Each file of `assets/character/` the demo reads, by its name there.
const BUILT_IN: &[(&str, &[u8])] = &[
    (
        "layers.json",
        include_bytes!("../../assets/character/layers.json"),
    ),
    (
        "handles.json",
        include_bytes!("../../assets/character/handles.json"),
    ),
    (
        "animations.json",
        include_bytes!("../../assets/character/animations.json"),
    ),
    (
        "events.json",
        include_bytes!("../../assets/character/events.json"),
    ),
    (
        "tail.png",
        include_bytes!("../../assets/character/tail.png"),
    ),
    (
        "leg_lower_l.png",
        include_bytes!("../../assets/character/leg_lower_l.png"),
    ),
    (
        "leg_upper_l.png",
        include_bytes!("../../assets/character/leg_upper_l.png"),
    ),
    (
        "leg_lower_r.png",
        include_bytes!("../../assets/character/leg_lower_r.png"),
    ),
    (
        "leg_upper_r.png",
        include_bytes!("../../assets/character/leg_upper_r.png"),
    ),
    (
        "torso.png",
        include_bytes!("../../assets/character/torso.png"),
    ),
    (
        "head.png",
        include_bytes!("../../assets/character/head.png"),
    ),
    (
        "arm_lower_l.png",
        include_bytes!("../../assets/character/arm_lower_l.png"),
    ),
    (
        "arm_upper_l.png",
        include_bytes!("../../assets/character/arm_upper_l.png"),
    ),
    (
        "arm_lower_r.png",
        include_bytes!("../../assets/character/arm_lower_r.png"),
    ),
    (
        "arm_upper_r.png",
        include_bytes!("../../assets/character/arm_upper_r.png"),
    ),
    ("bag.png", include_bytes!("../../assets/character/bag.png")),
    (
        "arm_lower_l_open.png",
        include_bytes!("../../assets/character/arm_lower_l_open.png"),
    ),
    (
        "bag_pail.png",
        include_bytes!("../../assets/character/bag_pail.png"),
    ),
];

/// Where the demo's character comes from: the copy built into sinew, or a folder laid out as
/// `assets/character/` is.
#[derive(Clone, Copy, Debug)]
pub enum DemoAssets<'a> {
    BuiltIn,
    Folder(&'a Path),
}

impl<'a> DemoAssets<'a> {
    /// The folder when one is given, else the built-in character.
    pub fn new(folder: Option<&'a Path>) -> Self {
        folder.map_or(DemoAssets::BuiltIn, DemoAssets::Folder)
    }

    /// A file as messages name it: its path, or `NAME (the character built into sinew)`.
    pub fn name(&self, file: &str) -> String {
        match self {
            DemoAssets::BuiltIn => format!("{file} (the character built into sinew)"),
            DemoAssets::Folder(dir) => dir.join(file).display().to_string(),
        }
    }

    /// The file's bytes, or `None` when there is no such file.
    pub fn read_optional(&self, file: &str) -> Result<Option<Cow<'static, [u8]>>> {
        match self {
            DemoAssets::BuiltIn => Ok(BUILT_IN
                .iter()
                .find(|(name, _)| *name == file)
                .map(|(_, bytes)| Cow::Borrowed(*bytes))),
            DemoAssets::Folder(dir) => {
                let path = dir.join(file);
                match std::fs::read(&path) {
                    Ok(bytes) => Ok(Some(Cow::Owned(bytes))),
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
                    Err(e) => Err(e).with_context(|| format!("{}: cannot read", path.display())),
                }
            }
        }
    }

    /// The file's bytes; a missing file is an error naming it.
    pub fn read(&self, file: &str) -> Result<Cow<'static, [u8]>> {
        self.read_optional(file)?.ok_or_else(|| match self {
            DemoAssets::BuiltIn => anyhow!(
                "{file}: not part of the character built into sinew (it has {})",
                BUILT_IN
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            DemoAssets::Folder(dir) => {
                anyhow!("{}: cannot read: no such file", dir.join(file).display())
            }
        })
    }

    /// A JSON file read as `T` (`what` names its kind in messages: "handles file"). A folder's
    /// files are read as `sinew rig` and the other commands read them.
    pub fn read_json<T: serde::de::DeserializeOwned>(&self, file: &str, what: &str) -> Result<T> {
        match self {
            DemoAssets::Folder(dir) => Ok(sinew::jobs::read_json(&dir.join(file), what)?),
            DemoAssets::BuiltIn => serde_json::from_slice(&self.read(file)?)
                .with_context(|| format!("{}: not a {what}", self.name(file))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CHECKOUT_ASSETS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/character");

    /// The built-in files are the checkout's, byte for byte, and they are every file the
    /// demo reads: the layer list's layers and attachments, the handles, animations and
    /// events.
    #[test]
    fn the_built_in_character_is_the_bundled_one_complete() {
        let list: serde_json::Value = DemoAssets::BuiltIn
            .read_json("layers.json", "layer list")
            .unwrap();
        let mut wanted: Vec<String> = [
            "layers.json",
            "handles.json",
            "animations.json",
            "events.json",
        ]
        .map(String::from)
        .to_vec();
        for name in list["layers"].as_array().unwrap() {
            wanted.push(format!("{}.png", name.as_str().unwrap()));
        }
        for name in list["attachments"].as_object().unwrap().keys() {
            wanted.push(format!("{name}.png"));
        }
        let mut built_in: Vec<&str> = BUILT_IN.iter().map(|(n, _)| *n).collect();
        built_in.sort_unstable();
        let mut wanted_sorted: Vec<&str> = wanted.iter().map(String::as_str).collect();
        wanted_sorted.sort_unstable();
        assert_eq!(built_in, wanted_sorted);
        for (name, bytes) in BUILT_IN {
            let file = std::fs::read(Path::new(CHECKOUT_ASSETS).join(name)).unwrap();
            assert!(file == *bytes, "{name} differs from the checkout's");
        }
    }

    #[test]
    fn a_file_the_character_lacks_is_named_with_what_it_has() {
        let error = DemoAssets::BuiltIn
            .read("cape.png")
            .unwrap_err()
            .to_string();
        assert!(
            error.starts_with("cape.png: not part of the character built into sinew"),
            "{error}"
        );
        assert!(error.contains("head.png"), "{error}");
        assert!(DemoAssets::BuiltIn
            .read_optional("cape.png")
            .unwrap()
            .is_none());
        let dir = Path::new(CHECKOUT_ASSETS);
        assert!(DemoAssets::Folder(dir)
            .read_optional("cape.png")
            .unwrap()
            .is_none());
        let error = DemoAssets::Folder(dir)
            .read("cape.png")
            .unwrap_err()
            .to_string();
        assert!(
            error.ends_with("cape.png: cannot read: no such file"),
            "{error}"
        );
    }
}
