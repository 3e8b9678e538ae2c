"""Models that learn online beside an env, for the intrinsic-reward wrappers: a gradient step
every few env steps, taken in one background thread, its weights published whole.

:class:`OnlineModel` holds the schedule that ``CuriosityModel`` (Eq. 13's features) and
``RNDModel`` (random network distillation) share; each subclass says only what it stores, how it
samples a batch and what one gradient step does.
"""

from __future__ import annotations

import copy
import dataclasses
import queue
import threading
import time
import weakref
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from concurrent.futures import Future
from typing import Any, ClassVar, TypeVar

import gymnasium as gym
import numpy as np
import torch
import torch.nn.functional as F
from gymnasium import spaces
from torch import nn

from simoun_agent.config.rules import Rule, is_int, rules_of
from simoun_agent.config.shapes import check_channel_first
from simoun_agent.device import default_device
from simoun_agent.replay import host_memory
from simoun_agent.state_checks import count_problems, module_problems, optimizer_problems
from simoun_wrappers.intrinsic_reward import triplet_shape

Model = TypeVar("Model", bound="OnlineModel")

__all__ = [
    "OnlineModel",
    "UpdateThread",
    "check_config_fields",
    "check_online_config",
    "default_device",
    "frozen_copy",
    "run_now",
]


class UpdateThread:
    """One daemon thread that runs the gradient steps handed to it, one at a time, in order.

    Its queue holds at most one job (``OnlineModel`` waits for an update before handing over
    the next), so updates can never pile up behind a slow trainer. A job's exception is kept in
    its ``Future`` for the caller to raise.
    """

    def __init__(self) -> None:
        self.jobs: queue.Queue[tuple[Callable[[], Any], Future] | None] = queue.Queue(maxsize=1)
        self.thread = threading.Thread(
            target=self._run, args=(self.jobs,), name="simoun-online-update", daemon=True
        )
        self.thread.start()

    @staticmethod
    def _run(jobs: queue.Queue) -> None:
        # A static method that drops each job once done: between jobs the thread holds the queue
        # but not the model, so a model nobody closed is still freed (and its finalizer stops us).
        while (job := jobs.get()) is not None:
            work, future = job
            del job
            if future.set_running_or_notify_cancel():
                try:
                    future.set_result(work())
                except BaseException as exc:  # handed to the caller's thread, raised there
                    future.set_exception(exc)
            del work, future

    def submit(self, work: Callable[[], Any]) -> Future:
        future: Future = Future()
        self.jobs.put((work, future))
        return future

    def close(self) -> None:
        """Let the job in progress finish, then stop the thread."""
        if self.thread.is_alive():
            self.jobs.put(None)
            # The model's finalizer may run on this thread (the last reference dropped there).
            if threading.current_thread() is not self.thread:
                self.thread.join()


def run_now(work: Callable[[], Any]) -> Future:
    """``work()`` on the caller's thread, its result or exception in a done ``Future``."""
    future: Future = Future()
    future.set_running_or_notify_cancel()
    try:
        future.set_result(work())
    except Exception as exc:  # raised where a background failure would be
        future.set_exception(exc)
    return future


SEED = Rule(
    "None or an int in [0, 2**32)",
    lambda v: v is None or (is_int(v) and 0 <= v < 2**32),
    "e.g. seed=0, or seed=None (the default) for a nondeterministic model",
)
"""A config's ``seed``: it seeds numpy's and torch's generators."""

ENCODER_SIZE = Rule(
    "None or an int >= 1",
    lambda v: v is None or (is_int(v) and v >= 1),
    "e.g. encoder_size=42 (the default: 84x84 frames are pooled to 42x42), or None to encode "
    "frames at full size",
)
"""A config's ``encoder_size``: the side frames are pooled to, or None."""


SWITCH = Rule("True or False", lambda v: isinstance(v, (bool, np.bool_)))
"""A config's on/off switch: a truthy stand-in such as ``"no"`` would switch it on."""


def count(low: int) -> Rule:
    """An int ``>= low`` (a size or a count of steps)."""
    return Rule(f"an int >= {low}", lambda v: is_int(v) and v >= low)


def check_config_fields(config: Any) -> None:
    """Raise ValueError for the first field of ``config`` (a dataclass whose every field is a
    :func:`~simoun_agent.config.rules.setting`) that breaks its rule, naming the field, the
    value and a fix in Python's spelling: ``RNDConfig.seed=-1 must be ...; e.g. ...``."""
    name = type(config).__name__
    rules = rules_of(config)
    for field in dataclasses.fields(config):
        value = getattr(config, field.name)
        rule = rules[field.name]
        if not rule.ok(value):
            fix = rule.fix or f"e.g. {name}({field.name}={field.default!r}) (the default)"
            raise ValueError(f"{name}.{field.name}={value!r} must be {rule.need}; {fix}")


def check_online_config(config: Any) -> None:
    """The checks of an online model's config: every field against its rule (types, bool-only
    switches, ranges, the seed), then ``batch_size <= learning_starts <= capacity``; each error
    names the field, the value and a fix."""
    check_config_fields(config)
    name = type(config).__name__
    if not config.batch_size <= config.learning_starts <= config.capacity:
        raise ValueError(
            f"{name} needs batch_size <= learning_starts <= capacity, got "
            f"{config.batch_size}, {config.learning_starts}, {config.capacity}."
        )


def frozen_copy(module: nn.Module) -> nn.Module:
    """A copy of ``module`` that no optimizer holds: the published weights rewards come from."""
    snapshot = copy.deepcopy(module)
    for parameter in snapshot.parameters():
        parameter.grad = None
        parameter.requires_grad_(False)
    return snapshot


class OnlineModel(ABC):
    """The online-training schedule of an intrinsic-reward model.

    The wrappers hand every transition to :meth:`watch`; the model stores it (``_store``) and
    every ``config.update_every`` calls, once ``config.learning_starts`` transitions are stored,
    samples a batch (``_sample``, on the caller's thread) and takes one gradient step on it
    (``_train_step``), in a background thread when ``config.background``. The step due at watch
    call ``k`` is published at the next due call, ``k + update_every``, where ``watch`` waits for
    it if it has not finished. Rewards always come from :attr:`published`, a frozen copy of the
    trained module, never from a module half-way through a step, so with a seed the rewards are
    the same with and without the thread, whatever its timing. A failed step is raised by the
    first call after it failed, and the model refuses to go on until :meth:`load_state_dict`.

    A subclass names its ``config_type`` (a dataclass with ``encoder_size``, ``capacity``,
    ``update_every``, ``learning_starts``, ``background``, ``batch_size``, ``lr``, ``seed``) and
    says only what differs: the smallest frame its networks take (``_smallest_frame``), its
    networks and optimizer (``_build``, run under the config's seed), what it stores of a
    transition (``_store``, into the ring-buffer slots of :meth:`_next_slots`), the batch it
    samples (``_sample``, from :meth:`_batch_indices`), its loss (``_loss``) and the objects whose
    state it saves (``_stateful``).
    """

    config_type: ClassVar[type]
    """the config class; ``config_type()`` when a model is built without a config"""
    _more_state: ClassVar[tuple[str, ...]] = ()
    """keys a subclass's state holds besides those of every online model"""
    config: Any
    device: torch.device
    size: int
    """transitions stored (at most ``config.capacity``)"""
    optimizer: torch.optim.Optimizer

    def __init__(
        self,
        frame_shape: tuple[int, int, int],
        action_space: gym.Space | None = None,
        config: Any = None,
        device: str | torch.device | None = None,
    ) -> None:
        """Build the model.

        Args:
            frame_shape: ``(C, H, W)`` of one frame as the env gives it (pooled by
                ``config.encoder_size``, at least the subclass's smallest side).
            action_space: the env's action space.
            config: hyperparameters; ``config_type()`` when None.
            device: torch device; None picks cuda when available, else cpu.
        """
        self.config = config = self._checked_config(config)
        self._init_frames(frame_shape, config.encoder_size)
        smallest, needs, size = self._smallest_frame()
        if min(self.encoded_shape[1:]) < smallest:
            pooling = f"{self.pool}, {type(config).__name__}.encoder_size={config.encoder_size}"
            raise ValueError(
                f"frames of {frame_shape} are encoded at {self.encoded_shape} (pooled by "
                f"{pooling}); {needs} need H, W >= {smallest}. Render larger frames "
                f"(SimounObservation(env, size={size}) or more) or raise encoder_size."
            )
        self.action_space = action_space
        self._check_memory()
        self.device = default_device(device)
        with torch.random.fork_rng(devices=[]):
            if config.seed is not None:
                torch.manual_seed(config.seed)
            trained = self._build()
        self.size = 0
        self._head = 0
        self._init_schedule(trained)

    @classmethod
    def _checked_config(cls, config: Any) -> Any:
        """``config``, or ``config_type()`` for None; a TypeError naming the argument for
        anything else (a dict of its fields, say). A config is checked again here: a dataclass
        takes any value assigned after it was built (``config.lr = -1``), which would otherwise
        fail inside torch naming no field."""
        if config is None:
            return cls.config_type()
        if not isinstance(config, cls.config_type):
            kind = cls.config_type.__name__
            raise TypeError(
                f"{cls.__name__}'s config must be of type {kind}, got {type(config).__name__} "
                f"{config!r:.60}; e.g. {cls.__name__}.for_env(env, config={kind}(lr=1e-4)), or "
                f"{kind}(**values) for a dict of its fields"
            )
        try:
            check_online_config(config)
        except ValueError as err:
            raise ValueError(f"{cls.__name__} cannot use this config: {err}") from None
        return config

    @classmethod
    def for_env(
        cls: type[Model],
        env: gym.Env | gym.vector.VectorEnv,
        config: Any = None,
        device: str | torch.device | None = None,
    ) -> Model:
        """A model sized for ``env``'s Simoun observations and action space (single or vector)."""
        vector = isinstance(env, gym.vector.VectorEnv)
        obs_space = env.single_observation_space if vector else env.observation_space
        act_space = env.single_action_space if vector else env.action_space
        return cls(triplet_shape(obs_space)[1:], act_space, config, device)

    def _init_schedule(self, published: nn.Module) -> None:
        """Counters, RNGs, and the first published weights (a frozen copy of ``published``)."""
        self.generator = torch.Generator(self.device)
        self.rng = np.random.default_rng(self.config.seed)
        self.generator.manual_seed(int(self.rng.integers(2**62)))
        self.watch_calls = 0
        self.published = frozen_copy(published)
        """the module rewards come from; replaced, never modified"""
        self.updates = 0
        self.last_metrics: dict[str, float] = {}
        self._pending: Future | None = None
        self._failure: BaseException | None = None
        self._thread: UpdateThread | None = None

    @abstractmethod
    def _smallest_frame(self) -> tuple[int, str, int]:
        """The smallest side the networks take after pooling, what needs it (for the error) and
        a ``SimounObservation`` size to suggest."""

    def _check_memory(self) -> None:
        """Refuse a buffer larger than this machine's memory, naming the bytes and the fix
        (numpy's MemoryError names neither the config field nor a capacity that fits)."""
        per_slot = self._slot_bytes()
        need = self.config.capacity * per_slot
        have = host_memory()
        if have is None or need <= have:
            return
        kind = type(self.config).__name__
        raise ValueError(
            f"{kind}.capacity={self.config.capacity} makes {type(self).__name__}'s buffer "
            f"{need:,} bytes ({need / 1e9:,.1f} GB) for frames of {self.encoded_shape}, more "
            f"than this machine's {have / 1e9:,.1f} GB of memory; lower capacity (about "
            f"{int(have / 2 / per_slot):,} take half of it), e.g. {kind}(capacity=1000) (the "
            "default)"
        )

    @abstractmethod
    def _slot_bytes(self) -> int:
        """Bytes the buffer holds per stored transition."""

    @abstractmethod
    def _build(self) -> nn.Module:
        """Build the networks and the optimizer (under the config's seed); the trained module,
        whose frozen copies are published."""

    @abstractmethod
    def _store(self, triplets: np.ndarray, actions: np.ndarray, next_triplets: np.ndarray) -> None:
        """Keep a batch of checked transitions in the buffer and raise ``size``."""

    @abstractmethod
    def _sample(self) -> tuple[torch.Tensor, ...]:
        """A batch copied out of the buffer, on the caller's thread (the buffer keeps filling)."""

    @abstractmethod
    def _loss(self, *batch: torch.Tensor) -> tuple[torch.Tensor, dict[str, float]]:
        """The loss of one gradient step on ``batch`` and its metrics."""

    @abstractmethod
    def _trained(self) -> nn.Module:
        """The module the optimizer trains (whose frozen copies are published)."""

    @abstractmethod
    def _stateful(self) -> dict[str, Any]:
        """The modules and the optimizer, by name, whose ``state_dict`` :meth:`state_dict`
        saves."""

    def _after_step(self) -> None:
        """Run after each optimizer step (e.g. a momentum encoder's EMA); nothing by default."""
        return None

    def _train_step(self, *batch: torch.Tensor) -> tuple[dict[str, float], nn.Module]:
        """One gradient step (on the update thread when ``background``): its metrics with its
        duration ``update_ms``, and a frozen copy of the new weights."""
        start = time.perf_counter()
        loss, metrics = self._loss(*batch)
        if not torch.isfinite(loss):
            raise FloatingPointError(
                f"the {type(self).__name__} loss is {float(loss.detach())} before this step"
            )
        self.optimizer.zero_grad(set_to_none=True)
        loss.backward()
        self.optimizer.step()
        self._after_step()
        metrics["update_ms"] = 1000.0 * (time.perf_counter() - start)
        return metrics, frozen_copy(self._trained())

    def _modules_state(self) -> dict[str, Any]:
        """The state of the modules and the optimizer, for :meth:`state_dict`."""
        return {name: part.state_dict() for name, part in self._stateful().items()}

    def _load_modules_state(self, state: dict[str, Any]) -> None:
        """Load what :meth:`_modules_state` returned."""
        for name, part in self._stateful().items():
            part.load_state_dict(state[name])

    def _next_slots(self, n: int) -> np.ndarray:
        """The ring-buffer slots of the next ``n`` transitions (the oldest overwritten once
        ``capacity`` are stored); moves the head on and raises ``size``."""
        capacity = self.config.capacity
        slots = (self._head + np.arange(n)) % capacity
        self._head = int((self._head + n) % capacity)
        self.size = min(self.size + n, capacity)
        return slots

    def _batch_indices(self) -> np.ndarray:
        """``batch_size`` stored slots drawn with replacement, or an error while too few are
        stored."""
        if self.size < self.config.batch_size:
            raise RuntimeError(
                f"{type(self).__name__}.update needs {self.config.batch_size} stored "
                f"transitions, has {self.size}; call watch() more first."
            )
        return self.rng.integers(0, self.size, size=self.config.batch_size)

    def _init_frames(self, frame_shape: tuple[int, ...], encoder_size: int | None) -> None:
        """Set ``frame_shape`` (C, H, W as the env gives it), the integer average-pooling factor
        ``pool`` that brings the shorter side to about ``encoder_size`` (1 when None or below 2)
        and ``encoded_shape``, the frame's shape after pooling."""
        self.frame_shape = tuple(int(v) for v in frame_shape)
        if len(self.frame_shape) != 3:
            raise ValueError(f"frame_shape must be one frame's (C, H, W), got {frame_shape}.")
        check_channel_first(self.frame_shape)
        c, h, w = self.frame_shape
        self.pool = max(1, min(h, w) // encoder_size) if encoder_size else 1
        self.encoded_shape = (c, h // self.pool, w // self.pool)

    def _pooled(self, frames: np.ndarray) -> np.ndarray:
        """uint8 ``(..., C, H, W)`` average-pooled by ``self.pool`` (rounded back to uint8)."""
        if self.pool == 1:
            return frames
        x = torch.from_numpy(np.ascontiguousarray(frames))
        flat = x.reshape(-1, *x.shape[-3:]).float()
        pooled = F.avg_pool2d(flat, self.pool).round_().to(torch.uint8)
        return pooled.reshape(*x.shape[:-3], *self.encoded_shape).numpy()

    def _check(self, triplets: np.ndarray, name: str) -> np.ndarray:
        """``triplets`` as an array, or an error naming ``name`` and the expected shape."""
        triplets = np.asarray(triplets)
        if triplets.dtype != np.uint8 or triplets.shape[1:] != (3, *self.frame_shape):
            expected = ", ".join(map(str, (3, *self.frame_shape)))
            raise ValueError(
                f"{type(self).__name__} expects {name} as uint8 (B, {expected}), "
                f"got {triplets.dtype} {triplets.shape}; it was built for frames of shape "
                f"{self.frame_shape} (build it with {type(self).__name__}.for_env(env))."
            )
        return triplets

    def _check_actions(self, actions: Any, batch: int) -> np.ndarray:
        """``actions`` as an array of ``batch`` actions of the action space, or an error naming
        the argument and the expected shape: finite numbers, and for Discrete, MultiDiscrete
        and MultiBinary spaces integers within the space."""
        space = self.action_space
        shape = (batch, *space.shape) if space is not None and space.shape is not None else None
        array = np.asarray(actions)
        problem = None
        if array.dtype.kind not in "biuf":
            problem = f"{array.dtype} values, not numbers"
        elif shape is not None and array.shape != shape:
            problem = f"shape {array.shape}"
        elif shape is None and (array.ndim == 0 or len(array) != batch):
            problem = f"shape {array.shape}, not one action per transition"
        elif not np.all(np.isfinite(array)):
            problem = "a NaN or infinite value"
        elif isinstance(space, (spaces.Discrete, spaces.MultiDiscrete, spaces.MultiBinary)):
            if array.dtype.kind == "f" and np.any(array != np.round(array)):
                problem = "a fractional value"
            elif not all(space.contains(np.asarray(a).astype(space.dtype)) for a in array):
                problem = "a value outside the space"
        if problem is None:
            return array
        want = f"shape {shape}" if shape is not None else f"{batch} actions"
        raise ValueError(
            f"{type(self).__name__}.watch() expects actions of {want} in {space}, one per "
            f"transition, got {problem}; pass the batch of actions that env.step took"
        )

    def watch(
        self,
        triplets: np.ndarray,
        actions: np.ndarray,
        next_triplets: np.ndarray,
        terminated: np.ndarray,
        truncated: np.ndarray,
    ) -> None:
        """Store a batch of transitions; publish the last gradient step and start the next when
        one is due.

        ``next_triplets`` must continue ``triplets`` (same episode), as the wrappers guarantee.
        ``terminated``/``truncated`` are accepted for the wrappers' hook and not needed.
        """
        self._raise_failure()
        triplets = self._check(triplets, "triplets")
        next_triplets = self._check(next_triplets, "next_triplets")
        batch = len(triplets)
        if batch == 0 or len(next_triplets) != batch:
            raise ValueError(
                f"{type(self).__name__}.watch() needs one or more transitions, with as many "
                f"next_triplets as triplets; got {batch} triplets and {len(next_triplets)} "
                "next_triplets (pass the batch of one vector step, or obs[None] for one env)"
            )
        actions = self._check_actions(actions, batch)
        for name, flags in (("terminated", terminated), ("truncated", truncated)):
            if np.shape(flags) != (batch,):
                raise ValueError(
                    f"{type(self).__name__}.watch() expects {name} of shape ({batch},), one flag "
                    f"per transition, got shape {np.shape(flags)}"
                )
        self._store(triplets, actions, next_triplets)
        self.watch_calls += 1
        if self.watch_calls % self.config.update_every == 0:
            self._publish()
            if self.size >= self.config.learning_starts:
                self._start(self._sample())

    @property
    def pending(self) -> bool:
        """True while a gradient step has been started and its weights are not yet published."""
        return self._pending is not None

    def _start(self, batch: tuple[torch.Tensor, ...]) -> None:
        def work() -> tuple[dict[str, float], nn.Module]:
            return self._train_step(*batch)

        if not self.config.background:
            self._pending = run_now(work)
            return
        if self._thread is None:
            self._thread = UpdateThread()
            weakref.finalize(self, self._thread.close)
        self._pending = self._thread.submit(work)

    def _publish(self) -> None:
        """Wait for the step in flight, if any, and make its weights the published ones."""
        if self._pending is None:
            return
        start = time.perf_counter()
        try:
            metrics, module = self._pending.result()
        except Exception as exc:  # kept, then raised with the fix
            self._failure, self._pending = exc, None
            self._raise_failure()
        self._pending = None
        self.published = module
        self.updates += 1
        self.last_metrics = {**metrics, "wait_ms": 1000.0 * (time.perf_counter() - start)}

    def _raise_failure(self) -> None:
        pending = self._pending
        if pending is not None and pending.done() and pending.exception() is not None:
            self._failure, self._pending = pending.exception(), None
        if self._failure is not None:
            name = type(self).__name__
            raise RuntimeError(
                f"{name}'s gradient step failed ({type(self._failure).__name__}: "
                f"{self._failure}). Its weights may be half-updated, so it stops here: build a "
                f"new model or load_state_dict() a saved one (for a non-finite loss, lower "
                f"{type(self.config).__name__}.lr)."
            ) from self._failure

    def wait(self) -> None:
        """Block until the gradient step in flight (if any) has run; it is still published at its
        due ``watch`` call, so waiting changes no result."""
        if self._pending is not None:
            self._pending.exception()

    def close(self) -> None:
        """Stop the update thread after the step in progress (its result is kept)."""
        if self._thread is not None:
            self._thread.close()
            self._thread = None

    def __getstate__(self) -> dict[str, Any]:
        """Pickle without the thread: the step in flight is waited for and kept unpublished."""
        self.wait()
        state = {**self.__dict__, "_thread": None, "_pending": None}
        pending = self._pending
        if pending is not None and pending.exception() is not None:
            state["_failure"] = pending.exception()
        elif pending is not None:
            state["_pending_result"] = pending.result()
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        result = state.pop("_pending_result", None)
        self.__dict__.update(state)
        if result is not None:
            self._pending = run_now(lambda: result)

    def update(self) -> dict[str, float]:
        """One gradient step on a batch from the buffer, now, on this thread, its weights
        published at once (a step in flight is published first); returns its metrics."""
        self._raise_failure()
        self._publish()
        batch = self._sample()
        self._pending = run_now(lambda: self._train_step(*batch))
        self._publish()
        return self.last_metrics

    def state_dict(self) -> dict[str, Any]:
        """Weights (trained and published), optimizer, counters and RNG states (not the
        buffer); waits for the step in flight, which stays unpublished."""
        self.wait()
        self._raise_failure()
        pending = None if self._pending is None else self._pending.result()[0]
        return {
            **self._modules_state(),
            "published": self.published.state_dict(),
            "pending_metrics": pending,
            "watch_calls": self.watch_calls,
            "updates": self.updates,
            "rng": self.rng.bit_generator.state,
            "generator": self.generator.get_state(),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`state_dict` returned (the buffer refills from new transitions);
        clears a failure. A state that does not fit this model (:meth:`check_state`) is refused
        before anything is loaded."""
        self.wait()
        self.check_state(state)
        self._load_modules_state(state)
        self.published = frozen_copy(self._trained())
        if "published" in state:  # states saved before the published weights were kept
            self.published.load_state_dict(state["published"])
        self._failure = None
        self._pending = None
        if state.get("pending_metrics") is not None:
            self._pending = run_now(
                lambda: (state["pending_metrics"], frozen_copy(self._trained()))
            )
        self.watch_calls = int(state["watch_calls"])
        self.updates = int(state["updates"])
        self.rng.bit_generator.state = state["rng"]
        self.generator.set_state(state["generator"])

    def check_state(self, state: Any) -> None:
        """A TypeError for a ``state`` that is no dict, a ValueError naming every part of it
        that does not fit this model (a part missing, a network or optimizer state of another
        shape, a counter or RNG state that is no such thing); nothing is loaded."""
        name = type(self).__name__
        fix = (
            f"the state must come from state_dict() of a {name} built for frames of "
            f"{self.frame_shape} with the same config, e.g. "
            "model.load_state_dict(other.state_dict())"
        )
        if not isinstance(state, Mapping):
            raise TypeError(
                f"{name}.load_state_dict got a {type(state).__name__}, not a dict; {fix}"
            )
        problems = self._state_problems(state)
        if problems:
            more = len(problems) - 4
            shown = "; ".join(problems[:4]) + (f"; {more} more" if more > 0 else "")
            raise ValueError(
                f"{name}.load_state_dict cannot load this state: {shown}; {fix}. "
                "Nothing was loaded."
            )

    def _state_problems(self, state: Mapping) -> list[str]:
        """What of ``state`` does not fit: the parts of :meth:`_stateful`, the published
        weights, the step in flight, the counters and the RNG states."""
        parts = self._stateful()
        required = [*parts, "watch_calls", "updates", "rng", "generator", *self._more_state]
        missing = [key for key in required if key not in state]
        problems = [f"it lacks {', '.join(missing)}"] if missing else []
        for key, part in parts.items():
            if key not in state:
                continue
            if isinstance(part, torch.optim.Optimizer):
                problems += optimizer_problems(key, part, state[key])
            else:
                problems += module_problems(key, part, state[key])
        if "published" in state:
            problems += module_problems("published", self._trained(), state["published"])
        metrics = state.get("pending_metrics")
        if metrics is not None and not isinstance(metrics, Mapping):
            problems.append(f"its pending_metrics is {metrics!r:.60}, not None or a dict")
        for key in ("watch_calls", "updates"):
            if key in state:
                problems += count_problems(key, state[key])
        if "rng" in state and not self._fits_rng(state["rng"]):
            kind = type(self.rng.bit_generator).__name__
            problems.append(f"its rng is no state of numpy's {kind} generator")
        if "generator" in state and not self._fits_generator(state["generator"]):
            problems.append(f"its generator is no state of a torch {self.device.type} generator")
        return problems

    def _fits_rng(self, saved: Any) -> bool:
        """Whether ``saved`` is a state of this model's numpy bit generator (set on a scratch
        one)."""
        scratch = type(self.rng.bit_generator)()
        try:
            scratch.state = saved
        except (TypeError, ValueError, KeyError):
            return False
        return True

    def _fits_generator(self, saved: Any) -> bool:
        """Whether ``saved`` is a state of this model's torch generator (set on a scratch
        one)."""
        if not isinstance(saved, torch.Tensor):
            return False
        scratch = torch.Generator(self.device)
        try:
            scratch.set_state(saved)
        except (TypeError, ValueError, RuntimeError):
            return False
        return True
