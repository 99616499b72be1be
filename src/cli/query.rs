//! `obbtree collide | distance | span | hausdorff`: queries between two posed models.

use super::build::{build_with_progress, load_mesh, TreeArgs};
use super::files::is_obbt;
use super::poses::PoseArgs;
use super::print::{self, out};
use super::{number, Failure};
use clap::{Args, ValueEnum};
use obbtree::build::BuildOptions;
use obbtree::experiment::median_time;
use obbtree::format::ObbtFile;
use obbtree::query::triangle::IntersectionKind;
use obbtree::query::{
    BatchOptions, BoxTest, CollideOptions, DescentRule, DistanceOptions, HausdorffDirection,
    HausdorffOptions, PairQuery, Pose, PoseBatch, SpanOptions, ToleranceOptions, Witness, Work,
};
use serde_json::{json, Value};
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

/// The two models and their poses, shared by every query command.
#[derive(Args, Debug)]
pub struct QueryInputs {
    /// Model A: a .obbt file, or a mesh (.obj, .stl) built in memory first.
    pub a: PathBuf,
    /// Model B: a .obbt file, or a mesh built in memory first.
    pub b: PathBuf,
    #[command(flatten)]
    pub poses: PoseArgs,
    /// Print JSON (one object; a batch prints JSON lines unless --csv).
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print CSV: a header, then one row per pose with the answer, the work (D, I, S, K as
    /// in the dissertation, bv_tests = D + I, tri_tests = S + K; for all-pairs collision
    /// between trees of one triangle per leaf also the least number of volume tests that
    /// can find its contacts, §2.6.3, empty without contacts) and the time.
    #[arg(long)]
    pub csv: bool,
    /// Run each query K times and report the median time (the answer is the same each
    /// time).
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: u32,
    /// Threads that run a batch's poses [default: one per core]. Times measured while
    /// other threads work are inflated (1.5x seen with sphere trees on two cores): take
    /// timings with --threads 1.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..1025))]
    pub threads: Option<u32>,
    /// How mesh inputs are built in memory. They do not apply to .obbt inputs (given with
    /// two .obbt inputs they are refused), and a mesh paired with a .obbt file is built
    /// with that file's volume and precision.
    #[command(
        flatten,
        next_help_heading = "Mesh inputs (built in memory; not for .obbt inputs)"
    )]
    pub tree: TreeArgs,
}

/// The descent rule of the queries that descend both trees (not `hausdorff`, which
/// measures A's surface against B's as a whole).
#[derive(Args, Debug)]
pub struct DescentArgs {
    /// Which tree to descend when both can be: larger diameter, volume or area, or always
    /// A or B.
    #[arg(long, value_enum, default_value_t = RuleArg::Diameter)]
    pub rule: RuleArg,
}

/// `--rule` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum RuleArg {
    /// Descend the node with the larger diameter.
    Diameter,
    /// Descend the node with the larger volume.
    Volume,
    /// Descend the node with the larger surface area.
    Area,
    /// Always descend A first.
    A,
    /// Always descend B first.
    B,
}

impl RuleArg {
    fn rule(self) -> DescentRule {
        match self {
            RuleArg::Diameter => DescentRule::LargestDiameter,
            RuleArg::Volume => DescentRule::LargestVolume,
            RuleArg::Area => DescentRule::LargestArea,
            RuleArg::A => DescentRule::AlwaysA,
            RuleArg::B => DescentRule::AlwaysB,
        }
    }
}

/// `--box-test` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum BoxTestArg {
    /// The 15 separating axes (exact up to the guard).
    Sat,
    /// B's box re-wrapped in a box aligned with A's and tested on A's axes: the AABB test
    /// of the dissertation's experiments (looser and cheaper).
    Rewrapped,
}

/// Find the triangle pairs where two posed models touch.
///
/// Models are surfaces: they collide when some triangle of A shares a point with some
/// triangle of B (touching counts); a model wholly inside another does not collide.
///
/// Example: obbtree collide a.obbt b.obbt --pose-b 1,0,0,0,1,0,0,0,1,0.5,0,0 --pairs
#[derive(Args, Debug)]
pub struct CollideArgs {
    /// Stop at the first contact found (yes/no with one witness pair).
    #[arg(long)]
    pub first: bool,
    /// List the contacting pairs (input-mesh triangle ids; not with --csv).
    #[arg(long, conflicts_with = "csv")]
    pub pairs: bool,
    /// Also compute where the models meet: the length of the intersection curve, the area
    /// coplanar triangles share and the box of every contact point (CSV columns
    /// curve_length, overlap_area); with --json also each pair's segment or shared
    /// polygon (world frame) and how far its points lie from the two triangles.
    #[arg(long)]
    pub geometry: bool,
    /// How box pairs are tested (for experiments; the answer is the same, the work not).
    #[arg(long, value_enum, default_value_t = BoxTestArg::Sat)]
    pub box_test: BoxTestArg,
    #[command(flatten)]
    pub descent: DescentArgs,
    #[command(flatten)]
    pub inputs: QueryInputs,
}

/// Compute the separation distance between two posed models, with the closest points.
///
/// Exact by default. With --rel-err / --abs-err the answer d satisfies
/// d* <= d <= max(d* (1 + rel), d* + abs) for the true distance d*. With --tolerance T it
/// only answers whether the models come closer than T, stopping as soon as it knows.
///
/// Example: obbtree distance a.obbt b.obbt --pose-b 1,0,0,0,1,0,0,0,1,2,0,0 --json
#[derive(Args, Debug)]
pub struct DistanceArgs {
    /// Relative error allowed (>= 0).
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "E",
        allow_negative_numbers = true
    )]
    pub rel_err: f64,
    /// Absolute error allowed, world units (>= 0).
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "E",
        allow_negative_numbers = true
    )]
    pub abs_err: f64,
    /// Only decide whether the distance is below T.
    #[arg(long, value_name = "T", allow_negative_numbers = true, conflicts_with_all = ["rel_err", "abs_err"])]
    pub tolerance: Option<f64>,
    /// Only look for a distance below D (world units, >= 0): volume pairs at least D apart
    /// are never opened, and models at least D apart print "beyond D" (JSON: "distance":
    /// null, "beyond": D).
    #[arg(
        long,
        value_name = "D",
        allow_negative_numbers = true,
        conflicts_with = "tolerance"
    )]
    pub max_distance: Option<f64>,
    #[command(flatten)]
    pub descent: DescentArgs,
    #[command(flatten)]
    pub inputs: QueryInputs,
}

/// Compute the span: the largest distance between a point of A and a point of B.
///
/// Example: obbtree span a.obbt b.obbt --json
#[derive(Args, Debug)]
pub struct SpanArgs {
    #[command(flatten)]
    pub descent: DescentArgs,
    #[command(flatten)]
    pub inputs: QueryInputs,
}

/// Compute the Hausdorff distance: how far a point of A's surface can be from B's (with
/// --symmetric, the larger of that and the reverse), and where.
///
/// Prints the distance, the witness point and its closest point on the other model (world
/// frame) with their triangles, and the proven upper bound: the true distance lies between
/// the two. Exact to f64 rounding unless --rel-err or --abs-err allow more.
///
/// Example: obbtree hausdorff scan.obj part.obbt --symmetric --json
///
/// Example: obbtree hausdorff simplified.obbt original.obbt --rel-err 0.001
#[derive(Args, Debug)]
pub struct HausdorffArgs {
    /// Relative error allowed: the answer h and the true h* satisfy h <= h* <= h (1 + E).
    #[arg(
        long,
        value_name = "E",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub rel_err: f64,
    /// Absolute error allowed (world units), as --rel-err (the larger of the two applies).
    #[arg(
        long,
        value_name = "E",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub abs_err: f64,
    /// Also measure from B to A and answer the larger: the symmetric Hausdorff distance.
    #[arg(long)]
    pub symmetric: bool,
    // Last: its mesh flags' heading would also take the flags after it.
    #[command(flatten)]
    pub inputs: QueryInputs,
}

/// Whether an input is to be read as a tree: it starts with the `.obbt` signature, or it
/// is named `*.obbt` (so a damaged or empty one gets the reader's error, such as
/// "truncated", not the mesh loader's "unknown mesh format").
pub(super) fn is_tree_input(path: &Path) -> bool {
    is_obbt(path)
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obbt"))
}

/// Opens a .obbt file, or loads and builds a mesh with `options`.
pub(super) fn open_input(path: &Path, options: &BuildOptions) -> Result<ObbtFile, Failure> {
    if is_tree_input(path) {
        return Ok(ObbtFile::open(path)?);
    }
    let mesh = load_mesh(path)?;
    build_with_progress(&mesh, options, &path.display().to_string(), false)
}

/// The one model of a single-model query (`closest`, `ray`): a .obbt file, refusing mesh
/// build flags, or a mesh built with them (checked before the mesh is read).
pub(super) fn open_model(path: &Path, tree: &TreeArgs) -> Result<ObbtFile, Failure> {
    if is_tree_input(path) {
        if let Some(flag) = tree.given().first() {
            return Err(Failure::msg(format!(
                "{flag} applies to mesh models only, and {} is a .obbt file",
                path.display()
            )));
        }
    }
    let options = tree.options();
    options.validate()?;
    open_input(path, &options)
}

fn open_pair(inputs: &QueryInputs) -> Result<(ObbtFile, ObbtFile), Failure> {
    let tree = &inputs.tree;
    let mut options = tree.options();
    let trees: Vec<&PathBuf> = [&inputs.a, &inputs.b]
        .into_iter()
        .filter(|p| is_tree_input(p))
        .collect();
    if let ([_, _], Some(flag)) = (trees.as_slice(), tree.given().first()) {
        return Err(Failure::msg(format!(
            "{flag} applies to mesh inputs only, and A and B are both .obbt files"
        )));
    }
    // A mesh paired with a tree file is built to match it, so the pair can be queried.
    if let Some(path) = trees.first() {
        let info = ObbtFile::open(path)?.info();
        let conflict = |flag: &str, given: String, stored: &str| {
            Failure::msg(format!(
                "{flag} {given}: {} stores {stored}, and a mesh paired with it is built to match",
                path.display()
            ))
        };
        if options.bv != info.bv && tree.bv.is_some() {
            return Err(conflict("--bv", options.bv.name().into(), info.bv.name()));
        }
        if options.precision != info.precision && tree.precision.is_some() {
            let given = options.precision.name().into();
            return Err(conflict("--precision", given, info.precision.name()));
        }
        if options.layout != info.layout && tree.layout.is_some() {
            let given = options.layout.name().into();
            return Err(conflict("--layout", given, info.layout.name()));
        }
        options.bv = info.bv;
        options.precision = info.precision;
        if options.layout != info.layout {
            options.layout = info.layout;
            if tree.leaf_size.is_none() {
                options.leaf_size = info.layout.default_leaf_size();
            }
        }
    }
    Ok((
        open_input(&inputs.a, &options)?,
        open_input(&inputs.b, &options)?,
    ))
}

fn work_json(s: &Work) -> Value {
    json!({
        "bv_disjoint": s.bv_disjoint,
        "bv_overlap": s.bv_overlap,
        "tri_separated": s.tri_separated,
        "tri_contact": s.tri_contact,
        "nodes_visited": s.nodes_visited,
        "bv_tests": s.bv_tests(),
        "tri_tests": s.tri_tests(),
    })
}

fn work_text(s: &Work) -> String {
    format!(
        "D={} I={} S={} K={} nodes visited {}",
        s.bv_disjoint, s.bv_overlap, s.tri_separated, s.tri_contact, s.nodes_visited
    )
}

fn point(p: &nalgebra::Vector3<f64>) -> Value {
    json!([p.x, p.y, p.z])
}

/// The JSON of a distance or span answer: its distance under `key`, its points (world
/// frame) and triangles, the work and the query time.
fn witness_json(key: &str, w: &Witness, work: &Work, seconds: f64) -> Value {
    let mut out = json!({
        "point_a": point(&w.point_a),
        "point_b": point(&w.point_b),
        "tri_a": w.tri_a,
        "tri_b": w.tri_b,
        "work": work_json(work),
        "seconds": seconds,
    });
    insert(&mut out, key, json!(w.distance));
    out
}

/// Adds `key` to a JSON object (every caller's `value` is a `json!({...})` object).
fn insert(value: &mut Value, key: &str, item: Value) {
    if let Some(object) = value.as_object_mut() {
        object.insert(key.to_owned(), item);
    }
}

/// One query under one pose pair: its JSON object and its human-readable text.
type Answer = (Value, String);

/// The CSV columns of a command: JSON pointers into its answers (the header is each
/// pointer's last part). Every command's rows also start with the pose and end with the
/// work and the time.
fn csv_columns(answer: &[&'static str]) -> Vec<&'static str> {
    let mut columns = vec!["/pose"];
    columns.extend_from_slice(answer);
    columns.extend_from_slice(&[
        "/work/bv_disjoint",
        "/work/bv_overlap",
        "/work/tri_separated",
        "/work/tri_contact",
        "/work/bv_tests",
        "/work/tri_tests",
        "/work/nodes_visited",
        "/seconds",
    ]);
    columns
}

/// One CSV field: numbers and booleans as JSON prints them, null as empty.
fn csv_field(value: Option<&Value>) -> String {
    match value {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(text)) => text.clone(),
        Some(other) => other.to_string(),
    }
}

/// Runs `query` once, or over the batch in parallel, and prints the answers as text, JSON
/// or CSV (`columns`, see [`csv_columns`]).
fn run_query<F>(
    inputs: &QueryInputs,
    (a, b): (&ObbtFile, &ObbtFile),
    columns: &[&str],
    query: F,
) -> Result<(), Failure>
where
    F: Fn(&Pose, &Pose, &mut PairQuery<'_>) -> Result<Answer, Failure> + Sync,
{
    let batch = inputs.poses.batch()?;
    if inputs.csv {
        let header: Vec<&str> = columns
            .iter()
            .map(|c| c.rsplit('/').next().unwrap_or(c))
            .collect();
        out!("{}", header.join(","))?;
    }
    let print = |index: usize, mut value: Value| -> Result<(), Failure> {
        insert(&mut value, "pose", json!(index));
        if inputs.csv {
            let row: Vec<String> = columns
                .iter()
                .map(|c| csv_field(value.pointer(c)))
                .collect();
            out!("{}", row.join(","))
        } else {
            out!("{value}")
        }
    };
    let Some(batch) = batch else {
        let (pose_a, pose_b) = inputs.poses.single()?;
        let (value, text) = query(&pose_a, &pose_b, &mut PairQuery::new(a, b)?)?;
        return if inputs.csv {
            print(0, value)
        } else if inputs.json {
            out!("{value}")
        } else {
            out!("{text}")
        };
    };
    let (poses_a, poses_b): (Vec<Pose>, Vec<Pose>) = batch.into_iter().unzip();
    let options = BatchOptions {
        threads: inputs
            .threads
            .and_then(|n| NonZeroUsize::new(usize::try_from(n).ok()?)),
    };
    let answers = obbtree::query::batch(
        a,
        b,
        PoseBatch::new(&poses_a, &poses_b)?,
        &options,
        |pair, pa, pb| query(pa, pb, pair).map(|(value, _)| value),
    )?;
    for (index, answer) in answers.into_iter().enumerate() {
        if print::closed() {
            break;
        }
        print(index, answer?)?;
    }
    Ok(())
}

pub fn collide(args: &CollideArgs) -> Result<(), Failure> {
    let (a, b) = open_pair(&args.inputs)?;
    let options = CollideOptions {
        first_contact: args.first,
        rule: args.descent.rule.rule(),
        box_test: match args.box_test {
            BoxTestArg::Sat => BoxTest::SeparatingAxes,
            BoxTestArg::Rewrapped => BoxTest::Rewrapped,
        },
        geometry: args.geometry,
        ..CollideOptions::default()
    };
    let columns = csv_columns(&[
        "/colliding",
        "/contacts",
        "/bv_test_lower_bound",
        "/curve_length",
        "/overlap_area",
    ]);
    let repeat = args.inputs.repeat;
    run_query(&args.inputs, (&a, &b), &columns, |pa, pb, pair| {
        let (r, seconds) = median_time(repeat, || pair.collide(pa, pb, &options))?;
        // (A first-contact query finds one contact, not all: no bound applies.)
        let bound = obbtree::experiment::lower_bound(&a, &b, r.pairs.len()).filter(|_| !args.first);
        let mut value = json!({
            "colliding": r.colliding,
            "contacts": r.pairs.len(),
            "bv_test_lower_bound": bound,
            "work": work_json(&r.work),
            "seconds": seconds,
        });
        if args.pairs {
            let pairs = r.pairs.iter().map(|&(x, y)| [x, y]).collect::<Vec<_>>();
            insert(&mut value, "pairs", json!(pairs));
        }
        if args.geometry {
            insert(&mut value, "curve_length", json!(r.curve_length()));
            insert(&mut value, "overlap_area", json!(r.overlap_area()));
            insert(&mut value, "contact_bounds", json!(r.contact_bounds()));
            let contacts: Vec<Value> = r
                .contacts
                .iter()
                .map(|c| {
                    let points: Vec<[f64; 3]> =
                        c.intersection.points().iter().map(|&p| p.into()).collect();
                    json!({
                        "tri_a": c.tri_a,
                        "tri_b": c.tri_b,
                        "kind": match c.intersection.kind {
                            IntersectionKind::Segment => "segment",
                            IntersectionKind::Polygon => "polygon",
                        },
                        "points": points,
                        "residual": c.intersection.residual,
                    })
                })
                .collect();
            insert(&mut value, "geometry", json!(contacts));
        }
        let mut text = format!(
            "colliding: {}, {} contact{}{} ({}) in {:.6} s",
            if r.colliding { "yes" } else { "no" },
            r.pairs.len(),
            if r.pairs.len() == 1 { "" } else { "s" },
            if args.first {
                " (stopped at the first)"
            } else {
                ""
            },
            work_text(&r.work),
            seconds
        );
        if args.geometry {
            text.push_str(&format!(
                "\nintersection curve {}, coplanar overlap area {}",
                number(r.curve_length()),
                number(r.overlap_area())
            ));
        }
        if args.pairs {
            for (x, y) in &r.pairs {
                text.push_str(&format!("\n{x} {y}"));
            }
        }
        Ok((value, text))
    })
}

pub fn distance(args: &DistanceArgs) -> Result<(), Failure> {
    let (a, b) = open_pair(&args.inputs)?;
    let rule = args.descent.rule.rule();
    let options = DistanceOptions {
        rel_err: args.rel_err,
        abs_err: args.abs_err,
        max_distance: args.max_distance.unwrap_or(f64::INFINITY),
        rule,
        ..DistanceOptions::default()
    };
    let columns = csv_columns(if args.tolerance.is_some() {
        &[
            "/closer_than_tolerance",
            "/tolerance",
            "/distance",
            "/tri_a",
            "/tri_b",
        ]
    } else {
        &["/distance", "/tri_a", "/tri_b"]
    });
    let repeat = args.inputs.repeat;
    run_query(&args.inputs, (&a, &b), &columns, |pa, pb, pair| {
        if let Some(t) = args.tolerance {
            let tolerance = ToleranceOptions { tolerance: t, rule };
            let (r, seconds) = median_time(repeat, || pair.within(pa, pb, &tolerance))?;
            let w = r.witness.as_ref();
            let value = json!({
                "closer_than_tolerance": r.closer(),
                "tolerance": t,
                "distance": w.map(|w| w.distance),
                "point_a": w.map(|w| point(&w.point_a)),
                "point_b": w.map(|w| point(&w.point_b)),
                "tri_a": w.map(|w| w.tri_a),
                "tri_b": w.map(|w| w.tri_b),
                "work": work_json(&r.work),
                "seconds": seconds,
            });
            let text = match w {
                Some(w) => format!(
                    "closer than {t}: yes (triangles {} and {} at {}) ({}) in {seconds:.6} s",
                    w.tri_a,
                    w.tri_b,
                    number(w.distance),
                    work_text(&r.work)
                ),
                None => format!(
                    "closer than {t}: no ({}) in {seconds:.6} s",
                    work_text(&r.work)
                ),
            };
            return Ok((value, text));
        }
        let (r, seconds) = median_time(repeat, || pair.distance(pa, pb, &options))?;
        // Without a maximum distance every query finds a closest pair.
        let Some(w) = r.closest else {
            let beyond = options.max_distance;
            let value = json!({"distance": null, "beyond": beyond, "point_a": null,
                "point_b": null, "tri_a": null, "tri_b": null,
                "work": work_json(&r.work), "seconds": seconds});
            let work = work_text(&r.work);
            return Ok((
                value,
                format!("distance: beyond {beyond} ({work}) in {seconds:.6} s"),
            ));
        };
        let value = witness_json("distance", &w, &r.work, seconds);
        let text = format!(
            "distance: {} between triangle {} of A at {:?} and triangle {} of B at {:?} ({}) in {seconds:.6} s",
            number(w.distance),
            w.tri_a,
            w.point_a.as_slice(),
            w.tri_b,
            w.point_b.as_slice(),
            work_text(&r.work)
        );
        Ok((value, text))
    })
}

pub fn hausdorff(args: &HausdorffArgs) -> Result<(), Failure> {
    let (a, b) = open_pair(&args.inputs)?;
    let options = HausdorffOptions {
        rel_err: args.rel_err,
        abs_err: args.abs_err,
        symmetric: args.symmetric,
        warm_start: None,
    };
    let columns = csv_columns(&[
        "/hausdorff",
        "/upper_bound",
        "/direction",
        "/tri_a",
        "/tri_b",
    ]);
    let repeat = args.inputs.repeat;
    run_query(&args.inputs, (&a, &b), &columns, |pa, pb, _| {
        let (h, seconds) = median_time(repeat, || {
            obbtree::query::hausdorff(&a, pa, &b, pb, &options)
        })?;
        let (direction, witness) = match h.direction {
            HausdorffDirection::AToB => ("a_to_b", "on A"),
            HausdorffDirection::BToA => ("b_to_a", "on B"),
        };
        let value = json!({
            "hausdorff": h.distance,
            "upper_bound": h.upper_bound,
            "direction": direction,
            "point_a": h.point_a,
            "point_b": h.point_b,
            "tri_a": h.tri_a,
            "tri_b": h.tri_b,
            "work": work_json(&h.work),
            "seconds": seconds,
        });
        let text = format!(
            "hausdorff: {} (at most {}) from {:?} on A (triangle {}) to {:?} on B (triangle {}), the witness {witness} ({}) in {seconds:.6} s",
            number(h.distance),
            number(h.upper_bound),
            h.point_a,
            h.tri_a,
            h.point_b,
            h.tri_b,
            work_text(&h.work)
        );
        Ok((value, text))
    })
}

pub fn span(args: &SpanArgs) -> Result<(), Failure> {
    let (a, b) = open_pair(&args.inputs)?;
    let options = SpanOptions {
        rule: args.descent.rule.rule(),
    };
    let columns = csv_columns(&["/span", "/tri_a", "/tri_b"]);
    let repeat = args.inputs.repeat;
    run_query(&args.inputs, (&a, &b), &columns, |pa, pb, pair| {
        let (r, seconds) = median_time(repeat, || pair.span(pa, pb, &options))?;
        let w = &r.farthest;
        let value = witness_json("span", w, &r.work, seconds);
        let text = format!(
            "span: {} between {:?} on A and {:?} on B ({}) in {seconds:.6} s",
            number(w.distance),
            w.point_a.as_slice(),
            w.point_b.as_slice(),
            work_text(&r.work)
        );
        Ok((value, text))
    })
}
