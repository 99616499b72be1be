"""Scenes: the same reports and summary as `obbtree scene --json`."""

import shutil

import numpy as np
import pytest

import obbtree
from conftest import SCENES, cli_json_lines, run_cli

CELL = SCENES / "cell.toml"


def without_time(summary):
    s = dict(summary)
    for k in ["seconds", "frames_per_second"]:
        s.pop(k)
    s["narrow"] = {k: {kk: vv for kk, vv in v.items() if kk != "seconds"} for k, v in s["narrow"].items()}
    return s


@pytest.mark.parametrize("naive", [False, True])
def test_run_equals_cli(naive):
    lines = cli_json_lines("scene", CELL, "--json", *(["--naive"] if naive else []))
    *frames, summary = lines
    scene = obbtree.Scene.load(CELL, naive=naive)
    reports = scene.run()
    assert len(reports) == len(frames) > 10
    assert reports == frames
    assert without_time(scene.summary) == without_time(summary["summary"])


def test_step_with_poses():
    scene = obbtree.Scene.load(CELL)
    assert scene.names[0] == "base" and "gripper" in scene.names
    first = scene.step()
    assert first["frame"] == 0
    # Move the gripper onto the part: a contact starts.
    part = obbtree.Scene.load(CELL)
    pose = np.eye(4)
    pose[:3, 3] = [1.3, 0, 0.6]
    report = part.step({"gripper": pose})
    kinds = {(e["a"], e["b"], e["event"]) for e in report["events"]}
    assert ("gripper", "part", "contact_started") in kinds
    # (R, t) and 12 numbers give the same frame.
    other = obbtree.Scene.load(CELL)
    assert other.step({"gripper": (np.eye(3), [1.3, 0, 0.6])}) == report
    again = obbtree.Scene.load(CELL)
    assert again.step({"gripper": [1, 0, 0, 0, 1, 0, 0, 0, 1, 1.3, 0, 0.6]}) == report
    assert part.summary["frames"] == 1


def test_step_errors():
    scene = obbtree.Scene.load(CELL)
    with pytest.raises(obbtree.SceneError, match='no object named "robot"'):
        scene.step({"robot": np.eye(4)})
    with pytest.raises(obbtree.PoseError, match="rotation is not orthonormal"):
        scene.step({"gripper": 2 * np.eye(4) - np.diag([0, 0, 0, 1])})
    with pytest.raises(obbtree.PoseError, match="one pose, not a batch"):
        scene.step({"gripper": np.tile(np.eye(4), (2, 1, 1))})


def test_an_unreadable_scene_file_is_a_file_error(tmp_path):
    missing = tmp_path / "missing.toml"
    with pytest.raises(obbtree.FileError, match="missing.toml: cannot read") as raised:
        obbtree.Scene.load(missing)
    assert isinstance(raised.value, OSError)
    done = run_cli("scene", missing, check=False)
    assert done.returncode == 1 and str(raised.value) in done.stderr


def test_bad_scene_file_message_equals_cli(tmp_path):
    shutil.copytree(SCENES, tmp_path / "scenes")
    bad = tmp_path / "scenes" / "bad.toml"
    text = CELL.read_text().replace('b = "fixtures"', 'b = "fixturez"')
    bad.write_text(text.replace('frames = "cell.jsonl"', ""))
    done = run_cli("scene", bad, check=False)
    with pytest.raises(obbtree.SceneError) as raised:
        obbtree.Scene.load(bad)
    assert done.returncode == 1 and str(raised.value) in done.stderr
    assert "fixturez" in str(raised.value)
