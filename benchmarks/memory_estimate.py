"""The memory estimate of ``simoun_agent.run.memory`` against the memory a real update takes.

For each image size, a fresh process builds the cpu preset's agent on the CPU, runs two real
gradient updates on a random batch and reports how much its peak resident memory grew; beside it
the estimate (``update_bytes``, the update run on the meta device). The ratio measured /
estimated says how much the lower bound underestimates (allocator caching, conv workspaces).

    python benchmarks/memory_estimate.py --sizes 64 96 128
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

CHILD = """
import json, resource, sys, torch
from simoun_agent import SimounAgent
from simoun_agent.run.memory import ACTION_DIM, frame_shape
from simoun_agent.config import resolve

config = resolve("cpu", {"image_size": int(sys.argv[1])})
torch.set_num_threads(1)
shape, agent_config = frame_shape(config), config.agent
agent = SimounAgent(shape, ACTION_DIM, agent_config, device="cpu")
b = agent_config.batch_size
window = torch.randint(0, 256, (b, agent_config.num_frames + 1, *shape), dtype=torch.uint8)
frames = torch.randint(0, 256, (b, agent_config.num_frames, *shape), dtype=torch.uint8)
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
for _ in range(2):
    agent.update_window(window, torch.zeros(b, ACTION_DIM), torch.zeros(b), torch.ones(b), 1,
                        (frames, torch.zeros(b)) if agent_config.n_step > 1 else None)
print(json.dumps(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - before))
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 96, 128])
    args = parser.parse_args()
    from simoun_agent.config import resolve
    from simoun_agent.run.memory import update_bytes

    print("size  estimated GB  measured GB (peak RSS growth)  measured / estimated")
    row = "{:4d}  {:12.2f}  {:30.2f}  {:20.2f}"
    for size in args.sizes:
        estimated = update_bytes(resolve("cpu", {"image_size": size}))
        done = subprocess.run(
            [sys.executable, "-c", CHILD, str(size)], capture_output=True, text=True, check=True
        )
        measured = json.loads(done.stdout.strip().splitlines()[-1])
        print(row.format(size, estimated / 1e9, measured / 1e9, measured / estimated))


if __name__ == "__main__":
    main()
