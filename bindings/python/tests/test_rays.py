"""obbtree.ray: one posed model against many rays, checked against a brute-force
Möller–Trumbore over every triangle, the CLI, and closed meshes' parity."""

import json

import numpy as np
import pytest

import obbtree
from conftest import run_cli


def brute_force(vertices, faces, origins, directions):
    """Per ray, the smallest t ≥ 0 at which it meets a triangle (Möller–Trumbore over
    all of them), its triangle, and the smallest margin of its barycentric weights."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    e1, e2 = b - a, c - a
    out = []
    for o, d in zip(origins, directions):
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = o - a
            u = np.einsum("ij,ij->i", s, p) / det
            q = np.cross(s, e1)
            v = (q @ d) / det
            t = np.einsum("ij,ij->i", e2, q) / det
        margin = np.minimum(np.minimum(u, v), 1 - u - v)
        ok = (margin >= 0) & (t >= 0) & np.isfinite(t)
        if not ok.any():
            out.append((np.inf, -1, np.inf))
            continue
        k = np.flatnonzero(ok)[np.argmin(t[ok])]
        out.append((t[k], k, margin[k]))
    return out


def aimed_rays(vertices, faces, n, seed):
    """Rays from a sphere around the model at random triangles' centroids (clear hits,
    away from edges) and at random points (mostly misses)."""
    rng = np.random.default_rng(seed)
    centre = vertices.mean(axis=0)
    radius = np.linalg.norm(vertices - centre, axis=1).max()
    u = rng.normal(size=(n, 3))
    origins = centre + 2 * radius * u / np.linalg.norm(u, axis=1)[:, None]
    tri = faces[rng.integers(len(faces), size=n)]
    targets = vertices[tri].mean(axis=1)
    targets[::3] = centre + rng.uniform(-radius, radius, size=(len(targets[::3]), 3))
    return origins, targets - origins


@pytest.mark.parametrize("precision", ["f64", "f32"])
def test_closest_hits_match_brute_force(cow, precision):
    vertices = np.asarray(cow.vertices, dtype=np.float64)
    faces = np.asarray(cow.faces, dtype=np.int64)
    tree = obbtree.build((vertices, faces), precision=precision)
    vertices = np.asarray(tree.vertices, dtype=np.float64)
    origins, directions = aimed_rays(vertices, faces, 300, seed=4)
    h = obbtree.ray(tree, np.eye(4), origins, directions)
    brute = brute_force(vertices, faces, origins, directions)
    clear = 0
    for i, (t, k, margin) in enumerate(brute):
        if margin > 1e-9 or not np.isfinite(t):
            clear += 1
            assert h.hit[i] == np.isfinite(t)
            if h.hit[i]:
                assert h.tri[i] == k or abs(h.t[i] - t) <= 1e-9 * t
                assert abs(h.t[i] - t) <= 1e-9 * t
    assert clear > 250
    # What a hit must satisfy: its point is the ray's at t, and the weights give it too.
    hit = h.hit
    assert np.allclose(h.point[hit], origins[hit] + h.t[hit, None] * directions[hit], atol=1e-12)
    corners = vertices[faces[h.tri[hit]]]
    assert np.allclose(np.einsum("ij,ijk->ik", h.barycentric[hit], corners), h.point[hit],
                       atol=1e-9)
    assert np.allclose(np.linalg.norm(h.normal[hit], axis=1), 1.0)
    for a in (h.hit, h.t, h.tri, h.point, h.barycentric, h.normal):
        assert not a.flags.writeable


def test_any_and_all_agree_with_closest(cow):
    vertices = np.asarray(cow.vertices, dtype=np.float64)
    origins, directions = aimed_rays(vertices, np.asarray(cow.faces), 200, seed=9)
    pose = np.eye(4)
    pose[:3, 3] = [0.3, -0.2, 0.1]
    origins = origins + pose[:3, 3]
    closest = obbtree.ray(cow, pose, origins, directions)
    any_ = obbtree.ray(cow, pose, origins, directions, mode="any")
    every = obbtree.ray(cow, pose, origins, directions, mode="all")
    assert np.array_equal(any_.hit, closest.hit)
    assert np.array_equal(every.count > 0, closest.hit)
    offsets = np.concatenate([[0], np.cumsum(every.count)])
    for i in np.flatnonzero(closest.hit):
        ts = every.t[offsets[i]:offsets[i + 1]]
        assert ts[0] == closest.t[i] and np.all(np.diff(ts) >= 0)
        assert any_.t[i] in ts
    # t_max cuts the ray to a segment.
    cut = obbtree.ray(cow, pose, origins, directions, t_max=0.5)
    assert np.array_equal(cut.hit, closest.hit & (closest.t <= 0.5))


def test_rays_through_a_closed_mesh_cross_it_an_even_number_of_times():
    # A cube of 12 triangles, rays aimed exactly at its corners and edge midpoints from
    # outside: a ray slipping through an edge or hitting it twice breaks the parity.
    v = np.array([[x, y, z] for z in (-1.0, 1.0) for y in (-1.0, 1.0) for x in (-1.0, 1.0)])
    f = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    cube = obbtree.build((v, f))
    targets = np.concatenate([v, (v[f[:, 0]] + v[f[:, 1]]) / 2, (v[f[:, 1]] + v[f[:, 2]]) / 2])
    rng = np.random.default_rng(2)
    origins = targets + rng.normal(size=targets.shape) * 4
    origins = origins[np.abs(origins).max(axis=1) > 1.5]
    targets = targets[: len(origins)]
    every = obbtree.ray(cube, np.eye(4), origins, targets - origins, mode="all")
    assert np.all(every.count % 2 == 0)
    inside = obbtree.ray(cube, np.eye(4), [0.1, 0.2, -0.1], targets, mode="all")
    assert np.all(inside.count == 1)


def test_ray_matches_the_cli(tmp_path, cow):
    vertices = np.asarray(cow.vertices, dtype=np.float64)
    origins, directions = aimed_rays(vertices, np.asarray(cow.faces), 30, seed=1)
    h = obbtree.ray(cow, np.eye(4), origins, directions)
    path = tmp_path / "rays.txt"
    np.savetxt(path, np.hstack([origins, directions]), fmt="%.17g")
    lines = [json.loads(l) for l in run_cli("ray", cow.path, "--rays", path, "--json")
             .stdout.splitlines()]
    assert len(lines) == len(origins)
    for i, line in enumerate(lines):
        assert line["hit"] == h.hit[i]
        if line["hit"]:
            assert line["tri"] == h.tri[i]
            assert line["t"] == pytest.approx(h.t[i], rel=1e-15)


def test_bad_rays_raise(cow):
    with pytest.raises(obbtree.OptionError, match="ray 1: direction must not be zero"):
        obbtree.ray(cow, np.eye(4), [0, 0, 0], [[1, 0, 0], [0, 0, 0]])
    with pytest.raises(obbtree.OptionError, match="ray 0: origin"):
        obbtree.ray(cow, np.eye(4), [np.nan, 0, 0], [1, 0, 0])
    with pytest.raises(obbtree.OptionError, match="shape"):
        obbtree.ray(cow, np.eye(4), [0, 0], [1, 0, 0])
    with pytest.raises(obbtree.OptionError, match="differ in length"):
        obbtree.ray(cow, np.eye(4), np.zeros((2, 3)), np.ones((3, 3)))
    with pytest.raises(obbtree.OptionError, match="t_max"):
        obbtree.ray(cow, np.eye(4), [0, 0, 0], [1, 0, 0], t_max=0)
    with pytest.raises(obbtree.OptionError, match="mode"):
        obbtree.ray(cow, np.eye(4), [0, 0, 0], [1, 0, 0], mode="first")
    with pytest.raises(obbtree.PoseError):
        obbtree.ray(cow, np.eye(4) * 2, [0, 0, 0], [1, 0, 0])


def test_batches_check_options_when_empty_and_name_a_bad_ray_by_its_index(cow):
    # Batches are cast in chunks: an empty one still checks its options, and a bad ray
    # past the first chunk is named by its index in the whole batch.
    for mode in ("closest", "any", "all"):
        with pytest.raises(obbtree.OptionError, match="t_max"):
            obbtree.ray(cow, np.eye(4), np.zeros((0, 3)), np.zeros((0, 3)), t_max=-1.0, mode=mode)
    empty = obbtree.ray(cow, np.eye(4), np.zeros((0, 3)), np.zeros((0, 3)))
    assert empty.hit.shape == (0,) and empty.point.shape == (0, 3)
    directions = np.tile([1.0, 0.0, 0.0], (10_000, 1))
    directions[9_000] = 0.0
    with pytest.raises(obbtree.OptionError, match="9000"):
        obbtree.ray(cow, np.eye(4), np.zeros((10_000, 3)), directions)
