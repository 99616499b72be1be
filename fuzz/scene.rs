//! The scene fuzz targets: the scheduler against its naive reference, and the two parsers
//! of what users write (scene files and frame streams).
//!
//! Shared by `fuzz_targets/scene_*.rs` and by the stable test `tests/it/fuzz_corpus.rs`.
//!
//! - [`scene_differential`]: a scene of 2 to 8 objects (meshes from the input and small
//!   generated solids, in one tree type), 1 to 6 rules of every effect, and up to 16
//!   frames, each moving some objects to poses on a grid (so that touching, coincident and
//!   barely separated pairs are common). The fast path must report every frame as
//!   `Scene::set_naive` does (`FrameReport::disagreement`), with no more narrow queries.
//! - [`scene_file`]: the input is a scene file, next to a tree and a mesh it may name. It
//!   loads, or is refused with one line.
//! - [`frame_stream`]: the first byte picks a pose format and repair; the rest is a frame
//!   stream for a scene of three objects. Each line is a frame, stepped on the fast and the
//!   naive scene alike, or refused with one line naming the line.

// Each target uses one entry point.
#![allow(dead_code)]
// The panics and `expect`s are the assertions (a scene refusing assets it built is a bug in
// the library), and the indexing is into constant arrays, modulo their length.
#![allow(clippy::panic, clippy::expect_used, clippy::indexing_slicing)]

#[path = "bytes.rs"]
mod bytes;
use bytes::Bytes;

use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::generate::{cuboid, lat_long_sphere};
use obbtree::query::{Pose, PoseFormat};
use obbtree::scene::{load, Effect, Frame, FrameReader, Scene, SceneBuilder, SceneError};
use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

/// The fast scheduler against the naive reference on a scene read from `data`.
pub fn scene_differential(data: &[u8]) {
    let mut bytes = Bytes::new(data);
    let options = bytes.options();
    let Some(builder) = scene_from(&mut bytes, &options) else {
        return;
    };
    let mut scene = builder.clone().build().expect("the builder built it once");
    let mut naive = builder.build().expect("the builder built it once");
    naive.set_naive(true);
    let objects = scene.objects().len();
    for _ in 0..1 + bytes.byte() % 16 {
        let (low, high) = (bytes.byte(), bytes.byte());
        let moved = u16::from_le_bytes([low, high]);
        let mut frame = Frame::new();
        for k in (0..objects).filter(|k| moved >> k & 1 == 1) {
            frame.set(k, bytes.pose());
        }
        compare(&mut scene, &mut naive, &frame);
    }
    let (fast, reference) = (scene.summary(), naive.summary());
    assert!(
        fast.narrow.total().queries <= reference.narrow.total().queries,
        "the fast path ran {} narrow queries, the naive one {}",
        fast.narrow.total().queries,
        reference.narrow.total().queries
    );
}

/// Objects, their groups and start poses, and rules, from the input; `None` when the
/// builder refuses the rules (a refusal must be one line).
fn scene_from(bytes: &mut Bytes, options: &BuildOptions) -> Option<SceneBuilder> {
    let generated = [
        cuboid([0.5, 0.25, 1.0], [0.0; 3]).expect("a cuboid"),
        lat_long_sphere(0.75, 4, 6).expect("a sphere"),
    ];
    let mut assets = Vec::new();
    for mesh in [bytes.mesh(), bytes.mesh()]
        .into_iter()
        .flatten()
        .chain(generated)
    {
        // Meshes of only degenerate triangles are refused by the builder.
        if let Ok(tree) = build(&mesh, options, None) {
            assets.push(Arc::new(tree));
        }
    }
    let mut builder = SceneBuilder::new();
    let count = 2 + usize::from(bytes.byte() % 7);
    let names: Vec<String> = (0..count).map(|k| format!("o{k}")).collect();
    let groups = ["g0", "g1", "g2"];
    for name in &names {
        let asset = assets[usize::from(bytes.byte()) % assets.len()].clone();
        let group = groups[usize::from(bytes.byte()) % groups.len()];
        builder.object(name, asset, &[group], bytes.pose());
    }
    let side = |bytes: &mut Bytes| match bytes.byte() % 4 {
        0 => "*".to_owned(),
        1 => groups[usize::from(bytes.byte()) % groups.len()].to_owned(),
        _ => names[usize::from(bytes.byte()) % names.len()].clone(),
    };
    for _ in 0..1 + bytes.byte() % 6 {
        let (a, b) = (side(bytes), side(bytes));
        let effect = effect(bytes);
        builder.rule(&a, &b, effect);
    }
    match builder.clone().build() {
        Ok(_) => Some(builder),
        Err(e) => {
            assert_one_line(&e);
            None
        }
    }
}

/// Any effect, with parameters on coarse grids (clearances and limits in sixteenths).
fn effect(bytes: &mut Bytes) -> Effect {
    match bytes.byte() % 6 {
        0 => Effect::None,
        1 => Effect::Contact,
        2 => Effect::Contacts,
        3 => Effect::Clearance {
            clearance: f64::from(1 + bytes.byte() % 64) / 16.0,
        },
        4 => {
            let rel_err = [0.0, 0.01, 0.1, 0.3][usize::from(bytes.byte() % 4)];
            let limit = bytes.byte();
            Effect::Distance {
                rel_err,
                max_distance: (limit % 2 == 1).then(|| f64::from(limit / 2) / 16.0),
            }
        }
        _ => Effect::Span,
    }
}

/// Steps both scenes by `frame` and panics where the fast one departs from the naive one.
fn compare(fast: &mut Scene, naive: &mut Scene, frame: &Frame) {
    let got = fast.step(frame).expect("a built scene steps").clone();
    let want = naive.step(frame).expect("a built scene steps");
    if let Some(d) = got.disagreement(want, |a, b| fast.effect(a, b)) {
        panic!("fast and naive scenes disagree: {d}");
    }
}

/// A refusal is one line with something after its origin.
fn assert_one_line(e: &SceneError) {
    let text = e.to_string();
    assert!(!text.contains('\n'), "an error of several lines: {text:?}");
    assert!(
        !e.message.trim().is_empty(),
        "an error without a message: {text:?}"
    );
}

/// The directory of `part.obbt` (a cuboid's tree) and `mesh.obj` (a sphere), which the
/// seed scene files name. Shared by every process (each writes the same files, atomically),
/// so that fuzzing and tests leave one small directory behind, not one per run.
fn scene_dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join("obbtree-fuzz-scene");
        std::fs::create_dir_all(&dir).expect("a scratch directory");
        let part = cuboid([0.5, 0.25, 1.0], [0.0; 3]).expect("a cuboid");
        let tree = build(&part, &BuildOptions::default(), None).expect("a tree");
        tree.write_atomic(dir.join("part.obbt"))
            .expect("the tree written");
        let sphere = lat_long_sphere(0.75, 4, 6).expect("a sphere");
        let mut obj = String::new();
        for v in sphere.vertices() {
            obj += &format!("v {} {} {}\n", v[0], v[1], v[2]);
        }
        for f in sphere.faces() {
            obj += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
        }
        let scratch = dir.join(format!("mesh.obj.{}", std::process::id()));
        std::fs::write(&scratch, obj).expect("the mesh written");
        std::fs::rename(&scratch, dir.join("mesh.obj")).expect("the mesh written");
        dir
    })
}

/// A scene file from arbitrary bytes: loaded and stepped, or refused with one line.
pub fn scene_file(data: &[u8]) {
    // One file per process, removed after the load: parallel jobs never share it.
    let path = scene_dir().join(format!("scene-{}.toml", std::process::id()));
    std::fs::write(&path, data).expect("the scene file written");
    let loaded = load(&path);
    let again = loaded
        .is_ok()
        .then(|| load(&path).expect("the same file loads twice"));
    std::fs::remove_file(&path).expect("the scene file removed");
    match loaded {
        Ok(loaded) => {
            let mut fast = loaded.scene;
            let mut naive = again.expect("loaded twice").scene;
            naive.set_naive(true);
            let mut frame = Frame::new();
            for k in 0..fast.objects().len() {
                frame.set(k, Pose::translation(0.125 * k as f64, 0.0, 0.0));
            }
            compare(&mut fast, &mut naive, &Frame::new());
            compare(&mut fast, &mut naive, &frame);
        }
        Err(e) => assert_one_line(&e),
    }
}

/// The scene the frame-stream target moves: objects `a`, `b`, `c` with every pair asked for
/// contacts, a distance and a clearance.
fn frame_scene() -> Scene {
    static ASSETS: OnceLock<[Arc<ObbtFile>; 2]> = OnceLock::new();
    let [part, ball] = ASSETS.get_or_init(|| {
        let tree = |mesh| Arc::new(build(&mesh, &BuildOptions::default(), None).expect("a tree"));
        [
            tree(cuboid([0.5, 0.25, 1.0], [0.0; 3]).expect("a cuboid")),
            tree(lat_long_sphere(0.75, 4, 6).expect("a sphere")),
        ]
    });
    let mut builder = SceneBuilder::new();
    builder.object("a", part.clone(), &["parts"], Pose::identity());
    builder.object(
        "b",
        part.clone(),
        &["parts"],
        Pose::translation(2.0, 0.0, 0.0),
    );
    builder.object("c", ball.clone(), &[], Pose::translation(0.0, 2.0, 0.0));
    builder.rule("parts", "parts", Effect::Contacts);
    builder.rule(
        "a",
        "c",
        Effect::Distance {
            rel_err: 0.0,
            max_distance: Some(1.0),
        },
    );
    builder.rule("b", "c", Effect::Clearance { clearance: 0.25 });
    builder.build().expect("the frame scene builds")
}

/// A frame stream from arbitrary bytes (after a byte choosing the pose format and repair).
pub fn frame_stream(data: &[u8]) {
    let Some((&choice, stream)) = data.split_first() else {
        return;
    };
    let format = PoseFormat::ALL[usize::from(choice) % PoseFormat::ALL.len()];
    let repair = choice & 0x80 != 0;
    let mut fast = frame_scene();
    let mut naive = frame_scene();
    naive.set_naive(true);
    let reader = FrameReader::new(stream, "frames.jsonl", &fast, format, repair);
    for (line, frame) in reader.enumerate().take(64) {
        match frame {
            Ok(frame) => compare(&mut fast, &mut naive, &frame),
            Err(e) => {
                assert_one_line(&e);
                assert_eq!(e.line, Some(line + 1), "{e}");
            }
        }
    }
}
