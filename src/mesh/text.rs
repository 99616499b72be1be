//! Line and number handling shared by the text formats (OBJ, ASCII STL).

use std::borrow::Cow;

use super::error::quote;
use super::{Location, MeshError, Place};

/// `bytes` as text: invalid UTF-8 becomes U+FFFD (so a Latin-1 comment is
/// harmless, and a bad byte inside a number is reported as a bad token), and a
/// leading byte-order mark is dropped (it would otherwise hide the first keyword).
pub(crate) fn decode(bytes: &[u8]) -> Cow<'_, str> {
    match String::from_utf8_lossy(bytes) {
        Cow::Borrowed(text) => Cow::Borrowed(text.strip_prefix('\u{feff}').unwrap_or(text)),
        Cow::Owned(text) => match text.strip_prefix('\u{feff}') {
            Some(rest) => Cow::Owned(rest.to_owned()),
            None => Cow::Owned(text),
        },
    }
}

/// The lines of `text` with their 1-based numbers. Lines end at `\n` only; the `\r`
/// of a CRLF ending is whitespace to every caller, so both endings number alike.
pub(crate) fn numbered_lines(text: &str) -> NumberedLines<'_> {
    (1..).zip(text.split('\n'))
}

/// Iterator of [`numbered_lines`]: `(1-based line number, line)`.
pub(crate) type NumberedLines<'a> =
    std::iter::Zip<std::ops::RangeFrom<usize>, std::str::Split<'a, char>>;

/// The vertex coordinate written as `word` on `line` of `file`: an f64 decimal
/// (`f64::from_str`), which must be finite (a decimal beyond the f64 range is not).
pub(crate) fn coordinate(word: &str, file: &str, line: usize) -> Result<f64, MeshError> {
    let value: f64 = word.parse().map_err(|_| {
        MeshError::syntax(file, line, format!("bad vertex coordinate {}", quote(word)))
    })?;
    if !value.is_finite() {
        return Err(MeshError::NonFinite {
            place: Place::new(file, Location::Line(line)),
            value,
        });
    }
    Ok(value)
}
