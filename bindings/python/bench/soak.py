"""Soak run of the Python batch calls: many queries in a loop, resident memory sampled.

    python soak.py [--queries 10000000] [--batch 10000] [--samples 100]

The bundled cow's tree (built once into a temporary directory, then memory-mapped) is
queried against a turned copy of itself in batches of random poses, rotating through
collision (all pairs, with pair lists), first contact, exact distance, a tolerance check
and the span, until the number of queries is reached. Resident memory (``/proc/self/statm``)
is sampled after each of ``--samples`` evenly spaced batches and printed as a JSON line;
the last line gives the memory at the end of warm-up (the first tenth of the batches) and
its largest value after. Every sampled batch is answered again at the end on trees opened
afresh and must agree bit for bit (exit status 1 if not).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import pathlib
import sys
import tempfile
import time

import numpy as np

import obbtree

REPO = pathlib.Path(__file__).resolve().parents[3]


def rss_mib() -> float:
    """Resident memory of this process (MiB)."""
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


def poses(seed: int, count: int) -> np.ndarray:
    """`count` (4, 4) poses: random rotations (normalised quaternions), translations in a
    ball of radius 1.2 around the origin, so that contact and separation both occur."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(count, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    out = np.zeros((count, 4, 4))
    out[:, 0, 0] = 1 - 2 * (y * y + z * z)
    out[:, 0, 1] = 2 * (x * y - w * z)
    out[:, 0, 2] = 2 * (x * z + w * y)
    out[:, 1, 0] = 2 * (x * y + w * z)
    out[:, 1, 1] = 1 - 2 * (x * x + z * z)
    out[:, 1, 2] = 2 * (y * z - w * x)
    out[:, 2, 0] = 2 * (x * z - w * y)
    out[:, 2, 1] = 2 * (y * z + w * x)
    out[:, 2, 2] = 1 - 2 * (x * x + y * y)
    direction = rng.normal(size=(count, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    out[:, :3, 3] = direction * 1.2 * rng.random((count, 1)) ** (1 / 3)
    out[:, 3, 3] = 1
    return out


def answer(kind: int, a, b, batch: np.ndarray):
    """The arrays one batch of query `kind` returns (what a fresh run must reproduce)."""
    identity = np.eye(4)
    if kind == 0:
        r = obbtree.collide(a, identity, b, batch)
        return [r.contacts] + list(r.pairs)
    if kind == 1:
        return [obbtree.collide(a, identity, b, batch, first_contact=True).contacts]
    if kind == 2:
        d = obbtree.distance(a, identity, b, batch)
        return [d.distance, d.point_a, d.point_b, d.tri_a, d.tri_b]
    if kind == 3:
        w = obbtree.within(a, identity, b, batch, 0.05)
        return [w.closer, w.distance]
    return [obbtree.span(a, identity, b, batch).span]


def digest(arrays) -> str:
    """A hash of the arrays' shapes, types and bytes: what is kept of a sampled batch, so
    that keeping it does not itself grow the memory measured."""
    h = hashlib.sha256()
    for x in arrays:
        x = np.ascontiguousarray(x)
        h.update(f"{x.dtype}{x.shape}".encode())
        h.update(x.tobytes())
    return h.hexdigest()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--queries", type=int, default=10_000_000)
    parser.add_argument("--batch", type=int, default=10_000)
    parser.add_argument("--samples", type=int, default=100)
    args = parser.parse_args()
    batches = max(1, args.queries // args.batch)
    sample_every = max(1, batches // args.samples)
    warm_up = max(sample_every, batches // 10)

    with tempfile.TemporaryDirectory(prefix="obbtree-soak-") as scratch:
        path = pathlib.Path(scratch) / "cow.obbt"
        obbtree.build(str(REPO / "assets" / "cow.obj"), str(path))
        a, b = obbtree.open(str(path)), obbtree.open(str(path))
        sampled = {}
        rss_warm, rss_max_after = float("nan"), 0.0
        started = time.perf_counter()
        for k in range(batches):
            batch = poses(k, args.batch)
            result = answer(k % 5, a, b, batch)
            if (k + 1) % sample_every == 0:
                rss = rss_mib()
                if k + 1 == warm_up:
                    rss_warm = rss
                elif k + 1 > warm_up:
                    rss_max_after = max(rss_max_after, rss)
                sampled[k] = digest(result)
                print(json.dumps({"batch": k + 1, "queries": (k + 1) * args.batch,
                                  "rss_mib": round(rss, 1),
                                  "seconds": round(time.perf_counter() - started, 1)}),
                      flush=True)
        seconds = time.perf_counter() - started

        # The sampled batches again, on trees opened afresh.
        fresh_a, fresh_b = obbtree.open(str(path)), obbtree.open(str(path))
        disagreed = [k for k, want in sampled.items()
                     if digest(answer(k % 5, fresh_a, fresh_b, poses(k, args.batch))) != want]
    for k in disagreed:
        print(f"soak: batch {k} answers differently on trees opened afresh", file=sys.stderr)
    print(json.dumps({"queries": batches * args.batch, "batches": batches,
                      "seconds": round(seconds, 1),
                      "rss_mib_after_warm_up": round(rss_warm, 1),
                      "rss_mib_max_after_warm_up": round(rss_max_after, 1),
                      "checked_batches": len(sampled), "agreed": len(sampled) - len(disagreed)}))
    return 1 if disagreed else 0


if __name__ == "__main__":
    sys.exit(main())
