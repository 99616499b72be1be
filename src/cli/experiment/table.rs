//! The tables printed after a run: a chapter 5 experiment's figures beside the
//! dissertation's, and the accuracy experiment's trades, choice by choice.

use crate::cli::print::out;
use crate::cli::{human_seconds, Failure};
use obbtree::experiment::accuracy::{Trade, Workload};
use obbtree::experiment::{Comparison, Outcome};

/// Prints what the run measured beside what the dissertation reports, one figure a line.
/// `quick` adds a note that the reduced sizes make the figures differ by construction.
pub fn print_comparisons(outcome: &Outcome, quick: bool) -> Result<(), Failure> {
    let width = |column: fn(&Comparison) -> &str| {
        let cells = outcome
            .comparisons
            .iter()
            .map(|c| column(c).chars().count());
        cells.max().unwrap_or(0)
    };
    let (what, reported) = (width(|c| &c.what), width(|c| &c.dissertation).max(12));
    out!("{}: measured against the dissertation", outcome.name)?;
    if quick {
        out!("  (--quick: smaller meshes and fewer queries, so sizes and counts differ by construction)")?;
    }
    out!("  {:<what$}  {:<reported$}  measured", "", "dissertation")?;
    for c in &outcome.comparisons {
        out!(
            "  {:<what$}  {:<reported$}  {}",
            c.what,
            c.dissertation,
            c.measured
        )?;
    }
    Ok(())
}

/// How the trade tables present one query of the accuracy experiment.
struct TradeTable {
    /// The query, as [`Trade::query`] names it.
    query: &'static str,
    /// The scene's poses that the query runs at.
    poses: fn(&Workload) -> usize,
    /// What the query's error measures.
    error: &'static str,
}

/// The accuracy experiment's queries, in the order their tables are printed.
const TRADE_TABLES: [TradeTable; 3] = [
    TradeTable {
        query: "distance",
        poses: |scene| scene.apart.len(),
        error: "relative excess of the distance",
    },
    TradeTable {
        query: "collision",
        poses: |scene| scene.crossing.len(),
        error: "share of contacting pairs gained or lost",
    },
    TradeTable {
        query: "hausdorff",
        poses: |scene| scene.crossing.len(),
        error: "relative error of the one-sided Hausdorff distance",
    },
];

/// Prints one table per scene and query: every choice, fastest first, with its time, its
/// errors, its volume tests and its trees' bytes per triangle, and a `*` on the choices of
/// the Pareto front.
pub fn print_trades(trades: &[Trade], scenes: &[Workload]) -> Result<(), Failure> {
    for scene in scenes {
        for table in &TRADE_TABLES {
            let query = table.query;
            let mut rows: Vec<&Trade> = trades
                .iter()
                .filter(|t| t.scene == scene.name && t.query == query)
                .collect();
            rows.sort_by(|p, q| p.seconds.total_cmp(&q.seconds));
            out!(
                "{} {query} ({} poses; time summed over them; error: {}; * on the Pareto front):",
                scene.name,
                (table.poses)(scene),
                table.error
            )?;
            out!(
                "  {:<40} {:>10} {:>12} {:>12} {:>10} {:>9}",
                "choice",
                "time",
                "error mean",
                "error max",
                "bv tests",
                "bytes/tri"
            )?;
            for t in rows {
                out!(
                    "  {:<40} {:>10} {:>12.2e} {:>12.2e} {:>10.0} {:>9.1} {}",
                    t.choice,
                    human_seconds(t.seconds),
                    t.error_mean,
                    t.error_max,
                    t.bv_tests,
                    t.bytes_per_triangle,
                    if t.pareto { "*" } else { "" }
                )?;
            }
        }
    }
    Ok(())
}
