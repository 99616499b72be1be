"""A pose batch too large for one machine, sharded over dask.distributed workers.

Every query of a batch is independent and every worker can map the same .obbt file, so the
batch splits into shards; each worker opens each tree once (a cache on the worker, keyed by
path) and answers its shards with obbtree's batch call (parallel, GIL released); the client
gathers the NumPy results in order.

    # On this machine (a LocalCluster of worker processes), 10^6 random poses of the cow:
    python dask_batch.py --workers 2 --poses 1000000

    # On a cluster: start `dask scheduler` and `dask worker tcp://HOST:8786` on each node,
    # put the trees on storage every worker sees (NFS, a shared volume) and name them by
    # that path; or add --send to copy them into each worker's local directory first.
    python dask_batch.py --scheduler tcp://HOST:8786 --a /shared/a.obbt --b /shared/b.obbt \
        --poses-file /shared/poses.npy

With --poses-file (an (N, 4, 4) or (N, 12) .npy on shared storage) the poses never pass
through the client: each worker maps the file and reads only its shard. Without it the
poses are random (seeded) and sent with the tasks.

As a library: ``run_batch(client, path_a, poses_a, path_b, poses_b, query)`` returns what
``answer`` returns for the whole batch, computed on the cluster.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import sys
import time
from typing import Dict, Optional

import numpy as np

import obbtree

QUERIES = ("first_contact", "collide", "distance", "within", "span")


def _worker_trees():
    """The trees this worker process has opened ({path: Tree}) and how many times it opened
    each, kept on the dask Worker object (module globals do not survive: tasks defined in
    a script are pickled by value); a plain dict outside a worker."""
    try:
        from dask.distributed import get_worker

        holder = get_worker()
    except (ImportError, ValueError):
        holder = sys.modules[__name__]
    if not hasattr(holder, "obbtree_trees"):
        holder.obbtree_trees = {}
        holder.obbtree_opens = {}
    return holder


def tree(path: str) -> obbtree.Tree:
    """The tree at `path`, opened once per worker process (memory-mapped, O(1))."""
    holder = _worker_trees()
    path = getattr(holder, "obbtree_aliases", {}).get(path, path)
    t = holder.obbtree_trees.get(path)
    if t is None or t.closed:
        t = holder.obbtree_trees[path] = obbtree.open(path)
        holder.obbtree_opens[path] = holder.obbtree_opens.get(path, 0) + 1
    return t


def answer(
    path_a: str,
    poses_a,
    path_b: str,
    poses_b,
    query: str = "first_contact",
    options: Optional[dict] = None,
) -> Dict[str, np.ndarray]:
    """One shard: the batch call on this process's trees. Returns plain arrays:
    first_contact/collide -> {"contacts"}; distance -> {"distance", "point_a", "point_b",
    "tri_a", "tri_b"}; within -> {"closer", "distance"}; span -> {"span"}."""
    options = dict(options or {})
    a, b = tree(path_a), tree(path_b)
    if query in ("first_contact", "collide"):
        r = obbtree.collide(a, poses_a, b, poses_b, first_contact=query == "first_contact",
                            pairs=False, **options)
        return {"contacts": np.array(r.contacts)}
    if query == "distance":
        d = obbtree.distance(a, poses_a, b, poses_b, **options)
        return {k: np.array(getattr(d, k)) for k in ("distance", "point_a", "point_b", "tri_a", "tri_b")}
    if query == "within":
        tolerance = options.pop("tolerance")
        w = obbtree.within(a, poses_a, b, poses_b, tolerance, **options)
        return {"closer": np.array(w.closer), "distance": np.array(w.distance)}
    if query == "span":
        return {"span": np.array(obbtree.span(a, poses_a, b, poses_b, **options).span)}
    raise ValueError(f"query {query!r} is not one of {', '.join(QUERIES)}")


def _npy_shard(path: str, start: int, stop: int) -> np.ndarray:
    """Poses start..stop of an .npy file, memory-mapped (only the shard is read)."""
    return np.array(np.load(path, mmap_mode="r")[start:stop])


def _is_batch(poses) -> bool:
    shape = np.shape(poses) if not isinstance(poses, tuple) else np.shape(poses[0])
    return len(shape) == 3 or (len(shape) == 2 and shape[1] == 12)


def run_batch(
    client,
    path_a: str,
    poses_a,
    path_b: str,
    poses_b,
    query: str = "first_contact",
    shard: int = 50_000,
    threads: Optional[int] = None,
    **options,
) -> Dict[str, np.ndarray]:
    """The batch answered on `client`'s workers in shards of `shard` poses and gathered in
    order. poses_a / poses_b: a batch array, a single pose (broadcast), or ("npy", path, n)
    for n poses in an .npy file every worker can read. threads: per worker batch call (None:
    every core of the worker's machine; 1 when the workers share one machine)."""
    if threads is not None:
        options["threads"] = threads

    def length(p):
        if isinstance(p, tuple) and len(p) == 3 and p[0] == "npy":
            return p[2]
        return len(p) if _is_batch(p) else None

    n = length(poses_a) or length(poses_b) or 1

    def cut(p, start, stop):
        if isinstance(p, tuple) and len(p) == 3 and p[0] == "npy":
            return ("npy", p[1], (start, stop))
        return p[start:stop] if _is_batch(p) else p

    futures = []
    for start in range(0, n, shard):
        stop = min(start + shard, n)
        pa, pb = cut(poses_a, start, stop), cut(poses_b, start, stop)
        futures.append(client.submit(_answer_shard, path_a, pa, path_b, pb, query, options, pure=False))
    parts = client.gather(futures)
    if not parts:
        return answer(path_a, poses_a, path_b, poses_b, query, options)
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def _answer_shard(path_a, poses_a, path_b, poses_b, query, options):
    """`answer` with ("npy", path, (start, stop)) shards read on the worker."""
    def read(p):
        if isinstance(p, tuple) and len(p) == 3 and p[0] == "npy":
            start, stop = p[2]
            return _npy_shard(p[1], start, stop)
        return p

    return answer(path_a, read(poses_a), path_b, read(poses_b), query, options)


def send_tree(client, path: str) -> None:
    """Copies a tree into every worker's local directory (for clusters without shared
    storage); tasks naming `path` then open the local copy."""
    data = pathlib.Path(path).read_bytes()
    name = os.path.basename(path)

    def receive(dask_worker, data=data, name=name, path=path):
        local = os.path.join(dask_worker.local_directory, "obbtree", name)
        os.makedirs(os.path.dirname(local), exist_ok=True)
        with open(local, "wb") as f:
            f.write(data)
        if not hasattr(dask_worker, "obbtree_aliases"):
            dask_worker.obbtree_aliases = {}
        dask_worker.obbtree_aliases[path] = local
        return local

    client.run(receive)


def opens(client) -> Dict[str, Dict[str, int]]:
    """How many times each worker opened each tree."""
    return client.run(lambda dask_worker: dict(getattr(dask_worker, "obbtree_opens", {})))


def random_poses(n: int, spread: float, seed: int = 1) -> np.ndarray:
    """n random (n, 12) poses: uniform rotations, translations in [-spread, spread]^3."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    r = np.stack(
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
         2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
         2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        axis=1,
    )
    return np.concatenate([r, rng.uniform(-spread, spread, size=(n, 3))], axis=1)


# Run as a script, the tasks are functions of __main__, which Dask pickles by value; used
# as a module (`import dask_batch`), the workers must import it too: put it on their path
# or send it with client.upload_file("dask_batch.py").


def main(argv=None) -> None:
    here = pathlib.Path(__file__).resolve().parent
    default_tree = here.parents[2] / "assets" / "scenes" / "cow.obbt"
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scheduler", help="scheduler address (default: a LocalCluster)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    p.add_argument("--a", default=str(default_tree), help="tree A (.obbt)")
    p.add_argument("--b", default=str(default_tree), help="tree B (.obbt)")
    p.add_argument("--poses", type=int, default=1_000_000, help="random poses of B (A at identity)")
    p.add_argument("--poses-file", help="an (N, 4, 4) or (N, 12) .npy of B's poses on shared storage")
    p.add_argument("--query", choices=QUERIES, default="first_contact")
    p.add_argument("--shard", type=int, default=50_000)
    p.add_argument("--send", action="store_true", help="copy the trees to the workers first")
    p.add_argument("--compare", action="store_true", help="also time one process and check the answers")
    args = p.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    if args.scheduler:
        client = Client(args.scheduler)
        threads = None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True)
        client = Client(cluster)
        threads = 1  # the workers share this machine's cores
    if args.send:
        send_tree(client, args.a)
        send_tree(client, args.b)
    if args.poses_file:
        n = np.load(args.poses_file, mmap_mode="r").shape[0]
        poses_b = ("npy", args.poses_file, n)
    else:
        n = args.poses
        poses_b = random_poses(n, spread=1.0)
    identity = np.eye(4)
    client.run(lambda: None)
    # Warm-up: every worker opens its trees (once), and the first shard's code paths run.
    run_batch(client, args.a, identity, args.b, random_poses(4 * args.workers, 1.0), args.query,
              shard=4, threads=threads)
    started = time.perf_counter()
    result = run_batch(client, args.a, identity, args.b, poses_b, args.query, shard=args.shard,
                       threads=threads)
    seconds = time.perf_counter() - started
    workers = len(client.scheduler_info()["workers"])
    print(f"dask: {n} poses ({args.query}) on {workers} workers in {seconds:.3f} s: "
          f"{n / seconds:,.0f} poses/s")
    print(f"opens per worker: {opens(client)}")
    if args.compare and not args.poses_file:
        started = time.perf_counter()
        single = answer(args.a, identity, args.b, poses_b, args.query)
        one = time.perf_counter() - started
        same = all(np.array_equal(single[k], result[k], equal_nan=True) for k in single)
        print(f"one process: {one:.3f} s: {n / one:,.0f} poses/s; dask/one = {one / seconds:.2f}x; "
              f"answers equal: {same}")
    client.close()


if __name__ == "__main__":
    main()
