"""obbtree.closest against libigl and Open3D: the closest surface point of a mesh to many
points, the same meshes and points, answers cross-checked.

    python bench/vs_closest.py                        # the bundled cow, and ../shared/meshes
    python bench/vs_closest.py --points 1000000
    RAYON_NUM_THREADS=1 python bench/vs_closest.py    # obbtree on one thread

Points: "near" — random surface points moved off the surface by up to 1% of the mesh's
bounding-box diagonal (a depth camera's cloud against a known part); "far" — uniform in the
box three times the mesh's bounding box. Peers, each where it installs:

- libigl (`igl.point_mesh_squared_distance`, f64): builds its AABB tree inside the call, so
  its time includes the build; obbtree's build time is printed beside it.
- Open3D (`RaycastingScene.compute_closest_points`, f32): its BVH is built on the first
  query, done before the clock starts.

obbtree answers from an f64 tree built in memory (`precision="f64"`), all points in one
call. libigl's distances (f64) must agree with obbtree's to 1e-9 relative: disagreements
are printed and make the exit status 1. Open3D computes in f32, whose point-triangle
arithmetic on long thin triangles can be off by far more than the coordinates' rounding:
where it differs from obbtree by more than 1e-6 of the mesh's diagonal, the count is
printed, for information. Times are the median of --repeat runs, on all cores unless
limited (RAYON_NUM_THREADS for obbtree; libigl and Open3D use their own thread pools).
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import obbtree
from common import median_seconds, mesh_of, meshes, peers  # noqa: E402


def query_points(v, f, n, rng):
    lo, hi = v.min(0), v.max(0)
    diagonal = float(np.linalg.norm(hi - lo))
    tri = v[f[rng.integers(0, len(f), n)]]
    a, b = rng.random((2, n, 1))
    flip = a + b > 1
    a, b = np.where(flip, 1 - a, a), np.where(flip, 1 - b, b)
    surface = tri[:, 0] + a * (tri[:, 1] - tri[:, 0]) + b * (tri[:, 2] - tri[:, 0])
    near = surface + rng.uniform(-0.01, 0.01, (n, 3)) * diagonal / np.sqrt(3)
    centre, half = (lo + hi) / 2, (hi - lo) / 2
    far = centre + rng.uniform(-3, 3, (n, 3)) * half
    return {"near": near, "far": far}


class Igl:
    name = "libigl"
    exact = True

    def __init__(self):
        import igl  # noqa: F401

        self.igl = igl

    def prepare(self, v, f):
        self.v, self.f = v, f

    def distances(self, points):
        squared, _, _ = self.igl.point_mesh_squared_distance(points, self.v, self.f)
        return np.sqrt(squared)


class Open3d:
    name = "Open3D"
    exact = False

    def __init__(self):
        import open3d as o3d

        self.o3d = o3d

    def prepare(self, v, f):
        o3d = self.o3d
        self.scene = o3d.t.geometry.RaycastingScene()
        self.scene.add_triangles(
            o3d.core.Tensor(v.astype(np.float32)), o3d.core.Tensor(f.astype(np.uint32))
        )
        self.distances(np.zeros((1, 3)))  # builds the BVH

    def distances(self, points):
        t = self.o3d.core.Tensor(points.astype(np.float32))
        return self.scene.compute_distance(t).numpy().astype(np.float64)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    others = peers([Igl, Open3d])
    rng = np.random.default_rng(args.seed)
    disagreements = 0
    ratios = {p.name: [] for p in others}
    print(f"{'mesh':<14} {'points':<5} {'triangles':>9} {'obbtree':>10} {'build':>9}"
          + "".join(f" {p.name:>10} {'ratio':>6}" for p in others))
    for name, path in meshes():
        built_at = time.perf_counter()
        tree = obbtree.build(str(path), precision="f64")
        build_seconds = time.perf_counter() - built_at
        v, f = mesh_of(tree)
        diagonal = float(np.linalg.norm(v.max(0) - v.min(0)))
        for peer in others:
            peer.prepare(v, f)
        for kind, points in query_points(v, f, args.points, rng).items():
            ours, answer = median_seconds(lambda: obbtree.closest(tree, np.eye(4), points), args.repeat)
            row = f"{name:<14} {kind:<5} {len(f):>9} {ours * 1e3:>8.1f}ms {build_seconds * 1e3:>7.1f}ms"
            for peer in others:
                theirs, d = median_seconds(lambda: peer.distances(points), args.repeat)
                allowed = 1e-9 * answer.distance if peer.exact else 1e-6 * diagonal
                bad = np.abs(d - answer.distance) > allowed
                if bad.any():
                    i = int(np.argmax(bad))
                    what = "disagrees" if peer.exact else "(f32) differs by more than 1e-6 of the diagonal"
                    print(f"  {peer.name} {what} at {int(bad.sum())} points, e.g. {points[i]}: "
                          f"{d[i]!r} against {answer.distance[i]!r}", file=sys.stderr)
                    if peer.exact:
                        disagreements += int(bad.sum())
                ratios[peer.name].append(ours / theirs)
                row += f" {theirs * 1e3:>8.1f}ms {ours / theirs:>6.2f}"
            print(row)
    for peer, r in ratios.items():
        if r:
            g = float(np.exp(np.mean(np.log(r))))
            print(f"obbtree / {peer}: geomean {g:.2f}, worst {max(r):.2f} over {len(r)} cases")
    if disagreements:
        print(f"{disagreements} disagreements", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
