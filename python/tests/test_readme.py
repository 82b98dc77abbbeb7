"""The README's Python quick start runs as written."""

from __future__ import annotations

import pathlib
import re


def test_readme_python_block_runs(repo: pathlib.Path) -> None:
    text = (repo / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "the README has a Python quick start"
    for block in blocks:
        exec(compile(block, "README.md", "exec"), {})
