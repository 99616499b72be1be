//! The exception classes of `obbtree` and the library's errors mapped onto them.
//!
//! Every message is the library's one-line `Display` (the text the CLI prints after
//! `obbtree: error:`), sometimes prefixed with what the binding adds: the argument and pose
//! index of a bad pose, the path of a file.

use obbtree::build::BuildError;
use obbtree::format::{FormatError, OpenError};
use obbtree::mesh::MeshError;
use obbtree::query::{BatchError, QueryError};
use obbtree::scene::SceneError;
use pyo3::exceptions::{PyException, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

/// Which exception class an error raises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `obbtree.Error`: the base; also trees of different kinds queried together, and a
    /// closed tree.
    Base,
    /// `obbtree.MeshError`: a mesh that cannot be loaded or built.
    Mesh,
    /// `obbtree.FormatError`: a damaged or foreign `.obbt` file.
    Format,
    /// `obbtree.PoseError` (also a `ValueError`): a pose that is not a rigid motion.
    Pose,
    /// `obbtree.SceneError`: a scene file, asset or frame refused.
    Scene,
    /// `obbtree.OptionError` (also a `ValueError`): an option out of range.
    Option,
    /// `obbtree.FileError` (also an `OSError`): a file that cannot be read or written.
    File,
}

/// An error made where the GIL may not be held (inside a batch); raised once back in
/// Python.
#[derive(Clone, Debug)]
pub struct Failure {
    /// The class to raise.
    pub kind: Kind,
    /// The one-line message.
    pub message: String,
}

impl Failure {
    /// A failure of class `kind`.
    pub fn new(kind: Kind, message: impl Into<String>) -> Failure {
        Failure {
            kind,
            message: message.into(),
        }
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> PyErr {
        Python::attach(|py| raise(py, f.kind, f.message))
    }
}

impl From<QueryError> for Failure {
    fn from(e: QueryError) -> Failure {
        let kind = match e {
            QueryError::MismatchedTrees { .. } => Kind::Base,
            QueryError::CorruptTree { .. } | QueryError::Format(_) => Kind::Format,
            QueryError::BadOption { .. } | QueryError::BadInput { .. } => Kind::Option,
            _ => Kind::Base,
        };
        Failure::new(kind, e.to_string())
    }
}

impl From<BatchError> for Failure {
    fn from(e: BatchError) -> Failure {
        match e {
            BatchError::Pair(e) => Failure::from(e),
            // In the names of the batch functions' arguments.
            BatchError::Lengths { a, b } => Failure::new(
                Kind::Pose,
                format!(
                    "poses_a holds {a} poses and poses_b {b}: give batches of one length, or one pose to broadcast"
                ),
            ),
            BatchError::Threads { ref source, .. } => {
                Failure::new(Kind::Base, format!("{e}: {source}"))
            }
            other => Failure::new(Kind::Base, other.to_string()),
        }
    }
}

impl From<OpenError> for Failure {
    fn from(e: OpenError) -> Failure {
        let kind = match e {
            OpenError::Io { .. } => Kind::File,
            _ => Kind::Format,
        };
        Failure::new(kind, e.to_string())
    }
}

impl From<FormatError> for Failure {
    fn from(e: FormatError) -> Failure {
        Failure::new(Kind::Format, e.to_string())
    }
}

impl From<MeshError> for Failure {
    fn from(e: MeshError) -> Failure {
        let kind = match e {
            MeshError::Io { .. } => Kind::File,
            _ => Kind::Mesh,
        };
        Failure::new(kind, e.to_string())
    }
}

impl From<BuildError> for Failure {
    fn from(e: BuildError) -> Failure {
        let kind = match e {
            BuildError::LeafSize(_)
            | BuildError::HullMinFaces(_)
            | BuildError::HullMaxPoints(_)
            | BuildError::Scale(_)
            | BuildError::SphereFit(_)
            | BuildError::Layout(_) => Kind::Option,
            // (CompactRange, like the other coordinate overflows, is the mesh's.)
            _ => Kind::Mesh,
        };
        Failure::new(kind, e.to_string())
    }
}

impl From<SceneError> for Failure {
    fn from(e: SceneError) -> Failure {
        // A scene or frames file that cannot be read is a file error, as for a tree or
        // a mesh; an asset the scene names is the scene's (its cause is the open error).
        let unreadable = std::error::Error::source(&e).is_some_and(|c| c.is::<std::io::Error>());
        let kind = if unreadable { Kind::File } else { Kind::Scene };
        Failure::new(kind, e.to_string())
    }
}

/// The classes, made once when the module is imported.
struct Classes {
    base: Py<PyType>,
    mesh: Py<PyType>,
    format: Py<PyType>,
    pose: Py<PyType>,
    scene: Py<PyType>,
    option: Py<PyType>,
    file: Py<PyType>,
}

static CLASSES: PyOnceLock<Classes> = PyOnceLock::new();

/// A class `name(bases...)` in module `obbtree`, with a docstring.
fn class<'py>(
    py: Python<'py>,
    name: &str,
    bases: Vec<Bound<'py, PyAny>>,
    doc: &str,
) -> PyResult<Py<PyType>> {
    let namespace = PyDict::new(py);
    namespace.set_item("__module__", "obbtree")?;
    namespace.set_item("__doc__", doc)?;
    let bases = PyTuple::new(py, bases)?;
    let made = py
        .get_type::<PyType>()
        .call1((name, bases, namespace))?
        .cast_into::<PyType>()?;
    Ok(made.unbind())
}

fn make(py: Python<'_>) -> PyResult<Classes> {
    let base = class(
        py,
        "Error",
        vec![py.get_type::<PyException>().into_any()],
        "Base class of every error obbtree raises. Its message is the library's one-line \
         message (the line the obbtree CLI prints). Raised as itself for trees of different \
         volume types or precisions queried together, and for a closed tree.",
    )?;
    let b = || base.bind(py).clone().into_any();
    let mesh = class(
        py,
        "MeshError",
        vec![b()],
        "A mesh that cannot be loaded or built: unknown format, malformed file, non-finite \
         coordinates, out-of-range or negative face indices, too large for the format.",
    )?;
    let format = class(
        py,
        "FormatError",
        vec![b()],
        "A .obbt file that is damaged or not a .obbt file: refused by open (header and \
         directory checks) or by Tree.verify (checksums and the whole tree).",
    )?;
    let pose = class(
        py,
        "PoseError",
        vec![b(), py.get_type::<PyValueError>().into_any()],
        "A pose that is not a rigid motion (non-orthonormal, reflected, non-finite, a 4x4 \
         matrix whose last row is not 0 0 0 1) or an array of the wrong shape. The message \
         names the argument and the pose index. Also a ValueError.",
    )?;
    let scene = class(
        py,
        "SceneError",
        vec![b()],
        "A scene file, one of its assets, or a frame that is refused; the message names the \
         file, line and field as the CLI does.",
    )?;
    let option = class(
        py,
        "OptionError",
        vec![b(), py.get_type::<PyValueError>().into_any()],
        "An option out of range (negative error allowance or tolerance, leaf size, scale, \
         thread count...). Also a ValueError.",
    )?;
    let file = class(
        py,
        "FileError",
        vec![b(), py.get_type::<PyOSError>().into_any()],
        "A file that cannot be opened, read or written (missing, a directory, no \
         permission). Also an OSError.",
    )?;
    Ok(Classes {
        base,
        mesh,
        format,
        pose,
        scene,
        option,
        file,
    })
}

fn classes(py: Python<'_>) -> PyResult<&Classes> {
    CLASSES.get_or_try_init(py, || make(py))
}

/// The exception of class `kind` with `message`.
pub fn raise(py: Python<'_>, kind: Kind, message: impl Into<String>) -> PyErr {
    let message = message.into();
    let classes = match classes(py) {
        Ok(c) => c,
        Err(e) => return e,
    };
    let class = match kind {
        Kind::Base => &classes.base,
        Kind::Mesh => &classes.mesh,
        Kind::Format => &classes.format,
        Kind::Pose => &classes.pose,
        Kind::Scene => &classes.scene,
        Kind::Option => &classes.option,
        Kind::File => &classes.file,
    };
    PyErr::from_type(class.bind(py).clone(), (message,))
}

/// Adds the classes to the module.
pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    let c = classes(py)?;
    for (name, class) in [
        ("Error", &c.base),
        ("MeshError", &c.mesh),
        ("FormatError", &c.format),
        ("PoseError", &c.pose),
        ("SceneError", &c.scene),
        ("OptionError", &c.option),
        ("FileError", &c.file),
    ] {
        module.add(name, class.bind(py))?;
    }
    Ok(())
}
