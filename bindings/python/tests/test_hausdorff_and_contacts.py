"""obbtree.hausdorff: closed forms on squares, batches against one-at-a-time calls and the
CLI, the symmetric measure, and refusals; collide(geometry=True): where the pairs meet."""

import numpy as np
import pytest

import obbtree
from conftest import cli_json_lines


def square(dx=0.0):
    v = np.array([[dx, 0, 0], [dx + 1, 0, 0], [dx + 1, 1, 0], [dx, 1, 0]], dtype=float)
    return obbtree.build((v, np.array([[0, 1, 2], [0, 2, 3]])))


def test_squares_half_a_side_apart():
    h = obbtree.hausdorff(square(), np.eye(4), square(0.5), np.eye(4))
    assert h.distance.tolist() == [0.5]
    assert h.upper_bound.tolist() == [0.5]
    assert h.point_a[0, 0] == 0.0 and h.direction.tolist() == ["a_to_b"]


def test_a_batch_equals_single_calls_and_the_cli(trees, cow):
    poses = np.tile(np.eye(4), (4, 1, 1))
    poses[:, 0, 3] = [0.0, 0.01, 0.02, 0.05]
    poses[2, :3, :3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    batch = obbtree.hausdorff(cow, np.eye(4), cow, poses, symmetric=True)
    assert batch.distance.shape == (4,) and batch.point_a.shape == (4, 3)
    assert batch.distance[0] <= 1e-15
    assert np.all(batch.upper_bound >= batch.distance)
    for i, pose in enumerate(poses):
        one = obbtree.hausdorff(cow, np.eye(4), cow, pose, symmetric=True)
        assert one.distance[0] == batch.distance[i]
        np.testing.assert_array_equal(one.point_a[0], batch.point_a[i])
    # The moved copy is exactly as far as it moved: every point of A has its twin.
    assert abs(batch.distance[1] - 0.01) <= 1e-12
    pose = ",".join(str(x) for x in np.concatenate([poses[2, :3, :3].ravel(), poses[2, :3, 3]]))
    path = trees["cow_f32"]
    (line,) = cli_json_lines("hausdorff", path, path, "--pose-b", pose, "--symmetric", "--json")
    assert abs(line["hausdorff"] - batch.distance[2]) <= 1e-12 * batch.distance[2]
    assert line["direction"] == batch.direction[2]


def test_rel_err_trades_bounds_for_work(cow):
    pose = np.eye(4)
    pose[:3, :3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    exact = obbtree.hausdorff(cow, np.eye(4), cow, pose)
    loose = obbtree.hausdorff(cow, np.eye(4), cow, pose, rel_err=0.1)
    assert loose.distance[0] <= exact.upper_bound[0]
    assert exact.distance[0] <= loose.upper_bound[0] <= loose.distance[0] * 1.1 + 1e-15
    assert loose.work["tri_tests"][0] <= exact.work["tri_tests"][0]


def test_bad_options_raise(cow):
    with pytest.raises(obbtree.OptionError, match="rel_err"):
        obbtree.hausdorff(cow, np.eye(4), cow, np.eye(4), rel_err=-1.0)
    with pytest.raises(obbtree.OptionError, match="abs_err"):
        obbtree.hausdorff(cow, np.eye(4), cow, np.eye(4), abs_err=float("nan"))
    with pytest.raises(obbtree.PoseError):
        obbtree.hausdorff(cow, np.eye(4), cow, np.eye(4) * 2)


def test_collide_geometry_gives_each_pair_its_segment(cow):
    pose = np.eye(4)
    pose[:3, :3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    pose[0, 3] = 0.05
    r = obbtree.collide(cow, np.eye(4), cow, pose, geometry=True)
    (pieces,) = r.geometry
    assert len(pieces) == r.contacts[0] > 0
    lengths = sum(float(np.linalg.norm(p[1] - p[0])) for p in pieces if len(p) == 2)
    assert abs(r.curve_length[0] - lengths) <= 1e-9 * lengths
    plain = obbtree.collide(cow, np.eye(4), cow, pose)
    assert plain.geometry is None and plain.curve_length is None
    np.testing.assert_array_equal(plain.pairs[0], r.pairs[0])
