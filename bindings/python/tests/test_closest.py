"""obbtree.closest: one posed model against many points, checked against the CLI and
against what the answers must satisfy."""

import json

import numpy as np
import pytest

import obbtree
from conftest import COW_OBJ, run_cli


def test_closest_matches_the_cli(tmp_path, cow):
    rng = np.random.default_rng(3)
    points = rng.uniform(-0.8, 0.8, size=(40, 3))
    pose = np.eye(4)
    pose[:3, 3] = [0.1, -0.05, 0.02]
    c = obbtree.closest(cow, pose, points)
    path = tmp_path / "points.txt"
    np.savetxt(path, points, fmt="%.17g")
    rt = ",".join(repr(float(x)) for x in list(pose[:3, :3].ravel()) + list(pose[:3, 3]))
    lines = [json.loads(l) for l in run_cli("closest", cow.path, "--points", path, "--pose", rt,
                                            "--json").stdout.splitlines()]
    assert len(lines) == len(points)
    for i, line in enumerate(lines):
        assert line["distance"] == c.distance[i]
        assert line["tri"] == c.tri[i]
        assert line["feature"]["kind"] == c.feature[i]
        assert np.array_equal(line["closest"], c.point[i])
    # What an answer must satisfy: the point is that far from the query.
    assert np.allclose(np.linalg.norm(c.point - points, axis=1), c.distance, rtol=1e-12, atol=0)
    for a in [c.distance, c.point, c.tri, c.feature, c.feature_index]:
        assert not a.flags.writeable


def test_vertices_are_at_distance_zero_and_max_distance_cuts(cow):
    vertices = np.asarray(cow.vertices, dtype=np.float64)[:25]
    on = obbtree.closest(cow, np.eye(4), vertices)
    assert np.all(on.distance == 0.0)
    assert set(on.feature) <= {"vertex", "edge", "face"}
    far = obbtree.closest(cow, np.eye(4), [[5.0, 5.0, 5.0], [0.0, 0.0, 0.3]], max_distance=1.0)
    assert far.distance[0] == np.inf and far.tri[0] == -1 and far.feature[0] == ""
    assert np.isnan(far.point[0]).all()
    assert far.distance[1] < 1.0 and far.tri[1] >= 0
    one = obbtree.closest(cow, np.eye(4), [0.0, 0.0, 0.3])
    assert one.distance.shape == (1,) and one.distance[0] == far.distance[1]


def test_bad_points_raise():
    tree = obbtree.build(str(COW_OBJ))
    with pytest.raises(obbtree.OptionError, match="shape"):
        obbtree.closest(tree, np.eye(4), np.zeros((4, 2)))
    with pytest.raises(obbtree.OptionError, match="finite"):
        obbtree.closest(tree, np.eye(4), [[0.0, np.nan, 0.0]])
    with pytest.raises(obbtree.OptionError, match="max_distance"):
        obbtree.closest(tree, np.eye(4), [[0.0, 0.0, 0.0]], max_distance=0.0)
    with pytest.raises(obbtree.PoseError):
        obbtree.closest(tree, 2 * np.eye(4), [[0.0, 0.0, 0.0]])
    # What NumPy cannot make numbers of is named too, not left to NumPy's own error.
    with pytest.raises(obbtree.OptionError, match="^points must be numbers"):
        obbtree.closest(tree, np.eye(4), [[0.0, 0.0, 0.0], [1.0, 2.0]])
    with pytest.raises(obbtree.OptionError, match="^origins must be numbers"):
        obbtree.ray(tree, np.eye(4), "abc", [0.0, 0.0, 1.0])
    with pytest.raises(obbtree.OptionError, match="^points must be numbers"):
        obbtree.winding_number(tree, np.eye(4), [["a", "b", "c"]])
    # Squared distances would overflow beyond 1e150: refused by name, not NaN or nothing.
    with pytest.raises(obbtree.OptionError, match=r"query point 1: coordinates must be within ±1e150"):
        obbtree.closest(tree, np.eye(4), [[0.0, 0.0, 0.0], [2e150, 0.0, 0.0]])
