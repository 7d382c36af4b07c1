//! The bundled motion library: capture clips built into the binary, so that a character moves
//! with no capture file at all. Sources and licences: `assets/motions/SOURCES.md`.

use super::bvh::{parse, BvhError, BvhLimits, Clip};

/// A clip of the library.
pub struct Motion {
    /// What `--motion NAME` calls it.
    pub name: &'static str,
    /// One line on what it is.
    pub about: &'static str,
    /// The BVH file's bytes.
    pub bvh: &'static [u8],
    /// Whether it is a cycle, made to loop ([`crate::motion::LoopMode::Blend`]), or a one-off
    /// ([`crate::motion::LoopMode::Off`]).
    pub looping: bool,
}

/// Every clip of the library, in the order `sinew animate` lists them.
pub const MOTIONS: &[Motion] = &[
    Motion {
        name: "idle",
        about: "standing, weight shifting slightly (CMU 01_01)",
        bvh: include_bytes!("../../assets/motions/idle.bvh"),
        looping: true,
    },
    Motion {
        name: "walk",
        about: "one walk cycle, two steps, loops (DeepMimic)",
        bvh: include_bytes!("../../assets/motions/walk.bvh"),
        looping: true,
    },
    Motion {
        name: "run",
        about: "one run cycle, two strides, loops (DeepMimic)",
        bvh: include_bytes!("../../assets/motions/run.bvh"),
        looping: true,
    },
    Motion {
        name: "jump",
        about: "a two-footed jump forward with an arm swing (DeepMimic)",
        bvh: include_bytes!("../../assets/motions/jump.bvh"),
        looping: false,
    },
    Motion {
        name: "jump_forward",
        about: "a standing jump forward: crouch, flight, landing (CMU 01_01)",
        bvh: include_bytes!("../../assets/motions/jump_forward.bvh"),
        looping: false,
    },
    Motion {
        name: "wave",
        about: "the right hand raised and waved three times (keyed by hand)",
        bvh: include_bytes!("../../assets/motions/wave.bvh"),
        looping: false,
    },
];

/// The library's clip called `name`, if there is one.
pub fn find(name: &str) -> Option<&'static Motion> {
    MOTIONS.iter().find(|m| m.name == name)
}

impl Motion {
    /// How its loop is made when the person leaves it to sinew.
    pub fn loop_mode(&self) -> crate::motion::LoopMode {
        if self.looping {
            crate::motion::LoopMode::Blend
        } else {
            crate::motion::LoopMode::Off
        }
    }

    /// The clip, parsed.
    pub fn clip(&self) -> Result<Clip, BvhError> {
        parse(self.bvh, &BvhLimits::default())
    }
}

/// The library's names, comma-separated (for messages).
pub fn names() -> String {
    MOTIONS
        .iter()
        .map(|m| m.name)
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bundled_motion_parses() {
        for m in MOTIONS {
            let clip = m.clip().unwrap_or_else(|e| panic!("{}: {e}", m.name));
            assert!(clip.frame_count() > 10, "{}", m.name);
        }
        assert!(find("walk").is_some() && find("moonwalk").is_none());
    }
}
