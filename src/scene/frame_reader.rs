//! Frames as JSON Lines, streamed: `{"poses": {"link2": [12 numbers], ...}}` per line.

use super::error::SceneError;
use super::frame::Frame;
use super::report::ObjectId;
use super::simulate::Scene;
use crate::query::{PoseFormat, Repairs};
use rustc_hash::FxHashMap;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::io::{BufRead, Read};

/// The longest frame line read (bytes): a frame moving 10,000 objects is about 2.5 MB.
pub const MAX_FRAME_LINE: u64 = 64 << 20;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameLine {
    poses: BTreeMap<String, Vec<f64>>,
}

/// Reads frames one line at a time from any reader, so a million frames are never held in
/// memory. The frame number is the line index from 0; every line must be a frame (a
/// frame that moves nothing is `{"poses": {}}`).
pub struct FrameReader<R> {
    input: R,
    source: String,
    line: usize,
    bytes: u64,
    ids: FxHashMap<String, ObjectId>,
    format: PoseFormat,
    repair: bool,
    repairs: Repairs,
    buffer: Vec<u8>,
}

impl<R: BufRead> FrameReader<R> {
    /// Frames for `scene` from `input` (named `source` in errors), poses in `format`,
    /// repaired to the nearest rotation when `repair` (see [`PoseFormat::parse`]).
    pub fn new(
        input: R,
        source: &str,
        scene: &Scene,
        format: PoseFormat,
        repair: bool,
    ) -> FrameReader<R> {
        FrameReader {
            input,
            source: source.to_owned(),
            line: 0,
            bytes: 0,
            ids: scene
                .names()
                .iter()
                .enumerate()
                .map(|(i, n)| (n.clone(), i))
                .collect(),
            format,
            repair,
            repairs: Repairs::default(),
            buffer: Vec::new(),
        }
    }

    /// Bytes read so far (for progress).
    pub fn bytes_read(&self) -> u64 {
        self.bytes
    }

    /// The rotations corrected so far when repair was asked for, the largest named as
    /// `SOURCE:LINE: poses.NAME`: for a note at the end of a run.
    pub fn repairs(&self) -> &Repairs {
        &self.repairs
    }

    fn error(&self, message: impl Into<String>) -> SceneError {
        SceneError::new(&self.source, message).at_line(self.line)
    }

    /// The next frame, `None` at the end of the input.
    ///
    /// # Errors
    ///
    /// `Some(Err)` with a [`SceneError`] naming the source and line (and the object for a
    /// pose): the input cannot be read, a line is empty or not a JSON frame, a frame names
    /// an unknown object, or a pose is not valid in the format ([`PoseFormat::parse`]).
    pub fn next_frame(&mut self) -> Option<Result<Frame, SceneError>> {
        self.buffer.clear();
        let read = (&mut self.input)
            .take(MAX_FRAME_LINE + 1)
            .read_until(b'\n', &mut self.buffer);
        self.line += 1;
        match read {
            Ok(0) => return None,
            Ok(n) => self.bytes += n as u64,
            Err(e) => return Some(Err(self.error(format!("cannot read: {e}")).caused_by(e))),
        }
        if self.buffer.len() as u64 > MAX_FRAME_LINE {
            let m = format!("a frame line is longer than {MAX_FRAME_LINE} bytes");
            return Some(Err(self.error(m)));
        }
        Some(self.parse())
    }

    fn parse(&mut self) -> Result<Frame, SceneError> {
        let text = self.buffer.strip_suffix(b"\n").unwrap_or(&self.buffer);
        let text = text.strip_suffix(b"\r").unwrap_or(text);
        if text.iter().all(u8::is_ascii_whitespace) {
            return Err(self.error(r#"empty line (a frame that moves nothing is {"poses": {}})"#));
        }
        let line: FrameLine = serde_json::from_slice(text)
            .map_err(|e| self.error(format!("not a frame: {e}")).caused_by(e))?;
        let mut frame = Frame::new();
        for (name, values) in &line.poses {
            let field = format!("poses.{name}");
            let Some(&id) = self.ids.get(name) else {
                let m = format!("no object named {name:?} in the scene");
                return Err(self.error(m).in_field(field));
            };
            let parsed = self
                .format
                .parse(values, self.repair)
                .map_err(|e| self.error(e.to_string()).in_field(&field).caused_by(e))?;
            let (source, line) = (&self.source, self.line);
            let pose = self
                .repairs
                .note(&parsed, || format!("{source}:{line}: {field}"));
            frame.set(id, pose);
        }
        Ok(frame)
    }
}

impl<R: BufRead> Iterator for FrameReader<R> {
    type Item = Result<Frame, SceneError>;
    fn next(&mut self) -> Option<Self::Item> {
        self.next_frame()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneBuilder;

    /// The bytes read count every byte of every frame read, line ends included, and stop at
    /// the end of the input.
    #[test]
    fn the_bytes_read_are_those_of_the_lines_read() {
        let scene = SceneBuilder::new().build().unwrap();
        let lines = ["{\"poses\": {}}\n", "{\"poses\": {}}\r\n", "{\"poses\":{}}"];
        let input = lines.concat();
        let format = PoseFormat::default();
        let mut frames = FrameReader::new(input.as_bytes(), "f", &scene, format, false);
        assert_eq!(frames.bytes_read(), 0);
        let mut total = 0;
        // Through `Iterator::next`, which library users call.
        for line in lines {
            assert!(frames.next().unwrap().is_ok());
            total += line.len() as u64;
            assert_eq!(frames.bytes_read(), total);
        }
        assert!(frames.next_frame().is_none());
        assert_eq!(frames.bytes_read(), total);
    }

    /// A line of `MAX_FRAME_LINE` bytes is read whole (and judged as a frame: here empty);
    /// one byte more is refused as too long, without reading further.
    #[test]
    fn a_line_longer_than_the_limit_is_refused_as_too_long() {
        let scene = SceneBuilder::new().build().unwrap();
        let message = |len: u64| {
            let spaces = std::io::BufReader::new(std::io::repeat(b' ').take(len));
            let mut frames = FrameReader::new(spaces, "f", &scene, PoseFormat::default(), false);
            let e = frames.next_frame().unwrap().unwrap_err().to_string();
            (e, frames.bytes_read())
        };
        let (at_limit, read) = message(MAX_FRAME_LINE);
        assert!(at_limit.starts_with("f:1: empty line"), "{at_limit}");
        assert_eq!(read, MAX_FRAME_LINE);
        let (over, read) = message(MAX_FRAME_LINE + 5);
        assert_eq!(
            over,
            format!("f:1: a frame line is longer than {MAX_FRAME_LINE} bytes")
        );
        assert_eq!(read, MAX_FRAME_LINE + 1);
    }
}
