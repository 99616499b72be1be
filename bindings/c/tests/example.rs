//! The C example, compiled with the system `cc` against the library this crate built
//! (statically and dynamically), run on a tree built from assets/cow.obj, and its every
//! answer checked against the same query through the Rust API. The README's "From C" code
//! is checked to be that example.

mod common;

use obbtree::build::BuildOptions;
use obbtree::format::ObbtFile;
use obbtree::query::{
    CollideOptions, DistanceOptions, PairQuery, Pose, SpanOptions, ToleranceOptions, Witness, Work,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One value of an output line: numbers (comma-separated) or text.
#[derive(Clone, Debug, PartialEq)]
enum Value {
    Numbers(Vec<f64>),
    Text(String),
}

/// Lines keyed by (query, pose index), each a map of its `key=value` tokens.
type Answers = BTreeMap<(String, usize), BTreeMap<String, Value>>;

fn parse(output: &str) -> Answers {
    let mut answers = Answers::new();
    for line in output.lines().filter(|l| !l.starts_with("error ")) {
        let mut tokens = line.split(' ');
        let query = tokens.next().expect("a query name").to_string();
        let index: usize = tokens
            .next()
            .and_then(|t| t.parse().ok())
            .unwrap_or_else(|| panic!("no pose index in {line:?}"));
        let mut values = BTreeMap::new();
        for token in tokens {
            let (key, value) = token
                .split_once('=')
                .unwrap_or_else(|| panic!("not key=value: {token:?} in {line:?}"));
            let numbers: Result<Vec<f64>, _> = if value.is_empty() {
                Ok(Vec::new())
            } else {
                value.split(',').map(str::parse::<f64>).collect()
            };
            let value = match numbers {
                Ok(numbers) if key != "v" => Value::Numbers(numbers),
                _ => Value::Text(value.to_string()),
            };
            values.insert(key.to_string(), value);
        }
        let previous = answers.insert((query, index), values);
        assert!(previous.is_none(), "line repeated: {line:?}");
    }
    answers
}

/// The answers the Rust API gives, keyed and formatted as the example prints them.
struct Expected(Answers);

impl Expected {
    fn line(&mut self, query: &str, index: usize, values: &[(&str, Value)]) {
        let values = values
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        self.0.insert((query.to_string(), index), values);
    }
}

fn nums<const N: usize>(values: [f64; N]) -> Value {
    Value::Numbers(values.to_vec())
}

fn num(value: impl Into<f64>) -> Value {
    Value::Numbers(vec![value.into()])
}

fn text(value: &str) -> Value {
    Value::Text(value.to_string())
}

fn work(w: &Work) -> Value {
    Value::Numbers(
        [
            w.bv_disjoint,
            w.bv_overlap,
            w.tri_separated,
            w.tri_contact,
            w.nodes_visited,
        ]
        .map(|x| x as f64)
        .to_vec(),
    )
}

/// `d=...` and, with a pair, its points and triangles.
fn witness(distance: f64, w: Option<&Witness>) -> Vec<(&'static str, Value)> {
    let mut values = vec![("d", num(distance))];
    if let Some(w) = w {
        values.push(("a", nums(w.point_a.into())));
        values.push(("b", nums(w.point_b.into())));
        values.push(("tri", nums([f64::from(w.tri_a), f64::from(w.tri_b)])));
    }
    values
}

fn pairs_value(pairs: &[(u32, u32)]) -> Value {
    Value::Numbers(
        pairs
            .iter()
            .flat_map(|&(a, b)| [f64::from(a), f64::from(b)])
            .collect(),
    )
}

fn bool_value(b: bool) -> Value {
    num(u8::from(b))
}

fn pose_of(answers: &Answers, query: &str, index: usize) -> Pose {
    match answers
        .get(&(query.to_string(), index))
        .and_then(|l| l.get("p"))
    {
        Some(Value::Numbers(p)) => Pose::from_row_major(p).expect("the example's pose is rigid"),
        other => panic!("no pose {query} {index}: {other:?}"),
    }
}

/// Every answer of the example, computed through the Rust API for the poses it printed.
fn expected(tree: &Path, printed: &Answers) -> Answers {
    let file = ObbtFile::open(tree).expect("opens");
    let info = file.info();
    let mut e = Expected(Answers::new());
    e.line("version", 0, &[("v", text(env!("CARGO_PKG_VERSION")))]);
    e.line(
        "info",
        0,
        &[
            ("triangles", num(info.triangles)),
            ("vertices", num(info.vertices)),
            ("nodes", num(info.nodes)),
            ("leaves", num(info.stats.shape.leaves)),
            ("depth", num(info.stats.shape.depth)),
            ("leaf_size", num(info.leaf_size)),
            ("bounds_min", nums(info.stats.bounds_min)),
            ("bounds_max", nums(info.stats.bounds_max)),
            ("volume", num(info.bv.tag())),
            ("precision", num(info.precision.tag())),
        ],
    );
    e.line(
        "names",
        0,
        &[
            ("volume", text(info.bv.name())),
            ("precision", text(info.precision.name())),
            ("fit", text(info.fit.name())),
            ("encoding", text(info.encoding.name())),
        ],
    );
    e.line(
        "embedded",
        0,
        &[
            ("triangles", num(info.triangles)),
            ("file_bytes", num(info.file_bytes as f64)),
        ],
    );
    let pose_a = pose_of(printed, "pose_a", 0);
    e.line("pose_a", 0, &[("p", nums(pose_a.row_major()))]);
    let mut pair = PairQuery::new(&file, &file).expect("pair");
    let first = CollideOptions {
        first_contact: true,
        ..CollideOptions::default()
    };
    let exact = DistanceOptions::default();
    let rel = DistanceOptions {
        rel_err: 0.1,
        ..DistanceOptions::default()
    };
    let max = DistanceOptions {
        max_distance: 0.5,
        ..DistanceOptions::default()
    };
    let tolerance = ToleranceOptions::new(0.05);
    for i in 0..4 {
        let pose_b = pose_of(printed, "pose_b", i);
        e.line("pose_b", i, &[("p", nums(pose_b.row_major()))]);
        let c = pair
            .collide(&pose_a, &pose_b, &CollideOptions::default())
            .expect("collide");
        let colliding = bool_value(c.colliding);
        let contacts = num(c.pairs.len() as f64);
        e.line(
            "collide",
            i,
            &[
                ("colliding", colliding.clone()),
                ("contacts", contacts.clone()),
                ("work", work(&c.work)),
            ],
        );
        e.line("pairs", i, &[("list", pairs_value(&c.pairs))]);
        let offset = (0..i)
            .map(|j| {
                let pose_b = pose_of(printed, "pose_b", j);
                let c = pair.collide(&pose_a, &pose_b, &CollideOptions::default());
                c.expect("collide").pairs.len()
            })
            .sum::<usize>();
        e.line(
            "batch_collide",
            i,
            &[
                ("colliding", colliding),
                ("contacts", contacts),
                ("offset", num(offset as f64)),
            ],
        );
        e.line("batch_pairs", i, &[("list", pairs_value(&c.pairs))]);
        let f = pair.collide(&pose_a, &pose_b, &first).expect("first");
        let mut values = vec![
            ("colliding", bool_value(f.colliding)),
            ("contacts", num(f.pairs.len() as f64)),
        ];
        if let Some(p) = f.pairs.first() {
            values.push(("pair", pairs_value(&[*p])));
        }
        e.line("first", i, &values);
        for (query, options, option) in [
            ("distance", &exact, None),
            ("distance_rel", &rel, Some(("rel_err", rel.rel_err))),
            (
                "distance_max",
                &max,
                Some(("max_distance", max.max_distance)),
            ),
        ] {
            let d = pair.distance(&pose_a, &pose_b, options).expect("distance");
            // The option as the example printed it, so that a change there shows here.
            let mut values: Vec<_> = option.map(|(k, v)| (k, num(v))).into_iter().collect();
            values.push(("found", bool_value(d.closest.is_some())));
            values.extend(witness(d.distance(), d.closest.as_ref()));
            if query == "distance" {
                e.line("batch_distance", i, &values);
                values.push(("work", work(&d.work)));
            }
            e.line(query, i, &values);
        }
        let t = pair.within(&pose_a, &pose_b, &tolerance).expect("within");
        let mut values = vec![
            ("tolerance", num(tolerance.tolerance)),
            ("closer", bool_value(t.closer())),
        ];
        let d = t.witness.map_or(f64::INFINITY, |w| w.distance);
        values.extend(witness(d, t.witness.as_ref()));
        e.line("within", i, &values);
        e.line("batch_within", i, &values);
        let s = pair
            .span(&pose_a, &pose_b, &SpanOptions::default())
            .expect("span");
        let values = witness(s.span(), Some(&s.farthest));
        e.line("span", i, &values);
        e.line("batch_span", i, &values);
    }
    e.0
}

/// The directory of the library this test run built: cargo compiles the crate's cdylib
/// and staticlib beside the test binaries, in `target/<profile>/deps/` (only `cargo build`
/// also copies them up to `target/<profile>/`, where a copy may be stale during a test).
fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe.parent().expect("target/<profile>/deps").to_path_buf();
    for lib in ["libobbtree_c.a", "libobbtree_c.so"] {
        assert!(
            dir.join(lib).is_file(),
            "{} is missing: cargo builds it with this test (cargo test -p obbtree-c)",
            dir.join(lib).display()
        );
    }
    dir
}

fn run(command: &mut Command) -> String {
    let output = command
        .output()
        .unwrap_or_else(|e| panic!("{command:?}: {e}"));
    assert!(
        output.status.success(),
        "{command:?} failed ({}):\n{}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).expect("UTF-8 output")
}

#[test]
fn the_c_example_answers_as_the_rust_api() {
    let dir = common::scratch("example");
    let tree = common::build_cow(&dir, "cow.obbt", &BuildOptions::default());
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = library_dir();
    let source = crate_dir.join("examples/shipped_asset.c");
    let include = crate_dir.join("include");
    let cc = || {
        let mut cc = Command::new("cc");
        cc.args(["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror", "-I"])
            .arg(&include)
            .arg(&source);
        cc
    };
    // Static: the archive linked in, as the README says.
    let static_exe = dir.join("shipped_asset_static");
    run(cc()
        .arg(lib.join("libobbtree_c.a"))
        .args(["-lm", "-lpthread", "-ldl", "-o"])
        .arg(&static_exe));
    // Dynamic: -lobbtree_c from the library directory, found at run time by its rpath.
    let shared_exe = dir.join("shipped_asset_shared");
    run(cc()
        .arg("-L")
        .arg(&lib)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .args(["-lobbtree_c", "-lm", "-o"])
        .arg(&shared_exe));

    let output = run(Command::new(&static_exe).arg(&tree));
    let shared_output = run(Command::new(&shared_exe).arg(&tree));
    assert_eq!(output, shared_output, "static and dynamic builds differ");

    let printed = parse(&output);
    let expected = expected(&tree, &printed);
    for (key, want) in &expected {
        assert_eq!(printed.get(key), Some(want), "line {key:?} of:\n{output}");
    }
    let extra: Vec<_> = printed
        .keys()
        .filter(|k| !expected.contains_key(k))
        .collect();
    assert!(extra.is_empty(), "lines the test does not check: {extra:?}");

    // The example covers what it claims: collisions and separations among its poses.
    let colliding: Vec<bool> = (0..4)
        .map(|i| printed[&("collide".to_string(), i)]["colliding"] == num(1))
        .collect();
    assert!(
        colliding.contains(&true) && colliding.contains(&false),
        "{colliding:?}"
    );
    let error = output
        .lines()
        .find(|l| l.starts_with("error "))
        .expect("the error line");
    assert!(
        error.starts_with("error 0 OBBTREE_STATUS_POSE: pose: rotation is not orthonormal"),
        "{error}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_header_compiles_as_c99_and_cxx() {
    let include = Path::new(env!("CARGO_MANIFEST_DIR")).join("include");
    let dir = common::scratch("header");
    let c = dir.join("uses_header.c");
    std::fs::write(
        &c,
        "#include \"obbtree.h\"\nint main(void) { ObbtreeTree *t = NULL; \
         return obbtree_open(\"x\", &t) == OBBTREE_STATUS_OK; }\n",
    )
    .expect("source written");
    for (compiler, language, standard) in [("cc", "c", "-std=c99"), ("c++", "c++", "-std=c++11")] {
        run(Command::new(compiler)
            .args([
                "-x",
                language,
                standard,
                "-pedantic",
                "-Wall",
                "-Wextra",
                "-Werror",
            ])
            .args(["-fsyntax-only", "-I"])
            .arg(&include)
            .arg(&c));
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_readme_shows_the_example() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(crate_dir.join("README.md")).expect("README.md");
    let example =
        std::fs::read_to_string(crate_dir.join("examples/shipped_asset.c")).expect("example");
    assert!(
        readme.contains(&format!("```c\n{example}```")),
        "README.md's \"From C\" code block is not examples/shipped_asset.c: copy it there"
    );
}
