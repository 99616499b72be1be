"""Trees: zero-copy views, in-memory builds, trimesh input, pickling."""

import pickle
import warnings

import numpy as np
import pytest

import obbtree
from conftest import COW_OBJ, random_poses

I = np.eye(4)


def load_obj(path):
    """Vertices and triangle faces of a triangle-only OBJ, read here independently."""
    v, f = [], []
    for line in open(path):
        parts = line.split()
        if parts and parts[0] == "v":
            v.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "f":
            f.append([int(x.split("/")[0]) - 1 for x in parts[1:4]])
    return np.array(v), np.array(f)


def test_views_are_zero_copy_and_read_only(cow, cow64):
    v = cow.vertices
    assert v.dtype == np.float32 and v.shape == (cow.info["vertices"], 3)
    assert cow64.vertices.dtype == np.float64
    for t in [cow, cow64]:
        for a in [t.vertices, t.faces, t.source_ids]:
            assert not a.flags.writeable and not a.flags.owndata
            with pytest.raises(ValueError):
                a[0] = 0
            # Two reads view the same bytes: nothing was copied.
            assert np.shares_memory(a, getattr(t, "vertices" if a.ndim == 2 and a.dtype.kind == "f" else
                                               "faces" if a.ndim == 2 else "source_ids"))
        assert t.faces.dtype == np.uint32 and t.source_ids.dtype == np.uint32
    # The f64 tree stores the mesh's vertices exactly; the faces, in leaf order, are the
    # input faces permuted by source_ids.
    verts, faces = load_obj(COW_OBJ)
    assert np.array_equal(cow64.vertices, verts)
    assert np.array_equal(cow.vertices, verts.astype(np.float32))
    assert np.array_equal(cow64.faces, faces[cow64.source_ids])
    assert sorted(cow64.source_ids.tolist()) == list(range(len(faces)))


def test_in_memory_build_equals_file_build(tmp_path, cow):
    verts, faces = load_obj(COW_OBJ)
    mem = obbtree.build((verts, faces))
    assert mem.path is None
    assert mem.info == cow.info
    poses = random_poses(30, spread=0.5, seed=4)
    assert np.array_equal(obbtree.collide(mem, I, mem, poses).contacts,
                          obbtree.collide(cow, I, cow, poses).contacts)
    # Queries mixing an in-memory tree and a mapped one.
    assert np.array_equal(obbtree.distance(mem, I, cow, poses).distance,
                          obbtree.distance(cow, I, cow, poses).distance)


def test_build_warns_when_f32_is_coarse_for_the_model(tmp_path):
    verts, faces = load_obj(COW_OBJ)
    far = verts + [30_000.0, -20_000.0, 10_000.0]
    with pytest.warns(UserWarning, match=r"collapsed to zero area: build with "
                      r"center=True or precision=\"f64\" to keep the detail") as caught:
        obbtree.build((far, faces))
    # Attributed to the line that called obbtree.build.
    ours = [w for w in caught if "collapsed to zero area" in str(w.message)]
    assert len(ours) == 1 and ours[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        obbtree.build((far, faces), center=True)
        obbtree.build((far, faces), precision="f64")
        obbtree.build((verts, faces))


def test_build_returns_open_mapped_tree(tmp_path):
    out = tmp_path / "cow.obbt"
    t = obbtree.build(str(COW_OBJ), str(out))
    assert str(t.path) == str(out) and out.exists()
    t.verify()
    assert obbtree.open(out).info == t.info


def test_compact_layout_is_smaller_and_answers_alike(tmp_path, cow):
    out = tmp_path / "cow-compact.obbt"
    small = obbtree.build(str(COW_OBJ), str(out), layout="compact")
    small.verify()
    info = small.info
    assert info["layout"] == "compact" and info["version"] == "1.2"
    assert info["leaf_size"] == 4
    assert cow.info["layout"] == "fast"
    assert info["bytes_per_triangle"] < cow.info["bytes_per_triangle"] / 3
    poses = random_poses(30, spread=0.5, seed=5)
    fast_hits = obbtree.collide(cow, I, cow, poses)
    small_hits = obbtree.collide(small, I, small, poses)
    assert np.array_equal(fast_hits.contacts, small_hits.contacts)
    assert fast_hits.contacts.sum() > 0
    assert np.allclose(obbtree.distance(small, I, small, poses).distance,
                       obbtree.distance(cow, I, cow, poses).distance, rtol=1e-12, atol=0)
    # Trees of two layouts are not paired; a layout without f32 boxes is refused.
    with pytest.raises(obbtree.Error, match="compact"):
        obbtree.collide(cow, I, small, I)
    with pytest.raises(obbtree.OptionError, match="compact layout"):
        obbtree.build(str(COW_OBJ), layout="compact", precision="f64")
    with pytest.raises(obbtree.OptionError, match="layout"):
        obbtree.build(str(COW_OBJ), layout="tiny")


def test_trimesh_input():
    trimesh = pytest.importorskip("trimesh", reason="trimesh is installed by scripts/test")
    mesh = trimesh.load(str(COW_OBJ), process=False, force="mesh")
    t = obbtree.build(mesh)
    reference = obbtree.build(COW_OBJ)
    assert t.info == reference.info
    poses = random_poses(20, spread=0.5, seed=8)
    assert np.array_equal(obbtree.distance(t, I, t, poses).distance,
                          obbtree.distance(reference, I, reference, poses).distance)
    # A trimesh primitive: a box of side 1 and a copy 0.9 away touch; 1.1 away they do not.
    box = obbtree.build(trimesh.creation.box(extents=[1, 1, 1]), precision="f64")
    moved = np.eye(4)
    moved[0, 3] = 0.9
    assert obbtree.collide(box, I, box, moved).contacts[0] > 0
    moved[0, 3] = 1.5
    assert obbtree.distance(box, I, box, moved).distance[0] == pytest.approx(0.5, abs=1e-12)


def test_pickle_reopens(tmp_path, trees):
    t = obbtree.open(trees["cow_f32"])
    back = pickle.loads(pickle.dumps(t))
    assert back.info == t.info and str(back.path) == str(t.path)
    mem = obbtree.build(COW_OBJ)
    back = pickle.loads(pickle.dumps(mem))
    assert back.info == mem.info and back.path is None
    t.close()
    with pytest.raises(obbtree.Error):
        pickle.dumps(t)


def test_repr_and_help():
    assert "first_contact" in obbtree.collide.__doc__ and "poses_a" in obbtree.collide.__doc__
    for f in [obbtree.build, obbtree.open, obbtree.distance, obbtree.within, obbtree.span,
              obbtree.Tree, obbtree.Scene, obbtree.Scene.load, obbtree.Scene.step,
              obbtree.CollideResult, obbtree.DistanceResult, obbtree.Tree.verify]:
        assert f.__doc__ and len(f.__doc__) > 40, f
