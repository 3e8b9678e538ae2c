"""The memory a run will need, estimated from its config before anything is built.

Frames of 512x512 at the cpu preset's batch of 64 need about 80 GB for one gradient update (the
interactive module's attention maps grow with the fourth power of the image side), which a run
would find out only by being killed after building its envs. :func:`update_bytes` runs the
agent's real update on torch's meta device (shapes only: nothing is allocated or computed, about
0.2 s) and records the peak of the bytes its tensors hold at once; :func:`check_memory` compares
that, with the replay's frames, to the machine's memory.

The estimate is a lower bound: it counts the tensors, not the allocator's caching or the conv
libraries' workspaces. ``python benchmarks/memory_estimate.py --sizes 64 96 128`` measured the
real peak (resident memory growth over two updates, cpu preset) at 1.34, 1.31 and 1.52 times the
estimate of 0.12, 0.30 and 0.67 GB (2 cores, one torch thread).
"""

from __future__ import annotations

import math
import os
import weakref
from dataclasses import dataclass, replace
from typing import Any

import torch
from torch.utils._python_dispatch import TorchDispatchMode

from simoun_agent.config import SetupError, TrainConfig
from simoun_agent.device import default_device

ACTION_DIM = 2
"""Action size assumed before the env is built; the networks' share of memory barely depends
on it."""

WARN_FRACTION = 0.5
"""Above this share of the memory (and below all of it) a run starts with a warning: the real
peak is higher than the estimate."""

GB = 1e9


class PeakBytes(TorchDispatchMode):
    """Counts the bytes of every tensor an op creates (views and in-place results share their
    input's storage and are skipped) until the tensor is freed; ``peak`` is the most held at
    once."""

    def __init__(self) -> None:
        super().__init__()
        self.live = 0
        self.peak = 0

    def _free(self, size: int) -> None:
        self.live -= size

    def __torch_dispatch__(self, func: Any, types: Any, args: Any = (), kwargs: Any = None) -> Any:
        out = func(*args, **(kwargs or {}))
        outputs = out if isinstance(out, (tuple, list)) else (out,)
        for result, declared in zip(outputs, func._schema.returns, strict=False):
            if isinstance(result, torch.Tensor) and declared.alias_info is None:
                size = result.untyped_storage().nbytes()
                self.live += size
                self.peak = max(self.peak, self.live)
                weakref.finalize(result, self._free, size)
        return out


def frame_shape(config: TrainConfig) -> tuple[int, int, int]:
    """``(C, H, W)`` of the frames the agent of ``config`` sees (cameras side by side)."""
    channels = 1 if config.grayscale else 3
    return channels, config.image_size, config.image_size * config.cameras


def update_bytes(config: TrainConfig) -> int:
    """Peak bytes of one gradient update of ``config``'s agent: its networks, optimiser states,
    the batch and every intermediate tensor, from the real update run on the meta device."""
    from simoun_agent import SimounAgent

    shape = frame_shape(config)
    agent_config = config.agent
    with torch.device("meta"):
        agent = SimounAgent(shape, ACTION_DIM, agent_config, device="meta")
    held = 0
    for part in vars(agent).values():
        # an optimiser, or a tuple of them (CURL's contrastive step has two)
        for optimizer in part if isinstance(part, tuple) else (part,):
            if isinstance(optimizer, torch.optim.Optimizer):
                # fused Adam has no meta kernel; the plain one allocates the same states
                optimizer.defaults["fused"] = False
                for group in optimizer.param_groups:
                    group["fused"] = False
        if isinstance(part, torch.nn.Module):
            held += sum(t.numel() * t.element_size() for t in part.state_dict().values())
    batch = agent_config.batch_size
    counter = PeakBytes()
    with counter, torch.device("meta"):
        window = torch.zeros(batch, agent_config.num_frames + 1, *shape, dtype=torch.uint8)
        bootstrap = None
        if agent_config.n_step > 1:
            frames = torch.zeros(batch, agent_config.num_frames, *shape, dtype=torch.uint8)
            bootstrap = (frames, torch.zeros(batch))
        action, reward = torch.zeros(batch, ACTION_DIM), torch.zeros(batch)
        try:
            agent.update_window(window, action, reward, torch.ones(batch), 1, bootstrap)
        except RuntimeError as err:
            # A tensor of more than 2**63 bytes (frames of 100,000 pixels a side at a batch of
            # 512): torch cannot even size it on the meta device, and no machine holds it.
            if "overflow" not in str(err):
                raise
            return MORE_THAN_TORCH_COUNTS
    return held + counter.peak


MORE_THAN_TORCH_COUNTS = 2**63 - 1
"""What :func:`update_bytes` returns for an update whose tensors torch cannot size: a lower bound
of its need, larger than any machine's memory."""


def replay_bytes(config: TrainConfig) -> int:
    """Bytes of the replay's frames when full (each frame stored once, uint8)."""
    return config.replay_capacity * math.prod(frame_shape(config))


def device_memory(device: str | None) -> tuple[str, int | None]:
    """The device a run of ``device`` trains on and its memory in bytes (None: unknown)."""
    name = str(default_device(device))
    kind = torch.device(name)
    if kind.type == "cuda":
        return name, torch.cuda.get_device_properties(kind.index or 0).total_memory
    if hasattr(os, "sysconf") and "SC_PHYS_PAGES" in os.sysconf_names:
        return name, os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    return name, None


@dataclass(frozen=True)
class MemoryEstimate:
    """What a run of a config needs against what the machine has."""

    update: int
    """bytes of one gradient update on the training device (:func:`update_bytes`)"""
    replay: int
    """bytes of the full replay, in host memory"""
    device: str
    """the training device"""
    device_bytes: int | None
    """memory of the training device (None: unknown)"""
    host_bytes: int | None
    """host memory (None: unknown)"""

    def shortfall(self) -> tuple[float, str] | None:
        """The largest need / have ratio and what it is about, or None when memory is unknown."""
        ratios = []
        on_host = self.device.startswith(("cpu", "mps"))
        if self.host_bytes:
            host_need = self.replay + (self.update if on_host else 0)
            ratios.append((host_need / self.host_bytes, "host"))
        if self.device_bytes and not on_host:
            ratios.append((self.update / self.device_bytes, self.device))
        return max(ratios) if ratios else None


def estimate(config: TrainConfig) -> MemoryEstimate:
    """The memory estimate of ``config`` (about 0.2 s: the update runs on the meta device)."""
    device, device_bytes = device_memory(config.device)
    _, host_bytes = device_memory("cpu")
    return MemoryEstimate(
        update_bytes(config), replay_bytes(config), device, device_bytes, host_bytes
    )


@dataclass(frozen=True)
class Spelling:
    """How the interface a user is in spells a config key and a value for it."""

    prefix: str
    """``--`` for flags"""
    separator: str
    """between the key and its value"""
    dashes: bool
    """underscores written as dashes (flags)"""

    def name(self, key: str) -> str:
        return self.prefix + (key.replace("_", "-") if self.dashes else key)

    def set(self, key: str, value: Any) -> str:
        return f"{self.name(key)}{self.separator}{value}"


FLAGS = Spelling("--", " ", True)
"""simoun-train's and simoun-sweep's flags: ``--agent.batch-size 16``"""
SPEC_KEYS = Spelling("", " = ", False)
"""a study spec's keys: ``agent.batch_size = 16``"""


def check_memory(config: TrainConfig, knob: Spelling = FLAGS) -> str | None:
    """Raise SetupError when ``config`` needs more memory than the machine has, naming the
    estimate and every setting that must change, as ``knob`` spells them; return a warning when it
    needs more than :data:`WARN_FRACTION` of it, else None."""
    need = estimate(config)
    worst = need.shortfall()
    if worst is None or worst[0] <= WARN_FRACTION:
        return None
    ratio, where = worst
    have = need.host_bytes if where == "host" else need.device_bytes
    batch = config.agent.batch_size
    c, h, w = frame_shape(config)
    owner = "this machine" if where == "host" else f"the {where} device"
    size, batch_set = knob.set("image_size", config.image_size), knob.set("agent.batch_size", batch)
    text = (
        f"{size} with {batch_set}: one gradient update needs at least {need.update / GB:.1f} GB "
        f"on {need.device} ({batch} windows of {config.agent.num_frames + 1} frames of "
        f"{c}x{h}x{w}, estimated on torch's meta device) and the full replay "
        f"{need.replay / GB:.1f} GB of host memory "
        f"({knob.set('replay_capacity', config.replay_capacity)}); {owner} has {have / GB:.1f} GB"
    )
    if ratio <= 1:
        return f"{text}. It may not fit: the real peak is higher than this estimate."
    raise SetupError(f"{text}, so the run would be killed. {_fix(config, need, knob)}")


def _fix(config: TrainConfig, need: MemoryEstimate, knob: Spelling) -> str:
    """Every setting that must change for the run to fit in :data:`WARN_FRACTION` of the memory
    (the real peak exceeds the estimate): the replay's capacity, the batch (the update is
    linear in it: networks and optimiser states, plus a share per window), or both when
    lowering one cannot make room; the image size when not even a batch of one fits."""
    per_frame = need.replay / config.replay_capacity
    batch = config.agent.batch_size
    one = replace(config, agent=replace(config.agent, batch_size=1))
    fixed = update_bytes(one) if batch > 1 else need.update
    per_window = max(need.update - fixed, 1) / max(batch - 1, 1)
    capacity, windows = config.replay_capacity, batch

    def frames_in(room: float) -> int:
        return int(room / per_frame)

    def windows_in(room: float) -> int:
        return int((room - fixed) / per_window) + 1

    if need.device.startswith(("cpu", "mps")):  # the update and the replay share the host
        budget = WARN_FRACTION * (need.host_bytes or 0)
        if need.update < budget and frames_in(budget - need.update) >= batch:
            capacity = frames_in(budget - need.update)
        elif need.replay < budget and windows_in(budget - need.replay) >= 1:
            windows = windows_in(budget - need.replay)
        else:
            capacity, windows = frames_in(budget / 2), windows_in(budget / 2)
    else:  # the update on the device, the replay on the host
        if need.host_bytes and need.replay > WARN_FRACTION * need.host_bytes:
            capacity = frames_in(WARN_FRACTION * need.host_bytes)
        if need.device_bytes and need.update > WARN_FRACTION * need.device_bytes:
            windows = windows_in(WARN_FRACTION * need.device_bytes)
    capacity, windows = min(capacity, config.replay_capacity), min(windows, batch)
    if windows < 1 or capacity < max(windows, 1):
        return (
            f"Lower {knob.name('image_size')} (84 is the paper's; the update grows "
            "with the fourth power of the side), then the batch or the replay if it still does "
            "not fit"
        )
    changes = [
        knob.set(key, value)
        for key, value, now in (
            ("replay_capacity", capacity, config.replay_capacity),
            ("agent.batch_size", windows, batch),
        )
        if value != now
    ]
    both = " and ".join(changes)
    return f"Set {both} (or lower the image size) so that it fits with room to spare"


def replay_holds(config: TrainConfig, capacity: int, episode_steps: int) -> int:
    """Whole transitions a full replay of ``capacity`` keeps of ``episode_steps``-step
    episodes: :class:`~simoun_agent.replay.FrameReplay` sizes its ring for 50-step episodes,
    and each shorter episode's reset frame takes a slot (the oldest windows lose a frame too)."""
    frames = config.agent.num_frames
    slots = capacity + (capacity + 48) // 50 + frames
    return (slots - frames) * episode_steps // (episode_steps + 1) - frames


def check_replay(config: TrainConfig, env_steps: int | None, knob: Spelling = FLAGS) -> None:
    """Raise SetupError when the replay, full, cannot hold one batch of whole transitions of
    the env's episodes of ``env_steps`` env steps (None: no limit, nothing to check): sampling
    would fail once the replay is full, hours into a run."""
    if env_steps is None:
        return
    steps = max(1, math.ceil(env_steps / config.resolved_action_repeat()))
    batch = config.agent.batch_size
    held = replay_holds(config, config.replay_capacity, steps)
    if held >= batch:
        return
    enough = config.replay_capacity
    while replay_holds(config, enough, steps) < batch:
        enough += max(1, enough // 20)
    raise SetupError(
        f"{knob.set('replay_capacity', config.replay_capacity)} keeps about {held} whole "
        f"transitions of {config.env}'s {steps}-step episodes (each episode's first frame takes "
        f"a slot), fewer than a batch of {batch} ({knob.set('agent.batch_size', batch)}): "
        f"sampling would fail once the replay is full. Set {knob.set('replay_capacity', enough)} "
        "or more, or lower the batch size"
    )


def usable_cores() -> int:
    """The CPU cores this process may run on (its affinity where the OS says, else all)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def threads_warning(threads: int | None, knob: str = "--torch-threads") -> str | None:
    """A warning when ``threads`` torch threads (``knob``'s value) exceed the cores this process
    may use: the extra threads only wait on each other (a 40-step run took 64 s with 64 threads
    on 2 cores); None when they fit or torch picks its own number."""
    cores = usable_cores()
    if threads is None or threads <= cores:
        return None
    return (
        f"{knob} {threads} is more than the {cores} CPU core{'s' if cores > 1 else ''} this "
        f"process can use: the extra threads wait on each other and slow every update; pass "
        f"{knob} {cores} or fewer"
    )
