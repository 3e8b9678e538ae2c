"""simoun_agent.config is a leaf: it imports no torch and nothing of simoun_agent outside itself,
so reading a run's config (simoun-report) or checking a command line loads no networks. The
package's ``__init__`` loads one more module, ``simoun_agent.moved`` (the lab's former names,
standard library only)."""

import subprocess
import sys
from pathlib import Path

from test_layers import imports

import simoun_agent.config

PACKAGE = Path(simoun_agent.config.__file__).parent
ALLOWED = {"gymnasium", "numpy"}
"""Third-party packages the configuration may import (besides the standard library)."""

CHILD = """
import sys
from simoun_agent.config import TrainConfig, from_dict, resolve, to_dict
TrainConfig()
config = resolve("cpu", {"agent.recipe": "drq", "device": "cpu", "image_size": 32})
assert from_dict(to_dict(config)) == config
outside = [m for m in sys.modules if m.startswith("simoun_agent.")
           and not m.startswith("simoun_agent.config") and m != "simoun_agent.moved"]
print("torch" in sys.modules, outside)
"""


def test_building_and_resolving_configs_imports_no_torch_and_nothing_outside_config():
    done = subprocess.run(
        [sys.executable, "-c", CHILD], capture_output=True, text=True, timeout=300, check=True
    )
    assert done.stdout.split("\n")[0] == "False []", done.stdout + done.stderr


def test_the_package_imports_only_itself_the_standard_library_numpy_and_gymnasium():
    files = sorted(PACKAGE.glob("*.py"))
    assert len(files) > 5
    foreign = {
        f"{path.name}: {name}"
        for path in files
        for name in imports(path)
        if not name.startswith("simoun_agent.config")
        and name.split(".")[0] not in sys.stdlib_module_names | ALLOWED
        # device.py asks torch about the machine's GPUs, only when a config names one
        and not (path.name == "device.py" and name == "torch")
    }
    assert foreign == set()
