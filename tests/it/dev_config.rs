//! The development configuration files are what the development docs say they are.
//!
//! `.cargo/mutants.toml` is read only by `cargo mutants`, which no other test runs: once it
//! was committed garbled (a megabyte of its own text repeated) and nothing noticed. Here it
//! must parse, each examined glob must name files that exist, each test filter must be
//! `tests::` (the library's unit tests) or a module of this binary, each exclusion must
//! read as a mutant's name, and one that names its mutant by line must find its code on
//! that line (four had gone stale as code above them moved).
// Test code: a failure is a failed test.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use std::collections::BTreeSet;
use std::fs;
use std::path::Path;

#[derive(serde::Deserialize)]
struct MutantsConfig {
    examine_globs: Vec<String>,
    profile: String,
    additional_cargo_args: Vec<String>,
    additional_cargo_test_args: Vec<String>,
    exclude_re: Vec<String>,
}

/// `.cargo/mutants.toml`, parsed.
fn mutants_config() -> MutantsConfig {
    let text = fs::read_to_string(root().join(".cargo/mutants.toml")).unwrap();
    toml::from_str(&text).unwrap()
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Whether `glob` (a path, or a directory followed by `*.rs` or `**/*.rs`) names at least
/// one file.
fn glob_names_files(glob: &str) -> bool {
    match glob.split_once('*') {
        None => root().join(glob).is_file(),
        Some((dir, _)) => fs::read_dir(root().join(dir)).is_ok_and(|entries| {
            entries
                .flatten()
                .any(|e| e.path().extension().is_some_and(|x| x == "rs"))
        }),
    }
}

#[test]
fn mutants_config_parses_and_names_what_exists() {
    let config = mutants_config();
    assert!(!config.examine_globs.is_empty());
    for glob in &config.examine_globs {
        assert!(
            glob_names_files(glob),
            "examine_globs names no file: {glob}"
        );
    }
    let manifest = fs::read_to_string(root().join("Cargo.toml")).unwrap();
    assert!(
        manifest.contains(&format!("[profile.{}]", config.profile)),
        "no [profile.{}] in Cargo.toml",
        config.profile
    );

    let main = fs::read_to_string(root().join("tests/it/main.rs")).unwrap();
    let modules: BTreeSet<&str> = main
        .lines()
        .filter_map(|l| l.strip_prefix("mod ")?.strip_suffix(';'))
        .collect();
    assert_eq!(config.additional_cargo_args, ["--lib", "--test", "it"]);
    let (dash, filters) = config.additional_cargo_test_args.split_first().unwrap();
    assert_eq!(dash, "--");
    for filter in filters {
        let module = filter.strip_suffix("::").unwrap();
        assert!(
            module == "tests" || modules.contains(module),
            "test filter {filter} is not a module of tests/it"
        );
    }
    // Each exclusion names a kind of mutant the way cargo-mutants does ("replace X with Y",
    // "delete field F from struct S expression in G", "delete ! in G", "delete match arm A
    // in G").
    for re in &config.exclude_re {
        assert!(
            re.contains(" with ") || re.contains("delete "),
            "not a mutant's name: {re}"
        );
    }
}

/// Where an exclusion names a mutant by line, that line still holds what the mutant
/// changes: code moved under a line-named exclusion would leave it excluding nothing, or a
/// mutant nobody looked at.
#[test]
fn mutants_exclusions_named_by_line_still_find_their_code() {
    let config = mutants_config();
    let mut sources = Vec::new();
    rust_files(&root().join("src"), &mut sources);
    let mut checked = 0;
    for re in &config.exclude_re {
        let Some(Site {
            path,
            line: number,
            column,
            text,
        }) = named_site(re)
        else {
            continue;
        };
        // One that names a line but no mutant read here would go unchecked.
        assert!(text.is_some(), "{re}: names a line, but what mutant?");
        let text = text.unwrap();
        let here = |file: &&std::path::PathBuf| {
            let source = fs::read_to_string(file).unwrap();
            let Some(line) = source.lines().nth(number - 1) else {
                return false;
            };
            match column {
                Some(c) => line
                    .chars()
                    .skip(c - 1)
                    .collect::<String>()
                    .starts_with(&text),
                None => line.contains(&text),
            }
        };
        assert!(
            sources
                .iter()
                .filter(|f| f.ends_with(&path))
                .any(|f| here(&f)),
            "{re}: line {number} of {path} has no `{text}` (has the code moved?)"
        );
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} exclusions named by line");
}

/// A place an exclusion names: the end of a file's path, a line, the column if one is
/// given, and the text the mutant changes there (the operator replaced, the field or
/// unary operator deleted; `None` if the exclusion names no mutant this reads), regex
/// escapes removed.
struct Site {
    path: String,
    line: usize,
    column: Option<usize>,
    text: Option<String>,
}

/// The place `re` names, if it names one line (not `\d+` or a range of lines).
fn named_site(re: &str) -> Option<Site> {
    let (head, mutant) = re.split_once(": ")?;
    let mut parts = head.split(':');
    let (path, line, column) = (parts.next()?, parts.next()?, parts.next());
    let line = line.parse().ok()?;
    let text = match mutant.strip_prefix("replace ") {
        Some(rest) => rest.split_once(" with ").map(|(from, _)| from),
        // A field deleted, a match arm (`delete match arm PATTERN in f`, found by its
        // pattern), or a unary operator (`delete - in f`).
        None => mutant.strip_prefix("delete ").and_then(|rest| {
            match rest.strip_prefix("field ") {
                Some(field) => field.split_once(' '),
                None => rest
                    .strip_prefix("match arm ")
                    .unwrap_or(rest)
                    .split_once(" in "),
            }
            .map(|(deleted, _)| deleted)
        }),
    };
    let unescape = |s: &str| s.replace('\\', "");
    Some(Site {
        path: unescape(path),
        line,
        column: column.and_then(|c| c.parse().ok()),
        text: text.map(unescape),
    })
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}
