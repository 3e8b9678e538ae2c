#!/usr/bin/env bash
# Creates .venv and installs simoun with every extra. torch is pinned and installed first:
# an unpinned torch pulls a multi-GB CUDA build, while torch==2.13.0 resolves to a CPU wheel.
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet "torch==2.13.0"
.venv/bin/python -m pip install --quiet -e ".[all,dev]"
