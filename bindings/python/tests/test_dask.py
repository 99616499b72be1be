"""examples/dask_batch.py on a LocalCluster of worker processes: the same answers as the
single-process batch, each worker opening each tree once."""

import importlib
import sys

import numpy as np
import pytest

import obbtree
from conftest import HERE

distributed = pytest.importorskip("dask.distributed", reason="scripts/test installs dask[distributed]")


def load_example():
    """The example as a module. Dask pickles functions of an importable module by
    reference, so the workers must import it too: they are spawned with this process's
    sys.path (on a real cluster: client.upload_file("dask_batch.py"))."""
    examples = str(HERE.parent / "examples")
    if examples not in sys.path:
        sys.path.insert(0, examples)
    return importlib.import_module("dask_batch")


@pytest.fixture(scope="module")
def client():
    load_example()  # before the workers start, so that they can import it
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    yield client
    client.close()
    cluster.close()


def test_dask_batch_equals_single_process(client, trees):
    example = load_example()
    path = str(trees["cow_f32"])
    poses = example.random_poses(3000, spread=0.8, seed=3)
    tree = obbtree.open(path)
    I = np.eye(4)
    for query, options, check in [
        ("first_contact", {}, lambda r: obbtree.collide(tree, I, tree, poses, first_contact=True).contacts),
        ("collide", {}, lambda r: obbtree.collide(tree, I, tree, poses).contacts),
        ("distance", {"rel_err": 0.01}, lambda r: obbtree.distance(tree, I, tree, poses, rel_err=0.01).distance),
        ("span", {}, lambda r: obbtree.span(tree, I, tree, poses).span),
    ]:
        result = example.run_batch(client, path, I, path, poses, query, shard=500, threads=1, **options)
        key = {"first_contact": "contacts", "collide": "contacts", "distance": "distance", "span": "span"}[query]
        assert np.array_equal(result[key], check(None)), query
    w = example.run_batch(client, path, I, path, poses, "within", shard=700, tolerance=0.02)
    assert np.array_equal(w["closer"], obbtree.within(tree, I, tree, poses, 0.02).closer)
    # Every worker that ran shards opened the tree once, however many shards it answered.
    opens = example.opens(client)
    assert len(opens) == 2 and all(counts == {path: 1} for counts in opens.values()), opens


def test_dask_npy_shards_and_sent_trees(client, trees, tmp_path):
    example = load_example()
    path = str(trees["cow_f64"])
    poses = example.random_poses(1000, spread=0.8, seed=4)
    npy = tmp_path / "poses.npy"
    np.save(npy, poses)
    example.send_tree(client, path)
    result = example.run_batch(client, path, np.eye(4), path, ("npy", str(npy), len(poses)),
                               "first_contact", shard=300)
    tree = obbtree.open(path)
    assert np.array_equal(result["contacts"],
                          obbtree.collide(tree, np.eye(4), tree, poses, first_contact=True).contacts)
