"""obbtree.winding_number and obbtree.signed_distance: inside or outside one posed model,
on a closed mesh, on soups with known winding numbers, and against the exact sum."""

import numpy as np
import pytest

import obbtree


def cube(half=1.0):
    v = np.array([[x, y, z] for z in (-half, half) for y in (-half, half) for x in (-half, half)])
    f = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return v, f


def test_closed_cube_and_soups_have_their_known_winding_numbers():
    v, f = cube()
    closed = obbtree.build((v, f))
    points = [[0.1, 0.2, -0.3], [3.0, 0.0, 0.0]]
    for options in [{}, {"tolerance": 0}, {"tolerance": 1e-3}, {"beta": 3.0}]:
        w = obbtree.winding_number(closed, np.eye(4), points, **options)
        assert w[0] == pytest.approx(1.0, abs=2e-3) and w[1] == pytest.approx(0.0, abs=2e-3)
        assert not w.flags.writeable
    # One face (two triangles, at x = +1) left out: a sixth of the directions from the centre.
    keep = [k for k in range(12) if not np.all(v[f[k], 0] == 1.0)]
    open_cube = obbtree.build((v, f[keep]))
    assert obbtree.winding_number(open_cube, np.eye(4), [0.0, 0.0, 0.0], tolerance=0)[0] == \
        pytest.approx(5 / 6, abs=1e-12)
    doubled = obbtree.build((v, np.concatenate([f, f])))
    assert obbtree.winding_number(doubled, np.eye(4), [0.2, 0.1, 0.0], tolerance=0)[0] == \
        pytest.approx(2.0, abs=1e-12)


def test_the_bounded_and_fast_sums_stay_near_the_exact_one(cow):
    rng = np.random.default_rng(5)
    pose = np.eye(4)
    pose[:3, 3] = [0.2, 0.0, -0.1]
    points = pose[:3, 3] + rng.uniform(-0.7, 0.7, size=(300, 3))
    exact = obbtree.winding_number(cow, pose, points, tolerance=0)
    bounded = obbtree.winding_number(cow, pose, points, tolerance=1e-2)
    fast = obbtree.winding_number(cow, pose, points)
    assert np.abs(bounded - exact).max() <= 1e-2
    assert np.abs(fast - exact).max() <= 5e-2
    assert np.mean((fast > 0.5) == (exact > 0.5)) > 0.99


def test_signed_distance_is_the_closest_distance_signed_by_inside():
    v, f = cube(0.5)
    tree = obbtree.build((v, f))
    points = np.array([[0.0, 0.0, 0.0], [0.2, 0.1, 0.0], [2.0, 0.0, 0.0], [0.0, 0.9, 0.0]])
    s = obbtree.signed_distance(tree, np.eye(4), points)
    assert np.allclose(s, [-0.5, -0.3, 1.5, 0.4], atol=1e-12)
    c = obbtree.closest(tree, np.eye(4), points)
    assert np.array_equal(np.abs(s), c.distance)


def test_bad_input_raises(cow):
    with pytest.raises(obbtree.OptionError, match="query point 1"):
        obbtree.winding_number(cow, np.eye(4), [[0, 0, 0], [np.nan, 0, 0]])
    with pytest.raises(obbtree.OptionError, match="shape"):
        obbtree.winding_number(cow, np.eye(4), [[0, 0]])
    with pytest.raises(obbtree.OptionError, match="beta"):
        obbtree.winding_number(cow, np.eye(4), [0, 0, 0], beta=1.0)
    with pytest.raises(obbtree.OptionError, match="tolerance"):
        obbtree.signed_distance(cow, np.eye(4), [0, 0, 0], tolerance=-1)
    with pytest.raises(obbtree.PoseError):
        obbtree.signed_distance(cow, np.eye(4) * 2, [0, 0, 0])


def test_thread_counts_do_not_change_the_answers(cow):
    rng = np.random.default_rng(7)
    lo, hi = cow.vertices.min(axis=0), cow.vertices.max(axis=0)
    points = rng.uniform(lo, hi, size=(300, 3))
    origins, directions = points, rng.normal(size=(300, 3))
    answers = []
    for threads in (None, 1, 2):
        answers.append([
            obbtree.winding_number(cow, np.eye(4), points, threads=threads),
            obbtree.signed_distance(cow, np.eye(4), points, threads=threads),
            obbtree.closest(cow, np.eye(4), points, threads=threads).distance,
            obbtree.ray(cow, np.eye(4), origins, directions, threads=threads).t,
        ])
    for other in answers[1:]:
        for a, b in zip(answers[0], other):
            np.testing.assert_array_equal(a, b)
    for call in (
        lambda: obbtree.winding_number(cow, np.eye(4), points, threads=0),
        lambda: obbtree.closest(cow, np.eye(4), points, threads=-1),
        lambda: obbtree.ray(cow, np.eye(4), origins, directions, threads=2000),
    ):
        with pytest.raises(obbtree.OptionError, match="threads"):
            call()
