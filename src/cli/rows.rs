//! Query inputs given as rows of numbers: one on the command line, or a file or stdin of
//! lines (what `closest` and `ray` read).

use super::input::{input_lines, parse_numbers, read_input};
use super::Failure;
use clap::Args;
use obbtree::query::QueryError;
use std::path::{Path, PathBuf};

/// Rows of `N` numbers read by [`numeric_rows`], with where each one was read.
pub struct Rows<const N: usize> {
    /// The rows, in input order.
    pub values: Vec<[f64; N]>,
    /// The flag, file name or `<stdin>` they came from.
    source: String,
    /// Each row's line number (from 1) in a file; empty for a flag's one row.
    lines: Vec<usize>,
}

impl<const N: usize> Rows<N> {
    /// `error`, a query's over these rows, with the place of the row it names in front
    /// (`FILE: line L: ray 3: ...`): a batch index alone does not say which line to mend.
    pub fn locate(&self, error: QueryError) -> Failure {
        let place = match &error {
            // (Not the model's own triangles, which the error names otherwise.)
            QueryError::BadInput {
                what: "query point" | "ray",
                index,
                ..
            } => match self.lines.get(*index) {
                Some(line) => Some(format!("{}: line {line}", self.source)),
                None => Some(self.source.clone()),
            },
            _ => None,
        };
        match place {
            Some(place) => Failure::from(error).context(place),
            None => error.into(),
        }
    }
}

/// The rows of `N` numbers (named `names`, e.g. `x y z`) given by exactly one of
/// `single` (the text of flag `single_flag`) and `file` (a path, `-` for stdin, of lines
/// of `N` numbers separated by spaces or commas; blank lines and `#` comments skipped).
pub fn numeric_rows<const N: usize>(
    single: Option<&str>,
    single_flag: &str,
    file: Option<&Path>,
    file_flag: &str,
    names: &str,
) -> Result<Rows<N>, Failure> {
    let row = |numbers: Vec<f64>, at: &dyn Fn() -> String| -> Result<[f64; N], Failure> {
        <[f64; N]>::try_from(numbers.as_slice()).map_err(|_| {
            Failure::msg(format!(
                "{}: {} numbers, not the {N} of {names}",
                at(),
                numbers.len()
            ))
        })
    };
    match (single, file) {
        (Some(text), None) => Ok(Rows {
            values: vec![row(parse_numbers(text, single_flag)?, &|| {
                single_flag.into()
            })?],
            source: single_flag.into(),
            lines: Vec::new(),
        }),
        (None, Some(path)) => {
            let (shown, text) = read_input(path)?;
            let (mut values, mut lines) = (Vec::new(), Vec::new());
            for (line, content) in input_lines(&text) {
                let at = || format!("{shown}: line {line}");
                values.push(row(parse_numbers(content, &at())?, &at)?);
                lines.push(line);
            }
            if values.is_empty() {
                return Err(Failure::msg(format!("{shown}: no rows of {names}")));
            }
            Ok(Rows {
                values,
                source: shown,
                lines,
            })
        }
        _ => Err(Failure::msg(format!(
            "give {single_flag} or {file_flag} FILE (- for stdin)"
        ))),
    }
}

/// The query points of a one-model query: one on the command line, or many in a file.
#[derive(Args, Debug)]
pub struct PointArgs {
    /// One query point, world frame: x,y,z.
    #[arg(
        long,
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        conflicts_with = "points"
    )]
    pub point: Option<String>,
    /// Query points, world frame: a file (`-` for stdin) of lines `x y z` (or `x,y,z`);
    /// blank lines and lines starting with `#` are skipped. Answered in parallel, printed
    /// in input order, each with "point": its index from 0.
    #[arg(long, value_name = "FILE")]
    pub points: Option<PathBuf>,
}

impl PointArgs {
    /// The points given.
    pub fn rows(&self) -> Result<Rows<3>, Failure> {
        numeric_rows::<3>(
            self.point.as_deref(),
            "--point X,Y,Z",
            self.points.as_deref(),
            "--points",
            "x y z",
        )
    }
}

/// How many threads answer a one-model query's rows.
#[derive(Args, Debug)]
pub struct ThreadArgs {
    /// Threads that answer the queries [default: one per core]. The answers do not depend
    /// on it; take timings with --threads 1.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..1025))]
    pub threads: Option<u32>,
}
