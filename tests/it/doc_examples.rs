//! The documentation's example outputs are what the commands print.
//!
//! In `README.md` the quick start's commands are followed by a `text` block of what its
//! queries print, one line each; in `docs/GUIDE.md` a command line followed at once by a
//! `# ` line shows the first line it prints (on standard error when it begins
//! `obbtree: `). Each such command is run from the crate root (`/tmp/` made a scratch
//! directory) and its line compared: `…` stands for digits left off, `...` for any text,
//! and a trailing ` in SECONDS s` is not compared. Work counts, answers and triangle ids
//! are deterministic, so a change that moves them must update the documents too.
// Test code outside `#[test]` functions (the text matcher): a failure is a failed test.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::string_slice)]

use crate::common::cli::{scratch, stderr};
use std::path::Path;
use std::process::Command;

/// Whether `actual` is what `shown` shows: equal, except that `…` in `shown` matches a run
/// of digits and `...` any text.
fn shows(shown: &str, actual: &str) -> bool {
    if let Some(rest) = shown.strip_prefix("...") {
        return (0..=actual.len())
            .filter(|&i| actual.is_char_boundary(i))
            .any(|i| shows(rest, &actual[i..]));
    }
    if let Some(rest) = shown.strip_prefix('…') {
        let digits = actual.len()
            - actual
                .trim_start_matches(|c: char| c.is_ascii_digit())
                .len();
        return (0..=digits).any(|i| shows(rest, &actual[i..]));
    }
    match (shown.chars().next(), actual.chars().next()) {
        (None, None) => true,
        (Some(s), Some(a)) if s == a => shows(&shown[s.len_utf8()..], &actual[a.len_utf8()..]),
        _ => false,
    }
}

/// `line` without a trailing ` in SECONDS s` (a time, which varies).
fn untimed(line: &str) -> &str {
    match line.rfind(" in ") {
        Some(at)
            if line[at + 4..]
                .strip_suffix(" s")
                .is_some_and(|t| t.parse::<f64>().is_ok()) =>
        {
            &line[..at]
        }
        _ => line,
    }
}

/// Runs the binary with `args` (those of `command`, as the document shows it) from the
/// crate root, where the documents' relative paths start; it must succeed.
fn run(command: &str, args: &[impl AsRef<std::ffi::OsStr>]) -> std::process::Output {
    let o = Command::new(env!("CARGO_BIN_EXE_obbtree"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{command}: {}", stderr(&o));
    o
}

/// Runs `command` (a shell line starting `obbtree `, words split on spaces) from the crate
/// root with `/tmp/` replaced by `tmp`, and returns its first line: of standard error when
/// `on_stderr`, else of standard output.
fn first_line(command: &str, tmp: &Path, on_stderr: bool) -> String {
    let tmp = format!("{}/", tmp.display());
    let words: Vec<String> = command
        .split_whitespace()
        .skip(1)
        .map(|w| w.replace("/tmp/", &tmp))
        .collect();
    let o = run(command, &words);
    let text = if on_stderr { o.stderr } else { o.stdout };
    String::from_utf8_lossy(&text)
        .lines()
        .next()
        .unwrap_or("")
        .to_string()
}

/// Compares each shown line with its command's, reporting every mismatch at once.
fn check(document: &str, examples: &[(String, String)], tmp: &Path) {
    let wrong: Vec<String> = examples
        .iter()
        .filter_map(|(command, shown)| {
            let actual = first_line(command, tmp, shown.starts_with("obbtree: "));
            (!shows(untimed(shown), untimed(&actual)))
                .then(|| format!("{command}\n  shown:  {shown}\n  prints: {actual}"))
        })
        .collect();
    assert!(wrong.is_empty(), "{document}:\n{}", wrong.join("\n"));
}

#[test]
fn the_readme_quick_start_prints_what_it_shows() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let start = readme
        .find("## Thirty seconds on the command line")
        .unwrap();
    let mut blocks = readme[start..].split("```").skip(1).step_by(2);
    let commands: Vec<&str> = blocks
        .next()
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("obbtree "))
        .collect();
    let shown: Vec<&str> = blocks.next().unwrap().lines().skip(1).collect();
    let tmp = scratch("readme-quick-start");
    // The builds print no shown line; they make the trees the queries read.
    let (builds, queries): (Vec<&str>, Vec<&str>) = commands
        .iter()
        .partition(|c| c.starts_with("obbtree build "));
    for build in builds {
        first_line(build, &tmp, false);
    }
    assert_eq!(queries.len(), shown.len(), "one shown line per query");
    let examples: Vec<(String, String)> = queries
        .iter()
        .zip(&shown)
        .map(|(c, s)| (c.to_string(), s.to_string()))
        .collect();
    check("README.md", &examples, &tmp);
}

#[test]
fn the_guide_s_commands_print_what_it_shows() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let guide = std::fs::read_to_string(root.join("docs/GUIDE.md")).unwrap();
    let lines: Vec<&str> = guide.lines().collect();
    let examples: Vec<(String, String)> = lines
        .windows(2)
        .filter(|w| w[0].starts_with("obbtree ") && w[1].starts_with("# "))
        .map(|w| (w[0].to_string(), w[1][2..].to_string()))
        .collect();
    assert!(examples.len() >= 5, "{examples:?}");
    check("docs/GUIDE.md", &examples, &scratch("guide-examples"));
}

/// `line` with its times blanked: a number before a unit of time (`ms`, `µs`, `s`) and a
/// rate in frames per second become `T`, and the unit goes (a time may print in another
/// unit on another run).
fn timeless(line: &str) -> String {
    let is_time_unit = |w: &str| matches!(w, "ms" | "µs" | "s");
    let words: Vec<&str> = line.split_whitespace().collect();
    let kept: Vec<&str> = words
        .iter()
        .enumerate()
        .filter(|&(i, w)| !(i > 0 && is_time_unit(w)))
        .map(|(i, w)| match words.get(i + 1) {
            Some(&next) if is_time_unit(next) || next == "frames" => "T",
            _ => w,
        })
        .collect();
    kept.join(" ")
}

/// A `text` block that starts `$ obbtree ...` shows the command's whole output. Blocks
/// naming files that are not in the repository are illustrations, not run.
#[test]
fn the_guide_s_transcripts_are_what_the_commands_print() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let guide = std::fs::read_to_string(root.join("docs/GUIDE.md")).unwrap();
    let mut checked = 0;
    for block in guide.split("```text\n").skip(1) {
        let block = block.split("```").next().unwrap();
        let mut lines = block.lines();
        let Some(command) = lines.next().and_then(|l| l.strip_prefix("$ ")) else {
            continue;
        };
        let args: Vec<&str> = command.split_whitespace().skip(1).collect();
        if args
            .iter()
            .any(|a| a.contains('.') && !root.join(a).exists())
        {
            continue;
        }
        let o = run(command, &args);
        let printed = String::from_utf8_lossy(&o.stdout);
        let shown: Vec<String> = lines.map(timeless).collect();
        let actual: Vec<String> = printed.lines().map(timeless).collect();
        assert_eq!(shown, actual, "docs/GUIDE.md: {command}");
        checked += 1;
    }
    assert!(checked >= 1);
}

#[test]
fn the_matcher_reads_elisions() {
    assert!(shows("at [-0.1253…, 2]", "at [-0.12534567, 2]"));
    assert!(!shows("at [-0.1253…, 2]", "at [-0.1254, 2]"));
    assert!(shows("from [...] on A", "from [1, 2, 3] on A"));
    assert!(!shows("from [...] on A", "from [1, 2, 3] on B"));
    assert_eq!(untimed("yes (D=1) in 0.000070 s"), "yes (D=1)");
    assert_eq!(untimed("distance 2 in total"), "distance 2 in total");
    assert_eq!(timeless("  total  348  6.49 ms"), "total 348 T");
    assert_eq!(timeless("  total  348  649 µs"), "total 348 T");
    assert_eq!(
        timeless("13.76 ms (17441 frames per second)"),
        "T T frames per second)"
    );
}
