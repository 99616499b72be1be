//! Line handling shared by the text formats (OBJ, ASCII STL).

use std::borrow::Cow;

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

/// The lines of `text` with their 1-based numbers. Lines end at `\n` only, as
/// in `BufRead::lines` (which tobj uses), so our numbers match its view; a
/// trailing `\r` is whitespace to every caller.
pub(crate) fn numbered_lines(text: &str) -> NumberedLines<'_> {
    (1..).zip(text.split('\n'))
}

/// Iterator of [`numbered_lines`]: `(1-based line number, line)`.
pub(crate) type NumberedLines<'a> =
    std::iter::Zip<std::ops::RangeFrom<usize>, std::str::Split<'a, char>>;
