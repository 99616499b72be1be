//! `Scene`: many models moving over frames, each pair answering what its rules ask for.

use crate::errors::{Failure, Kind};
use crate::json::to_python;
use crate::poses::single_pose;
use obbtree::query::PoseFormat;
use obbtree::scene::{load, Frame, FrameReader, LoadedScene};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::io::BufReader;
use std::path::PathBuf;
use std::sync::Mutex;

/// A scene loaded from a scene file (TOML): objects (each a .obbt tree or a mesh, and a
/// start pose), rules giving each pair of objects an effect (contact, contacts, clearance,
/// distance, span), and optionally a frames file. The same scheduler as `obbtree scene`:
/// broad phase, reuse of unchanged pairs, the cheapest query per pair, in parallel.
///
/// `Scene.load(path)` reads it; `step({name: pose})` moves objects and answers every pair
/// (a dict like one JSON line of `obbtree scene --json`); `run()` steps through its frames
/// file; `summary` totals the frames stepped so far.
#[pyclass(module = "obbtree", name = "Scene", frozen)]
pub struct Scene {
    state: Mutex<State>,
    /// The scene file.
    path: PathBuf,
}

struct State {
    scene: obbtree::scene::Scene,
    frames: Option<PathBuf>,
    format: PoseFormat,
    orthonormalize: bool,
}

impl Scene {
    fn with<T>(&self, f: impl FnOnce(&mut State) -> Result<T, Failure>) -> Result<T, Failure> {
        let mut guard = self
            .state
            .lock()
            .map_err(|_| Failure::new(Kind::Base, "the scene's lock is poisoned"))?;
        f(&mut guard)
    }
}

#[pymethods]
impl Scene {
    /// Reads a scene file: objects, their assets (each opened or built once), rules, and
    /// the frames file it names. naive=True runs the reference instead of the scheduler
    /// (every pair's full exact query every frame). Raises `obbtree.SceneError` naming the
    /// file, line and field of a problem, `obbtree.FileError` when the file cannot be read.
    #[staticmethod]
    #[pyo3(signature = (path, naive=false))]
    fn load(py: Python<'_>, path: PathBuf, naive: bool) -> PyResult<Scene> {
        let loaded = py.detach(|| load(&path).map_err(Failure::from))?;
        let LoadedScene {
            mut scene,
            frames,
            pose_format,
            orthonormalize,
            ..
        } = loaded;
        scene.set_naive(naive);
        Ok(Scene {
            state: Mutex::new(State {
                scene,
                frames,
                format: pose_format,
                orthonormalize,
            }),
            path,
        })
    }

    /// Moves the objects named in `poses` ({name: pose}; a pose is a (4, 4) matrix, 12
    /// numbers R then t, or an (R, t) pair; objects not named keep their poses) and answers
    /// every pair with an effect. Returns the frame's report as a dict:
    /// {"frame": k, "pairs": [{"a", "b", "effect", ...answer}], "events": [{"a", "b",
    /// "event"}]}, the JSON line `obbtree scene --json` prints. Rotations are repaired
    /// when the scene file says `orthonormalize = true`.
    #[pyo3(signature = (poses=None))]
    fn step<'py>(
        &self,
        py: Python<'py>,
        poses: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let repair = self.with(|s| Ok(s.orthonormalize))?;
        let mut frame = Frame::new();
        if let Some(poses) = poses {
            for (key, value) in poses.iter() {
                let name: String = key.extract().map_err(|_| {
                    Failure::new(
                        Kind::Scene,
                        format!("step: object names are strings, got {key}"),
                    )
                })?;
                let id = self
                    .with(|s| Ok(s.scene.object_id(&name)))?
                    .ok_or_else(|| {
                        Failure::new(
                            Kind::Scene,
                            format!("step: poses.{name}: no object named {name:?}"),
                        )
                    })?;
                let pose = single_pose(&format!("poses[{name:?}]"), &value, repair)?;
                frame.set(id, pose);
            }
        }
        let report = py.detach(|| {
            self.with(|s| {
                s.scene.step(&frame)?;
                let report = s.scene.report().to_json(s.scene.names());
                Ok(report)
            })
        })?;
        to_python(py, &report)
    }

    /// Steps through a frames file (JSON Lines, `{"poses": {name: [numbers]}}` per line,
    /// in the scene's pose format) — `frames`, or the one the scene file names — and
    /// returns the list of frame reports (as `step`). Without any frames file, steps one
    /// frame at the start poses, as `obbtree scene` does.
    #[pyo3(signature = (frames=None))]
    fn run<'py>(&self, py: Python<'py>, frames: Option<PathBuf>) -> PyResult<Bound<'py, PyAny>> {
        let reports = py.detach(|| {
            self.with(|s| {
                let path = frames.or_else(|| s.frames.clone());
                let Some(path) = path else {
                    s.scene.step(&Frame::new())?;
                    return Ok(vec![s.scene.report().to_json(s.scene.names())]);
                };
                let name = path.display().to_string();
                let file = std::fs::File::open(&path)
                    .map_err(|e| Failure::new(Kind::File, format!("{name}: {e}")))?;
                let mut reader = FrameReader::new(
                    BufReader::new(file),
                    &name,
                    &s.scene,
                    s.format,
                    s.orthonormalize,
                );
                let mut reports = Vec::new();
                while let Some(frame) = reader.next_frame() {
                    let frame = frame?;
                    s.scene.step(&frame)?;
                    reports.push(s.scene.report().to_json(s.scene.names()));
                }
                Ok(reports)
            })
        })?;
        let list = PyList::empty(py);
        for r in &reports {
            list.append(to_python(py, r)?)?;
        }
        Ok(list.into_any())
    }

    /// The totals of the frames stepped so far, as the `summary` object of
    /// `obbtree scene --json` (frames, objects, pairs_with_effect, culled, reused, narrow
    /// work by effect, early_exits, warm_starts, box and triangle tests, seconds,
    /// frames_per_second).
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let json = self.with(|s| {
            let mode = if s.scene.is_naive() { "naive" } else { "fast" };
            Ok(s.scene.summary().to_json(mode))
        })?;
        let inner = json.get("summary").cloned().unwrap_or(json);
        to_python(py, &inner)
    }

    /// The objects' names, in scene-file order.
    #[getter]
    fn names(&self) -> PyResult<Vec<String>> {
        Ok(self.with(|s| Ok(s.scene.names().to_vec()))?)
    }

    /// The frames file the scene file names (resolved against its directory), or None.
    #[getter]
    fn frames(&self) -> PyResult<Option<PathBuf>> {
        Ok(self.with(|s| Ok(s.frames.clone()))?)
    }

    /// The scene file.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    fn __repr__(&self) -> String {
        let objects = self.with(|s| Ok(s.scene.names().len())).unwrap_or(0);
        format!("<obbtree.Scene {}: {objects} objects>", self.path.display())
    }
}
