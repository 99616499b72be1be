//! Text inputs of the query commands (pose batches, points, rays): a file or standard
//! input, its data lines, and the numbers on a line.

use super::{Failure, WithContext};
use std::io::Read;
use std::path::Path;

/// The text of an input file, or of standard input for `-`, with the name errors show
/// for it (`<stdin>` for `-`).
pub fn read_input(path: &Path) -> Result<(String, String), Failure> {
    let stdin = path.as_os_str() == "-";
    let shown = if stdin {
        "<stdin>".to_string()
    } else {
        path.display().to_string()
    };
    let mut text = String::new();
    if stdin {
        std::io::stdin()
            .read_to_string(&mut text)
            .with_context(|| format!("{shown}: cannot read"))?;
    } else {
        text = std::fs::read_to_string(path).with_context(|| format!("{shown}: cannot read"))?;
    }
    Ok((shown, text))
}

/// The lines of an input file that hold data, trimmed, with their numbers (from 1): blank
/// lines and lines starting with `#` are skipped.
pub fn input_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
}

/// Numbers separated by commas and/or white space; `what` names the source in errors.
pub fn parse_numbers(text: &str, what: &str) -> Result<Vec<f64>, Failure> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .enumerate()
        .map(|(i, t)| {
            t.parse::<f64>()
                .map_err(|_| Failure::msg(format!("{what}: value {i} ({t:?}) is not a number")))
        })
        .collect()
}
