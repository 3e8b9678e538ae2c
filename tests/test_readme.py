"""Every Python block of README.md runs on its own, as written, in a fresh interpreter.

Blocks are found by their fence (```python or ```py), whatever section they sit in, so a block
added later is tested without editing this file. Each runs in a temporary directory, so files
it writes do not land in the repository.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parent.parent / "README.md"
FENCE = re.compile(r"^```(?:python|py)[ \t]*\n(.*?)^```", re.DOTALL | re.MULTILINE)
TIMEOUT_S = 300


def python_blocks(text: str) -> list[tuple[str, str]]:
    """``(id, code)`` per Python block; the id is its section's heading and its rank there."""
    blocks = []
    for match in FENCE.finditer(text):
        headings = re.findall(r"^#+ +(.+)$", text[: match.start()], re.MULTILINE)
        section = re.sub(r"\W+", "-", headings[-1]).strip("-").lower() if headings else "top"
        rank = sum(block_id.rsplit("-", 1)[0] == section for block_id, _ in blocks) + 1
        blocks.append((f"{section}-{rank}", match.group(1)))
    return blocks


BLOCKS = python_blocks(README.read_text(encoding="utf-8"))


def test_readme_has_python_blocks():
    assert len(BLOCKS) >= 1, f"no ```python block found in {README}; check the fence pattern"


@pytest.mark.parametrize("code", [code for _, code in BLOCKS], ids=[i for i, _ in BLOCKS])
def test_readme_block_runs_on_its_own(code, tmp_path):
    done = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env={**os.environ, "OMP_NUM_THREADS": "1"},  # two shared cores: one torch thread
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
    )
    assert done.returncode == 0, f"README block failed:\n{code}\n--- stderr ---\n{done.stderr}"
