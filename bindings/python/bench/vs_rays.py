"""obbtree.ray against Embree and Open3D: closest-hit rays on one thread, the same meshes
and rays, answers cross-checked.

    python bench/vs_rays.py                 # the bundled cow, and ../shared/meshes
    python bench/vs_rays.py --rays 1000000

Rays (as `benches/rays.rs` casts them): "camera" — a square image of the mesh's bounding
sphere seen from three radii away along +z (coherent); "random" — from uniform points of
the sphere twice the bounding sphere to uniform points of the bounding box (incoherent).
Peers, each where it installs, each on one thread:

- Embree through embreex (`rtcIntersect1`, one ray at a time, f32; its BVH built before
  the clock);
- Open3D (`RaycastingScene.cast_rays(nthreads=1)`, Embree inside, f32).

obbtree casts from an f64 tree built in memory, all rays in one call on one thread
(RAYON_NUM_THREADS=1, set here before obbtree is imported). A ray that one hits and the
other misses, or whose `t` differs by more than 1e-4 relative, is counted and printed
for information: f32 peers can legitimately differ on rays that graze an edge. Times are
medians of --repeat runs, in microseconds per ray.
"""

from __future__ import annotations

import argparse
import os
import sys

os.environ.setdefault("RAYON_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import obbtree  # noqa: E402
from common import median_seconds, mesh_of, meshes, peers  # noqa: E402


def ray_sets(v, n, rng):
    lo, hi = v.min(0), v.max(0)
    centre, radius = (lo + hi) / 2, float(np.linalg.norm(hi - lo)) / 2
    side = int(np.ceil(np.sqrt(n)))
    u, w = np.meshgrid(np.arange(side) / side, np.arange(side) / side)
    targets = np.stack([centre[0] + (2 * u.ravel() - 1) * radius,
                        centre[1] + (2 * w.ravel() - 1) * radius,
                        np.full(side * side, centre[2])], axis=1)
    eye = centre + [0.0, 0.0, 3 * radius]
    camera = (np.broadcast_to(eye, targets.shape).copy(), targets - eye)
    d = rng.normal(size=(n, 3))
    origins = centre + 2 * radius * d / np.linalg.norm(d, axis=1)[:, None]
    random = (origins, lo + (hi - lo) * rng.random((n, 3)) - origins)
    return {"camera": camera, "random": random}


class Embree:
    name = "Embree"

    def __init__(self):
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        self.rtcore_scene, self.TriangleMesh = rtcore_scene, TriangleMesh

    def prepare(self, v, f):
        self.scene = self.rtcore_scene.EmbreeScene()
        self.TriangleMesh(self.scene, v[f].astype(np.float32))

    def cast(self, origins, directions):
        o, d = origins.astype(np.float32), directions.astype(np.float32)

        def run():
            out = self.scene.run(o, d, output=1)
            return np.where(out["geomID"] >= 0, out["tfar"].astype(np.float64), np.inf)

        return run


class Open3d:
    name = "Open3D"

    def __init__(self):
        import open3d as o3d

        self.o3d = o3d

    def prepare(self, v, f):
        o3d = self.o3d
        self.scene = o3d.t.geometry.RaycastingScene()
        self.scene.add_triangles(
            o3d.core.Tensor(v.astype(np.float32)), o3d.core.Tensor(f.astype(np.uint32))
        )
        self.cast(np.zeros((1, 3)), np.ones((1, 3)))()  # builds the BVH

    def cast(self, origins, directions):
        rays = self.o3d.core.Tensor(np.hstack([origins, directions]).astype(np.float32))
        return lambda: self.scene.cast_rays(rays, nthreads=1)["t_hit"].numpy().astype(np.float64)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rays", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    others = peers([Embree, Open3d])
    rng = np.random.default_rng(args.seed)
    ratios = {p.name: [] for p in others}
    print("| mesh | rays | triangles | obbtree µs | " + " | ".join(
        f"{p.name} µs | obbtree / {p.name} | differ" for p in others) + " |")
    print("|---|---|---:|---:|" + "---:|---:|---:|" * len(others))
    for name, path in meshes():
        tree = obbtree.build(str(path), precision="f64")
        v, f = mesh_of(tree)
        for peer in others:
            peer.prepare(v, f)
        for kind, (origins, directions) in ray_sets(v, args.rays, rng).items():
            n = len(origins)
            cast = lambda: obbtree.ray(tree, np.eye(4), origins, directions)  # noqa: E731
            cast()  # untimed: makes the index, as the peers' BVHs are made before the clock
            ours, hits = median_seconds(cast, args.repeat)
            row = f"| {name} | {kind} | {len(f)} | {ours / n * 1e6:.3f} |"
            for peer in others:
                run = peer.cast(origins, directions)
                run()  # untimed, as obbtree's first call
                theirs, t = median_seconds(run, args.repeat)
                # Both peers report a miss as t = inf, as obbtree does.
                both = hits.hit & np.isfinite(t)
                differ = (np.isfinite(t) != hits.hit)
                differ[both] |= np.abs(t[both] - hits.t[both]) > 1e-4 * np.maximum(hits.t[both], 1.0)
                ratios[peer.name].append(ours / theirs)
                row += f" {theirs / n * 1e6:.3f} | {ours / theirs:.2f} | {int(differ.sum())} |"
            print(row)
    for peer, r in ratios.items():
        if r:
            g = float(np.exp(np.mean(np.log(r))))
            print(f"\nobbtree / {peer}: geomean {g:.2f}, worst {max(r):.2f} over {len(r)} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
