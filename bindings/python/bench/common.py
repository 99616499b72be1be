"""What the peer benchmarks share: the meshes, a tree's mesh in input order, timing."""

from __future__ import annotations

import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[2]
SHARED = REPO.parent / "shared" / "meshes"
NAMES = ["bunny.obj", "fandisk.stl", "pig.stl", "cad/boeing.obj", "cad/ALSTOM_TEST4.obj",
         "cad/anchor.obj"]


def meshes():
    """(name, path) of the bundled cow and the shared meshes that exist."""
    out = [("cow", REPO / "assets" / "cow.obj")]
    for name in NAMES:
        path = SHARED / name
        if path.exists():
            out.append((pathlib.Path(name).stem, path))
        else:
            print(f"skipping {name}: {path} not found", file=sys.stderr)
    return out


def mesh_of(tree):
    """Vertices (float64) and faces in input order, from an f64 tree's zero-copy views."""
    order = np.argsort(tree.source_ids)
    return np.array(tree.vertices, dtype=np.float64), np.array(tree.faces[order], dtype=np.int64)


def median_seconds(run, repeat):
    """The median time of `repeat` calls of `run`, and the last call's answer."""
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - started)
    return float(np.median(times)), result


def peers(makers):
    """An instance of each peer class that imports, with a message for each that does not."""
    out = []
    for make in makers:
        try:
            out.append(make())
        except ImportError as e:
            print(f"skipping {make.name}: {e}", file=sys.stderr)
    return out
