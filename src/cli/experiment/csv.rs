//! The experiments' CSV files, written through the csv crate: one row per measured point,
//! per fitted line, or per accuracy trade. Fields are written as text, numbers as Rust's
//! `Display` writes them (the shortest decimals that read back exactly, never with an
//! exponent), which the files have always held; the crate's serde path would write them
//! its own way.

use crate::cli::files::write_file;
use crate::cli::Failure;
use ::csv::{QuoteStyle, WriterBuilder};
use obbtree::experiment::accuracy::Trade;
use obbtree::experiment::Outcome;
use std::path::{Path, PathBuf};

/// Writes `header` and then `rows` as a CSV file at `path` (atomically, as every file the
/// command writes), with the fields quoted as `quoting` says; returns the path.
fn write<Row>(
    path: PathBuf,
    header: &[&str],
    rows: impl IntoIterator<Item = Row>,
    quoting: QuoteStyle,
) -> Result<PathBuf, Failure>
where
    Row: IntoIterator,
    Row::Item: AsRef<[u8]>,
{
    let mut writer = WriterBuilder::new()
        .quote_style(quoting)
        .from_writer(Vec::new());
    writer.write_record(header)?;
    for row in rows {
        writer.write_record(row)?;
    }
    write_file(&path, &writer.into_inner()?)?;
    Ok(path)
}

/// Writes `{name}.csv` in `dir`: one row per volume type and parameter value, each count
/// the mean over the point's queries and the time the median of one query.
pub fn write_points(outcome: &Outcome, dir: &Path) -> Result<PathBuf, Failure> {
    let header = [
        "volume",
        outcome.x_column,
        "queries",
        "contacts",
        "bv_disjoint",
        "bv_overlap",
        "tri_separated",
        "tri_contact",
        "bv_tests",
        "tri_tests",
        "bv_test_lower_bound",
        "seconds",
    ];
    let rows = outcome.points.iter().map(|p| {
        // No contacts, no bound: an empty field, as `collide --csv` writes it.
        let bound = if p.lower_bound > 0.0 {
            p.lower_bound.to_string()
        } else {
            String::new()
        };
        [
            p.label(),
            p.x.to_string(),
            p.queries.to_string(),
            p.contacts.to_string(),
            p.disjoint.to_string(),
            p.overlap.to_string(),
            p.separated.to_string(),
            p.contacts.to_string(),
            p.bv_tests().to_string(),
            p.tri_tests().to_string(),
            bound,
            p.seconds.to_string(),
        ]
    });
    let path = dir.join(format!("{}.csv", outcome.name));
    write(path, &header, rows, QuoteStyle::Necessary)
}

/// Writes `{name}-fits.csv` in `dir`: one row per fitted line,
/// `log10(measure) = slope · log10(x) + intercept` over `from` to `to`.
pub fn write_fits(outcome: &Outcome, dir: &Path) -> Result<PathBuf, Failure> {
    let header = ["bv", "measure", "slope", "intercept", "from", "to"];
    let rows = outcome.fits.iter().map(|f| {
        [
            f.bv.name().to_string(),
            f.measure.to_string(),
            f.line.slope.to_string(),
            f.line.intercept.to_string(),
            f.from.to_string(),
            f.to.to_string(),
        ]
    });
    let path = dir.join(format!("{}-fits.csv", outcome.name));
    write(path, &header, rows, QuoteStyle::Necessary)
}

/// Writes `accuracy.csv` in `dir`: one row per scene, query and choice. Times are summed
/// over the scene's poses (each pose's median); errors are relative excesses of the
/// distance, or shares of contacting pairs differing.
pub fn write_trades(trades: &[Trade], dir: &Path) -> Result<PathBuf, Failure> {
    let header = [
        "scene",
        "query",
        "choice",
        "seconds_all_poses",
        "error_mean",
        "error_max",
        "bv_tests_mean",
        "bytes_per_triangle",
        "pareto",
    ];
    let rows = trades.iter().map(|t| {
        Ok([
            always_quoted(&t.scene)?,
            t.query.to_string(),
            always_quoted(&t.choice)?,
            t.seconds.to_string(),
            t.error_mean.to_string(),
            t.error_max.to_string(),
            t.bv_tests.to_string(),
            t.bytes_per_triangle.to_string(),
            t.pareto.to_string(),
        ])
    });
    let rows = rows.collect::<Result<Vec<_>, Failure>>()?;
    // The free-text fields come quoted; the others (a query name, numbers, booleans)
    // never need quotes.
    write(dir.join("accuracy.csv"), &header, rows, QuoteStyle::Never)
}

/// `text` as a quoted CSV field, whatever it holds. The accuracy CSV has always quoted
/// its free-text columns (scene names are file names, choices hold commas), and the csv
/// crate chooses quoting per writer, not per field: a one-field writer that always quotes
/// writes it.
fn always_quoted(text: &str) -> Result<String, Failure> {
    let mut writer = WriterBuilder::new()
        .quote_style(QuoteStyle::Always)
        .from_writer(Vec::new());
    writer.write_record([text])?;
    let line = String::from_utf8(writer.into_inner()?)?;
    // The record's terminator, which the row's own writer adds.
    Ok(line.strip_suffix('\n').unwrap_or(&line).to_string())
}

#[cfg(test)]
mod tests {
    use super::always_quoted;

    /// Quotes around the whole field, quotes inside doubled, commas and line breaks kept:
    /// what accuracy.csv has always held.
    #[test]
    fn free_text_is_quoted_whatever_it_holds() {
        for (text, field) in [
            ("spheres", "\"spheres\""),
            ("", "\"\""),
            ("f32, --rel-err 0.01", "\"f32, --rel-err 0.01\""),
            ("a \"cow\"", "\"a \"\"cow\"\"\""),
            ("two\nlines", "\"two\nlines\""),
        ] {
            assert_eq!(always_quoted(text).unwrap(), field);
        }
    }
}
