"""Batches equal one-at-a-time calls; pose forms; broadcasting; threads; the GIL."""

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import obbtree
from conftest import random_poses, rt12

N = 40


@pytest.fixture(scope="module")
def poses():
    return random_poses(N, spread=0.05, seed=11), random_poses(N, spread=0.6, seed=12)


def test_collide_batch_equals_single_calls(cow, poses):
    a, b = poses
    batch = obbtree.collide(cow, a, cow, b)
    for i in range(N):
        one = obbtree.collide(cow, a[i], cow, b[i])
        assert one.contacts.shape == (1,)
        assert one.contacts[0] == batch.contacts[i]
        assert np.array_equal(one.pairs[0], batch.pairs[i])
        assert one.work["bv_tests"][0] == batch.work["bv_tests"][i]


def test_distance_within_span_batch_equal_single_calls(cow, poses):
    a, b = poses
    d = obbtree.distance(cow, a, cow, b, rel_err=0.01)
    w = obbtree.within(cow, a, cow, b, 0.02)
    s = obbtree.span(cow, a, cow, b)
    for i in range(N):
        d1 = obbtree.distance(cow, a[i], cow, b[i], rel_err=0.01)
        assert d1.distance[0] == d.distance[i]
        assert np.array_equal(d1.point_a[0], d.point_a[i])
        assert (d1.tri_a[0], d1.tri_b[0]) == (d.tri_a[i], d.tri_b[i])
        w1 = obbtree.within(cow, a[i], cow, b[i], 0.02)
        assert w1.closer[0] == w.closer[i]
        assert np.array_equal(w1.distance, w.distance[i : i + 1], equal_nan=True)
        s1 = obbtree.span(cow, a[i], cow, b[i])
        assert s1.span[0] == s.span[i]


def test_pose_forms_agree(cow, poses):
    a, b = poses
    ref = obbtree.distance(cow, a, cow, b).distance
    r, t = b[:, :3, :3], b[:, :3, 3]
    for form in [rt12(b), (r, t), list(b), b.astype(np.float64, order="F"), rt12(b).tolist()]:
        assert np.array_equal(obbtree.distance(cow, a, cow, form).distance, ref)
    # One pose in each single form.
    i = 3
    for one in [b[i], rt12(b)[i], (r[i], t[i]), b[i].tolist(), (r[i].tolist(), tuple(t[i]))]:
        assert obbtree.distance(cow, a[i], cow, one).distance[0] == ref[i]


def test_an_r_t_pair_reads_r_before_t_runs_python_code(cow):
    # Converting t may run Python code; R's numbers must be read before it, not borrowed
    # across it (a t that changes R on conversion once made the binding read the new R).
    r = np.eye(3)

    class Translation:
        def __array__(self, dtype=None, copy=None):
            r[0, 0] = 12.0
            return np.array([3.0, 0.0, 0.0])

    as_given = np.eye(4)
    as_given[0, 3] = 3.0
    exact = obbtree.distance(cow, np.eye(4), cow, as_given).distance
    assert np.array_equal(obbtree.distance(cow, np.eye(4), cow, (r, Translation())).distance, exact)


def test_float32_and_int_poses_are_converted(cow):
    p = np.eye(4, dtype=np.float32)
    p[0, 3] = 3
    exact = obbtree.distance(cow, np.eye(4), cow, p.astype(np.float64)).distance
    assert np.array_equal(obbtree.distance(cow, np.eye(4, dtype=int), cow, p).distance, exact)


def test_single_pose_broadcasts(cow, poses):
    a, b = poses
    fixed = np.eye(4)
    r1 = obbtree.collide(cow, fixed, cow, b)
    r2 = obbtree.collide(cow, np.tile(fixed, (N, 1, 1)), cow, b)
    assert np.array_equal(r1.contacts, r2.contacts)
    r3 = obbtree.collide(cow, b, cow, fixed)
    r4 = obbtree.collide(cow, b, cow, np.tile(fixed, (N, 1, 1)))
    assert np.array_equal(r3.contacts, r4.contacts)
    # A batch of one broadcasts as a single pose does.
    r5 = obbtree.collide(cow, fixed[None], cow, b)
    assert np.array_equal(r1.contacts, r5.contacts)


def test_empty_batch(cow):
    r = obbtree.collide(cow, np.eye(4), cow, np.zeros((0, 4, 4)))
    assert r.contacts.shape == (0,) and r.pairs == []
    d = obbtree.distance(cow, np.zeros((0, 12)), cow, np.eye(4))
    assert d.distance.shape == (0,) and d.point_a.shape == (0, 3)


def test_pairs_false_and_first_contact(cow, poses):
    a, b = poses
    full = obbtree.collide(cow, a, cow, b)
    lean = obbtree.collide(cow, a, cow, b, pairs=False)
    first = obbtree.collide(cow, a, cow, b, first_contact=True)
    assert lean.pairs is None
    assert np.array_equal(lean.contacts, full.contacts)
    assert np.array_equal(first.contacts, (full.contacts > 0).astype(np.int64))
    for i in range(N):
        assert len(first.pairs[i]) == first.contacts[i]
        if first.contacts[i]:
            # The witness pair is one of the contacting pairs.
            assert first.pairs[i][0].tolist() in full.pairs[i].tolist()


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_threads_give_the_same_answers(cow, poses, threads):
    a, b = poses
    ref = obbtree.collide(cow, a, cow, b)
    r = obbtree.collide(cow, a, cow, b, threads=threads)
    assert np.array_equal(r.contacts, ref.contacts)
    assert all(np.array_equal(x, y) for x, y in zip(r.pairs, ref.pairs))
    d = obbtree.distance(cow, a, cow, b, threads=threads)
    assert np.array_equal(d.distance, obbtree.distance(cow, a, cow, b).distance)


def test_results_are_read_only(cow, poses):
    a, b = poses
    r = obbtree.collide(cow, a, cow, b)
    with pytest.raises(ValueError):
        r.contacts[0] = 5
    assert r.contacts is r.contacts  # made once, then cached


def test_python_threads_share_trees_and_run_concurrently(cow):
    """Queries release the GIL: Python threads calling at once get the right answers and a
    pure-Python thread keeps running while a long batch is in Rust."""
    b = random_poses(400, spread=0.3, seed=5)
    ref = obbtree.collide(cow, np.eye(4), cow, b).contacts
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda _: obbtree.collide(cow, np.eye(4), cow, b, threads=1).contacts, range(8)))
    assert all(np.array_equal(r, ref) for r in results)

    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1
            time.sleep(0)

    counter = threading.Thread(target=count)
    big = random_poses(3000, spread=0.2, seed=6)
    counter.start()
    try:
        started = time.perf_counter()
        obbtree.collide(cow, np.eye(4), cow, big, threads=1)
        elapsed = time.perf_counter() - started
    finally:
        done.set()
        counter.join()
    assert elapsed > 0.02, "the batch should take a while for this check to mean anything"
    assert ticks > 100, f"the Python thread ran only {ticks} times during a {elapsed:.3f} s batch"
