"""Type stubs of the native module obbtree._obbtree (re-exported by ``obbtree``)."""

import os
import pathlib
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, "os.PathLike[str]"]
#: One pose — a (4, 4) rigid matrix, 12 numbers (R row-major, then t), or an (R, t) pair —
#: or a batch: (N, 4, 4), (N, 12), or (R (N, 3, 3), t (N, 3)).
Poses = Union[npt.ArrayLike, Tuple[npt.ArrayLike, npt.ArrayLike]]

class Error(Exception):
    """Base class of every error obbtree raises (the library's one-line message)."""

class MeshError(Error):
    """A mesh that cannot be loaded or built."""

class FormatError(Error):
    """A damaged or foreign .obbt file (open or Tree.verify)."""

class PoseError(Error, ValueError):
    """A pose that is not a rigid motion, or of the wrong shape; names argument and index."""

class SceneError(Error):
    """A scene file, asset or frame refused (file, line and field)."""

class OptionError(Error, ValueError):
    """An option out of range."""

class FileError(Error, OSError):
    """A file that cannot be opened, read or written."""

class Tree:
    """An opened .obbt file (memory-mapped) or an in-memory tree."""

    @property
    def info(self) -> Dict[str, Any]:
        """The keys of ``obbtree info --json``."""
    def verify(self) -> None:
        """The full O(n) check; raises FormatError naming the first problem."""
    @property
    def vertices(self) -> Union[npt.NDArray[np.float32], npt.NDArray[np.float64]]:
        """(n, 3) read-only view of the stored vertices: float32 (f32 trees) or float64."""
    @property
    def faces(self) -> npt.NDArray[np.uint32]:
        """(m, 3) read-only view of the stored triangles (leaf order)."""
    @property
    def source_ids(self) -> npt.NDArray[np.uint32]:
        """(m,) read-only view: the input-mesh id of each stored triangle."""
    @property
    def path(self) -> Optional[pathlib.Path]:
        """The file, or None for an in-memory tree."""
    @property
    def closed(self) -> bool:
        """Whether close() was called."""
    def close(self) -> None:
        """Releases the tree; later use raises Error (views taken stay valid)."""
    def __enter__(self) -> "Tree": ...
    def __exit__(self, *args: object) -> bool: ...

class CollideResult:
    """The answers of collide for N pose pairs."""

    @property
    def contacts(self) -> npt.NDArray[np.int64]:
        """(N,) contacting triangle pairs per pose (first_contact: 0 or 1)."""
    @property
    def colliding(self) -> npt.NDArray[np.bool_]:
        """(N,) whether the models touch."""
    @property
    def pairs(self) -> Optional[List[npt.NDArray[np.int64]]]:
        """N (k, 2) arrays of input-mesh triangle ids; None with pairs=False."""
    @property
    def geometry(self) -> Optional[List[List[npt.NDArray[np.float64]]]]:
        """With geometry=True: per pose, one (m, 3) array per pair (segment ends or shared polygon)."""
    @property
    def curve_length(self) -> Optional[npt.NDArray[np.float64]]:
        """With geometry=True: (N,) length of the intersection curve."""
    @property
    def overlap_area(self) -> Optional[npt.NDArray[np.float64]]:
        """With geometry=True: (N,) area shared by coplanar triangles."""
    @property
    def work(self) -> Dict[str, npt.NDArray[np.int64]]:
        """(N,) arrays: bv_disjoint, bv_overlap, tri_separated, tri_contact, nodes_visited, bv_tests, tri_tests."""
    def __len__(self) -> int: ...

class _Witnesses:
    @property
    def point_a(self) -> npt.NDArray[np.float64]:
        """(N, 3) point on A, world frame (NaN where none)."""
    @property
    def point_b(self) -> npt.NDArray[np.float64]:
        """(N, 3) point on B, world frame (NaN where none)."""
    @property
    def tri_a(self) -> npt.NDArray[np.int64]:
        """(N,) input-mesh triangle of A (-1 where none)."""
    @property
    def tri_b(self) -> npt.NDArray[np.int64]:
        """(N,) input-mesh triangle of B (-1 where none)."""
    @property
    def work(self) -> Dict[str, npt.NDArray[np.int64]]:
        """The work per pose, as CollideResult.work."""
    def __len__(self) -> int: ...

class DistanceResult(_Witnesses):
    """The answers of distance for N pose pairs."""

    @property
    def distance(self) -> npt.NDArray[np.float64]:
        """(N,) separation distance; +inf where at least max_distance apart."""

class WithinResult(_Witnesses):
    """The answers of within for N pose pairs."""

    @property
    def closer(self) -> npt.NDArray[np.bool_]:
        """(N,) whether the models come closer than the tolerance."""
    @property
    def distance(self) -> npt.NDArray[np.float64]:
        """(N,) the witness pair's distance; NaN where not closer."""

class SpanResult(_Witnesses):
    """The answers of span for N pose pairs."""

    @property
    def span(self) -> npt.NDArray[np.float64]:
        """(N,) the largest distance between a point of A and a point of B."""

class HausdorffResult(_Witnesses):
    """The answers of hausdorff for N pose pairs."""

    @property
    def distance(self) -> npt.NDArray[np.float64]:
        """(N,) the Hausdorff distance found: the witness's distance to the other model."""
    @property
    def upper_bound(self) -> npt.NDArray[np.float64]:
        """(N,) a proven bound the true distance does not exceed."""
    @property
    def direction(self) -> npt.NDArray[np.str_]:
        """(N,) "a_to_b" (the witness is point_a) or "b_to_a" (it is point_b)."""

class Scene:
    """A scene file's objects and rules, stepped frame by frame."""

    @staticmethod
    def load(path: _Path, naive: bool = False) -> "Scene":
        """Reads a scene file (TOML); raises SceneError, or FileError if it cannot be read."""
    def step(self, poses: Optional[Dict[str, Poses]] = None) -> Dict[str, Any]:
        """Moves the named objects and answers every pair: {"frame", "pairs", "events"}."""
    def run(self, frames: Optional[_Path] = None) -> List[Dict[str, Any]]:
        """Steps through a frames file (JSON Lines); the reports of every frame."""
    @property
    def summary(self) -> Dict[str, Any]:
        """The totals so far: the summary object of ``obbtree scene --json``."""
    @property
    def names(self) -> List[str]:
        """The objects' names, in scene-file order."""
    @property
    def frames(self) -> Optional[pathlib.Path]:
        """The frames file the scene file names, or None."""
    @property
    def path(self) -> pathlib.Path:
        """The scene file."""

def open(path: _Path) -> Tree:
    """Memory-maps a .obbt file, checking its header in O(1)."""

def collide(
    a: Tree,
    poses_a: Poses,
    b: Tree,
    poses_b: Poses,
    *,
    first_contact: bool = False,
    pairs: bool = True,
    geometry: bool = False,
    threads: Optional[int] = None,
    orthonormalize: bool = False,
    rule: str = "diameter",
) -> CollideResult:
    """Contacting triangle pairs for each pose pair of a batch."""

def distance(
    a: Tree,
    poses_a: Poses,
    b: Tree,
    poses_b: Poses,
    *,
    rel_err: float = 0.0,
    abs_err: float = 0.0,
    max_distance: Optional[float] = None,
    threads: Optional[int] = None,
    orthonormalize: bool = False,
    rule: str = "diameter",
) -> DistanceResult:
    """Separation distance and closest points for each pose pair of a batch."""

def within(
    a: Tree,
    poses_a: Poses,
    b: Tree,
    poses_b: Poses,
    tolerance: float,
    *,
    threads: Optional[int] = None,
    orthonormalize: bool = False,
    rule: str = "diameter",
) -> WithinResult:
    """Whether the models come closer than the tolerance, for each pose pair."""

def span(
    a: Tree,
    poses_a: Poses,
    b: Tree,
    poses_b: Poses,
    *,
    threads: Optional[int] = None,
    orthonormalize: bool = False,
    rule: str = "diameter",
) -> SpanResult:
    """The span (largest distance between the models) for each pose pair."""

def hausdorff(
    a: Tree,
    poses_a: Poses,
    b: Tree,
    poses_b: Poses,
    *,
    rel_err: float = 0.0,
    abs_err: float = 0.0,
    symmetric: bool = False,
    threads: Optional[int] = None,
    orthonormalize: bool = False,
) -> HausdorffResult:
    """The Hausdorff distance from A to B (or the symmetric one) for each pose pair."""

def _build(
    mesh_path: Optional[str],
    vertices: Optional[npt.NDArray[np.float64]],
    faces: Optional[npt.NDArray[np.int64]],
    out: Optional[str],
    bv: str,
    precision: str,
    layout: str,
    fit: str,
    leaf_size: Optional[int],
    scale: float,
    center: bool,
    hull_min_faces: Optional[int],
    hull_max_points: Optional[int],
    model_axes: bool,
    split_by_volume: bool,
    sphere_fit: str,
    force: bool,
) -> Tree: ...
def _from_bytes(data: bytes) -> Tree: ...
def _closest(
    tree: Tree,
    pose: Poses,
    points: npt.NDArray[np.float64],
    max_distance: float,
    orthonormalize: bool,
    threads: Optional[int],
) -> Tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.int64],
    npt.NDArray[np.int8],
    npt.NDArray[np.int8],
]: ...
def _ray(
    tree: Tree,
    pose: Poses,
    origins: npt.NDArray[np.float64],
    directions: npt.NDArray[np.float64],
    t_max: float,
    mode: str,
    orthonormalize: bool,
    threads: Optional[int],
) -> Tuple[
    npt.NDArray[np.bool_],
    npt.NDArray[np.float64],
    npt.NDArray[np.int64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
]: ...
def _ray_all(
    tree: Tree,
    pose: Poses,
    origins: npt.NDArray[np.float64],
    directions: npt.NDArray[np.float64],
    t_max: float,
    orthonormalize: bool,
    threads: Optional[int],
) -> Tuple[
    npt.NDArray[np.int64],
    npt.NDArray[np.float64],
    npt.NDArray[np.int64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
]: ...
def _inside(
    tree: Tree,
    pose: Poses,
    points: npt.NDArray[np.float64],
    beta: float,
    tolerance: Optional[float],
    orthonormalize: bool,
    threads: Optional[int],
    signed: bool,
) -> npt.NDArray[np.float64]: ...
def _time_rust_loop(
    a: Tree, poses_a: Poses, b: Tree, poses_b: Poses, query: str, repeat: int
) -> float: ...
