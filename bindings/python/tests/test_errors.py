"""Every bad input raises the right exception with the library's message; a damaged file
and a closed tree raise, never crash."""

import gc
import shutil

import numpy as np
import pytest

import obbtree
from conftest import COW_OBJ, random_poses, run_cli

I = np.eye(4)


def test_exception_hierarchy():
    for cls in [obbtree.MeshError, obbtree.FormatError, obbtree.PoseError, obbtree.SceneError,
                obbtree.OptionError, obbtree.FileError]:
        assert issubclass(cls, obbtree.Error)
        assert cls.__module__ == "obbtree" and cls.__doc__
    assert issubclass(obbtree.PoseError, ValueError)
    assert issubclass(obbtree.OptionError, ValueError)
    assert issubclass(obbtree.FileError, OSError)


# --- poses -------------------------------------------------------------------------------

def bad_batch(n=6, at=4):
    b = random_poses(n, spread=0.5, seed=2)
    return b, at


@pytest.mark.parametrize(
    "spoil, message",
    [
        (lambda p: p.__setitem__((0, 1), np.nan), r"pose value 1 is not finite \(NaN\)"),
        (lambda p: p.__setitem__((1, 3), np.inf), r"pose value 7 is not finite \(inf\)"),
        (lambda p: p.__setitem__((slice(0, 3), 0), p[:3, 0] * 1.1), "rotation is not orthonormal"),
        (lambda p: p.__setitem__((slice(0, 3), 2), -p[:3, 2]), "rotation has determinant -1.000000: a reflection"),
        (lambda p: p.__setitem__((3, 0), 0.5), "a 4x4 pose matrix must end in the row 0 0 0 1"),
    ],
)
def test_bad_pose_in_batch_names_index(cow, spoil, message):
    b, at = bad_batch()
    spoil(b[at])
    with pytest.raises(obbtree.PoseError, match=f"^poses_b: pose {at}: {message}") as raised:
        obbtree.collide(cow, I, cow, b)
    assert isinstance(raised.value, ValueError)
    # The same in the (N, 12) form, and on side A, for every query.
    for query in [lambda x, y: obbtree.collide(cow, x, cow, y),
                  lambda x, y: obbtree.distance(cow, x, cow, y),
                  lambda x, y: obbtree.within(cow, x, cow, y, 0.1),
                  lambda x, y: obbtree.span(cow, x, cow, y)]:
        with pytest.raises(obbtree.PoseError, match=f"^poses_a: pose {at}: "):
            query(b, I)


def test_single_bad_pose(cow):
    p = I.copy()
    p[0, 0] = 2
    with pytest.raises(obbtree.PoseError, match="^poses_a: rotation is not orthonormal"):
        obbtree.distance(cow, p, cow, I)


@pytest.mark.parametrize(
    "pose",
    [np.eye(3), np.zeros(7), np.zeros((2, 3, 4)), np.zeros((5, 16)), np.zeros((2, 2, 4, 4)), 1.0,
     (np.eye(3), np.zeros(4)), (np.eye(3),), (np.eye(3), np.zeros(3), 1), ["a", "b"]],
)
def test_wrongly_shaped_poses(cow, pose):
    with pytest.raises(obbtree.PoseError, match="^poses_b: .*expected a \\(4, 4\\) matrix|^poses_b: an \\(R, t\\) pair needs"):
        obbtree.collide(cow, I, cow, pose)


def test_batches_of_different_lengths(cow):
    with pytest.raises(obbtree.PoseError, match="poses_a holds 3 poses and poses_b 4"):
        obbtree.collide(cow, np.tile(I, (3, 1, 1)), cow, np.tile(I, (4, 1, 1)))


def test_orthonormalize_refuses_beyond_repair(cow):
    p = I.copy()
    p[:3, :3] *= 1.1
    with pytest.raises(obbtree.PoseError, match="a scaled or sheared matrix"):
        obbtree.collide(cow, I, cow, p, orthonormalize=True)
    p = I.copy()
    p[2, 2] = -1
    with pytest.raises(obbtree.PoseError, match="reflection"):
        obbtree.collide(cow, I, cow, p, orthonormalize=True)


# --- options -----------------------------------------------------------------------------

@pytest.mark.parametrize(
    "call, message",
    [
        (lambda t: obbtree.distance(t, I, t, I, rel_err=-1), "rel_err must be"),
        (lambda t: obbtree.distance(t, I, t, I, abs_err=float("nan")), "abs_err must be"),
        (lambda t: obbtree.distance(t, I, t, I, max_distance=-1), "max_distance must be"),
        # As for closest: nothing is nearer than 0, so 0 could only answer "beyond".
        (lambda t: obbtree.distance(t, I, t, I, max_distance=0), "max_distance must be greater"),
        (lambda t: obbtree.within(t, I, t, I, -0.5), "tolerance must be"),
        (lambda t: obbtree.collide(t, I, t, I, threads=0), "threads must be None or 1 to 1024"),
        (lambda t: obbtree.collide(t, I, t, I, rule="largest"), "rule \"largest\" is not one of"),
    ],
)
def test_bad_options(cow, call, message):
    with pytest.raises(obbtree.OptionError, match=message) as raised:
        call(cow)
    assert isinstance(raised.value, ValueError)


def test_messages_equal_the_clis_for_options(trees):
    # The same message, each naming the option as its caller writes it: the keyword
    # here, the flag on the command line.
    done = run_cli("distance", trees["cow_f32"], trees["cow_f32"], "--rel-err", "-1", check=False)
    with pytest.raises(obbtree.OptionError) as raised:
        t = obbtree.open(trees["cow_f32"])
        obbtree.distance(t, I, t, I, rel_err=-1)
    message = str(raised.value)
    assert message.startswith("rel_err must be")
    assert done.returncode == 1 and "--rel-err" + message[len("rel_err"):] in done.stderr


def test_wrong_argument_types(cow):
    with pytest.raises(TypeError):
        obbtree.collide("cow.obbt", I, cow, I)
    with pytest.raises(TypeError):
        obbtree.build(42)


# --- meshes and build options ------------------------------------------------------------

TRI = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])


@pytest.mark.parametrize(
    "vertices, faces, message",
    [
        (TRI, [[0, 1, 3]], r"<memory>: face 0: face index 3 out of range \(3 vertices\)"),
        (TRI, [[0, 1, 2], [0, -1, 2]], r"<memory>: face 1: face index -1 out of range \(3 vertices\)"),
        (np.array([[0.0, 0, 0], [1, np.nan, 0], [0, 1, 0]]), [[0, 1, 2]], "<memory>: vertex 1: non-finite vertex coordinate NaN"),
        (TRI, np.zeros((0, 3), dtype=int), "<memory>: no faces"),
        (TRI[:, :2], [[0, 1, 2]], r"vertices must be an \(n, 3\) array"),
        (TRI, [[0, 1]], r"faces must be an \(m, 3\) array"),
        (TRI, [[0.0, 1.0, 2.0]], "faces must be integer vertex indices"),
    ],
)
def test_bad_meshes(vertices, faces, message):
    with pytest.raises(obbtree.MeshError, match=message):
        obbtree.build((vertices, faces))


def test_mesh_files(tmp_path):
    with pytest.raises(obbtree.FileError, match="cannot read") as raised:
        obbtree.build(tmp_path / "missing.obj")
    assert isinstance(raised.value, OSError)
    junk = tmp_path / "junk.obj"
    junk.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(obbtree.MeshError, match="junk.obj:3"):
        obbtree.build(junk)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"leaf_size": 0}, "leaf size 0 is out of range"),
        ({"scale": -1.0}, "scale -1 is not a finite number greater than 0"),
        ({"bv": "box"}, "bv \"box\" is not one of obb, aabb, sphere"),
        ({"precision": "f16"}, "precision \"f16\" is not one of f32, f64"),
        ({"sphere_fit": "minimal"}, "--sphere-fit minimal applies to sphere trees"),
    ],
)
def test_bad_build_options(kwargs, message):
    with pytest.raises(obbtree.OptionError, match=message):
        obbtree.build((TRI, [[0, 1, 2]]), **kwargs)


def test_build_refuses_to_overwrite(tmp_path):
    mesh = tmp_path / "m.obj"
    shutil.copy(COW_OBJ, mesh)
    with pytest.raises(obbtree.FileError, match="is the input"):
        obbtree.build(mesh, mesh)
    other = tmp_path / "notes.txt"
    other.write_text("keep me")
    with pytest.raises(obbtree.FileError, match="exists and is not an .obbt file"):
        obbtree.build(mesh, other)
    assert other.read_text() == "keep me"
    obbtree.build(mesh, other, force=True).verify()


# --- files -------------------------------------------------------------------------------

def test_open_missing_and_directory(tmp_path):
    with pytest.raises(obbtree.FileError, match="No such file"):
        obbtree.open(tmp_path / "none.obbt")
    with pytest.raises(obbtree.FileError, match="is a directory"):
        obbtree.open(tmp_path)


def test_open_foreign_and_truncated(tmp_path, trees):
    junk = tmp_path / "junk.obbt"
    junk.write_bytes(b"hello world" * 20)
    with pytest.raises(obbtree.FormatError, match="bad signature"):
        obbtree.open(junk)
    short = tmp_path / "short.obbt"
    short.write_bytes(trees["cow_f32"].read_bytes()[:1000])
    with pytest.raises(obbtree.FormatError):
        obbtree.open(short)


def flipped(tmp_path, source, offset):
    data = bytearray(source.read_bytes())
    data[offset] ^= 0x40
    path = tmp_path / f"flip-{offset}.obbt"
    path.write_bytes(bytes(data))
    return path


def test_damaged_header_fails_open_like_the_cli(tmp_path, trees):
    path = flipped(tmp_path, trees["cow_f32"], 20)
    done = run_cli("info", path, check=False)
    with pytest.raises(obbtree.FormatError) as raised:
        obbtree.open(path)
    assert done.returncode == 1 and str(raised.value) in done.stderr


def test_damaged_section_fails_verify_like_the_cli(tmp_path, trees):
    t = obbtree.open(trees["cow_f32"])
    nodes = next(s for s in t.info["sections"] if s["name"] == "nodes")
    path = flipped(tmp_path, trees["cow_f32"], nodes["offset"] + 100)
    damaged = obbtree.open(path)  # the O(1) open does not read sections
    done = run_cli("verify", path, check=False)
    with pytest.raises(obbtree.FormatError, match="verify failed: .*checksum") as raised:
        damaged.verify()
    assert done.returncode == 1 and str(raised.value) in done.stderr
    # Queries on the unverified damaged tree answer or raise, never crash.
    for pose in random_poses(50, spread=0.3, seed=9):
        try:
            obbtree.collide(damaged, I, damaged, pose)
            obbtree.distance(damaged, I, damaged, pose)
        except obbtree.Error:
            pass


def test_every_flipped_byte_of_a_small_tree_is_handled(tmp_path):
    """Flip each byte of a small tree in turn: open or verify raise FormatError, and
    queries on what opens never crash."""
    src = tmp_path / "small.obbt"
    obbtree.build((TRI, [[0, 1, 2]]), src)
    data = src.read_bytes()
    refused = 0
    for offset in range(0, len(data), 3):
        path = flipped(tmp_path, src, offset)
        try:
            t = obbtree.open(path)
            t.verify()
        except obbtree.FormatError:
            refused += 1
            try:
                t = obbtree.open(path)
                obbtree.collide(t, I, t, I)
                obbtree.distance(t, I, t, I)
            except obbtree.Error:
                pass
        path.unlink()
    assert refused > 0.9 * len(range(0, len(data), 3))


# --- closed trees ------------------------------------------------------------------------

def test_closed_tree_raises(trees):
    t = obbtree.open(trees["cow_f32"])
    t.close()
    t.close()  # idempotent
    assert t.closed
    for use in [lambda: t.info, lambda: t.verify(), lambda: t.vertices, lambda: t.faces,
                lambda: t.source_ids, lambda: obbtree.collide(t, I, t, I),
                lambda: obbtree.distance(t, I, t, I), lambda: obbtree.within(t, I, t, I, 0.1),
                lambda: obbtree.span(t, I, t, I)]:
        with pytest.raises(obbtree.Error, match="the tree is closed"):
            use()
    assert "closed" in repr(t)


def test_context_manager_closes(trees):
    with obbtree.open(trees["cow_f32"]) as t:
        assert not t.closed
    assert t.closed
    with pytest.raises(obbtree.Error):
        obbtree.collide(t, I, t, I)


def test_views_outlive_close(trees):
    """A view of the mapped file keeps the map alive: reading it after close (and after the
    tree object is gone) is safe and gives the same numbers."""
    t = obbtree.open(trees["cow_f32"])
    v, f, ids = t.vertices, t.faces, t.source_ids
    copy = v.copy(), f.copy(), ids.copy()
    t.close()
    del t
    gc.collect()
    assert np.array_equal(v, copy[0]) and np.array_equal(f, copy[1]) and np.array_equal(ids, copy[2])
    assert float(v.sum()) == float(copy[0].sum())
