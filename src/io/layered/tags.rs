//! Spine's layer-name tags (`head [slot]`, `[bone:arm] arm`, `hand [ignore]`): the square
//! brackets Spine's Photoshop/GIMP/Krita scripts and its PSD import read, found anywhere in a
//! layer or group name.
//!
//! In: a layer or group name. Out: the name without its tags, trimmed, and the tags (lowercase
//! kind, optional value after `:`). What sinew does with each kind is in docs/formats.md:
//! `ignore`, `merge`, `path`, `origin`/`pivot`, `overlay` act; the others are removed from the
//! name and reported.

/// One `[kind]` or `[kind:value]` tag.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tag {
    /// Lowercase, as `bone` in `[Bone:arm]`.
    pub kind: String,
    /// What follows the first `:`, trimmed (`arm` in `[bone:arm]`).
    pub value: Option<String>,
}

/// A name split into its text and its tags.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tagged {
    pub name: String,
    pub tags: Vec<Tag>,
}

impl Tagged {
    /// Whether a tag of `kind` is present.
    pub fn has(&self, kind: &str) -> bool {
        self.tags.iter().any(|t| t.kind == kind)
    }

    /// The value of the first tag of `kind` that has one.
    pub fn value(&self, kind: &str) -> Option<&str> {
        self.tags
            .iter()
            .find(|t| t.kind == kind)
            .and_then(|t| t.value.as_deref())
    }
}

/// The tags sinew acts on; every other tag is removed from the name and reported.
pub const ACTED_ON: [&str; 6] = ["ignore", "merge", "path", "origin", "pivot", "overlay"];

/// Splits `raw` into its name and tags. An unclosed `[` is kept as text.
pub fn parse(raw: &str) -> Tagged {
    let mut name = String::new();
    let mut tags = Vec::new();
    let mut rest = raw;
    while let Some(open) = rest.find('[') {
        let Some(close) = rest[open..].find(']').map(|c| open + c) else {
            break;
        };
        name.push_str(&rest[..open]);
        let inner = &rest[open + 1..close];
        let (kind, value) = match inner.split_once(':') {
            Some((k, v)) => (k, Some(v.trim().to_string()).filter(|v| !v.is_empty())),
            None => (inner, None),
        };
        tags.push(Tag {
            kind: kind.trim().to_ascii_lowercase(),
            value,
        });
        rest = &rest[close + 1..];
    }
    name.push_str(rest);
    let name = name.split_whitespace().collect::<Vec<_>>().join(" ");
    Tagged { name, tags }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tags_anywhere_in_the_name() {
        let t = parse("[bone:Arm] upper  arm [slot] [IGNORE]");
        assert_eq!(t.name, "upper arm");
        assert_eq!(t.value("bone"), Some("Arm"));
        assert!(t.has("slot") && t.has("ignore") && !t.has("merge"));
        assert_eq!(parse("head").tags, vec![]);
        assert_eq!(parse("half [open").name, "half [open");
        assert_eq!(parse("[path:]x").value("path"), None);
    }
}
