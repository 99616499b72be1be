//! What can be wrong with a scene, its assets or its frames, located for people to fix.

use std::error::Error;
use std::fmt::{self, Write as _};
use std::sync::Arc;

/// A refused scene file, asset or frame, or a query that failed in a scene.
///
/// Displayed as one line, `ORIGIN:LINE: FIELD: MESSAGE` (parts omitted when unknown, control
/// characters escaped), for
/// example `cell.toml:14: rule 2, field a: no object or group named "robto"`.
///
/// When another error is why (an I/O error, a TOML or JSON error, a pose, tree, mesh or
/// build error, a query error), it is the [`std::error::Error::source`], for callers that
/// inspect it (downcast it to its type) or walk the chain. The message already includes
/// the cause's text, so the display is complete on its own: a printer of chains stops at a
/// `SceneError`, or prints the cause's text twice. (A TOML error's message is the cause's
/// message without toml's own location and snippet, which `:LINE` replaces.)
#[derive(Clone, Debug)]
pub struct SceneError {
    /// Where the problem is: the file (`-` for standard input), `scene` for a scene built
    /// in code and its queries, or `frame` for a frame built in code. Not named `source`,
    /// which for errors means the cause ([`Error::source`]).
    pub origin: String,
    /// The line, from 1, when the problem has one.
    pub line: Option<usize>,
    /// The item and field, e.g. `rule 2, field effect` or `poses.link2`.
    pub field: Option<String>,
    /// What is wrong, including the cause's text when there is a cause.
    pub message: String,
    /// The error that caused this one, if another error is why; shared, so that the
    /// error stays cheap to clone.
    cause: Option<Arc<dyn Error + Send + Sync + 'static>>,
}

impl SceneError {
    /// An error in `origin` about `message`, without a place yet.
    pub fn new(origin: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError {
            origin: origin.into(),
            line: None,
            field: None,
            message: message.into(),
            cause: None,
        }
    }

    /// The same error, caused by `cause` (its [`Error::source`]); the message should
    /// already say what `cause` says.
    pub fn caused_by(mut self, cause: impl Error + Send + Sync + 'static) -> SceneError {
        self.cause = Some(Arc::new(cause));
        self
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
        write_escaped(f, &self.origin)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(field) = &self.field {
            f.write_str(": ")?;
            write_escaped(f, field)?;
        }
        f.write_str(": ")?;
        write_escaped(f, &self.message)
    }
}

/// Writes `text` with control characters escaped (a newline as `\n`): the parts come from
/// what users wrote (a JSON key may hold a newline, a path anything), and must not break
/// the one line.
fn write_escaped(f: &mut fmt::Formatter<'_>, text: &str) -> fmt::Result {
    for c in text.chars() {
        if c.is_control() {
            write!(f, "{}", c.escape_default())?;
        } else {
            f.write_char(c)?;
        }
    }
    Ok(())
}

impl Error for SceneError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        let cause: &(dyn Error + 'static) = self.cause.as_deref()?;
        Some(cause)
    }
}

/// The line (from 1) of byte offset `offset` in `text`.
pub(crate) fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()
        .iter()
        .take(offset)
        .filter(|&&b| b == b'\n')
        .count()
        .saturating_add(1)
}

#[cfg(test)]
mod tests {
    use super::super::{load, Frame, FrameReader, SceneBuilder};
    use crate::query::{Pose, PoseFormat};
    use std::error::Error;

    /// The error that caused `e`, as a `T`.
    fn cause<T: Error + 'static>(e: &super::SceneError) -> &T {
        e.source().and_then(|c| c.downcast_ref::<T>()).unwrap()
    }

    /// A scene file that cannot be opened keeps the I/O error, whose text the display
    /// already says.
    #[test]
    fn an_unopened_scene_file_keeps_its_io_error() {
        let e = load("no/such/scene.toml".as_ref()).unwrap_err();
        let io: &std::io::Error = cause(&e);
        assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
        assert_eq!(
            e.to_string(),
            format!("no/such/scene.toml: cannot read: {io}")
        );
    }

    /// A scene file that is not TOML keeps the TOML error; the display keeps its message
    /// and replaces its location with the line.
    #[test]
    fn a_scene_file_that_is_not_toml_keeps_its_toml_error() {
        let path = std::env::temp_dir().join(format!("obbtree-scene-{}.toml", std::process::id()));
        std::fs::write(&path, "\n[[object]\n").unwrap();
        let e = load(&path).unwrap_err();
        std::fs::remove_file(&path).unwrap();
        let toml: &toml::de::Error = cause(&e);
        let expected = format!("{}:2: {}", path.display(), toml.message().trim());
        assert_eq!(e.to_string(), expected);
    }

    /// A frame that is not JSON keeps the JSON error.
    #[test]
    fn a_frame_that_is_not_json_keeps_its_json_error() {
        let scene = SceneBuilder::new().build().unwrap();
        let input: &[u8] = b"{\"poses\": \n";
        let mut frames = FrameReader::new(input, "f.jsonl", &scene, PoseFormat::default(), false);
        let e = frames.next_frame().unwrap().unwrap_err();
        let json: &serde_json::Error = cause(&e);
        assert_eq!(e.to_string(), format!("f.jsonl:1: not a frame: {json}"));
        // Errors without a cause have no source.
        let missing = Frame::new().set(0, Pose::identity()).clone();
        let mut scene = scene;
        assert!(scene.step(&missing).unwrap_err().source().is_none());
    }

    /// A scene file of exactly the size limit is read (and judged as TOML: NUL bytes are
    /// not); one byte more is refused by its size, without reading further.
    #[test]
    fn a_scene_file_over_the_size_limit_is_refused_by_its_size() {
        use super::super::file::MAX_SCENE_BYTES;
        let name = format!("obbtree-scene-limit-{}.toml", std::process::id());
        let path = std::env::temp_dir().join(name);
        let message = |len: u64| {
            // Sparse: no disk is written for the NUL bytes.
            std::fs::File::create(&path).unwrap().set_len(len).unwrap();
            load(&path).unwrap_err().to_string()
        };
        let (at_limit, over) = (message(MAX_SCENE_BYTES), message(MAX_SCENE_BYTES + 1));
        std::fs::remove_file(&path).unwrap();
        assert!(!at_limit.contains("larger than"), "{at_limit}");
        let limit = format!("larger than {MAX_SCENE_BYTES} bytes");
        assert_eq!(over, format!("{}: {limit}", path.display()));
    }

    /// A scene of as many objects, or as many rules, as the limits allow loads; one more
    /// of either, or many more, is refused before any asset is opened.
    #[test]
    fn scenes_over_the_object_or_rule_limit_are_refused() {
        use super::super::file::{MAX_OBJECTS, MAX_RULES};
        let dir = std::env::temp_dir().join(format!("obbtree-limits-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let load_with = |objects: usize, rules: usize| {
            let mut text = String::new();
            for k in 0..objects {
                text += &format!("[[object]]\nname = \"o{k}\"\nasset = \"t.obj\"\n");
            }
            for _ in 0..rules {
                text += "[[rule]]\na = \"o0\"\nb = \"o1\"\neffect = \"contact\"\n";
            }
            let path = dir.join("scene.toml");
            std::fs::write(&path, text).unwrap();
            load(&path).map(|_| ()).map_err(|e| e.to_string())
        };
        let refused = Err(format!(
            "{}: at most {MAX_OBJECTS} objects and {MAX_RULES} rules",
            dir.join("scene.toml").display()
        ));
        assert_eq!(load_with(MAX_OBJECTS, 1), Ok(()));
        assert_eq!(load_with(2, MAX_RULES), Ok(()));
        for (objects, rules) in [
            (MAX_OBJECTS + 1, 1),
            (2 * MAX_OBJECTS, 1),
            (2, MAX_RULES + 1),
            (2, 2 * MAX_RULES),
        ] {
            assert_eq!(load_with(objects, rules), refused, "{objects} {rules}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
