//! The BVH (Biovision Hierarchy) motion-capture reader.
//!
//! In: the bytes of a `.bvh` file (or its path) and [`BvhLimits`]. Out: a [`Clip`]: the
//! joints in file order (each with its parent, `OFFSET`, `CHANNELS` in the order written and
//! its `End Site`), the frame time in seconds, and the channel values, one row per frame.
//!
//! What is read:
//!
//! ```text
//! HIERARCHY
//! ROOT name { OFFSET x y z  CHANNELS n c1 … cn  (JOINT name { … } | End Site { OFFSET x y z })* }
//! MOTION
//! Frames: N
//! Frame Time: seconds
//! N rows, each one line of exactly (sum of every joint's n) numbers, in joint order
//! ```
//!
//! Channels are any of `Xposition Yposition Zposition Xrotation Yrotation Zrotation`, each at
//! most once per joint, in any order and count (0 to 6); names are matched case-insensitively.
//! A joint's name is the rest of its line (a `{` there opens its block). Several `ROOT`s are
//! read as a forest. Tokens are separated by any white space, except that a frame row is one
//! line: a row with more or fewer numbers than channels is refused with its line number.
//!
//! Units are the file's: offsets and position channels in whatever length unit the file uses
//! (the CMU conversions: the CMU database's unit, 1/0.45 inch ≈ 5.6 cm; clips converted from
//! DeepMimic: metres), rotation channels in degrees, the frame time in seconds. Nothing is
//! converted here.
//! The frame is the file's: BVH is conventionally y-up and right-handed; the reader neither
//! checks nor changes that. [`super::fk`] turns a frame into world positions.
//!
//! Every way a file can be wrong is one [`BvhError`] naming the line, never a panic: not text,
//! truncated anywhere, unknown keywords, wrong counts, numbers that are not finite, and sizes
//! beyond [`BvhLimits`] (checked before anything is allocated for them).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Named bounds on what [`parse`] and [`read`] accept, so an absurd or hostile file is one
/// clear error instead of minutes of work or gigabytes of memory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct BvhLimits {
    /// Largest file, bytes. Default 128 MiB ([`DEFAULT_MAX_FILE_BYTES`]): about 15 minutes of
    /// a 31-joint CMU clip at 120 frames per second.
    pub max_file_bytes: u64,
    /// Most joints (`ROOT` and `JOINT`; end sites are not counted). Default 1,000: a full
    /// body with fingers and face has a few hundred.
    pub max_joints: usize,
    /// Most frames (the `Frames:` count). Default 200,000: 55 minutes at 60 frames per second.
    pub max_frames: usize,
    /// Most channel values (frames × channels), the size of [`Clip::frames`]. Default
    /// 16,000,000 (128 MB of `f64`).
    pub max_values: usize,
}

/// Default of [`BvhLimits::max_file_bytes`].
pub const DEFAULT_MAX_FILE_BYTES: u64 = 128 * 1024 * 1024;
/// Default of [`BvhLimits::max_joints`].
pub const DEFAULT_MAX_JOINTS: usize = 1_000;
/// Default of [`BvhLimits::max_frames`].
pub const DEFAULT_MAX_FRAMES: usize = 200_000;
/// Default of [`BvhLimits::max_values`].
pub const DEFAULT_MAX_VALUES: usize = 16_000_000;

impl Default for BvhLimits {
    fn default() -> Self {
        Self {
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            max_joints: DEFAULT_MAX_JOINTS,
            max_frames: DEFAULT_MAX_FRAMES,
            max_values: DEFAULT_MAX_VALUES,
        }
    }
}

/// What is wrong with a BVH file. Displayed as one line a user can act on, e.g. `line 12:
/// expected 6 channel names after CHANNELS 6, found 3 (then 'JOINT')`.
#[derive(Debug, thiserror::Error)]
pub enum BvhError {
    /// The file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The file is larger than [`BvhLimits::max_file_bytes`].
    #[error("the file has {bytes} bytes, more than the {max} allowed (BvhLimits::max_file_bytes)")]
    TooLarge { bytes: u64, max: u64 },
    /// The text does not follow the format. `line` is 1-based.
    #[error("line {line}: {message}")]
    Syntax { line: usize, message: String },
    /// A count beyond one of [`BvhLimits`]. `line` is 1-based.
    #[error("line {line}: {message}")]
    Limit { line: usize, message: String },
}

impl BvhError {
    /// The 1-based line the error is about, if it is about one.
    pub fn line(&self) -> Option<usize> {
        match self {
            BvhError::Syntax { line, .. } | BvhError::Limit { line, .. } => Some(*line),
            _ => None,
        }
    }
}

/// One of the six BVH channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Channel {
    Xposition,
    Yposition,
    Zposition,
    Xrotation,
    Yrotation,
    Zrotation,
}

impl Channel {
    /// All six, in the usual writing order of their names.
    pub const ALL: [Channel; 6] = [
        Channel::Xposition,
        Channel::Yposition,
        Channel::Zposition,
        Channel::Xrotation,
        Channel::Yrotation,
        Channel::Zrotation,
    ];

    /// The name as BVH writes it (`Xposition`, …).
    pub fn name(self) -> &'static str {
        match self {
            Channel::Xposition => "Xposition",
            Channel::Yposition => "Yposition",
            Channel::Zposition => "Zposition",
            Channel::Xrotation => "Xrotation",
            Channel::Yrotation => "Yrotation",
            Channel::Zrotation => "Zrotation",
        }
    }

    /// The axis, 0 = x, 1 = y, 2 = z.
    pub fn axis(self) -> usize {
        match self {
            Channel::Xposition | Channel::Xrotation => 0,
            Channel::Yposition | Channel::Yrotation => 1,
            Channel::Zposition | Channel::Zrotation => 2,
        }
    }

    /// Whether this is a rotation (degrees) rather than a position (file units).
    pub fn is_rotation(self) -> bool {
        matches!(
            self,
            Channel::Xrotation | Channel::Yrotation | Channel::Zrotation
        )
    }

    /// The channel a name denotes (case-insensitive), if any.
    pub fn from_name(name: &str) -> Option<Channel> {
        Channel::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(name))
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A joint of one [`Clip`]: its index in [`Clip::joints`] (file order; a parent always comes
/// before its children).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointId(u32);

impl JointId {
    /// The index in [`Clip::joints`].
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// One `ROOT` or `JOINT`.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The name as written (the rest of its line, trimmed).
    pub name: String,
    /// `None` for a root.
    pub parent: Option<JointId>,
    /// `OFFSET`: the joint's origin in its parent's frame (the root's: in the world), file units.
    pub offset: Vector3<f64>,
    /// `CHANNELS`, in the order written (the order of the values in each frame row).
    pub channels: Vec<Channel>,
    /// Index of this joint's first value in a frame row.
    pub first_channel: usize,
    /// `End Site`'s `OFFSET` in this joint's frame, if it has one.
    pub end_site: Option<Vector3<f64>>,
}

/// A parsed BVH file.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// In file order: a parent before its children.
    pub joints: Vec<Joint>,
    /// `Frame Time:`, seconds, finite and > 0.
    pub frame_time_s: f64,
    /// Every channel value, row-major: frame `f`'s values are
    /// `frames[f * channel_count .. (f + 1) * channel_count]`, in joint and channel order.
    pub frames: Vec<f64>,
    /// Values per frame row (the sum of the joints' channel counts), ≥ 1.
    pub channel_count: usize,
}

impl Clip {
    /// Number of frames (≥ 1).
    pub fn frame_count(&self) -> usize {
        self.frames.len() / self.channel_count.max(1)
    }

    /// Frame `f`'s values, or `None` past the last frame.
    pub fn frame(&self, f: usize) -> Option<&[f64]> {
        let start = f.checked_mul(self.channel_count)?;
        self.frames
            .get(start..start.checked_add(self.channel_count)?)
    }

    /// Time of the last frame, seconds: (frames − 1) × frame time.
    pub fn duration_s(&self) -> f64 {
        self.frame_count().saturating_sub(1) as f64 * self.frame_time_s
    }

    /// The joint, or `None` for an id of another clip past this one's joints.
    pub fn joint(&self, id: JointId) -> Option<&Joint> {
        self.joints.get(id.index())
    }

    /// Every joint id, in file order.
    pub fn ids(&self) -> impl Iterator<Item = JointId> + '_ {
        (0..self.joints.len()).map(|i| JointId(i as u32))
    }

    /// The first joint of this name (exact match).
    pub fn find(&self, name: &str) -> Option<JointId> {
        self.joints
            .iter()
            .position(|j| j.name == name)
            .map(|i| JointId(i as u32))
    }

    /// The children of a joint, in file order.
    pub fn children(&self, id: JointId) -> impl Iterator<Item = JointId> + '_ {
        self.ids()
            .filter(move |&c| self.joints[c.index()].parent == Some(id))
    }

    /// The value of `channel` of joint `id` in frame `f`, if the joint has that channel.
    pub fn value(&self, f: usize, id: JointId, channel: Channel) -> Option<f64> {
        let joint = self.joint(id)?;
        let k = joint.channels.iter().position(|&c| c == channel)?;
        self.frame(f)?.get(joint.first_channel + k).copied()
    }
}

/// Reads a BVH file, refusing one larger than `limits.max_file_bytes` before reading it.
pub fn read(path: &Path, limits: &BvhLimits) -> Result<Clip, BvhError> {
    let io = |source| BvhError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let bytes = file.metadata().map_err(io)?.len();
    if bytes > limits.max_file_bytes {
        return Err(BvhError::TooLarge {
            bytes,
            max: limits.max_file_bytes,
        });
    }
    let mut data = Vec::new();
    // The file may grow between the check and the read: never read more than the limit + 1.
    file.take(limits.max_file_bytes.saturating_add(1))
        .read_to_end(&mut data)
        .map_err(io)?;
    parse(&data, limits)
}

/// Parses the bytes of a BVH file (see the module documentation for what is read).
pub fn parse(data: &[u8], limits: &BvhLimits) -> Result<Clip, BvhError> {
    let bytes = data.len() as u64;
    if bytes > limits.max_file_bytes {
        return Err(BvhError::TooLarge {
            bytes,
            max: limits.max_file_bytes,
        });
    }
    let text = String::from_utf8_lossy(data);
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    Parser::new(text, limits).clip()
}

fn syntax(line: usize, message: impl Into<String>) -> BvhError {
    BvhError::Syntax {
        line,
        message: message.into(),
    }
}

/// Shortens a token for an error message.
fn shown(token: &str) -> String {
    const MAX: usize = 40;
    if token.chars().count() <= MAX {
        token.to_string()
    } else {
        format!("{}…", token.chars().take(MAX).collect::<String>())
    }
}

/// Whitespace tokens with their 1-based line numbers.
struct Lexer<'a> {
    lines: std::str::Lines<'a>,
    current: std::str::SplitWhitespace<'a>,
    /// Line of `current` (0 before the first).
    line: usize,
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str) -> Self {
        Self {
            lines: text.lines(),
            current: "".split_whitespace(),
            line: 0,
        }
    }

    /// The next token and its line, or `None` at the end of the text.
    fn next(&mut self) -> Option<(usize, &'a str)> {
        loop {
            if let Some(t) = self.current.next() {
                return Some((self.line, t));
            }
            let l = self.lines.next()?;
            self.line += 1;
            self.current = l.split_whitespace();
        }
    }

    /// The tokens left on the current line.
    fn rest_of_line(&mut self) -> Vec<&'a str> {
        self.current.by_ref().collect()
    }

    /// The next whole line after the current one, with its number.
    fn next_line(&mut self) -> Option<(usize, &'a str)> {
        let l = self.lines.next()?;
        self.line += 1;
        self.current = "".split_whitespace();
        Some((self.line, l))
    }
}

struct Parser<'a, 'l> {
    lex: Lexer<'a>,
    /// Bytes of the whole text: a bound on the values it can hold.
    text_len: usize,
    limits: &'l BvhLimits,
}

/// A joint being read: its index and what its block has given so far.
struct Open {
    index: usize,
    line: usize,
    has_offset: bool,
    has_channels: bool,
}

fn number(line: usize, token: &str, what: &str) -> Result<f64, BvhError> {
    match token.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(value),
        _ => Err(number_error(line, token, what)),
    }
}

/// Why `token` is not a finite number.
fn number_error(line: usize, token: &str, what: &str) -> BvhError {
    if token.parse::<f64>().is_ok() {
        syntax(
            line,
            format!("{what} is '{}', not a finite number", shown(token)),
        )
    } else {
        syntax(
            line,
            format!("expected a number for {what}, found '{}'", shown(token)),
        )
    }
}

impl<'a, 'l> Parser<'a, 'l> {
    fn new(text: &'a str, limits: &'l BvhLimits) -> Self {
        Self {
            lex: Lexer::new(text),
            text_len: text.len(),
            limits,
        }
    }

    /// The next token, or an error saying what was expected where the file ended.
    fn token(&mut self, expected: &str) -> Result<(usize, &'a str), BvhError> {
        match self.lex.next() {
            Some(t) => Ok(t),
            None => Err(syntax(
                self.lex.line.max(1),
                format!("the file ends where {expected} was expected (is it truncated?)"),
            )),
        }
    }

    fn keyword(&mut self, word: &str) -> Result<usize, BvhError> {
        let (line, t) = self.token(word)?;
        if t != word {
            return Err(syntax(
                line,
                format!("expected {word}, found '{}'", shown(t)),
            ));
        }
        Ok(line)
    }

    fn vector(&mut self, what: &str) -> Result<Vector3<f64>, BvhError> {
        let mut v = Vector3::zeros();
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let (line, t) = self.token(&format!("the {axis} of {what}"))?;
            v[i] = number(line, t, &format!("the {axis} of {what}"))?;
        }
        Ok(v)
    }

    fn clip(mut self) -> Result<Clip, BvhError> {
        let (line, first) = self
            .lex
            .next()
            .ok_or_else(|| syntax(1, "the file is empty: a BVH file starts with HIERARCHY"))?;
        if first != "HIERARCHY" {
            return Err(syntax(
                line,
                format!(
                    "expected HIERARCHY (a BVH file starts with it), found '{}'",
                    shown(first)
                ),
            ));
        }
        let joints = self.hierarchy()?;
        let channel_count: usize = joints.iter().map(|j| j.channels.len()).sum();
        let (frame_time_s, frames) = self.motion(&joints, channel_count)?;
        Ok(Clip {
            joints,
            frame_time_s,
            frames,
            channel_count,
        })
    }

    /// The joints, up to and including the `MOTION` keyword.
    fn hierarchy(&mut self) -> Result<Vec<Joint>, BvhError> {
        let mut joints: Vec<Joint> = Vec::new();
        let mut open: Vec<Open> = Vec::new();
        let mut channel_count = 0usize;
        loop {
            let expected = match open.last() {
                Some(o) => format!("the rest of joint '{}'", shown(&joints[o.index].name)),
                None => "ROOT or MOTION".to_string(),
            };
            let (line, t) = self.token(&expected)?;
            match t {
                "ROOT" | "JOINT" => {
                    if t == "ROOT" && !open.is_empty() {
                        return Err(syntax(line, "ROOT inside a joint: use JOINT"));
                    }
                    if t == "JOINT" && open.is_empty() {
                        return Err(syntax(line, "JOINT outside any ROOT"));
                    }
                    if joints.len() >= self.limits.max_joints {
                        return Err(BvhError::Limit {
                            line,
                            message: format!(
                                "more than the {} joints allowed (BvhLimits::max_joints)",
                                self.limits.max_joints
                            ),
                        });
                    }
                    let mut words = self.lex.rest_of_line();
                    let brace = words.last() == Some(&"{");
                    if brace {
                        words.pop();
                    }
                    if words.is_empty() {
                        return Err(syntax(line, format!("{t} without a name")));
                    }
                    let name = words.join(" ");
                    if !brace {
                        let (l, b) =
                            self.token(&format!("'{{' to open joint '{}'", shown(&name)))?;
                        if b != "{" {
                            return Err(syntax(
                                l,
                                format!(
                                    "expected '{{' to open joint '{}', found '{}'",
                                    shown(&name),
                                    shown(b)
                                ),
                            ));
                        }
                    }
                    let parent = open.last().map(|o| JointId(o.index as u32));
                    open.push(Open {
                        index: joints.len(),
                        line,
                        has_offset: false,
                        has_channels: false,
                    });
                    joints.push(Joint {
                        name,
                        parent,
                        offset: Vector3::zeros(),
                        channels: Vec::new(),
                        first_channel: channel_count,
                        end_site: None,
                    });
                }
                "OFFSET" => {
                    let Some(o) = open.last_mut() else {
                        return Err(syntax(line, "OFFSET outside any joint"));
                    };
                    if o.has_offset {
                        return Err(syntax(
                            line,
                            format!(
                                "a second OFFSET in joint '{}'",
                                shown(&joints[o.index].name)
                            ),
                        ));
                    }
                    o.has_offset = true;
                    let index = o.index;
                    joints[index].offset = self.vector("OFFSET")?;
                }
                "CHANNELS" => {
                    let Some(o) = open.last_mut() else {
                        return Err(syntax(line, "CHANNELS outside any joint"));
                    };
                    if o.has_channels {
                        return Err(syntax(
                            line,
                            format!(
                                "a second CHANNELS in joint '{}'",
                                shown(&joints[o.index].name)
                            ),
                        ));
                    }
                    o.has_channels = true;
                    let index = o.index;
                    let channels = self.channels(line)?;
                    channel_count += channels.len();
                    joints[index].channels = channels;
                }
                "End" => {
                    self.end_site(line, &open, &mut joints)?;
                }
                "}" => {
                    let Some(o) = open.pop() else {
                        return Err(syntax(line, "'}' with no joint to close"));
                    };
                    if !o.has_offset {
                        return Err(syntax(
                            o.line,
                            format!("joint '{}' has no OFFSET", shown(&joints[o.index].name)),
                        ));
                    }
                }
                "MOTION" => {
                    if let Some(o) = open.last() {
                        return Err(syntax(
                            line,
                            format!(
                                "MOTION before joint '{}' (line {}) is closed with '}}'",
                                shown(&joints[o.index].name),
                                o.line
                            ),
                        ));
                    }
                    if joints.is_empty() {
                        return Err(syntax(line, "MOTION before any ROOT"));
                    }
                    return Ok(joints);
                }
                other => {
                    return Err(syntax(
                        line,
                        format!("expected {expected}, found '{}'", shown(other)),
                    ));
                }
            }
        }
    }

    /// `n c1 … cn` after `CHANNELS`.
    fn channels(&mut self, line: usize) -> Result<Vec<Channel>, BvhError> {
        let (l, t) = self.token("the number of channels after CHANNELS")?;
        let n: usize = t.parse().ok().filter(|&n| n <= 6).ok_or_else(|| {
            syntax(
                l,
                format!(
                    "CHANNELS must be followed by a count from 0 to 6 (each of Xposition … Zrotation at most once), found '{}'",
                    shown(t)
                ),
            )
        })?;
        let mut channels = Vec::with_capacity(n);
        for _ in 0..n {
            let found = channels.len();
            let (l, t) = self.lex.next().ok_or_else(|| {
                syntax(
                    line,
                    format!("expected {n} channel names after CHANNELS {n}, found {found} (then the end of the file)"),
                )
            })?;
            let Some(c) = Channel::from_name(t) else {
                return Err(syntax(
                    l,
                    format!(
                        "expected {n} channel names after CHANNELS {n}, found {found} (then '{}')",
                        shown(t)
                    ),
                ));
            };
            if channels.contains(&c) {
                return Err(syntax(l, format!("channel {c} listed twice")));
            }
            channels.push(c);
        }
        Ok(channels)
    }

    /// `Site { OFFSET x y z }` after `End`.
    fn end_site(
        &mut self,
        line: usize,
        open: &[Open],
        joints: &mut [Joint],
    ) -> Result<(), BvhError> {
        let Some(o) = open.last() else {
            return Err(syntax(line, "End Site outside any joint"));
        };
        let (l, site) = self.token("Site after End")?;
        if site != "Site" {
            return Err(syntax(
                l,
                format!("expected 'End Site', found 'End {}'", shown(site)),
            ));
        }
        if joints[o.index].end_site.is_some() {
            return Err(syntax(
                line,
                format!(
                    "a second End Site in joint '{}'",
                    shown(&joints[o.index].name)
                ),
            ));
        }
        self.keyword("{")?;
        self.keyword("OFFSET")?;
        let offset = self.vector("the End Site's OFFSET")?;
        self.keyword("}")?;
        joints[o.index].end_site = Some(offset);
        Ok(())
    }

    /// `Frames:`, `Frame Time:` and the rows, after `MOTION`.
    fn motion(
        &mut self,
        joints: &[Joint],
        channel_count: usize,
    ) -> Result<(f64, Vec<f64>), BvhError> {
        let (line, t) = self.token("Frames:")?;
        let count_token = match t.strip_prefix("Frames:") {
            Some("") => self.token("the number of frames after Frames:")?.1,
            Some(rest) => rest,
            None => {
                return Err(syntax(
                    line,
                    format!("expected Frames:, found '{}'", shown(t)),
                ))
            }
        };
        let frame_count: usize = count_token.parse().map_err(|_| {
            syntax(
                line,
                format!(
                    "Frames: must be followed by a whole number, found '{}'",
                    shown(count_token)
                ),
            )
        })?;
        if frame_count == 0 {
            return Err(syntax(line, "Frames: 0: a clip needs at least one frame"));
        }
        if frame_count > self.limits.max_frames {
            return Err(BvhError::Limit {
                line,
                message: format!(
                    "Frames: {frame_count} is more than the {} frames allowed (BvhLimits::max_frames)",
                    self.limits.max_frames
                ),
            });
        }
        if channel_count == 0 {
            return Err(syntax(
                line,
                format!(
                    "no joint of the {} has CHANNELS: there is nothing to animate",
                    joints.len()
                ),
            ));
        }
        let values = frame_count
            .checked_mul(channel_count)
            .filter(|&v| v <= self.limits.max_values)
            .ok_or_else(|| BvhError::Limit {
                line,
                message: format!(
                    "{frame_count} frames of {channel_count} channels are more than the {} values allowed (BvhLimits::max_values)",
                    self.limits.max_values
                ),
            })?;
        let l = self.keyword("Frame")?;
        let (tl, time) = self.token("Time: after Frame")?;
        let time_token = match time.strip_prefix("Time:") {
            Some("") => self.token("the frame time after Frame Time:")?.1,
            Some(rest) => rest,
            None => {
                return Err(syntax(
                    tl,
                    format!("expected 'Frame Time:', found 'Frame {}'", shown(time)),
                ))
            }
        };
        let frame_time_s = number(l, time_token, "Frame Time")?;
        if frame_time_s <= 0.0 {
            return Err(syntax(
                l,
                format!("Frame Time is {frame_time_s} s: it must be more than 0"),
            ));
        }
        let after = self.lex.rest_of_line();
        if let Some(t) = after.first() {
            return Err(syntax(
                self.lex.line,
                format!(
                    "'{}' after the frame time: frame rows start on the next line",
                    shown(t)
                ),
            ));
        }
        // Each value takes at least two bytes ("0 "): a count the rest of the file cannot hold
        // is not allocated for; the rows themselves then say where the file ends.
        let mut frames = Vec::with_capacity(values.min(self.text_len / 2 + 1));
        let mut read = 0usize;
        while let Some((line, row)) = self.lex.next_line() {
            if row.trim().is_empty() {
                continue;
            }
            if read == frame_count {
                return Err(syntax(
                    line,
                    format!(
                        "a row after the last of the {frame_count} frames that Frames: announced"
                    ),
                ));
            }
            let start = frames.len();
            let mut tokens = row.split_whitespace();
            for (k, t) in tokens.by_ref().take(channel_count).enumerate() {
                match t.parse::<f64>() {
                    Ok(v) if v.is_finite() => frames.push(v),
                    _ => {
                        let (joint, channel) = channel_at(joints, k);
                        let what =
                            format!("frame {} ({} of '{}')", read + 1, channel, shown(joint));
                        return Err(number_error(line, t, &what));
                    }
                }
            }
            let found = frames.len() - start + tokens.count();
            if found != channel_count {
                return Err(syntax(
                    line,
                    format!(
                        "frame {} has {found} numbers, expected {channel_count} (one per channel of the hierarchy)",
                        read + 1
                    ),
                ));
            }
            read += 1;
        }
        if read < frame_count {
            return Err(syntax(
                self.lex.line.max(1),
                format!(
                    "the file ends after {read} of the {frame_count} frames that Frames: announced (is it truncated?)"
                ),
            ));
        }
        Ok((frame_time_s, frames))
    }
}

/// The joint name and channel of value `k` of a frame row.
fn channel_at(joints: &[Joint], k: usize) -> (&str, Channel) {
    for j in joints {
        if k >= j.first_channel && k < j.first_channel + j.channels.len() {
            return (&j.name, j.channels[k - j.first_channel]);
        }
    }
    ("?", Channel::Xposition)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) const TINY: &str = "HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
  JOINT Leg {
    OFFSET 2 0 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site { OFFSET 0 -8 0 }
  }
}
MOTION
Frames: 2
Frame Time: 0.5
0 0 0 0 0 0 0 0 0 0 0 0
1 2 3 90 0 0 0 90 0 90 0 0
";

    fn parse_str(text: &str) -> Result<Clip, BvhError> {
        parse(text.as_bytes(), &BvhLimits::default())
    }

    /// The error's message, asserting it is on `line`.
    fn error_at(text: &str, line: usize) -> String {
        let e = parse_str(text).expect_err("the file must be refused");
        assert_eq!(e.line(), Some(line), "{e}");
        e.to_string()
    }

    #[test]
    fn reads_the_hierarchy_and_motion() {
        let clip = parse_str(TINY).unwrap();
        assert_eq!(clip.joints.len(), 3);
        let names: Vec<_> = clip.joints.iter().map(|j| j.name.as_str()).collect();
        assert_eq!(names, ["Hips", "Spine", "Leg"]);
        let spine = clip.find("Spine").unwrap();
        let leg = clip.find("Leg").unwrap();
        let hips = clip.find("Hips").unwrap();
        assert_eq!(clip.joint(spine).unwrap().parent, Some(hips));
        assert_eq!(clip.joint(hips).unwrap().parent, None);
        assert_eq!(
            clip.joint(spine).unwrap().offset,
            Vector3::new(0.0, 10.0, 0.0)
        );
        assert_eq!(
            clip.joint(leg).unwrap().end_site,
            Some(Vector3::new(0.0, -8.0, 0.0))
        );
        assert_eq!(clip.joint(hips).unwrap().end_site, None);
        assert_eq!(
            clip.joint(leg).unwrap().channels,
            [Channel::Xrotation, Channel::Yrotation, Channel::Zrotation]
        );
        assert_eq!(clip.joint(leg).unwrap().first_channel, 9);
        assert_eq!(clip.channel_count, 12);
        assert_eq!(clip.frame_count(), 2);
        assert_eq!(clip.frame_time_s, 0.5);
        assert_eq!(clip.duration_s(), 0.5);
        assert_eq!(clip.frame(1).unwrap()[3], 90.0);
        assert_eq!(clip.frame(2), None);
        assert_eq!(clip.value(1, spine, Channel::Xrotation), Some(90.0));
        assert_eq!(clip.value(1, spine, Channel::Xposition), None);
        assert_eq!(clip.children(hips).collect::<Vec<_>>(), [spine, leg]);
    }

    #[test]
    fn accepts_crlf_a_bom_names_with_spaces_and_joined_colons() {
        let text = "\u{feff}HIERARCHY\r\nROOT my root\r\n{\r\nOFFSET 1 2 3\r\nCHANNELS 1 yrotation\r\n}\r\nMOTION\r\nFrames:1\r\nFrame Time:0.1\r\n\r\n45\r\n\r\n";
        let clip = parse_str(text).unwrap();
        assert_eq!(clip.joints[0].name, "my root");
        assert_eq!(clip.joints[0].channels, [Channel::Yrotation]);
        assert_eq!(clip.frames, [45.0]);
    }

    #[test]
    fn truncated_files_are_one_error_each() {
        // Every prefix of the file that cuts it short is refused, never a panic.
        let mut refused = 0;
        for end in 0..TINY.len() {
            if !TINY.is_char_boundary(end) {
                continue;
            }
            let cut = &TINY[..end];
            match parse_str(cut) {
                Ok(clip) => {
                    // Only a cut inside the last row's trailing newline or after it can pass,
                    // and only when the last number happens to stay the same.
                    assert!(end >= TINY.len() - 2, "{end}: {clip:?}");
                }
                Err(e) => {
                    assert!(e.line().is_some(), "{e}");
                    refused += 1;
                }
            }
        }
        assert!(refused > 300);
        let msg = error_at(&TINY[..TINY.find("1 2 3 90").unwrap()], 24);
        assert!(msg.contains("ends after 1 of the 2 frames"), "{msg}");
        let msg = error_at(&TINY[..TINY.find("JOINT Leg").unwrap()], 15);
        assert!(msg.contains("the file ends"), "{msg}");
    }

    #[test]
    fn wrong_channel_count_in_a_row() {
        let short = TINY.replace("1 2 3 90 0 0 0 90 0 90 0 0", "1 2 3 90 0 0 0 90 0 90 0");
        let msg = error_at(&short, 25);
        assert!(msg.contains("frame 2 has 11 numbers, expected 12"), "{msg}");
        let long = TINY.replace("1 2 3 90 0 0 0 90 0 90 0 0", "1 2 3 90 0 0 0 90 0 90 0 0 7");
        let msg = error_at(&long, 25);
        assert!(msg.contains("frame 2 has 13 numbers, expected 12"), "{msg}");
        let extra = format!("{TINY}0 0 0 0 0 0 0 0 0 0 0 0\n");
        let msg = error_at(&extra, 26);
        assert!(msg.contains("after the last of the 2 frames"), "{msg}");
    }

    #[test]
    fn wrong_channels_declarations() {
        let few = TINY.replace(
            "CHANNELS 3 Zrotation Xrotation Yrotation",
            "CHANNELS 6 Zrotation Xrotation Yrotation",
        );
        let msg = error_at(&few, 10);
        assert!(
            msg.contains("expected 6 channel names after CHANNELS 6, found 3 (then 'End')"),
            "{msg}"
        );
        let seven = TINY.replace(
            "CHANNELS 3 Zrotation Xrotation Yrotation",
            "CHANNELS 7 Zrotation",
        );
        assert!(error_at(&seven, 9).contains("count from 0 to 6"));
        let twice = TINY.replace(
            "CHANNELS 3 Zrotation Xrotation Yrotation",
            "CHANNELS 3 Zrotation Xrotation Zrotation",
        );
        assert!(error_at(&twice, 9).contains("Zrotation listed twice"));
        let unknown = TINY.replace(
            "Xrotation Yrotation Zrotation",
            "Xrotation Wrotation Zrotation",
        );
        assert!(error_at(&unknown, 17).contains("found 1 (then 'Wrotation')"));
    }

    #[test]
    fn non_finite_values_are_refused() {
        for bad in ["NaN", "nan", "inf", "-inf", "infinity", "1e400"] {
            let text = TINY.replace("1 2 3 90", &format!("1 2 {bad} 90"));
            let msg = error_at(&text, 25);
            assert!(msg.contains("not a finite number"), "{bad}: {msg}");
            assert!(msg.contains("frame 2 (Zposition of 'Hips')"), "{msg}");
            let text = TINY.replace("OFFSET 0 10 0", &format!("OFFSET 0 {bad} 0"));
            assert!(error_at(&text, 8).contains("not a finite number"));
        }
        let text = TINY.replace("Frame Time: 0.5", "Frame Time: nan");
        assert!(error_at(&text, 23).contains("Frame Time"));
        let text = TINY.replace("Frame Time: 0.5", "Frame Time: 0");
        assert!(error_at(&text, 23).contains("must be more than 0"));
        let text = TINY.replace("1 2 3 90", "1 2 x 90");
        assert!(error_at(&text, 25)
            .contains("expected a number for frame 2 (Zposition of 'Hips'), found 'x'"));
    }

    #[test]
    fn a_million_frames_is_refused_before_allocating() {
        let text = TINY.replace("Frames: 2", "Frames: 1000000");
        let msg = error_at(&text, 22);
        assert!(
            msg.contains("Frames: 1000000 is more than the 200000 frames allowed"),
            "{msg}"
        );
        // Within max_frames but beyond max_values.
        let limits = BvhLimits {
            max_values: 100,
            ..Default::default()
        };
        let text = TINY.replace("Frames: 2", "Frames: 100");
        let e = parse(text.as_bytes(), &limits).unwrap_err();
        assert!(matches!(e, BvhError::Limit { line: 22, .. }), "{e}");
        // A count within the limits that the file cannot hold: no huge allocation, the
        // truncation is the error.
        let text = TINY.replace("Frames: 2", "Frames: 199999");
        assert!(error_at(&text, 25).contains("ends after 2 of the 199999 frames"));
        // An actual million rows (of one channel).
        let mut text = String::from("HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: 1000000\nFrame Time: 0.01\n");
        text.push_str(&"0\n".repeat(1_000_000));
        let e = parse_str(&text).unwrap_err();
        assert!(matches!(e, BvhError::Limit { line: 8, .. }), "{e}");
        let limits = BvhLimits {
            max_frames: 1_000_000,
            ..Default::default()
        };
        assert_eq!(
            parse(text.as_bytes(), &limits).unwrap().frame_count(),
            1_000_000
        );
    }

    #[test]
    fn ten_thousand_joints_are_refused() {
        for nested in [false, true] {
            let mut text = String::from(
                "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n",
            );
            for i in 0..10_000 {
                text.push_str(&format!(
                    "JOINT j{i}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
                ));
                if !nested {
                    text.push_str("}\n");
                }
            }
            let e = parse_str(&text).unwrap_err();
            // Joint 1001 is the 1000th JOINT, 4 (nested) or 5 lines each after the root's 5.
            let line = if nested { 6 + 4 * 999 } else { 6 + 5 * 999 };
            assert_eq!(e.line(), Some(line), "{e}");
            assert!(matches!(e, BvhError::Limit { .. }), "{e}");
            assert!(
                e.to_string().contains("more than the 1000 joints allowed"),
                "{e}"
            );
        }
    }

    #[test]
    fn too_many_bytes() {
        let limits = BvhLimits {
            max_file_bytes: 100,
            ..Default::default()
        };
        let e = parse(TINY.as_bytes(), &limits).unwrap_err();
        assert!(matches!(e, BvhError::TooLarge { max: 100, .. }), "{e}");
    }

    #[test]
    fn structure_errors_name_their_line() {
        assert!(error_at("", 1).contains("empty"));
        let png = parse(b"\x89PNG\r\n\x1a\n", &BvhLimits::default()).unwrap_err();
        assert!(
            png.to_string().starts_with("line 1: expected HIERARCHY"),
            "{png}"
        );
        assert!(error_at("HIERARCHY\nJOINT a\n", 2).contains("JOINT outside any ROOT"));
        assert!(error_at("HIERARCHY\nMOTION\n", 2).contains("before any ROOT"));
        assert!(error_at("HIERARCHY\nROOT\n{\n", 2).contains("ROOT without a name"));
        let text = TINY.replace("    OFFSET 2 0 0\n", "");
        assert!(error_at(&text, 15).contains("joint 'Leg' has no OFFSET"));
        let text = TINY.replace("}\nMOTION", "MOTION");
        assert!(error_at(&text, 20).contains("MOTION before joint 'Hips' (line 2) is closed"));
        let text = TINY.replace(
            "End Site { OFFSET 0 -8 0 }",
            "End Site { OFFSET 0 -8 0 }\nEnd Site { OFFSET 0 -8 0 }",
        );
        assert!(error_at(&text, 19).contains("a second End Site"));
        let text = TINY.replace("End Site {", "End Sight {");
        assert!(error_at(&text, 18).contains("'End Sight'"));
        let text = TINY.replace("Frames: 2", "Frames: -2");
        assert!(error_at(&text, 22).contains("whole number"));
        let text = TINY.replace("Frames: 2", "Frames: 0");
        assert!(error_at(&text, 22).contains("at least one frame"));
        let text = TINY.replace("Frame Time: 0.5", "Frame Time: 0.5 0 0");
        assert!(error_at(&text, 23).contains("frame rows start on the next line"));
        let text = "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\n}\nMOTION\nFrames: 1\nFrame Time: 1\n\n";
        assert!(error_at(text, 7).contains("nothing to animate"));
    }

    /// The fuzz target's hand-written seeds: a forest with CRLF line ends, names with spaces,
    /// lower-case channels and joined `Frames:`; and a file with a NaN that is also short.
    #[test]
    fn the_fuzz_seeds_parse_or_fail_as_meant() {
        let limits = BvhLimits::default();
        let forest = parse(
            include_bytes!("../../tools/fuzz/seeds/bvh/forest-crlf.bvh"),
            &limits,
        )
        .unwrap();
        let names: Vec<_> = forest
            .joints
            .iter()
            .map(|j| (j.name.as_str(), j.parent))
            .collect();
        assert_eq!(names, [("a b", None), ("c", None)]);
        assert_eq!(
            forest.joints[0].channels,
            [Channel::Yrotation, Channel::Xposition]
        );
        assert_eq!(forest.frames, [45.0, -1000.0, 7.0, 0.0, 0.0, 0.0]);
        assert_eq!(forest.frame_time_s, 0.0083333);
        let tiny = parse(
            include_bytes!("../../tools/fuzz/seeds/bvh/tiny.bvh"),
            &limits,
        )
        .unwrap();
        assert_eq!(tiny, parse_str(TINY).unwrap());
        let bad = parse(
            include_bytes!("../../tools/fuzz/seeds/bvh/bad-nan-truncated.bvh"),
            &limits,
        )
        .unwrap_err();
        assert_eq!(
            bad.to_string(),
            "line 20: frame 2 (Xrotation of 'r') is 'nan', not a finite number"
        );
    }

    #[test]
    fn limits_round_trip_through_json_with_defaults() {
        let limits: BvhLimits = serde_json::from_str(r#"{"max_joints": 5}"#).unwrap();
        assert_eq!(limits.max_joints, 5);
        assert_eq!(limits.max_frames, DEFAULT_MAX_FRAMES);
        assert!(serde_json::from_str::<BvhLimits>(r#"{"max_joint": 5}"#).is_err());
    }

    #[test]
    fn read_refuses_a_missing_file_and_reads_a_real_one() {
        let e = read(Path::new("/nonexistent/x.bvh"), &BvhLimits::default()).unwrap_err();
        assert!(matches!(e, BvhError::Io { .. }));
        assert!(e.to_string().starts_with("/nonexistent/x.bvh: "), "{e}");
        let dir = crate::test_scratch::scratch("bvh");
        let path = dir.path().join("tiny.bvh");
        std::fs::write(&path, TINY).unwrap();
        assert_eq!(
            read(&path, &BvhLimits::default()).unwrap(),
            parse_str(TINY).unwrap()
        );
        let limits = BvhLimits {
            max_file_bytes: 10,
            ..Default::default()
        };
        assert!(matches!(
            read(&path, &limits),
            Err(BvhError::TooLarge { .. })
        ));
    }
}
