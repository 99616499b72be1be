"""The README's "From Python" example runs as written (and prints what it says)."""

import os
import pathlib
import re
import subprocess
import sys

from conftest import HERE, REPO


def test_readme_example(tmp_path):
    text = (HERE.parent / "README.md").read_text()
    section = text.split("## From Python", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    script = tmp_path / "example.py"
    script.write_text(code)
    env = dict(os.environ, OBBTREE_ASSETS=str(REPO / "assets"))
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "colliding poses:" in done.stdout
