"""A replay buffer that stores each frame once and rebuilds frame triplets at sample time."""

from __future__ import annotations

import functools
import inspect
import json
import math
import os
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import IO

import numpy as np

from simoun_agent.run.kept import binary_problem
from simoun_wrappers._checks import (
    check_bool,
    check_positive_int,
    is_int,
    is_real,
    unexpanded_home,
)

_MAX_STEP = 255  # position in episode saturates here; only min(step, num_frames) is ever used


class _ClassOrInstanceMethod:
    """A method given both its class and, when called on an instance, that instance (else None):
    as a classmethod, ``replay.load(path)`` would build a new buffer and leave ``replay`` empty."""

    def __init__(self, function: Callable) -> None:
        self.function = function
        signature = inspect.signature(function)
        self.signature = signature.replace(parameters=list(signature.parameters.values())[2:])

    def __get__(self, instance: object, owner: type) -> Callable:
        @functools.wraps(self.function)
        def bound(*args, **kwargs):
            return self.function(owner, instance, *args, **kwargs)

        bound.__signature__ = self.signature  # help() shows load(path), as users call it
        return bound


class FrameReplay:
    """Ring buffer of single uint8 frames with the transitions between them.

    Each environment step stores one frame (the next observation), its action, reward and the
    terminated / truncated flags; each reset stores the first frame. ``sample`` rebuilds the
    observation triplets ``[o_{t-2}, o_{t-1}, o_t]`` and ``[o_{t-1}, o_t, o_{t+1}]`` with the
    reset padding of ``simoun_wrappers.FrameTriplet`` (the first frame of an episode repeated),
    so nothing is stored twice: about one frame per transition instead of CURL's two stacks.

    The ring holds ``capacity + ceil((capacity - 1) / 50) + num_frames`` frames so that
    ``capacity`` transitions fit along with the reset frames of episodes of 50 steps or more
    (for ``num_frames`` < 50). Sampling (uniform, with replacement) uses the buffer's own
    ``numpy.random.Generator``, which :meth:`save` stores, so a reloaded buffer samples exactly
    what the original would have.

    Example:
        >>> import numpy as np
        >>> replay = FrameReplay(capacity=100, frame_shape=(3, 8, 8), action_dim=2, seed=0)
        >>> replay.start_episode(np.zeros((3, 8, 8), np.uint8))
        >>> for t in range(5):
        ...     replay.add(np.zeros(2), 1.0, np.full((3, 8, 8), t, np.uint8), False, False)
        >>> batch = replay.sample(4)
        >>> batch["obs"].shape, batch["next_obs"].shape, len(replay)
        ((4, 3, 3, 8, 8), (4, 3, 3, 8, 8), 5)
    """

    def __init__(
        self,
        capacity: int,
        frame_shape: tuple[int, ...],
        action_dim: int,
        num_frames: int = 3,
        seed: int | None = None,
    ) -> None:
        for name, value in (("capacity", capacity), ("action_dim", action_dim)):
            if not is_int(value) or value < 1:
                raise ValueError(
                    f"{name} must be an int >= 1, got {value!r}; e.g. FrameReplay(100_000, "
                    "frame_shape, env.action_space.shape[0])"
                )
        if not is_int(num_frames) or num_frames < 1:
            raise ValueError(f"num_frames must be an int >= 1, got {num_frames!r}; use 3")
        # a tuple of numpy ints or a 1-D array is what env.observation_space shapes give
        sequence = isinstance(frame_shape, (tuple, list)) or (
            isinstance(frame_shape, np.ndarray) and frame_shape.ndim == 1
        )
        shape = tuple(frame_shape) if sequence else ()
        if len(shape) != 3 or not all(is_int(v) and v > 0 for v in shape):
            raise ValueError(
                f"frame_shape must be (C, H, W) positive ints, got {frame_shape!r}; pass "
                "env.observation_space['frames'].shape[1:] of a SimounObservation env"
            )
        if seed is not None and not (is_int(seed) and seed >= 0):
            raise ValueError(f"seed must be None or an int >= 0, got {seed!r}; e.g. seed=0")
        self.capacity = int(capacity)
        self.frame_shape = tuple(int(s) for s in frame_shape)
        self.action_dim = int(action_dim)
        self.num_frames = int(num_frames)
        # episodes of 50 steps put one reset frame in every 51 frames: (capacity + 48) // 50
        # slots for them leave capacity transitions with whole windows, beside the num_frames
        # oldest frames whose windows lost their first frames
        slots = self.capacity + (self.capacity + 48) // 50 + self.num_frames
        self._check_memory(slots)
        self._allocate(slots)
        self.written = 0
        """frames written since creation; absolute index of the next frame"""
        self.transitions = 0
        """transition frames (step >= 1) in the ring, including up to num_frames whose window
        lost its oldest frames"""
        self.episode_step: int | None = None
        """step of the open episode, None between an episode's end and the next start_episode"""
        self.rng = np.random.default_rng(seed)

    def _slot_bytes(self) -> int:
        """Bytes of one ring slot: the frame, the action, the reward, two flags and the step."""
        return math.prod(self.frame_shape) + 4 * self.action_dim + 4 + 3

    def _check_memory(self, slots: int) -> None:
        """Refuse a ring larger than this machine's memory, with the bytes it needs and the
        capacity that fits (numpy's MemoryError names neither the argument nor the fix)."""
        need = slots * self._slot_bytes()
        have = host_memory()
        if have is None or need <= have:
            return
        fits = int(have / 2 / self._slot_bytes())
        raise ValueError(
            f"FrameReplay(capacity={self.capacity}) needs {need:,} bytes ({need / 1e9:,.1f} GB) "
            f"for frames of {self.frame_shape}, more than this machine's {have / 1e9:,.1f} GB of "
            f"memory; lower capacity (about {fits:,} transitions take half of it) or the frame "
            "size"
        )

    def _allocate(self, slots: int) -> None:
        """Empty arrays for a ring of ``slots`` frames."""
        self.slots = slots
        self.frames = np.zeros((slots, *self.frame_shape), np.uint8)
        self.actions = np.zeros((slots, self.action_dim), np.float32)
        self.rewards = np.zeros(slots, np.float32)
        self.terminated = np.zeros(slots, bool)
        self.truncated = np.zeros(slots, bool)
        self.steps = np.zeros(slots, np.uint8)
        """position of each frame in its episode (0 = reset frame), saturating at 255"""

    # -- writing -------------------------------------------------------------------------------

    def _check_frame(self, frame: np.ndarray, name: str) -> np.ndarray:
        frame = np.asarray(frame)
        if frame.shape != self.frame_shape or frame.dtype != np.uint8:
            raise ValueError(
                f"{name} must be a uint8 array of shape {self.frame_shape} (C, H, W), got "
                f"{frame.dtype} {frame.shape}; pass one frame (not the triplet) as uint8"
            )
        return frame

    def _write(self, frame, action, reward, terminated, truncated, step) -> None:
        slot = self.written % self.slots
        if self.written >= self.slots and self.steps[slot] >= 1:
            self.transitions -= 1
        self.transitions += step >= 1
        self.frames[slot] = frame
        self.actions[slot] = action
        self.rewards[slot] = reward
        self.terminated[slot] = terminated
        self.truncated[slot] = truncated
        self.steps[slot] = min(step, _MAX_STEP)
        self.written += 1

    def start_episode(self, frame: np.ndarray) -> None:
        """Store the first frame of an episode (call after every ``reset``)."""
        frame = self._check_frame(frame, "start_episode(frame)")
        self._write(frame, 0.0, 0.0, False, False, 0)
        self.episode_step = 0

    def add(
        self,
        action: np.ndarray,
        reward: float,
        next_frame: np.ndarray,
        terminated: bool,
        truncated: bool,
    ) -> None:
        """Store one step: the action taken, the reward received and the frame it led to."""
        for name, flag in (("terminated", terminated), ("truncated", truncated)):
            check_bool(flag, f"add({name}=...)")
        if self.episode_step is None:
            raise RuntimeError(
                "FrameReplay.add() called with no open episode; call start_episode(first_frame) "
                "after each env.reset() (and after an episode terminated or was truncated)"
            )
        try:
            reward = float(reward)
        except (TypeError, ValueError):
            raise ValueError(
                f"reward must be a number, got {type(reward).__name__} {reward!r}; pass the "
                "reward env.step returned"
            ) from None
        if not np.isfinite(reward):
            raise ValueError(
                f"reward {reward} is not finite; the replay only stores finite rewards - check "
                "the environment or the reward wrappers (clip or drop the step)"
            )
        action = np.asarray(action, dtype=np.float32)
        if action.size != self.action_dim or not np.all(np.isfinite(action)):
            raise ValueError(
                f"action must hold {self.action_dim} finite numbers, got {action.shape} {action}"
            )
        next_frame = self._check_frame(next_frame, "add(next_frame)")
        self.episode_step += 1
        self._write(
            next_frame, action.reshape(-1), reward, terminated, truncated, self.episode_step
        )
        if terminated or truncated:
            self.episode_step = None

    # -- reading -------------------------------------------------------------------------------

    @property
    def oldest(self) -> int:
        """Absolute index of the oldest frame still in the ring."""
        return max(0, self.written - self.slots)

    def _valid(self, index: np.ndarray) -> np.ndarray:
        """Transitions whose next frame is at ``index`` and whose whole window is still stored."""
        step = self.steps[index % self.slots]
        return (step >= 1) & (index - np.minimum(step, self.num_frames) >= self.oldest)

    def __len__(self) -> int:
        head = np.arange(self.oldest, min(self.oldest + self.num_frames, self.written))
        broken = np.count_nonzero((self.steps[head % self.slots] >= 1) & ~self._valid(head))
        return self.transitions - int(broken)

    def sample(
        self, batch_size: int, n_step: int = 1, discount: float = 1.0
    ) -> dict[str, np.ndarray]:
        """Sample ``batch_size`` transitions uniformly (with replacement).

        Returns uint8 ``obs`` and ``next_obs`` ``(B, k, C, H, W)`` (views of ``window``
        ``(B, k+1, C, H, W)`` = frames t-k+1 .. t+1), float32 ``action`` ``(B, A)``, ``reward``
        ``(B,)`` (the one-step reward r_{t+1}), bool ``truncated``, and the bootstrap of the TD
        target: with ``n_step`` = n, the return ``R = sum_{j<m} discount^j r_{t+1+j}`` over the
        ``m <= n`` steps that stay in the episode, ``bootstrap_obs`` (the triplet ending at frame
        t+m, = ``next_obs`` when m = 1) and ``discount`` = ``discount^(m-1)`` where the last of
        those steps did not terminate, else 0, so that ``R + discount * gamma * V(bootstrap_obs)``
        is the n-step target. The sum stops at a terminated step (no bootstrap), at a truncated
        one (bootstrapped from the frame it reached) and at the newest frame stored; it never
        crosses an episode boundary. With ``n_step=1`` ``return`` equals ``reward`` and
        ``discount`` is 1 - terminated.

        For a per-step term of the target (Eq. 13's intrinsic reward of each state s_{t+j}):
        float32 ``return_mask`` ``(B, n)``, 1 for the m steps j < m that ``return`` sums, 0
        after, and uint8 ``n_step_window`` ``(B, k+n, C, H, W)``, frames t-k+1 .. t+n (its first
        k+1 frames are ``window``; frame t+m is repeated after t+m, so it never holds a frame of
        another episode), whose k frames ending at t+j are s_{t+j}.
        """
        check_positive_int(batch_size, "sample(batch_size=...)", "e.g. sample(128)")
        check_positive_int(n_step, "sample(n_step=...)", "use 1, or the n of n-step returns")
        if not (is_real(discount) and 0 <= discount <= 1):
            raise ValueError(
                f"sample(discount=...) must be a number in [0, 1], got {discount!r}; pass the "
                "agent's discount, e.g. 0.99"
            )
        available = len(self)
        if batch_size > available:
            raise ValueError(
                f"cannot sample {batch_size} transitions: the replay holds {available}; collect "
                "more steps first (a warm-up of at least batch_size steps) or lower batch_size"
            )
        chosen = np.empty(0, np.int64)
        while chosen.size < batch_size:
            need = batch_size - chosen.size
            candidates = self.rng.integers(self.oldest, self.written, size=2 * need + 8)
            chosen = np.concatenate([chosen, candidates[self._valid(candidates)]])
        chosen = chosen[:batch_size]
        slot = chosen % self.slots
        window = self._frames_ending_at(chosen, self.num_frames + 1)
        end, n_return = chosen.copy(), self.rewards[slot].astype(np.float64)
        going = np.ones(batch_size, bool)
        mask = np.ones((batch_size, n_step), np.float32)
        for j in range(1, n_step):
            following = chosen + j
            previous = (following - 1) % self.slots
            going &= (
                (following < self.written)
                & ~self.terminated[previous]
                & ~self.truncated[previous]
                & (self.steps[following % self.slots] != 0)
            )
            n_return += np.where(going, discount**j * self.rewards[following % self.slots], 0.0)
            end = np.where(going, following, end)
            mask[:, j] = going
        steps_taken = end - chosen + 1
        alive = 1.0 - self.terminated[end % self.slots].astype(np.float64)
        # frames t+2 .. t+n of n_step_window (chosen holds frame t+1), clamped at frame t+m
        ahead = [self.frames[np.minimum(chosen + j, end) % self.slots] for j in range(1, n_step)]
        return {
            "obs": window[:, :-1],
            "next_obs": window[:, 1:],
            "window": window,
            "action": self.actions[slot],
            "reward": self.rewards[slot],
            "return": n_return.astype(np.float32),
            "bootstrap_obs": window[:, 1:]
            if n_step == 1
            else self._frames_ending_at(end, self.num_frames),
            "discount": (alive * discount ** (steps_taken - 1)).astype(np.float32),
            "truncated": self.truncated[slot],
            "return_mask": mask,
            "n_step_window": np.concatenate([window, np.stack(ahead, 1)], 1) if ahead else window,
        }

    def _frames_ending_at(self, index: np.ndarray, count: int) -> np.ndarray:
        """uint8 ``(B, count, C, H, W)``: the ``count`` frames up to absolute ``index``, the
        episode's first frame repeated before its start (FrameTriplet's reset padding)."""
        back = np.arange(count - 1, -1, -1)
        steps = self.steps[index % self.slots][:, None].astype(np.int64)
        return self.frames[(index[:, None] - np.minimum(back[None, :], steps)) % self.slots]

    # -- size and persistence ------------------------------------------------------------------

    @property
    def nbytes(self) -> int:
        """Bytes held by the buffer's arrays."""
        arrays = (
            self.frames,
            self.actions,
            self.rewards,
            self.terminated,
            self.truncated,
            self.steps,
        )
        return sum(a.nbytes for a in arrays)

    @property
    def bytes_per_transition(self) -> float:
        """``nbytes / capacity``."""
        return self.nbytes / self.capacity

    def save(self, path: str | os.PathLike | IO[bytes]) -> None:
        """Write the buffer (frames stored so far, flags, counters, RNG state) as an ``.npz`` to
        exactly ``path`` (no suffix is added, so callers can write a temporary file and rename)."""
        used = min(self.written, self.slots)
        meta = {
            "capacity": self.capacity,
            "frame_shape": self.frame_shape,
            "action_dim": self.action_dim,
            "num_frames": self.num_frames,
            "slots": self.slots,
            "written": self.written,
            "transitions": self.transitions,
            "episode_step": self.episode_step,
            "rng": self.rng.bit_generator.state,
        }
        arrays = {
            "frames": self.frames[:used],
            "actions": self.actions[:used],
            "rewards": self.rewards[:used],
            "terminated": self.terminated[:used],
            "truncated": self.truncated[:used],
            "steps": self.steps[:used],
            "meta": np.frombuffer(json.dumps(meta).encode(), np.uint8),
        }
        if hasattr(path, "write"):
            np.savez(path, **arrays)
        else:
            with open(_writable(path), "wb") as f:
                np.savez(f, **arrays)

    @_ClassOrInstanceMethod
    def load(cls, into: FrameReplay | None, path: str | os.PathLike | IO[bytes]) -> FrameReplay:
        """Read a buffer written by :meth:`save`, RNG state included.

        ``FrameReplay.load(path)`` returns a new buffer built as the saved one was.
        ``replay.load(path)`` loads the file into ``replay`` and returns it; ``replay`` must have
        the file's capacity, frame_shape, action_dim and num_frames, else ValueError names both.
        """
        with _open_replay(path) as data:
            try:
                meta = json.loads(data["meta"].tobytes().decode())
                built = {
                    "capacity": meta["capacity"],
                    "frame_shape": tuple(meta["frame_shape"]),
                    "action_dim": meta["action_dim"],
                    "num_frames": meta["num_frames"],
                }
            except (KeyError, ValueError, TypeError, OSError, EOFError, zipfile.BadZipFile) as err:
                raise _damaged(path, f"its 'meta' record cannot be read ({err})") from None
            if into is not None:
                differ = [key for key, value in built.items() if getattr(into, key) != value]
                if differ:
                    found = "; ".join(
                        f"{k} {built[k]} in the file, {getattr(into, k)} here" for k in differ
                    )
                    wanted = ", ".join(f"{k}={built[k]}" for k in differ)
                    raise ValueError(
                        f"cannot load {getattr(path, 'name', path)} into this FrameReplay: "
                        f"{found}. Load it as a new buffer with FrameReplay.load(path), or create "
                        f"this one with {wanted}"
                    )
            replay = cls(**built)
            # absolute frame i sits in slot i % slots: keep the ring size the file was written
            # with (files without "slots" predate the ceil((capacity - 1) / 50) reset frames)
            slots = meta.get(
                "slots", built["capacity"] + built["capacity"] // 50 + built["num_frames"]
            )
            if slots != replay.slots:
                replay._allocate(slots)
            try:
                used = data["frames"].shape[0]
                for name in ("frames", "actions", "rewards", "terminated", "truncated", "steps"):
                    getattr(replay, name)[:used] = data[name]
                replay.written = meta["written"]
                replay.transitions = meta["transitions"]
                replay.episode_step = meta["episode_step"]
                replay.rng.bit_generator.state = meta["rng"]
            except (KeyError, ValueError, TypeError, OSError, EOFError, zipfile.BadZipFile) as err:
                raise _damaged(path, f"{type(err).__name__}: {err}") from None
        if into is None:
            return replay
        vars(into).update(vars(replay))
        return into


def host_memory() -> int | None:
    """This machine's memory in bytes (None where the system does not say)."""
    if hasattr(os, "sysconf") and "SC_PHYS_PAGES" in os.sysconf_names:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    return None


def _check_path_type(path: object, method: str) -> None:
    """A TypeError naming the argument of ``FrameReplay.<method>(path)`` (``"save"`` or
    ``"load"``) for a path that is neither a file path nor a binary file object."""
    stream = "write" if method == "save" else "read"
    if not isinstance(path, (str, os.PathLike)) and not hasattr(path, stream):
        raise TypeError(
            f"FrameReplay.{method}(path) takes a file path (str or os.PathLike) or a binary file "
            f"object, got {type(path).__name__} {path!r:.60}; e.g. "
            f"replay.{method}('replay.npz')"
        )
    home = unexpanded_home(path)
    if home is not None:
        raise ValueError(f"FrameReplay.{method}(path={os.fspath(path)!r}): {home}")


def _writable(path: str | os.PathLike) -> str | os.PathLike:
    """``path`` if a file can be written there, else an error naming the path and the fix:
    a directory, or a folder that does not exist."""
    _check_path_type(path, "save")
    if os.path.isdir(path):
        raise ValueError(
            f"FrameReplay.save(path): {os.fspath(path)} is a directory; pass a file path in it, "
            f"e.g. replay.save({os.path.join(os.fspath(path), 'replay.npz')!r})"
        )
    folder = os.path.dirname(os.fspath(path)) or "."
    if not os.path.isdir(folder):
        raise FileNotFoundError(
            f"FrameReplay.save(path): the folder {folder} of {os.fspath(path)} does not exist; "
            "create it first (os.makedirs) or pass a path in an existing folder"
        )
    return path


def _name(path: str | os.PathLike | IO[bytes]) -> str:
    return str(getattr(path, "name", path))


def _damaged(path: str | os.PathLike | IO[bytes], problem: str) -> ValueError:
    """The error for a replay file that :meth:`FrameReplay.save` wrote but that was damaged
    since: what is wrong (``problem``, or an empty or all-zero file) and the fix."""
    if not hasattr(path, "read"):
        seen = binary_problem(Path(path))
        if not seen.startswith("it cannot be read"):
            problem = seen
    return ValueError(
        f"replay file {_name(path)} is damaged: {problem}. Restore it from a copy, or collect "
        "a new replay"
    )


def _open_replay(path: str | os.PathLike | IO[bytes]) -> np.lib.npyio.NpzFile:
    """``path`` opened as an ``.npz`` without pickled data, or an error that names the file as
    missing, damaged, or not a replay (numpy's own advice, ``allow_pickle``, would load code)."""
    _check_path_type(path, "load")
    if not hasattr(path, "read") and not os.path.isfile(path):
        raise FileNotFoundError(
            f"replay file {_name(path)} does not exist (or is not a file); pass the path "
            "FrameReplay.save wrote"
        )
    try:
        data = np.load(path)
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as err:
        if hasattr(path, "read"):
            path.seek(0)
            head = path.read(4)
        else:
            with open(path, "rb") as f:
                head = f.read(4)
        if head.startswith(b"PK") or not head.strip(b"\0"):
            raise _damaged(path, f"it is no readable .npz archive ({err})") from None
        raise ValueError(
            f"{_name(path)} is not a replay saved by FrameReplay.save (it is no .npz archive); "
            "pass the file that replay.save(path) wrote"
        ) from None
    if not isinstance(data, np.lib.npyio.NpzFile) or "meta" not in data.files:
        if isinstance(data, np.lib.npyio.NpzFile):
            data.close()
        raise ValueError(
            f"{_name(path)} is not a replay saved by FrameReplay.save (it holds no 'meta' "
            "record); pass the file that replay.save(path) wrote"
        )
    return data
