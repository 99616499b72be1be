//! What can be wrong with a scene, its assets or its frames, located for people to fix.

use std::fmt;

/// A refused scene file, asset or frame, or a query that failed in a scene.
///
/// Displayed as one line, `SOURCE:LINE: FIELD: MESSAGE` (parts omitted when unknown), for
/// example `cell.toml:14: rule 2, field a: no object or group named "robto"`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneError {
    /// The file (or `-` for standard input, or `scene` for one built in code).
    pub source: String,
    /// The line, from 1, when the problem has one.
    pub line: Option<usize>,
    /// The item and field, e.g. `rule 2, field effect` or `poses.link2`.
    pub field: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl SceneError {
    /// An error in `source` about `message`, without a place yet.
    pub fn new(source: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError {
            source: source.into(),
            line: None,
            field: None,
            message: message.into(),
        }
    }

    /// The same error at `line` (from 1).
    pub fn at_line(mut self, line: usize) -> SceneError {
        self.line = Some(line);
        self
    }

    /// The same error about `field`.
    pub fn in_field(mut self, field: impl Into<String>) -> SceneError {
        self.field = Some(field.into());
        self
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.source)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(field) = &self.field {
            write!(f, ": {field}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for SceneError {}

/// The line (from 1) of byte offset `offset` in `text`.
pub(crate) fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()
        .iter()
        .take(offset)
        .filter(|&&b| b == b'\n')
        .count()
        .saturating_add(1)
}
