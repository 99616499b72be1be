//! Every relative link in the documentation points somewhere.
//!
//! For `README.md`, every `docs/**/*.md` and every `formats/*.md`: each relative Markdown
//! link or image, `[text](path)`, `[text](path#anchor)`, `[text](#anchor)` or a reference
//! definition `[label]: path`, must name a file or directory that exists, and an anchor
//! into a Markdown file must be the slug of one of its headings (GitHub's rules: lower
//! case, spaces made `-`, punctuation other than `-` and `_` dropped, `-1`, `-2`, ...
//! appended to repeated slugs). Links with a scheme (`https:`, `mailto:`) are not
//! followed: no network. Code blocks and code spans are not read.
// Test code outside `#[test]` functions (the Markdown scanner): a failure is a failed test.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::string_slice)]

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Component, Path, PathBuf};

/// One link found in a Markdown text: its 1-based line and its raw target.
#[derive(Debug, PartialEq)]
struct Link {
    line: usize,
    target: String,
}

/// The Markdown files whose links are checked, relative to the crate root.
fn documents(root: &Path) -> Vec<PathBuf> {
    let mut files = vec![root.join("README.md")];
    collect_md(&root.join("docs"), true, &mut files);
    collect_md(&root.join("formats"), false, &mut files);
    files.sort();
    files
}

fn collect_md(dir: &Path, recurse: bool, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            if recurse {
                collect_md(&path, recurse, out);
            }
        } else if path.extension().is_some_and(|e| e == "md") {
            out.push(path);
        }
    }
}

/// The lines of `text` outside fenced code blocks, with their 1-based numbers.
fn prose_lines(text: &str) -> Vec<(usize, &str)> {
    let mut fence: Option<(char, usize)> = None;
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        let marker = trimmed.chars().next().filter(|c| *c == '`' || *c == '~');
        if let Some(c) = marker {
            let run = trimmed.chars().take_while(|&x| x == c).count();
            if run >= 3 {
                match fence {
                    None => {
                        fence = Some((c, run));
                        continue;
                    }
                    Some((open, len)) if open == c && run >= len => {
                        fence = None;
                        continue;
                    }
                    Some(_) => {}
                }
            }
        }
        if fence.is_none() {
            lines.push((i + 1, line));
        }
    }
    lines
}

/// `line` with its code spans blanked out (so that `[a](b)` inside backticks is not a link).
fn without_code_spans(line: &str) -> String {
    let chars: Vec<char> = line.chars().collect();
    let mut out = String::with_capacity(line.len());
    let mut i = 0;
    while i < chars.len() {
        if chars[i] == '`' {
            let run = chars[i..].iter().take_while(|&&c| c == '`').count();
            // Find the closing run of the same length.
            let mut j = i + run;
            let mut close = None;
            while j < chars.len() {
                if chars[j] == '`' {
                    let r = chars[j..].iter().take_while(|&&c| c == '`').count();
                    if r == run {
                        close = Some(j);
                        break;
                    }
                    j += r;
                } else {
                    j += 1;
                }
            }
            match close {
                Some(j) => {
                    out.extend(std::iter::repeat_n(' ', j + run - i));
                    i = j + run;
                }
                None => {
                    out.extend(&chars[i..i + run]);
                    i += run;
                }
            }
        } else {
            out.push(chars[i]);
            i += 1;
        }
    }
    out
}

/// Every inline link `[text](target)` / image `![alt](target)` and every reference
/// definition `[label]: target` in `text`.
fn links(text: &str) -> Vec<Link> {
    let mut found = Vec::new();
    for (number, raw) in prose_lines(text) {
        let line = without_code_spans(raw);
        // Reference definitions: `[label]: target`.
        let trimmed = line.trim_start();
        if let Some(rest) = trimmed.strip_prefix('[') {
            if let Some(end) = rest.find("]:") {
                if !rest[..end].contains('[') {
                    let target = rest[end + 2..].split_whitespace().next().unwrap_or("");
                    let target = target.trim_start_matches('<').trim_end_matches('>');
                    found.push(Link {
                        line: number,
                        target: target.to_string(),
                    });
                    continue;
                }
            }
        }
        // Inline links: a `]` directly followed by `(`, up to the matching `)`.
        let bytes = line.as_bytes();
        let mut i = 0;
        while i + 1 < bytes.len() {
            if bytes[i] == b']' && bytes[i + 1] == b'(' {
                let start = i + 2;
                let mut depth = 1;
                let mut j = start;
                while j < bytes.len() {
                    match bytes[j] {
                        b'(' => depth += 1,
                        b')' => {
                            depth -= 1;
                            if depth == 0 {
                                break;
                            }
                        }
                        _ => {}
                    }
                    j += 1;
                }
                let inner = line[start..j.min(line.len())].trim();
                let target = if let Some(rest) = inner.strip_prefix('<') {
                    rest.split('>').next().unwrap_or("")
                } else {
                    // A title may follow the target: `(path "title")`.
                    inner.split_whitespace().next().unwrap_or("")
                };
                found.push(Link {
                    line: number,
                    target: target.to_string(),
                });
                i = j;
            } else {
                i += 1;
            }
        }
    }
    found
}

/// GitHub's anchor for a heading's text.
fn slug(heading: &str) -> String {
    // Rendered text: a link shows its text, inline HTML tags show nothing.
    let mut text = String::new();
    let mut rest = heading;
    while let Some(open) = rest.find('[') {
        text.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        match after.find("](") {
            Some(close) => {
                text.push_str(&after[..close]);
                let tail = &after[close + 2..];
                rest = tail.find(')').map_or("", |p| &tail[p + 1..]);
            }
            None => {
                text.push('[');
                rest = after;
            }
        }
    }
    text.push_str(rest);
    let mut plain = String::new();
    let mut in_tag = false;
    for c in text.chars() {
        match c {
            '<' => in_tag = true,
            '>' if in_tag => in_tag = false,
            _ if !in_tag => plain.push(c),
            _ => {}
        }
    }
    plain
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| {
            if c == ' ' {
                Some('-')
            } else if c.is_alphanumeric() || c == '-' || c == '_' {
                Some(c)
            } else {
                None
            }
        })
        .collect()
}

/// The anchors of every heading of a Markdown text (ATX headings, `#` to `######`),
/// repeated slugs numbered as GitHub numbers them.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut out = BTreeSet::new();
    for (_, line) in prose_lines(text) {
        let trimmed = line.trim_start();
        if line.len() - trimmed.len() > 3 {
            continue;
        }
        let level = trimmed.chars().take_while(|&c| c == '#').count();
        if level == 0 || level > 6 {
            continue;
        }
        let rest = &trimmed[level..];
        if !(rest.is_empty() || rest.starts_with(' ') || rest.starts_with('\t')) {
            continue;
        }
        // An optional closing run of `#`.
        let title = rest.trim().trim_end_matches('#').trim_end();
        let base = slug(title);
        let count = seen.entry(base.clone()).or_insert(0);
        let anchor = if *count == 0 {
            base.clone()
        } else {
            format!("{base}-{count}")
        };
        *count += 1;
        out.insert(anchor);
    }
    out
}

/// `path` with `.` and `..` resolved lexically (the link is relative to a file in the
/// repository, so nothing here depends on symbolic links).
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// The problems of the links of one document, each a line of the report. `file` is the
/// document's path relative to `root`, the directory links may not leave.
fn check(
    root: &Path,
    file: &Path,
    text: &str,
    anchors_of: &mut dyn FnMut(&Path) -> Option<BTreeSet<String>>,
) -> Vec<String> {
    let mut problems = Vec::new();
    let dir = file.parent().unwrap_or(Path::new(""));
    for link in links(text) {
        let target = link.target.as_str();
        let place = format!("{}:{}: ({target})", file.display(), link.line);
        if target.is_empty() {
            problems.push(format!("{place}: empty link target"));
            continue;
        }
        let has_scheme = target.split_once(':').is_some_and(|(scheme, _)| {
            !scheme.is_empty()
                && scheme
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "+.-".contains(c))
        });
        if has_scheme {
            continue;
        }
        if target.starts_with('/') {
            problems.push(format!("{place}: absolute path; links must be relative"));
            continue;
        }
        let (path, anchor) = match target.split_once('#') {
            Some((p, a)) => (p, Some(a)),
            None => (target, None),
        };
        let resolved = normalize(&root.join(dir).join(path));
        if !resolved.starts_with(root) {
            problems.push(format!("{place}: leaves the repository"));
            continue;
        }
        if !resolved.exists() {
            problems.push(format!("{place}: no such file"));
            continue;
        }
        let Some(anchor) = anchor else {
            continue;
        };
        if resolved.extension().is_none_or(|e| e != "md") {
            continue;
        }
        match anchors_of(&resolved) {
            Some(known) if known.contains(anchor) => {}
            Some(_) => problems.push(format!("{place}: no heading with anchor #{anchor}")),
            None => problems.push(format!("{place}: cannot read the target")),
        }
    }
    problems
}

#[test]
fn every_relative_link_in_the_docs_resolves() {
    let root = normalize(Path::new(env!("CARGO_MANIFEST_DIR")));
    let mut cache: BTreeMap<PathBuf, Option<BTreeSet<String>>> = BTreeMap::new();
    let mut anchors_of = |path: &Path| {
        cache
            .entry(path.to_path_buf())
            .or_insert_with(|| fs::read_to_string(path).ok().map(|t| anchors(&t)))
            .clone()
    };
    let mut problems = Vec::new();
    let mut checked = 0;
    for file in documents(&root) {
        let text = fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let relative = file.strip_prefix(&root).unwrap_or(&file);
        checked += links(&text).len();
        problems.extend(check(&root, relative, &text, &mut anchors_of));
    }
    assert!(
        checked > 0,
        "no links found: is the checker reading the right files?"
    );
    assert!(problems.is_empty(), "dead links:\n{}", problems.join("\n"));
}

#[test]
fn github_slugs() {
    assert_eq!(slug("Known limitations"), "known-limitations");
    assert_eq!(
        slug("`obbtree collide | distance | span A B [POSES]`"),
        "obbtree-collide--distance--span-a-b-poses"
    );
    assert_eq!(
        slug("Robustness: hostile files, meshes and poses"),
        "robustness-hostile-files-meshes-and-poses"
    );
    assert_eq!(
        slug("5.5 Packed references (dissertation §7.2.2)"),
        "55-packed-references-dissertation-722"
    );
    assert_eq!(slug("f32 vs f64: which_one?"), "f32-vs-f64-which_one");
    assert_eq!(slug("See [the guide](GUIDE.md) now"), "see-the-guide-now");
    let text = "# A\n## A\n```\n# not a heading\n```\n### A\n";
    let found = anchors(text);
    assert_eq!(
        found,
        ["a", "a-1", "a-2"].iter().map(|s| s.to_string()).collect()
    );
}

#[test]
fn links_are_found_outside_code_only() {
    let text = "See [a](x.md) and ![b](img/y.svg \"title\").\n\
                `[not](code.md)` and\n\
                ```sh\n[nor](fenced.md)\n```\n\
                [ref]: refs/z.md\n\
                [web](https://example.com) [here](#top)\n";
    let targets: Vec<String> = links(text).into_iter().map(|l| l.target).collect();
    assert_eq!(
        targets,
        [
            "x.md",
            "img/y.svg",
            "refs/z.md",
            "https://example.com",
            "#top"
        ]
    );
}

#[test]
fn a_dead_link_or_anchor_is_reported() {
    let root = normalize(Path::new(env!("CARGO_MANIFEST_DIR")));
    let file = Path::new("README.md");
    let text = "[ok](formats/obbt.md#2-layout) [ok too](#there)\n\
                [gone](docs/NO-SUCH-FILE.md)\n\
                [bad anchor](formats/obbt.md#no-such-heading)\n\
                [outside](../elsewhere/README.md)\n\
                ## There\n";
    let readme = root.join(file);
    let mut anchors_of = |p: &Path| {
        if p == readme {
            Some(anchors(text))
        } else {
            fs::read_to_string(p).ok().map(|t| anchors(&t))
        }
    };
    let problems = check(&root, file, text, &mut anchors_of);
    assert_eq!(problems.len(), 3, "{problems:#?}");
    assert!(problems[0].contains("README.md:2: (docs/NO-SUCH-FILE.md): no such file"));
    assert!(problems[1].contains("README.md:3: (formats/obbt.md#no-such-heading): no heading"));
    assert!(problems[2].contains("leaves the repository"));
}
