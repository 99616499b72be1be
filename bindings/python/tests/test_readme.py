"""The READMEs' "From Python" examples (the binding's and the root's) run as written."""

import os
import pathlib
import re
import subprocess
import sys

from conftest import HERE, REPO


import pytest


@pytest.mark.parametrize("readme", [HERE.parent / "README.md", REPO / "README.md"],
                         ids=["binding", "root"])
def test_readme_example(tmp_path, readme):
    text = readme.read_text()
    section = text.split("## From Python", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    script = tmp_path / "example.py"
    script.write_text(code)
    env = dict(os.environ, OBBTREE_ASSETS=str(REPO / "assets"))
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "colliding poses:" in done.stdout


def test_root_readme_one_model_example(tmp_path):
    text = (REPO / "README.md").read_text()
    section = text.split("## One model: rays, closest points, inside", 1)[1].split("\n## ", 1)[0]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    script = tmp_path / "one_model.py"
    script.write_text(code)
    env = dict(os.environ, OBBTREE_ASSETS=str(REPO / "assets"))
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "depth image hits:" in done.stdout and "inside:" in done.stdout
