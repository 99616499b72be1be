//! `Tree`: an opened `.obbt` file (memory-mapped) or an in-memory tree; `open` and `build`.

use crate::errors::{Failure, Kind};
use crate::json::to_python;
use numpy::ndarray::ArrayView2;
use numpy::PyArray2;
use obbtree::build::{build as build_tree, rounding_loss, BuildOptions, RoundingLoss, SphereFit};
use obbtree::bv::{BvKind, Layout};
use obbtree::fit::FitMethod;
use obbtree::format::layout::SectionKind;
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use obbtree::real::Precision;
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::{Arc, RwLock};
use zerocopy::FromBytes;

/// A collision tree: an opened `.obbt` file (memory-mapped, opened in constant time) or a
/// tree built in memory. Pass it to `collide`, `distance`, `within` and `span`.
///
/// Safe to share between threads; queries on it run with the GIL released. `close()` (or
/// leaving a `with` block) releases it: any later use raises `obbtree.Error`. Arrays from
/// `vertices`, `faces` and `source_ids` are read-only views of the tree's bytes that keep
/// those bytes alive themselves, so they stay valid after `close()`; the file is unmapped
/// when the tree is closed (or collected) and the last such view is gone.
#[pyclass(module = "obbtree", name = "Tree", frozen)]
pub struct Tree {
    file: RwLock<Option<Arc<ObbtFile>>>,
    /// The file it was opened from or written to; `None` for an in-memory tree.
    path: Option<PathBuf>,
}

/// Owns a reference to a tree's bytes on behalf of NumPy arrays that view them: the arrays'
/// `base` object.
#[pyclass(module = "obbtree._obbtree", name = "TreeBytes", frozen)]
pub struct TreeBytes {
    file: Arc<ObbtFile>,
}

#[pymethods]
impl TreeBytes {
    fn __repr__(&self) -> String {
        format!("<obbtree tree bytes: {} bytes>", self.file.bytes().len())
    }
}

impl Tree {
    pub fn new(file: ObbtFile, path: Option<PathBuf>) -> Tree {
        Tree {
            file: RwLock::new(Some(Arc::new(file))),
            path,
        }
    }

    /// The open file, or `obbtree.Error` when closed.
    pub fn file(&self) -> Result<Arc<ObbtFile>, Failure> {
        let guard = self
            .file
            .read()
            .map_err(|_| Failure::new(Kind::Base, "the tree's lock is poisoned"))?;
        guard
            .clone()
            .ok_or_else(|| Failure::new(Kind::Base, format!("{}: the tree is closed", self.name())))
    }

    /// The tree's name in messages: its path, or `<memory>`.
    pub fn name(&self) -> String {
        self.path
            .as_ref()
            .map_or_else(|| "<memory>".to_owned(), |p| p.display().to_string())
    }
}

/// The bytes of the required section `kind` of `file`.
fn section(file: &ObbtFile, kind: SectionKind) -> Result<&[u8], Failure> {
    let s = file
        .sections()
        .iter()
        .find(|s| s.kind == Some(kind))
        .ok_or_else(|| {
            Failure::new(
                Kind::Format,
                format!("missing required section `{}`", kind.name()),
            )
        })?;
    let start = usize::try_from(s.offset).ok();
    let end = usize::try_from(s.offset.saturating_add(s.length)).ok();
    start
        .zip(end)
        .and_then(|(start, end)| file.bytes().get(start..end))
        .ok_or_else(|| {
            Failure::new(
                Kind::Format,
                format!("section `{}` is out of bounds", kind.name()),
            )
        })
}

/// A read-only (n, 3) NumPy view of the records of section `kind`, whose base object keeps
/// `file` alive.
fn view3<'py, T>(
    py: Python<'py>,
    file: &Arc<ObbtFile>,
    kind: SectionKind,
) -> PyResult<Bound<'py, PyAny>>
where
    T: numpy::Element + FromBytes + zerocopy::Immutable + zerocopy::KnownLayout,
{
    let bytes = section(file, kind)?;
    let records = <[[T; 3]]>::ref_from_bytes(bytes).map_err(|_| {
        Failure::new(
            Kind::Format,
            format!("section `{}` cannot be viewed as records", kind.name()),
        )
    })?;
    let flat: &[T] = records.as_flattened();
    let view = ArrayView2::from_shape((records.len(), 3), flat)
        .map_err(|e| Failure::new(Kind::Format, e.to_string()))?;
    let owner = Bound::new(py, TreeBytes { file: file.clone() })?;
    // SAFETY: the data is the tree's bytes, owned by `owner.file` (a memory map or an
    // aligned heap buffer that never moves or changes while the `ObbtFile` lives). The
    // array holds a reference to `owner` as its base object, so the bytes outlive it; the
    // array is made read-only below and nothing else writes to the bytes.
    let array = unsafe { PyArray2::borrow_from_array(&view, owner.into_any()) };
    array.call_method("setflags", (), Some(&[("write", false)].into_py_dict(py)?))?;
    Ok(array.into_any())
}

use pyo3::types::IntoPyDict;

#[pymethods]
impl Tree {
    /// What the tree holds, from its header alone: a dict with the keys of
    /// `obbtree info --json` (version, triangles, vertices, nodes, leaves, depth,
    /// max_leaf_faces, degenerate_triangles, bv, precision, layout, fit, leaf_size, encoding,
    /// bounds, placement, file_bytes, bytes_per_triangle, sections).
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let file = self.file()?;
        to_python(py, &file.info().to_json())
    }

    /// Checks the whole file (O(n)): checksums of the header and every section, zero
    /// padding, indices in bounds, a well-formed tree, finite values, every volume
    /// containing the triangles below it. Returns None; raises `obbtree.FormatError`
    /// naming the first problem. Runs with the GIL released.
    fn verify(&self, py: Python<'_>) -> PyResult<()> {
        let file = self.file()?;
        let name = self.name();
        py.detach(move || {
            file.verify()
                .map_err(|e| Failure::new(Kind::Format, format!("{name}: verify failed: {e}")))
        })?;
        Ok(())
    }

    /// The stored vertices, (n, 3): a read-only NumPy view of the tree's bytes (no copy).
    /// float64 for trees stored in f64, float32 for f32 trees (the default build). Stored
    /// coordinates are `scale * input + offset` (see `info["placement"]`).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let file = self.file()?;
        match file.precision() {
            Precision::F64 => view3::<f64>(py, &file, SectionKind::Vertices),
            Precision::F32 => view3::<f32>(py, &file, SectionKind::Vertices),
        }
    }

    /// The stored triangles, (m, 3) uint32 vertex indices: a read-only NumPy view of the
    /// tree's bytes (no copy), in the tree's leaf order. Stored triangle `i` is triangle
    /// `source_ids[i]` of the input mesh (the ids every query reports).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let file = self.file()?;
        view3::<u32>(py, &file, SectionKind::Faces)
    }

    /// The input-mesh id of each stored triangle, (m,) uint32: a read-only NumPy view of
    /// the tree's bytes. `faces[np.argsort(source_ids)]` lists the triangles in input order.
    #[getter]
    fn source_ids<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let file = self.file()?;
        let bytes = section(&file, SectionKind::SourceIds)?;
        let ids = <[u32]>::ref_from_bytes(bytes).map_err(|_| {
            Failure::new(
                Kind::Format,
                "section `source_ids` cannot be viewed as records",
            )
        })?;
        let view = numpy::ndarray::ArrayView1::from(ids);
        let owner = Bound::new(py, TreeBytes { file: file.clone() })?;
        // SAFETY: as in `view3`: `owner` keeps the bytes alive and unchanged.
        let array = unsafe { numpy::PyArray1::borrow_from_array(&view, owner.into_any()) };
        array.call_method("setflags", (), Some(&[("write", false)].into_py_dict(py)?))?;
        Ok(array.into_any())
    }

    /// The file the tree was opened from or written to, or None for an in-memory tree.
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.path.clone()
    }

    /// Whether `close()` was called.
    #[getter]
    fn closed(&self) -> bool {
        self.file.read().map(|f| f.is_none()).unwrap_or(true)
    }

    /// Releases the tree (idempotent). Later use raises `obbtree.Error`; arrays taken from
    /// it stay valid (they hold the bytes they view), and queries already running finish.
    fn close(&self) {
        if let Ok(mut guard) = self.file.write() {
            *guard = None;
        }
    }

    fn __enter__(slf: Bound<'_, Self>) -> Bound<'_, Self> {
        slf
    }

    #[pyo3(signature = (*_args))]
    fn __exit__(&self, _args: &Bound<'_, pyo3::types::PyTuple>) -> bool {
        self.close();
        false
    }

    /// Pickles as its path (reopened on unpickling); an in-memory tree pickles as its bytes.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let this = slf.get();
        let file = this.file()?;
        let module = py.import("obbtree._obbtree")?;
        let made = match &this.path {
            Some(path) => (module.getattr("open")?, (path.clone(),)).into_pyobject(py)?,
            None => {
                let bytes = pyo3::types::PyBytes::new(py, file.bytes());
                (module.getattr("_from_bytes")?, (bytes,))
                    .into_pyobject(py)?
                    .into_any()
                    .cast_into()?
            }
        };
        Ok(made.into_any())
    }

    fn __repr__(&self) -> String {
        match self.file() {
            Ok(file) => {
                let info = file.info();
                format!(
                    "<obbtree.Tree {}: {} triangles, {}, {} nodes>",
                    self.name(),
                    info.triangles,
                    file.node_type(),
                    info.nodes
                )
            }
            Err(_) => format!("<obbtree.Tree {} (closed)>", self.name()),
        }
    }
}

/// Opens a .obbt file: memory-maps it and checks its header and section directory, in
/// constant time whatever its size (nothing is parsed or rebuilt). Use `Tree.verify()` for
/// the full O(n) check of a file from elsewhere.
///
/// Raises `obbtree.FormatError` for a damaged or foreign file, `obbtree.FileError` (an
/// OSError) when it cannot be opened.
#[pyfunction]
pub fn open(py: Python<'_>, path: PathBuf) -> PyResult<Tree> {
    let file = py.detach(|| ObbtFile::open(&path).map_err(Failure::from))?;
    Ok(Tree::new(file, Some(path)))
}

/// A tree from the bytes of a .obbt file (copied into an aligned buffer; for unpickling
/// and embedded assets).
#[pyfunction]
pub fn _from_bytes(data: &[u8]) -> PyResult<Tree> {
    let file = ObbtFile::from_aligned(obbtree::format::AlignedBytes::copy_from(data))
        .map_err(|e| Failure::new(Kind::Format, format!("<memory>: {e}")))?;
    Ok(Tree::new(file, None))
}

fn choice<T: Copy>(what: &str, given: &str, options: &[(&str, T)]) -> Result<T, Failure> {
    options
        .iter()
        .find(|(name, _)| *name == given)
        .map(|&(_, v)| v)
        .ok_or_else(|| {
            let names: Vec<&str> = options.iter().map(|(n, _)| *n).collect();
            Failure::new(
                Kind::Option,
                format!("{what} {given:?} is not one of {}", names.join(", ")),
            )
        })
}

/// The build options of `build`'s keyword arguments.
#[allow(clippy::too_many_arguments)]
pub fn build_options(
    bv: &str,
    precision: &str,
    layout: &str,
    fit: &str,
    leaf_size: Option<u32>,
    scale: f64,
    center: bool,
    hull_min_faces: Option<u32>,
    hull_max_points: Option<u32>,
    model_axes: bool,
    split_by_volume: bool,
    sphere_fit: &str,
) -> Result<BuildOptions, Failure> {
    let default = BuildOptions::default();
    let layout = choice(
        "layout",
        layout,
        &[("fast", Layout::Fast), ("compact", Layout::Compact)],
    )?;
    let options = BuildOptions {
        layout,
        bv: choice(
            "bv",
            bv,
            &[
                ("obb", BvKind::Obb),
                ("aabb", BvKind::Aabb),
                ("sphere", BvKind::Sphere),
            ],
        )?,
        precision: choice(
            "precision",
            precision,
            &[("f32", Precision::F32), ("f64", Precision::F64)],
        )?,
        fit: choice(
            "fit",
            fit,
            &[
                ("hull", FitMethod::Hull),
                ("triangles", FitMethod::Triangles),
                ("vertices", FitMethod::Vertices),
            ],
        )?,
        sphere_fit: choice(
            "sphere_fit",
            sphere_fit,
            &[
                ("box-centre", SphereFit::BoxCentre),
                ("minimal", SphereFit::Minimal),
            ],
        )?,
        leaf_size: leaf_size.unwrap_or(layout.default_leaf_size()),
        scale,
        center,
        hull_min_faces: hull_min_faces.unwrap_or(default.hull_min_faces),
        hull_max_points: hull_max_points.unwrap_or(default.hull_max_points),
        model_axes,
        split_by_volume,
    };
    options.validate()?;
    Ok(options)
}

/// Refuses to write `output` when it is the input mesh, a directory, or an existing file
/// that is not a .obbt file (unless `force`): the CLI's rules for `build -o`.
fn check_output(output: &Path, input: Option<&Path>, force: bool) -> Result<(), Failure> {
    let shown = output.display();
    let refuse = |m: String| Err(Failure::new(Kind::File, m));
    if let Some(input) = input {
        let same = match (std::fs::canonicalize(input), std::fs::canonicalize(output)) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        if same {
            return refuse(format!(
                "{shown}: is the input {}; refusing to overwrite it (choose another output)",
                input.display()
            ));
        }
    }
    match std::fs::metadata(output) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => refuse(format!("{shown}: cannot check the output: {e}")),
        Ok(m) if m.is_dir() => refuse(format!("{shown}: is a directory")),
        Ok(_) if force || is_obbt(output) => Ok(()),
        Ok(_) => refuse(format!(
            "{shown}: exists and is not an .obbt file; refusing to replace it (use force=True)"
        )),
    }
}

fn is_obbt(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && head == obbtree::format::layout::SIGNATURE
}

/// The mesh source of `build`: a path, or validated vertex and face arrays.
pub enum MeshSource {
    Path(PathBuf),
    Arrays(Vec<[f64; 3]>, Vec<[u32; 3]>),
}

/// Loads or validates the mesh, builds its tree and writes it (atomically) when `output`
/// is given, all without the GIL.
pub fn build_tree_from(
    py: Python<'_>,
    source: MeshSource,
    output: Option<PathBuf>,
    options: BuildOptions,
    force: bool,
) -> PyResult<Tree> {
    let (made, loss) = py.detach(move || -> Result<(Tree, Option<RoundingLoss>), Failure> {
        let (mesh, input) = match source {
            MeshSource::Path(path) => (TriMesh::load(&path)?, Some(path)),
            MeshSource::Arrays(vertices, faces) => (TriMesh::new(vertices, faces)?, None),
        };
        let label = input
            .as_ref()
            .map_or_else(|| "<memory>".to_owned(), |p| p.display().to_string());
        if let Some(out) = &output {
            check_output(out, input.as_deref(), force)?;
        }
        let file = build_tree(&mesh, &options, None).map_err(|e| {
            let f = Failure::from(e);
            Failure::new(f.kind, format!("{label}: {}", f.message))
        })?;
        let loss = rounding_loss(&mesh, &file);
        match output {
            None => Ok((Tree::new(file, None), loss)),
            Some(out) => {
                let _ = obbtree::format::remove_stale_temporaries(&out);
                file.write_atomic(&out).map_err(|e| {
                    Failure::new(Kind::File, format!("{}: cannot write: {e}", out.display()))
                })?;
                drop(file);
                let opened = ObbtFile::open(&out)?;
                Ok((Tree::new(opened, Some(out)), loss))
            }
        }
    })?;
    if let Some(loss) = loss {
        let message = loss.warning("center=True", "precision=\"f64\"");
        let category = py.get_type::<PyUserWarning>();
        // (Level 2: the line that called `obbtree.build`.)
        PyErr::warn(py, &category, &std::ffi::CString::new(message)?, 2)?;
    }
    Ok(made)
}
