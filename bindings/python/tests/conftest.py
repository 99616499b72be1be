"""Shared fixtures: the obbtree CLI (the reference the binding must agree with), the
repository's assets, and trees built from them."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import obbtree

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[2]
ASSETS = REPO / "assets"
COW_OBJ = ASSETS / "cow.obj"
SCENES = ASSETS / "scenes"


def cli_path() -> pathlib.Path:
    """The obbtree binary: $OBBTREE_BIN (scripts/test sets it), else target/release/obbtree.
    Missing is a failure, never a skip: the CLI is what the answers are checked against."""
    path = pathlib.Path(os.environ.get("OBBTREE_BIN", REPO / "target" / "release" / "obbtree"))
    if not path.is_file():
        pytest.fail(f"obbtree CLI not found at {path}: run `cargo build --release` or set OBBTREE_BIN")
    return path


def run_cli(*args, check=True):
    """Runs the CLI; returns the CompletedProcess (text)."""
    done = subprocess.run([str(cli_path()), *map(str, args)], capture_output=True, text=True)
    if check and done.returncode != 0:
        raise AssertionError(f"obbtree {' '.join(map(str, args))} failed: {done.stderr}")
    return done


def cli_json_lines(*args):
    """The JSON lines the CLI prints."""
    return [json.loads(line) for line in run_cli(*args).stdout.splitlines() if line.strip()]


@pytest.fixture(scope="session")
def cli():
    return cli_path()


@pytest.fixture(scope="session")
def trees(tmp_path_factory):
    """The cow built by the CLI (f32 and f64) and a small CAD-like part, in a temp dir."""
    d = tmp_path_factory.mktemp("trees")
    out = {}
    for precision in ["f32", "f64"]:
        path = d / f"cow-{precision}.obbt"
        run_cli("build", COW_OBJ, "-o", path, "--precision", precision, "--quiet")
        out[f"cow_{precision}"] = path
    out["gripper"] = SCENES / "gripper.obbt"
    out["dir"] = d
    return out


@pytest.fixture()
def cow(trees):
    with obbtree.open(trees["cow_f32"]) as t:
        yield t


@pytest.fixture()
def cow64(trees):
    with obbtree.open(trees["cow_f64"]) as t:
        yield t


def random_rotations(rng, n):
    """n uniformly random rotations (from unit quaternions), (n, 3, 3)."""
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=1,
    )


def random_poses(n, spread=1.0, seed=7):
    """n random (4, 4) poses: random rotations, translations uniform in [-spread, spread]^3."""
    rng = np.random.default_rng(seed)
    poses = np.tile(np.eye(4), (n, 1, 1))
    poses[:, :3, :3] = random_rotations(rng, n)
    poses[:, :3, 3] = rng.uniform(-spread, spread, size=(n, 3))
    return poses


def rt12(poses):
    """(N, 4, 4) poses as (N, 12): R row-major, then t."""
    poses = np.asarray(poses)
    return np.concatenate([poses[:, :3, :3].reshape(-1, 9), poses[:, :3, 3]], axis=1)


def write_pose_file(path, poses_a, poses_b):
    """A CLI --poses file (format rt): pose A then pose B per line, numbers as repr() so
    that the CLI reads back the same f64 values."""
    a, b = rt12(poses_a), rt12(poses_b)
    with open(path, "w") as f:
        for x, y in zip(a, b):
            f.write(" ".join(repr(float(v)) for v in np.concatenate([x, y])) + "\n")
    return path


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Under scripts/test (OBBTREE_TEST_STRICT=1) a skip is a failure: the optional inputs
    (trimesh, dask) are installed there, so a skip would hide a test that did not run."""
    outcome = yield
    report = outcome.get_result()
    if os.environ.get("OBBTREE_TEST_STRICT") == "1" and report.skipped:
        report.outcome = "failed"
        report.longrepr = f"skipped under OBBTREE_TEST_STRICT=1: {report.longrepr}"
