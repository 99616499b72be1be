//! ASCII STL:
//!
//! ```text
//! solid [name]
//!   facet normal nx ny nz
//!     outer loop
//!       vertex x y z      (exactly three)
//!     endloop
//!   endfacet
//! endsolid [name]
//! ```
//!
//! Several solids may follow each other. Keywords are matched without regard
//! to case (some exporters shout); normals are skipped unread, as in binary STL;
//! coordinates are parsed as f64 decimals.

use std::str::SplitWhitespace;

use crate::mesh::error::quote;
use crate::mesh::text::{coordinate, decode, numbered_lines, NumberedLines};
use crate::mesh::weld::Welder;
use crate::mesh::{MeshError, TriMesh, MAX_TRIANGLES, MAX_VERTICES};

/// Parses an ASCII STL; `file` names it in errors.
pub(super) fn parse(bytes: &[u8], file: &str) -> Result<TriMesh, MeshError> {
    let text = decode(bytes);
    let mut tokens = Tokens::new(&text, file);
    let mut welder = Welder::default();
    tokens.keyword("solid")?;
    tokens.skip_line(); // the solid's name
    loop {
        match tokens.next() {
            Some(word) if word.eq_ignore_ascii_case("facet") => {
                if welder.triangle_count() >= MAX_TRIANGLES {
                    let count = MAX_TRIANGLES + 1;
                    return Err(MeshError::too_large(
                        file,
                        "triangles",
                        count,
                        MAX_TRIANGLES,
                    ));
                }
                let corners = facet(&mut tokens)?;
                welder.push_triangle(corners).map_err(|_| {
                    MeshError::too_large(file, "vertices", MAX_VERTICES + 1, MAX_VERTICES)
                })?;
            }
            Some(word) if word.eq_ignore_ascii_case("endsolid") => {
                tokens.skip_line(); // the solid's name
                match tokens.next() {
                    None => break,
                    Some(word) if word.eq_ignore_ascii_case("solid") => tokens.skip_line(),
                    Some(word) => {
                        return Err(tokens.error(format!(
                            "expected 'solid' or end of file after 'endsolid', found {}",
                            quote(word)
                        )))
                    }
                }
            }
            other => return Err(tokens.unexpected("'facet' or 'endsolid'", other)),
        }
    }
    let (vertices, faces) = welder.finish();
    TriMesh::validated(file, vertices, faces)
}

/// The rest of a facet after its `facet` keyword, up to and including `endfacet`.
fn facet(tokens: &mut Tokens<'_>) -> Result<[[f64; 3]; 3], MeshError> {
    tokens.keyword("normal")?;
    for _ in 0..3 {
        tokens.next_or_eof("a normal component")?;
    }
    tokens.keyword("outer")?;
    tokens.keyword("loop")?;
    let mut corners = [[0.0; 3]; 3];
    for corner in &mut corners {
        tokens.keyword("vertex")?;
        for coordinate in corner.iter_mut() {
            *coordinate = tokens.coordinate()?;
        }
    }
    tokens.keyword("endloop")?;
    tokens.keyword("endfacet")?;
    Ok(corners)
}

/// Whitespace-separated words of the text, remembering the line of the last one.
struct Tokens<'a> {
    lines: NumberedLines<'a>,
    words: SplitWhitespace<'a>,
    /// Line of the last word returned (the last line once the text is exhausted).
    line: usize,
    file: &'a str,
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str, file: &'a str) -> Tokens<'a> {
        Tokens {
            lines: numbered_lines(text),
            words: "".split_whitespace(),
            line: 1,
            file,
        }
    }

    /// The next word, if any.
    fn next(&mut self) -> Option<&'a str> {
        loop {
            if let Some(word) = self.words.next() {
                return Some(word);
            }
            let (number, line) = self.lines.next()?;
            self.line = number;
            self.words = line.split_whitespace();
        }
    }

    /// Drops the rest of the current line (a solid's free-form name).
    fn skip_line(&mut self) {
        self.words = "".split_whitespace();
    }

    /// A syntax error at the current line.
    fn error(&self, message: String) -> MeshError {
        MeshError::syntax(self.file, self.line, message)
    }

    /// The error for finding `found` where `wanted` should be.
    fn unexpected(&self, wanted: &str, found: Option<&str>) -> MeshError {
        match found {
            Some(word) => self.error(format!("expected {wanted}, found {}", quote(word))),
            None => self.error(format!("expected {wanted}, found end of file")),
        }
    }

    /// The next word, which must exist.
    fn next_or_eof(&mut self, wanted: &str) -> Result<&'a str, MeshError> {
        let word = self.next();
        word.ok_or_else(|| self.unexpected(wanted, None))
    }

    /// Consumes the keyword `keyword` (any case).
    fn keyword(&mut self, keyword: &str) -> Result<(), MeshError> {
        match self.next() {
            Some(word) if word.eq_ignore_ascii_case(keyword) => Ok(()),
            other => Err(self.unexpected(&format!("'{keyword}'"), other)),
        }
    }

    /// Consumes a finite vertex coordinate.
    fn coordinate(&mut self) -> Result<f64, MeshError> {
        let word = self.next_or_eof("a vertex coordinate")?;
        coordinate(word, self.file, self.line)
    }
}
