"""The binding answers exactly what the CLI answers, on the same files and poses."""

import numpy as np
import pytest

import obbtree
from conftest import COW_OBJ, SCENES, cli_json_lines, random_poses, run_cli, write_pose_file

N = 60


@pytest.fixture(scope="module")
def batch(tmp_path_factory):
    """N pose pairs where about half the cows touch, and their CLI pose file."""
    a = random_poses(N, spread=0.05, seed=1)
    b = random_poses(N, spread=0.6, seed=2)
    path = write_pose_file(tmp_path_factory.mktemp("poses") / "poses.txt", a, b)
    return a, b, path


@pytest.mark.parametrize("precision", ["f32", "f64"])
def test_info_equals_cli_json(trees, precision):
    path = trees[f"cow_{precision}"]
    [expected] = cli_json_lines("info", path, "--json")
    with obbtree.open(path) as t:
        assert t.info == expected
        assert list(t.info) == list(expected)


def test_info_of_scene_assets(trees):
    for path in sorted(SCENES.glob("*.obbt")):
        [expected] = cli_json_lines("info", path, "--json")
        assert obbtree.open(path).info == expected, path


@pytest.mark.parametrize("precision", ["f32", "f64"])
def test_build_writes_the_cli_bytes(tmp_path, trees, precision):
    """Building through Python writes the same file, byte for byte, as `obbtree build`."""
    out = tmp_path / "cow.obbt"
    t = obbtree.build(COW_OBJ, out, precision=precision)
    assert out.read_bytes() == trees[f"cow_{precision}"].read_bytes()
    assert t.path is not None and t.info["precision"] == precision
    # In memory from arrays: the same tree (the vertices and faces as the CLI loads them).
    assert t.info == obbtree.open(trees[f"cow_{precision}"]).info


def test_build_options_match_cli(tmp_path):
    out_cli, out_py = tmp_path / "cli.obbt", tmp_path / "py.obbt"
    run_cli("build", COW_OBJ, "-o", out_cli, "--bv", "sphere", "--leaf-size", "4",
            "--scale", "0.001", "--center", "--fit", "triangles", "--quiet")
    obbtree.build(COW_OBJ, out_py, bv="sphere", leaf_size=4, scale=0.001, center=True, fit="triangles")
    assert out_py.read_bytes() == out_cli.read_bytes()


def test_split_by_volume_off_matches_cli(tmp_path):
    out_cli, out_py = tmp_path / "cli.obbt", tmp_path / "py.obbt"
    run_cli("build", COW_OBJ, "-o", out_cli, "--split-by-volume", "no", "--model-axes", "no",
            "--quiet")
    obbtree.build(COW_OBJ, out_py, split_by_volume=False, model_axes=False)
    assert out_py.read_bytes() == out_cli.read_bytes()
    obbtree.build(COW_OBJ, tmp_path / "default.obbt")
    assert out_py.read_bytes() != (tmp_path / "default.obbt").read_bytes()


def test_verify_ok(trees):
    out = run_cli("verify", trees["cow_f32"]).stdout
    assert "ok" in out
    assert obbtree.open(trees["cow_f32"]).verify() is None


@pytest.mark.parametrize("first", [False, True])
def test_collide_equals_cli(trees, batch, first):
    a, b, path = batch
    flags = ["--first"] if first else []
    expected = cli_json_lines("collide", trees["cow_f32"], trees["cow_f32"], "--poses", path,
                              "--json", "--pairs", *flags)
    t = obbtree.open(trees["cow_f32"])
    r = obbtree.collide(t, a, t, b, first_contact=first)
    assert len(expected) == N == len(r)
    assert 5 < int(r.colliding.sum()) < N - 5, "the batch should mix hits and misses"
    for i, e in enumerate(expected):
        assert e["pose"] == i
        assert r.contacts[i] == e["contacts"]
        assert r.colliding[i] == e["colliding"]
        assert r.pairs[i].tolist() == e["pairs"]
        for key, column in r.work.items():
            assert column[i] == e["work"][key], key


@pytest.mark.parametrize("precision", ["f32", "f64"])
@pytest.mark.parametrize("errors", [(), ("--rel-err", "0.05"), ("--abs-err", "0.01")])
def test_distance_equals_cli(trees, batch, precision, errors):
    a, b, path = batch
    tree = trees[f"cow_{precision}"]
    expected = cli_json_lines("distance", tree, tree, "--poses", path, "--json", *errors)
    kwargs = {}
    if errors:
        kwargs[errors[0][2:].replace("-", "_")] = float(errors[1])
    t = obbtree.open(tree)
    d = obbtree.distance(t, a, t, b, **kwargs)
    for i, e in enumerate(expected):
        assert d.distance[i] == e["distance"]
        assert d.point_a[i].tolist() == e["point_a"]
        assert d.point_b[i].tolist() == e["point_b"]
        assert (d.tri_a[i], d.tri_b[i]) == (e["tri_a"], e["tri_b"])
        assert d.work["bv_tests"][i] == e["work"]["bv_tests"]


def test_within_equals_cli(trees, batch):
    a, b, path = batch
    tree = trees["cow_f32"]
    tolerance = 0.05
    expected = cli_json_lines("distance", tree, tree, "--poses", path, "--json",
                              "--tolerance", str(tolerance))
    t = obbtree.open(tree)
    w = obbtree.within(t, a, t, b, tolerance)
    assert 0 < int(w.closer.sum()) < N
    for i, e in enumerate(expected):
        assert w.closer[i] == e["closer_than_tolerance"]
        if e["distance"] is None:
            assert np.isnan(w.distance[i]) and w.tri_a[i] == -1 and np.isnan(w.point_a[i]).all()
        else:
            assert w.distance[i] == e["distance"]
            assert w.point_a[i].tolist() == e["point_a"]
            assert (w.tri_a[i], w.tri_b[i]) == (e["tri_a"], e["tri_b"])


def test_span_equals_cli(trees, batch):
    a, b, path = batch
    tree = trees["cow_f32"]
    expected = cli_json_lines("span", tree, tree, "--poses", path, "--json")
    t = obbtree.open(tree)
    s = obbtree.span(t, a, t, b)
    for i, e in enumerate(expected):
        assert s.span[i] == e["span"]
        assert s.point_b[i].tolist() == e["point_b"]
        assert (s.tri_a[i], s.tri_b[i]) == (e["tri_a"], e["tri_b"])


def test_single_pose_equals_cli(trees):
    """One pose pair through --pose-a / --pose-b (and a mesh input built in memory)."""
    pose_b = "0,-1,0,1,0,0,0,0,1,0.3,0.1,0"
    [expected] = cli_json_lines("collide", COW_OBJ, trees["cow_f32"], "--pose-b", pose_b,
                                "--json", "--pairs")
    t = obbtree.open(trees["cow_f32"])
    r = obbtree.collide(t, np.eye(4), t, np.array(pose_b.split(","), dtype=float))
    assert r.contacts.tolist() == [expected["contacts"]]
    assert r.pairs[0].tolist() == expected["pairs"]


def test_orthonormalize_equals_cli(tmp_path, trees):
    """Rotations printed with 4 decimals: refused without orthonormalize, repaired as the
    CLI repairs them with it."""
    rounded = np.round(random_poses(10, spread=0.5, seed=3), 4)
    ident = np.tile(np.eye(4), (10, 1, 1))
    path = write_pose_file(tmp_path / "rounded.txt", ident, rounded)
    expected = cli_json_lines("distance", trees["cow_f32"], trees["cow_f32"], "--poses", path,
                              "--json", "--orthonormalize")
    refused = run_cli("distance", trees["cow_f32"], trees["cow_f32"], "--poses", path, check=False)
    assert refused.returncode == 1 and "not orthonormal" in refused.stderr
    t = obbtree.open(trees["cow_f32"])
    with pytest.raises(obbtree.PoseError, match="poses_b: pose 0: rotation is not orthonormal"):
        obbtree.distance(t, ident, t, rounded)
    d = obbtree.distance(t, ident, t, rounded, orthonormalize=True)
    assert d.distance.tolist() == [e["distance"] for e in expected]


def test_mismatched_trees_message_equals_cli(trees):
    done = run_cli("collide", trees["cow_f32"], trees["cow_f64"], check=False)
    assert done.returncode == 1
    with pytest.raises(obbtree.Error) as raised:
        obbtree.collide(obbtree.open(trees["cow_f32"]), np.eye(4), obbtree.open(trees["cow_f64"]), np.eye(4))
    assert str(raised.value) in done.stderr
