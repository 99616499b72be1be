//! Scene files: TOML, for people to write.
//!
//! ```toml
//! pose_format = "rt"         # optional, for start poses and frames (see PoseFormat)
//! orthonormalize = false     # optional: take the nearest rotation of rounded poses
//! frames = "cell.jsonl"      # optional: the frames to run (relative to this file)
//!
//! [[object]]
//! name = "link2"                 # unique; [A-Za-z0-9_.-]+
//! asset = "assets/link2.obbt"    # a .obbt file, or a mesh built in memory; relative path
//! groups = ["robot"]             # optional
//! pose = [1,0,0, 0,1,0, 0,0,1, 0,0,0.4]   # optional start pose (default identity)
//!
//! [[rule]]
//! a = "robot"                    # object name, group name, or "*"
//! b = "fixtures"
//! effect = "clearance"           # none | contact | contacts | clearance | distance | span
//! clearance = 0.05               # required for clearance
//! # rel_err = 0.01               # optional for distance
//! # max_distance = 0.5           # optional for distance
//! ```

use super::builder::{Item, SceneBuilder};
use super::error::{line_of, SceneError};
use super::rules::Effect;
use super::simulate::Scene;
use crate::build::{build, BuildOptions};
use crate::format::layout::SIGNATURE;
use crate::format::ObbtFile;
use crate::mesh::TriMesh;
use crate::query::{Pose, PoseFormat, Repairs};
use serde::Deserialize;
use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::Spanned;

/// The largest scene file read (bytes).
pub const MAX_SCENE_BYTES: u64 = 64 << 20;
/// The most objects a scene may have: the scheduler looks at every pair once, at load.
pub const MAX_OBJECTS: usize = 10_000;
/// The most rules a scene may have.
pub const MAX_RULES: usize = 10_000;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneToml {
    #[serde(default)]
    pose_format: Option<Spanned<String>>,
    #[serde(default)]
    orthonormalize: bool,
    #[serde(default)]
    frames: Option<Spanned<String>>,
    #[serde(default)]
    object: Vec<Spanned<ObjectToml>>,
    #[serde(default)]
    rule: Vec<Spanned<RuleToml>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectToml {
    name: Spanned<String>,
    asset: Spanned<String>,
    #[serde(default)]
    groups: Option<Spanned<Vec<String>>>,
    #[serde(default)]
    pose: Option<Spanned<Vec<f64>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RuleToml {
    a: Spanned<String>,
    b: Spanned<String>,
    effect: Spanned<String>,
    #[serde(default)]
    clearance: Option<Spanned<f64>>,
    #[serde(default)]
    rel_err: Option<Spanned<f64>>,
    #[serde(default)]
    max_distance: Option<Spanned<f64>>,
}

/// A scene read from a file, with what the file says about its frames.
#[derive(Debug)]
pub struct LoadedScene {
    /// The scene at its start poses.
    pub scene: Scene,
    /// The frames file the scene names (resolved against the scene file's directory).
    pub frames: Option<PathBuf>,
    /// How poses are written, in the file and its frames.
    pub pose_format: PoseFormat,
    /// Whether rounded rotations are repaired to the nearest rotation.
    pub orthonormalize: bool,
    /// The start poses repaired (with `orthonormalize`), the largest named as
    /// `FILE:LINE: object K, field pose`: for a note, as a frames reader's
    /// [`FrameReader::repairs`](super::FrameReader::repairs).
    pub repairs: Repairs,
}

/// Reads a scene file: objects, their assets (each file opened or built once, shared by
/// every object that names it), and rules. Every error names the file, the line and the
/// field.
///
/// # Errors
///
/// A [`SceneError`] with `origin` the file (or, for an asset, the asset's path), the line
/// and the field when known, and the cause as its `source` when there is one:
///
/// - the scene file cannot be read, is not valid TOML, or has an unknown or ill-typed
///   field;
/// - a pose is not valid in the file's pose format ([`PoseFormat::parse`]);
/// - an asset cannot be opened ([`OpenError`](crate::format::OpenError)), loaded
///   ([`MeshError`](crate::mesh::MeshError)) or built ([`BuildError`](crate::build::BuildError));
/// - the objects and rules fail the checks of [`SceneBuilder::build`](super::SceneBuilder::build).
///
/// # Examples
///
/// ```
/// use obbtree::scene::{load, FrameReader};
/// use std::io::BufReader;
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let loaded = load(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/cell.toml").as_ref())?;
/// let frames = loaded.frames.as_ref().expect("cell.toml names its frames");
/// let mut scene = loaded.scene;
/// let input = BufReader::new(std::fs::File::open(frames)?);
/// let mut reader = FrameReader::new(input, "cell.jsonl", &scene, loaded.pose_format, loaded.orthonormalize);
/// for frame in reader.by_ref().take(10) {
///     scene.step(&frame?)?;
/// }
/// assert_eq!(scene.summary().frames, 10);
/// # Ok(())
/// # }
/// ```
pub fn load(path: &Path) -> Result<LoadedScene, SceneError> {
    let source = path.display().to_string();
    let fail = |m: String| SceneError::new(&source, m);
    let unreadable = |e: std::io::Error| fail(format!("cannot read: {e}")).caused_by(e);
    let file = std::fs::File::open(path).map_err(unreadable)?;
    let mut text = String::new();
    file.take(MAX_SCENE_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(unreadable)?;
    if text.len() as u64 > MAX_SCENE_BYTES {
        return Err(fail(format!("larger than {MAX_SCENE_BYTES} bytes")));
    }
    let base = path.parent().unwrap_or(Path::new("."));
    parse(&text, &source, base)
}

/// Reads the text of a scene file named `source`, resolving paths against `base`.
fn parse(text: &str, source: &str, base: &Path) -> Result<LoadedScene, SceneError> {
    let at = |span: std::ops::Range<usize>| line_of(text, span.start);
    let error = |span: std::ops::Range<usize>, field: String, m: String| {
        SceneError::new(source, m).at_line(at(span)).in_field(field)
    };
    let spec: SceneToml = toml::from_str(text).map_err(|e| {
        let located = SceneError::new(source, e.message().trim());
        let located = match e.span() {
            Some(span) => located.at_line(at(span)),
            None => located,
        };
        located.caused_by(e)
    })?;
    if spec.object.len() > MAX_OBJECTS || spec.rule.len() > MAX_RULES {
        let m = format!("at most {MAX_OBJECTS} objects and {MAX_RULES} rules");
        return Err(SceneError::new(source, m));
    }
    let pose_format = match &spec.pose_format {
        None => PoseFormat::default(),
        Some(f) => PoseFormat::from_name(f.get_ref()).ok_or_else(|| {
            let names: Vec<&str> = PoseFormat::ALL.iter().map(|f| f.name()).collect();
            let m = format!("{:?} is not one of {}", f.get_ref(), names.join(", "));
            error(f.span(), "pose_format".into(), m)
        })?,
    };
    let assets = open_assets(&spec, base, &error)?;
    let mut builder = SceneBuilder::new();
    let mut repairs = Repairs::default();
    for (k, object) in spec.object.iter().enumerate() {
        let o = object.get_ref();
        let field = |name: &str| format!("object {}, field {name}", k + 1);
        let pose = match &o.pose {
            None => Pose::identity(),
            Some(p) => {
                let parsed = pose_format
                    .parse(p.get_ref(), spec.orthonormalize)
                    .map_err(|e| error(p.span(), field("pose"), e.to_string()).caused_by(e))?;
                let line = at(p.span());
                repairs.note(&parsed, || format!("{source}:{line}: {}", field("pose")))
            }
        };
        let groups: Vec<&str> = o
            .groups
            .as_ref()
            .map(|g| g.get_ref().iter().map(String::as_str).collect())
            .unwrap_or_default();
        let asset = assets
            .get(k)
            .cloned()
            .ok_or_else(|| error(o.asset.span(), field("asset"), "not opened".into()))?;
        builder.object(o.name.get_ref(), asset, &groups, pose);
    }
    for (k, rule) in spec.rule.iter().enumerate() {
        let r = rule.get_ref();
        let effect = effect_of(r, &|span, name: &str, m| {
            error(span, format!("rule {}, field {name}", k + 1), m)
        })?;
        builder.rule(r.a.get_ref(), r.b.get_ref(), effect);
    }
    let scene = builder.checked().map_err(|p| {
        let line = match p.item {
            Item::Object(k) => spec.object.get(k).map(|o| {
                let o = o.get_ref();
                let span = match p.field {
                    "asset" => o.asset.span(),
                    "groups" => o.groups.as_ref().map_or(o.name.span(), |g| g.span()),
                    _ => o.name.span(),
                };
                at(span)
            }),
            Item::Rule(k) => spec.rule.get(k).map(|r| {
                let r = r.get_ref();
                let span = match p.field {
                    "a" => r.a.span(),
                    "b" => r.b.span(),
                    "clearance" => r.clearance.as_ref().map_or(r.effect.span(), |v| v.span()),
                    "rel_err" => r.rel_err.as_ref().map_or(r.effect.span(), |v| v.span()),
                    "max_distance" => r
                        .max_distance
                        .as_ref()
                        .map_or(r.effect.span(), |v| v.span()),
                    _ => r.effect.span(),
                };
                at(span)
            }),
        };
        p.located(source, line)
    })?;
    let frames = spec.frames.as_ref().map(|f| base.join(f.get_ref()));
    Ok(LoadedScene {
        scene,
        frames,
        pose_format,
        orthonormalize: spec.orthonormalize,
        repairs,
    })
}

/// The effect a rule asks for, refusing missing and misplaced parameters.
fn effect_of(
    r: &RuleToml,
    error: &dyn Fn(std::ops::Range<usize>, &str, String) -> SceneError,
) -> Result<Effect, SceneError> {
    let name = r.effect.get_ref().as_str();
    let value = |v: &Option<Spanned<f64>>| v.as_ref().map(|v| *v.get_ref());
    // Parameters that only some effects take.
    let misplaced = [
        ("clearance", r.clearance.as_ref(), name == "clearance"),
        ("rel_err", r.rel_err.as_ref(), name == "distance"),
        ("max_distance", r.max_distance.as_ref(), name == "distance"),
    ];
    for (field, given, allowed) in misplaced {
        if let (Some(v), false) = (given, allowed) {
            let m = format!("{field} does not apply to effect {name:?}");
            return Err(error(v.span(), field, m));
        }
    }
    Ok(match name {
        "none" => Effect::None,
        "contact" => Effect::Contact,
        "contacts" => Effect::Contacts,
        "clearance" => Effect::Clearance {
            clearance: value(&r.clearance).ok_or_else(|| {
                let m = "effect \"clearance\" needs `clearance = <distance>`".into();
                error(r.effect.span(), "clearance", m)
            })?,
        },
        "distance" => Effect::Distance {
            rel_err: value(&r.rel_err).unwrap_or(0.0),
            max_distance: value(&r.max_distance),
        },
        "span" => Effect::Span,
        other => {
            let m = format!(
                "unknown effect {other:?} (none, contact, contacts, clearance, distance, span)"
            );
            return Err(error(r.effect.span(), "effect", m));
        }
    })
}

/// The tree of every object, each distinct file opened or built once. Meshes are built with
/// the default options, in the volume type, precision and layout of the scene's `.obbt`
/// assets (fast OBB f32 when it has none), so that they can be queried together.
fn open_assets(
    spec: &SceneToml,
    base: &Path,
    error: &dyn Fn(std::ops::Range<usize>, String, String) -> SceneError,
) -> Result<Vec<Arc<ObbtFile>>, SceneError> {
    let path_of = |o: &ObjectToml| base.join(o.asset.get_ref());
    let is_tree = |path: &Path| {
        let mut head = [0u8; 8];
        let signed = std::fs::File::open(path)
            .and_then(|mut f| f.read_exact(&mut head))
            .is_ok()
            && head == SIGNATURE;
        signed
            || path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("obbt"))
    };
    let mut opened: HashMap<PathBuf, Arc<ObbtFile>> = HashMap::new();
    let mut options = BuildOptions::default();
    let mut kind_set = false;
    // Trees first: they decide how meshes are built.
    for pass_trees in [true, false] {
        for (k, object) in spec.object.iter().enumerate() {
            let o = object.get_ref();
            let path = path_of(o);
            if is_tree(&path) != pass_trees {
                continue;
            }
            let field = format!("object {}, field asset", k + 1);
            let fail = |m: String| error(o.asset.span(), field.clone(), m);
            let identity = std::fs::canonicalize(&path)
                .map_err(|e| fail(format!("{}: {e}", path.display())).caused_by(e))?;
            if opened.contains_key(&identity) {
                continue;
            }
            let file = if pass_trees {
                let file = ObbtFile::open(&path).map_err(|e| fail(e.to_string()).caused_by(e))?;
                if !kind_set {
                    options.bv = file.bv_kind();
                    options.precision = file.precision();
                    options.layout = file.layout();
                    options.leaf_size = file.layout().default_leaf_size();
                    kind_set = true;
                }
                file
            } else {
                let mesh = TriMesh::load(&path).map_err(|e| fail(e.to_string()).caused_by(e))?;
                build(&mesh, &options, None)
                    .map_err(|e| fail(format!("{}: {e}", path.display())).caused_by(e))?
            };
            opened.insert(identity, Arc::new(file));
        }
    }
    spec.object
        .iter()
        .enumerate()
        .map(|(k, object)| {
            let o = object.get_ref();
            let path = path_of(o);
            std::fs::canonicalize(&path)
                .ok()
                .and_then(|identity| opened.get(&identity).cloned())
                .ok_or_else(|| {
                    let m = format!("{}: not opened", path.display());
                    error(o.asset.span(), format!("object {}, field asset", k + 1), m)
                })
        })
        .collect()
}
