"""Collision, distance and span queries between posed triangle meshes, with the oriented
bounding box trees (OBBTrees) of Gottschalk's dissertation.

Build a tree once (``obbtree.build`` or ``obbtree build`` on the command line) into one
``.obbt`` file; ``obbtree.open`` maps it in constant time wherever queries run. Every query
takes two trees and their poses — one pose, or a whole batch as one NumPy array — and
answers all of them in one call, in parallel, with the GIL released::

    import numpy as np, obbtree

    cow = obbtree.build("cow.obj", "cow.obbt")          # once, offline
    cow = obbtree.open("cow.obbt")                     # memory-mapped, O(1)
    poses = np.tile(np.eye(4), (1000, 1, 1))
    poses[:, 0, 3] = np.linspace(0.0, 3.0, 1000)       # B slides along x
    hit = obbtree.collide(cow, np.eye(4), cow, poses, first_contact=True)
    hit.contacts                                       # (1000,) int64, 0 or 1
    d = obbtree.distance(cow, np.eye(4), cow, poses)   # d.distance, d.point_a, ...

A pose is a (4, 4) rigid matrix, 12 numbers (rotation row-major, then translation) or an
``(R, t)`` pair; a batch is (N, 4, 4) or (N, 12). A world point is ``R @ p + t``.

Functions: ``build``, ``open``, ``collide``, ``distance``, ``within``, ``span``,
``hausdorff``, and ``closest``, ``ray``, ``winding_number`` and ``signed_distance`` (one
model against many points or rays); classes ``Tree``, ``Scene`` and the result
classes; exceptions ``Error`` and its subclasses
``MeshError``, ``FormatError``, ``PoseError``, ``SceneError``, ``OptionError``,
``FileError``.
"""

from __future__ import annotations

import dataclasses
import os
from typing import Any, Optional, Union

import numpy as np

from ._obbtree import (
    CollideResult,
    DistanceResult,
    Error,
    FileError,
    FormatError,
    HausdorffResult,
    MeshError,
    OptionError,
    PoseError,
    Scene,
    SceneError,
    SpanResult,
    Tree,
    WithinResult,
    __version__,
    _build,
    _closest,
    _inside,
    _ray,
    _ray_all,
    collide,
    distance,
    hausdorff,
    open,
    span,
    within,
)

__all__ = [
    "build",
    "open",
    "collide",
    "distance",
    "within",
    "span",
    "hausdorff",
    "closest",
    "ClosestResult",
    "ray",
    "RayResult",
    "RayHits",
    "winding_number",
    "signed_distance",
    "Tree",
    "Scene",
    "CollideResult",
    "DistanceResult",
    "WithinResult",
    "SpanResult",
    "HausdorffResult",
    "Error",
    "MeshError",
    "FormatError",
    "PoseError",
    "SceneError",
    "OptionError",
    "FileError",
    "__version__",
]


def _mesh_arrays(vertices: Any, faces: Any) -> "tuple[np.ndarray, np.ndarray]":
    """Vertices as (n, 3) float64 and faces as (m, 3) int64, or MeshError."""
    try:
        v = np.ascontiguousarray(vertices, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise MeshError(f"<memory>: vertices are not an array of numbers ({e})") from None
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise MeshError(f"<memory>: vertices must be an (n, 3) array, got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3:
        raise MeshError(f"<memory>: faces must be an (m, 3) array of vertex indices, got shape {f.shape}")
    if f.size and f.dtype.kind not in "iu":
        raise MeshError(f"<memory>: faces must be integer vertex indices, got dtype {f.dtype}")
    if f.dtype.kind == "u" and f.size and int(f.max()) > np.iinfo(np.int64).max:
        raise MeshError(f"<memory>: face index {int(f.max())} out of range ({len(v)} vertices)")
    return v, np.ascontiguousarray(f, dtype=np.int64)


def build(
    mesh: Any,
    out: Union[str, "os.PathLike[str]", None] = None,
    *,
    bv: str = "obb",
    precision: str = "f32",
    layout: str = "fast",
    leaf_size: Optional[int] = None,
    scale: float = 1.0,
    center: bool = False,
    fit: str = "hull",
    hull_min_faces: Optional[int] = None,
    hull_max_points: Optional[int] = None,
    model_axes: bool = True,
    split_by_volume: bool = True,
    sphere_fit: str = "box-centre",
    force: bool = False,
) -> Tree:
    """Builds the tree of a mesh; with ``out``, writes it there atomically.

    ``mesh`` is a mesh file (``.obj`` or ``.stl``, binary or ASCII: a ``str`` or
    ``os.PathLike``), a ``(vertices, faces)`` pair of arrays ((n, 3) float, (m, 3) int
    vertex indices), or anything with ``.vertices`` and ``.faces`` (a ``trimesh.Trimesh``).
    Triangle ids in every query result are the positions in ``faces`` (file order for a
    mesh file).

    With ``out`` the tree is written to that path (atomically: readers never see a partial
    file) and the returned ``Tree`` maps it; without, the tree stays in memory. As with
    ``obbtree build -o``, ``out`` is never the input mesh, and an existing file that is not a
    ``.obbt`` file is replaced only with ``force=True``.

    Options (those of ``obbtree build``): ``bv`` "obb", "aabb" or "sphere"; ``precision``
    "f32" or "f64" (stored vertices and volumes; queries compute in f64); ``layout``
    "fast" or "compact" (quantised f32 boxes: about a third of the file size on typical
    meshes, slower queries); ``leaf_size`` 1 to 128 triangles per leaf (default 1, or 4 for the compact
    layout); ``scale`` multiplies every coordinate before storing
    (0.001: millimetres to metres); ``center`` moves the bounding-box centre to the
    origin (both recorded in ``info["placement"]``; queries work in stored units);
    ``fit`` "hull", "triangles" or "vertices"; ``hull_min_faces``, ``hull_max_points``,
    ``model_axes``, ``split_by_volume`` and ``sphere_fit`` ("box-centre" or "minimal") as
    the CLI's flags.

    Runs with the GIL released. Raises ``MeshError`` for a mesh that cannot be loaded or
    built, ``OptionError`` (a ValueError) for an option out of range, ``FileError`` (an
    OSError) for a file that cannot be read or written. Warns (``UserWarning``) when the
    stored precision is coarse for the model: coordinates far from the origin for the
    model's size, rounded by more than 1e-5 of it or collapsing triangles to zero area;
    ``center=True`` (or ``precision="f64"``) keeps the detail.
    """
    options = dict(
        out=None if out is None else os.fspath(out),
        bv=bv,
        precision=precision,
        layout=layout,
        fit=fit,
        leaf_size=leaf_size,
        scale=scale,
        center=center,
        hull_min_faces=hull_min_faces,
        hull_max_points=hull_max_points,
        model_axes=model_axes,
        split_by_volume=split_by_volume,
        sphere_fit=sphere_fit,
        force=force,
    )
    if isinstance(mesh, (str, os.PathLike)):
        return _build(os.fspath(mesh), None, None, **options)
    if isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        vertices, faces = _mesh_arrays(mesh[0], mesh[1])
    elif hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        vertices, faces = _mesh_arrays(mesh.vertices, mesh.faces)
    else:
        raise TypeError(
            "build takes a mesh file path, a (vertices, faces) pair, or an object with "
            f".vertices and .faces (such as a trimesh.Trimesh), not {type(mesh).__name__}"
        )
    return _build(None, vertices, faces, **options)


@dataclasses.dataclass(frozen=True)
class ClosestResult:
    """The answers of ``closest`` for N query points (read-only arrays).

    ``distance`` (N,) float64: from the query point to the model's surface, +inf where
    nothing is within ``max_distance``; ``point`` (N, 3) float64: the closest surface point,
    world frame (NaN without an answer); ``tri`` (N,) int64: its input-mesh triangle (-1);
    ``feature`` (N,) str: where on the triangle it lies, ``"face"``, ``"edge"`` or
    ``"vertex"`` (``""`` without an answer); ``feature_index`` (N,) int8: the edge (from
    corner k to corner k + 1) or corner k, in the input's corner order (-1).
    """

    distance: np.ndarray
    point: np.ndarray
    tri: np.ndarray
    feature: np.ndarray
    feature_index: np.ndarray


_FEATURES = np.array(["face", "edge", "vertex", ""])


def _numbers(name: str, value: Any) -> np.ndarray:
    """``value`` as a float64 array, or ``OptionError`` naming ``name`` when NumPy cannot
    make one (text, ragged rows)."""
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise OptionError(f"{name} must be numbers in an (N, 3) array: {e}") from e


def _point_rows(points: Any) -> np.ndarray:
    """``points`` as a contiguous (N, 3) float64 array; one point (3,) is one row."""
    array = _numbers("points", points)
    if array.shape == (3,):
        array = array.reshape(1, 3)
    if array.ndim != 2 or array.shape[1] != 3:
        raise OptionError(f"points must be an (N, 3) array or one point (3,), got shape {array.shape}")
    return np.ascontiguousarray(array)


def closest(
    tree: Tree,
    pose: Any,
    points: Any,
    max_distance: float = np.inf,
    *,
    threads: Optional[int] = None,
    orthonormalize: bool = False,
) -> ClosestResult:
    """The closest point of a posed model's surface to each query point.

    ``pose`` is one pose of ``tree`` (a (4, 4) matrix, 12 numbers or an ``(R, t)`` pair);
    ``points`` is an (N, 3) array of world points, or one point (3,). Points are answered in
    parallel with the GIL released; those farther than ``max_distance`` (world units, > 0)
    get no answer, sooner. ``threads``: None for every core, or how many. Returns a
    ``ClosestResult``.

    Raises ``OptionError`` (a ValueError) for points of another shape, non-finite points,
    points or model triangles beyond ±1e150 in the model's frame (where squared distances
    would overflow) or a ``max_distance`` not above 0, ``PoseError`` for a pose that is not
    a rigid motion.
    """
    distance, point, tri, feature, index = _closest(
        tree, pose, _point_rows(points), float(max_distance), orthonormalize, threads
    )
    arrays = [distance, point, tri, _FEATURES[feature], index]
    for a in arrays:
        a.flags.writeable = False
    return ClosestResult(*arrays)


@dataclasses.dataclass(frozen=True)
class RayResult:
    """The answers of ``ray`` in ``"closest"`` or ``"any"`` mode for N rays (read-only
    arrays).

    ``hit`` (N,) bool; ``t`` (N,) float64: the ray parameter of the hit, ``origin + t *
    direction`` (the distance for unit directions), +inf on a miss; ``tri`` (N,) int64: the
    input-mesh triangle hit (-1); ``point`` (N, 3) float64: the hit point, world frame
    (NaN); ``barycentric`` (N, 3) float64: its weights on the triangle's corners, in input
    order (NaN); ``normal`` (N, 3) float64: the triangle's unit normal, world frame, from its
    corners' order whichever side the ray came from (NaN).
    """

    hit: np.ndarray
    t: np.ndarray
    tri: np.ndarray
    point: np.ndarray
    barycentric: np.ndarray
    normal: np.ndarray


@dataclasses.dataclass(frozen=True)
class RayHits:
    """The answers of ``ray`` in ``"all"`` mode: the M hits of N rays, ray by ray and by
    increasing ``t`` within a ray (read-only arrays).

    ``count`` (N,) int64: hits per ray (even for a ray from outside a closed model);
    ``ray`` (M,) int64: the ray of each hit; ``t``, ``tri``, ``point``, ``barycentric``,
    ``normal``: as in ``RayResult``, one row per hit. The hits of ray ``i`` are rows
    ``offsets[i]:offsets[i + 1]`` with ``offsets = np.concatenate([[0], np.cumsum(count)])``.
    """

    count: np.ndarray
    ray: np.ndarray
    t: np.ndarray
    tri: np.ndarray
    point: np.ndarray
    barycentric: np.ndarray
    normal: np.ndarray


def ray(
    tree: Tree,
    pose: Any,
    origins: Any,
    directions: Any,
    t_max: float = np.inf,
    mode: str = "closest",
    *,
    threads: Optional[int] = None,
    orthonormalize: bool = False,
) -> Union[RayResult, RayHits]:
    """Where rays meet a posed model: the closest hit, any hit, or all hits of each.

    ``pose`` is one pose of ``tree``; ``origins`` and ``directions`` are (N, 3) arrays of
    world points and vectors, or one (3,) row shared by every ray (a camera's origin). A
    ray's points are ``origin + t * direction`` for ``0 <= t <= t_max``. ``mode`` is
    ``"closest"`` (the hit of smallest t), ``"any"`` (one hit, the first found: line of
    sight) or ``"all"``. Rays are cast in parallel with the GIL released, on ``threads``
    threads (None: every core). Hits are
    watertight: a ray through an edge or corner shared by triangles hits one of them.
    Returns a ``RayResult`` (closest, any) or a ``RayHits`` (all).

    Raises ``OptionError`` (a ValueError) for arrays of other shapes, a non-finite origin,
    a zero or non-finite direction (naming the ray), a ``t_max`` not above 0 or an unknown
    mode; ``PoseError`` for a pose that is not a rigid motion.
    """
    o = _numbers("origins", origins)
    d = _numbers("directions", directions)
    for name, a in (("origins", o), ("directions", d)):
        if not (a.shape == (3,) or (a.ndim == 2 and a.shape[1] == 3)):
            raise OptionError(f"{name} must be an (N, 3) array or one row (3,), got shape {a.shape}")
    n = max(len(a) if a.ndim == 2 else 1 for a in (o, d))
    o, d = (np.broadcast_to(a, (n, 3)) if a.ndim == 1 else a for a in (o, d))
    if len(o) != len(d):
        raise OptionError(f"origins and directions differ in length: {len(o)} and {len(d)}")
    o, d = np.ascontiguousarray(o), np.ascontiguousarray(d)
    if mode == "all":
        index, t, tri, point, bary, normal = _ray_all(
            tree, pose, o, d, float(t_max), orthonormalize, threads
        )
        count = np.bincount(index, minlength=n).astype(np.int64)
        result: Union[RayResult, RayHits] = RayHits(count, index, t, tri, point, bary, normal)
    else:
        result = RayResult(
            *_ray(tree, pose, o, d, float(t_max), mode, orthonormalize, threads)
        )
    # (Not dataclasses.astuple: it copies the arrays.)
    for field in dataclasses.fields(result):
        getattr(result, field.name).flags.writeable = False
    return result


def winding_number(
    tree: Tree,
    pose: Any,
    points: Any,
    *,
    beta: float = 2.0,
    tolerance: Optional[float] = None,
    threads: Optional[int] = None,
    orthonormalize: bool = False,
) -> np.ndarray:
    """The generalised winding number of a posed model at each query point: (N,) float64.

    1 inside a closed outward-facing surface, 0 outside, between for surfaces with holes;
    a point is inside where it is above 0.5, which holds for polygon soups too (holes,
    duplicate and self-intersecting triangles). ``points`` is an (N, 3) array of world
    points or one point (3,); computed in parallel with the GIL released, on ``threads``
    threads (None: every core).

    Far clusters of triangles are summed by their moments (Barill et al. 2018): by default
    those seen from more than ``beta`` times their radius (fast, as libigl's fast winding
    number; the error is not bounded beforehand and is measured small). With
    ``tolerance`` each value is instead proven within ``tolerance`` of the exact sum
    (slower: the proof adds worst cases), and ``tolerance=0`` sums every triangle exactly.

    Raises ``OptionError`` (a ValueError) for points of another shape, non-finite points
    (naming the first), points or model triangles beyond ±1e150 in the model's frame,
    ``beta`` not above 1 or a negative ``tolerance``; ``PoseError`` for a pose that is not a
    rigid motion.
    """
    value = _inside(tree, pose, _point_rows(points), float(beta), _tolerance(tolerance),
                    orthonormalize, threads, False)
    value.flags.writeable = False
    return value


def signed_distance(
    tree: Tree,
    pose: Any,
    points: Any,
    *,
    beta: float = 2.0,
    tolerance: Optional[float] = None,
    threads: Optional[int] = None,
    orthonormalize: bool = False,
) -> np.ndarray:
    """The signed distance of a posed model at each query point: (N,) float64, the
    distance to the closest surface point (as ``closest`` finds it), negative where the
    winding number (as ``winding_number`` computes it with ``beta`` or ``tolerance``) is
    above 0.5.

    Raises as ``winding_number``.
    """
    value = _inside(tree, pose, _point_rows(points), float(beta), _tolerance(tolerance),
                    orthonormalize, threads, True)
    value.flags.writeable = False
    return value


def _tolerance(tolerance: Optional[float]) -> Optional[float]:
    """A tolerance as the native call takes it: ``None``, or a float that is not negative."""
    if tolerance is None:
        return None
    if not tolerance >= 0:
        raise OptionError(f"tolerance must be 0 or more, got {tolerance}")
    return float(tolerance)
