"""obbtree's batch calls against python-fcl (and coal, where it installs) in a Python loop:
the same meshes, the same pose batch, four queries, answers cross-checked.

    python bench/vs_fcl.py                     # the bundled cow, and ../shared/meshes if present
    python bench/vs_fcl.py --first 100000 --others 5000

Queries: first contact (yes/no), all contacts (the contacting triangle pairs), exact
distance, and distance with a tolerance (rel_err 0.05; python-fcl has no error allowance,
so only coal runs it). obbtree runs each batch in one call, on every core (threads=None)
and on one (threads=1); the others answer one pose per Python call, on one core.

Cross-checks: the yes/no answers must agree pose by pose; all-contacts: the number of
contacting triangle pairs must agree (FCL and coal report each pair once when asked for
enough contacts); exact distances must agree to 1e-6 relative (FCL's is a GJK answer on
the closest triangle pair); distances with rel_err must stay within the allowance of the
exact one. Disagreements are counted and printed, and make the exit status 1.

obbtree's trees are built at the library's default precision (f32 coordinates and boxes),
and the peers are given the tree's vertices (exactly, as float64): every library answers
on the same geometry.

Also measures the per-call overhead of the binding: a single-pose obbtree call from Python
against the same query called from Rust (a loop in the extension, no Python in it).
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import numpy as np

import obbtree
from obbtree import _obbtree
from common import median_seconds

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[2]
SHARED = REPO.parent / "shared" / "meshes"


def random_poses(n, spread, seed):
    """(n, 4, 4) random poses: uniform rotations, translations in [-spread, spread]^3."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    poses = np.tile(np.eye(4), (n, 1, 1))
    poses[:, 0, :3] = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], 1)
    poses[:, 1, :3] = np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], 1)
    poses[:, 2, :3] = np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], 1)
    poses[:, :3, 3] = rng.uniform(-spread, spread, size=(n, 3))
    return poses


def mesh_of(tree):
    """Vertices (float64, exactly the stored ones) and faces in input order, from the tree's
    views."""
    order = np.argsort(tree.source_ids)
    return np.array(tree.vertices, dtype=np.float64), np.array(tree.faces[order], dtype=np.int64)


class Fcl:
    name = "python-fcl"

    def __init__(self, vertices, faces):
        import fcl

        self.fcl = fcl
        model = fcl.BVHModel()
        model.beginModel(len(vertices), len(faces))
        model.addSubModel(vertices, faces)
        model.endModel()
        self.a = fcl.CollisionObject(model, fcl.Transform())
        self.b = fcl.CollisionObject(model, fcl.Transform())

    def place(self, pose):
        self.b.setTransform(self.fcl.Transform(pose[:3, :3], pose[:3, 3]))

    def first(self, poses):
        fcl, out = self.fcl, np.zeros(len(poses), dtype=bool)
        for i, p in enumerate(poses):
            self.place(p)
            out[i] = fcl.collide(self.a, self.b, fcl.CollisionRequest(), fcl.CollisionResult()) > 0
        return out

    def all(self, poses):
        fcl, out = self.fcl, np.zeros(len(poses), dtype=np.int64)
        for i, p in enumerate(poses):
            self.place(p)
            request = fcl.CollisionRequest(num_max_contacts=10**7, enable_contact=True)
            out[i] = fcl.collide(self.a, self.b, request, fcl.CollisionResult())
        return out

    def distance(self, poses, rel_err=0.0):
        if rel_err:
            return None  # python-fcl exposes no error allowance
        fcl, out = self.fcl, np.zeros(len(poses))
        for i, p in enumerate(poses):
            self.place(p)
            out[i] = fcl.distance(self.a, self.b, fcl.DistanceRequest(), fcl.DistanceResult())
        return out


class Coal:
    name = "coal"

    def __init__(self, vertices, faces):
        import coal

        self.coal = coal
        self.model = coal.BVHModelOBBRSS()
        self.model.beginModel(len(faces), len(vertices))
        self.model.addVertices(vertices)
        self.model.addTriangles(faces)
        self.model.endModel()
        self.identity = coal.Transform3s(np.eye(3), np.zeros(3))

    def run(self, poses, request, result_type, call, value):
        coal, out = self.coal, []
        for p in poses:
            result = result_type()
            call(self.model, self.identity, self.model, coal.Transform3s(p[:3, :3], p[:3, 3]), request, result)
            out.append(value(result))
        return np.array(out)

    def first(self, poses):
        request = self.coal.CollisionRequest()
        request.num_max_contacts = 1
        return self.run(poses, request, self.coal.CollisionResult, self.coal.collide,
                        lambda r: r.isCollision())

    def all(self, poses):
        request = self.coal.CollisionRequest()
        request.num_max_contacts = 10**7
        return self.run(poses, request, self.coal.CollisionResult, self.coal.collide,
                        lambda r: r.numContacts())

    def distance(self, poses, rel_err=0.0):
        request = self.coal.DistanceRequest()
        request.rel_err = rel_err
        request.abs_err = 0.0
        return self.run(poses, request, self.coal.DistanceResult, self.coal.distance,
                        lambda r: r.min_distance)


def timed(f):
    started = time.perf_counter()
    value = f()
    return value, time.perf_counter() - started


def bench_mesh(name, path, n_first, n_others, seed, repeat):
    tree = obbtree.build(path)
    vertices, faces = mesh_of(tree)
    size = float(np.ptp(vertices, axis=0).max())
    poses = random_poses(n_first, spread=0.6 * size, seed=seed)
    few = poses[:n_others]
    I = np.eye(4)
    peers = []
    for make in (Fcl, Coal):
        try:
            peers.append(make(vertices, faces))
        except ImportError as e:
            print(f"  ({make.name} not installed: {e})")
    print(f"\n{name}: {len(faces)} triangles; {n_first} poses for first contact, {n_others} for the others")
    rows, bad = [], 0

    def ours(f):
        # Medians: obbtree's batches are short, and this machine's timings wander.
        t_all, all_cores = median_seconds(lambda: f(None), repeat)
        t_one, _ = median_seconds(lambda: f(1), repeat)
        return all_cores, t_all, t_one

    # First contact.
    mine, t_all, t_one = ours(lambda th: obbtree.collide(tree, I, tree, poses, first_contact=True,
                                                          pairs=False, threads=th).colliding)
    rows.append(("first contact", n_first, t_all, t_one, {}))
    for peer in peers:
        theirs, t = timed(lambda: peer.first(poses))
        wrong = int((np.asarray(theirs, dtype=bool) != mine).sum())
        bad += wrong
        rows[-1][4][peer.name] = (t, f"{wrong} disagree" if wrong else "agree")
    hits = int(mine.sum())
    # First contact over a wider workspace (most poses apart, as in a planner's samples).
    wide = random_poses(n_first, spread=2.0 * size, seed=seed + 1)
    mine_w, t_all, t_one = ours(lambda th: obbtree.collide(tree, I, tree, wide, first_contact=True,
                                                            pairs=False, threads=th).colliding)
    rows.append((f"first contact, wide ({int(mine_w.sum())} hit)", n_first, t_all, t_one, {}))
    for peer in peers:
        theirs, t = timed(lambda: peer.first(wide))
        wrong = int((np.asarray(theirs, dtype=bool) != mine_w).sum())
        bad += wrong
        rows[-1][4][peer.name] = (t, f"{wrong} disagree" if wrong else "agree")
    # All contacts.
    mine, t_all, t_one = ours(lambda th: obbtree.collide(tree, I, tree, few, pairs=False, threads=th).contacts)
    rows.append(("all contacts", n_others, t_all, t_one, {}))
    for peer in peers:
        theirs, t = timed(lambda: peer.all(few))
        wrong = int((theirs != mine).sum())
        yes_no = int(((theirs > 0) != (mine > 0)).sum())
        bad += yes_no
        worst = float(np.max(np.abs(theirs - mine) / np.maximum(mine, 1)))
        rows[-1][4][peer.name] = (t, "same counts" if not wrong else
                                  f"{wrong} counts differ (at most {worst:.1%}; touching pairs are tested differently), {yes_no} yes/no")
    # Exact distance.
    exact, t_all, t_one = ours(lambda th: obbtree.distance(tree, I, tree, few, threads=th).distance)
    rows.append(("exact distance", n_others, t_all, t_one, {}))
    for peer in peers:
        theirs, t = timed(lambda: peer.distance(few))
        err = np.abs(theirs - exact) / np.maximum(exact, 1e-3 * size)
        wrong = int((err > 1e-6).sum())
        bad += wrong
        rows[-1][4][peer.name] = (t, f"max rel diff {err.max():.1e}" + (f", {wrong} beyond 1e-6" if wrong else ""))
    # Distance within 5%.
    rel = 0.05
    approx, t_all, t_one = ours(lambda th: obbtree.distance(tree, I, tree, few, rel_err=rel, threads=th).distance)
    ok = (approx >= exact - 1e-9 * size) & (approx <= exact * (1 + rel) + 1e-9 * size)
    bad += int((~ok).sum())
    rows.append((f"distance rel_err {rel}", n_others, t_all, t_one, {}))
    for peer in peers:
        theirs, t = timed(lambda: peer.distance(few, rel_err=rel))
        if theirs is None:
            rows[-1][4][peer.name] = (None, "no error allowance")
            continue
        within = (theirs >= exact * (1 - 1e-6) - 1e-9 * size) & (theirs <= exact * (1 + rel) * (1 + 1e-6) + 1e-9 * size)
        wrong = int((~within).sum())
        bad += wrong
        rows[-1][4][peer.name] = (t, "within the allowance" if not wrong else f"{wrong} outside")

    print(f"  (poses: random rotations, translations within 0.6 x the model's size ({hits} of {n_first} collide), "
          f"or 2 x for 'wide'; obbtree on all cores / on 1 core, peers on 1 core in a Python loop)")
    header = f"  {'query':<34}{'poses':>8}{'obbtree':>11}{'1 core':>11}"
    for peer in peers:
        header += f"{peer.name:>14}{'ratio':>9}{'ratio 1c':>9}"
    print(header)
    for query, n, t_all, t_one, theirs in rows:
        line = f"  {query:<34}{n:>8}{t_all:>10.3f}s{t_one:>10.3f}s"
        for peer in peers:
            t, note = theirs.get(peer.name, (None, ""))
            if t is None:
                line += f"{'n/a':>14}{'':>9}{'':>9}"
            else:
                line += f"{t:>13.3f}s{t / t_all:>8.1f}x{t / t_one:>8.1f}x"
        print(line)
        notes = "; ".join(f"{p}: {theirs[p][1]}" for p in theirs)
        if notes:
            print(f"  {'':<34}{notes}")
    return bad


def overhead(path, repeat):
    """Seconds per single-pose call from Python and from Rust, for poses that stop at the
    roots (the call itself) and for a first contact found deep in the trees."""
    tree = obbtree.open(path) if str(path).endswith(".obbt") else obbtree.build(path)
    I = np.eye(4)
    far = np.eye(4)
    far[0, 3] = 100.0
    near = np.eye(4)
    near[:3, 3] = [0.3, 0.1, 0.0]
    print(f"\nper-call overhead ({repeat} single-pose calls each, threads=1 not needed: N=1 runs inline)")
    for label, pose, query, call in [
        ("first contact, culled at the roots", far, "first_contact",
         lambda: obbtree.collide(tree, I, tree, far, first_contact=True)),
        ("first contact, touching", near, "first_contact",
         lambda: obbtree.collide(tree, I, tree, near, first_contact=True)),
        ("exact distance, far apart", far, "distance", lambda: obbtree.distance(tree, I, tree, far)),
    ]:
        rust = _obbtree._time_rust_loop(tree, I, tree, pose, query, repeat)
        call()
        started = time.perf_counter()
        for _ in range(repeat):
            call()
        python = (time.perf_counter() - started) / repeat
        twelve = np.concatenate([pose[:3, :3].ravel(), pose[:3, 3]])
        one = np.concatenate([np.eye(3).ravel(), np.zeros(3)])
        started = time.perf_counter()
        if query == "first_contact":
            for _ in range(repeat):
                obbtree.collide(tree, one, tree, twelve, first_contact=True)
        else:
            for _ in range(repeat):
                obbtree.distance(tree, one, tree, twelve)
        python12 = (time.perf_counter() - started) / repeat
        print(f"  {label:<36} Rust {rust * 1e6:7.2f} us   Python (4x4) {python * 1e6:7.2f} us "
              f"(+{(python - rust) * 1e6:5.2f})   Python (12,) {python12 * 1e6:7.2f} us (+{(python12 - rust) * 1e6:5.2f})")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--first", type=int, default=100_000, help="poses for first contact")
    p.add_argument("--others", type=int, default=5_000, help="poses for the other queries")
    p.add_argument("--overhead", type=int, default=100_000, help="single calls timed (0: skip)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--repeat", type=int, default=5, help="obbtree runs per batch (median)")
    p.add_argument("--only-cow", action="store_true")
    args = p.parse_args(argv)
    meshes = [("cow", REPO / "assets" / "cow.obj")]
    if args.only_cow:
        pass
    elif SHARED.is_dir():
        for path in sorted(SHARED.iterdir()):
            if path.suffix.lower() in (".obj", ".stl") and path.name != "cow.obj":
                meshes.append((path.stem, path))
    else:
        print(f"({SHARED} not found: the shared meshes are skipped; only the bundled cow runs)")
    bad = 0
    for name, path in meshes:
        bad += bench_mesh(name, path, args.first, args.others, args.seed, args.repeat)
    if args.overhead:
        overhead(REPO / "assets" / "cow.obj", args.overhead)
    if bad:
        print(f"\n{bad} answers disagree")
        sys.exit(1)
    print("\nall answers agree")


if __name__ == "__main__":
    main()
