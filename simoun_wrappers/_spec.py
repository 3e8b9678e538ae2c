"""``env.spec`` of the wrappers whose arguments may be objects (a camera function, a model, a
``Normalization`` instance): ``to_json()`` names the argument that JSON cannot hold.

Gymnasium's ``EnvSpec.to_json`` fails inside ``json`` with "Object of type function is not JSON
serializable", naming neither the wrapper nor the argument. :class:`CheckedSpec` is the same
spec with a ``to_json`` that looks at every wrapper's arguments first. Gymnasium's wrappers
stacked above deep-copy the spec, which keeps its class, so the check holds over them too.
"""

from __future__ import annotations

import copy
import dataclasses
import json
from typing import Any

from gymnasium.envs.registration import EnvSpec


class SharedSource:
    """A source as recorded in ``env.spec``: kept by reference, never deep-copied.

    Every wrapper stacked above ours deep-copies the spec (SB3's ``Monitor`` reads ``env.spec``),
    which would copy a ``CuriosityModel``'s weights and frame buffer (measured: about 1 s and
    85 MB with an unpooled 84x84 buffer) and wait for its update thread.
    ``gym.make(env.spec)`` hands this holder back to the constructor, which unwraps it,
    so a rebuilt env shares the original source, as it does when nothing is stacked above.
    """

    def __init__(self, source: Any) -> None:
        self.source = source

    def __deepcopy__(self, memo: dict[int, Any]) -> SharedSource:
        return self

    def __repr__(self) -> str:
        return f"SharedSource({self.source!r})"

    @staticmethod
    def unwrap(source: Any) -> Any:
        """``source`` itself, or the source a :class:`SharedSource` holds."""
        return source.source if isinstance(source, SharedSource) else source


# how each object argument can be given as JSON instead, where there is a way
_JSON_FORMS = {
    "cameras": "give the cameras as dm_control camera names or ids, or highway-env viewport dicts",
    "normalization": "pass the normalization's name, e.g. normalization='return_std'",
}


class CheckedSpec(EnvSpec):
    """An ``EnvSpec`` whose ``to_json()`` refuses, with a TypeError naming the wrapper and the
    argument, a wrapper argument that JSON cannot hold; otherwise Gymnasium's ``EnvSpec``
    (equal to an ``EnvSpec`` of the same fields)."""

    def to_json(self) -> str:
        unwritable = [
            (wrapper.name, key, value)
            for wrapper in self.additional_wrappers
            for key, value in (wrapper.kwargs or {}).items()
            if not _writable(value)
        ]
        if unwritable:
            raise TypeError(_unwritable(unwritable))
        made_with = [(key, value) for key, value in self.kwargs.items() if not _writable(value)]
        if made_with:
            raise TypeError(_unwritable_make(made_with, "num_envs" in self.kwargs))
        return super().to_json()

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, EnvSpec):
            return NotImplemented
        return all(
            getattr(self, f.name) == getattr(other, f.name)
            for f in dataclasses.fields(EnvSpec)
            if f.compare
        )

    __hash__ = None  # type: ignore[assignment]  # as EnvSpec's: a mutable dataclass


def checked_spec(spec: EnvSpec | None) -> EnvSpec | None:
    """``spec`` (a wrapper's own copy) made a :class:`CheckedSpec`, which adds no field."""
    if spec is not None and not isinstance(spec, CheckedSpec):
        spec.__class__ = CheckedSpec
    return spec


class CheckedSpecWrapper:
    """Mixin for a ``gym.Wrapper`` whose recorded arguments may be objects: its ``spec`` is a
    :class:`CheckedSpec`."""

    @property
    def spec(self) -> EnvSpec | None:
        return checked_spec(super().spec)  # type: ignore[misc]


class CheckedVectorSpecWrapper:
    """Mixin for a ``VectorWrapper``: its ``spec`` is a :class:`CheckedSpec` copy of the vector
    env's (Gymnasium records no vector wrapper in the spec, and hands out the vector env's own
    spec, whose class is left as it is)."""

    @property
    def spec(self) -> EnvSpec | None:
        spec = super().spec  # type: ignore[misc]
        return None if spec is None else checked_spec(copy.copy(spec))


def _writable(value: Any) -> bool:
    try:
        json.dumps(value)
    except (TypeError, ValueError):
        return False
    return True


def _unwritable(arguments: list[tuple[str, str, Any]]) -> str:
    """The error for the wrapper ``(name, key, value)`` arguments that JSON cannot hold."""

    named, advice = [], []
    for name, key, value in arguments:
        named.append(f"{name}'s {key}={_shown(value)}")
        form = _JSON_FORMS.get(key)
        advice.append(
            f"to write the spec, {form}"
            if form
            else f"elsewhere, build {name}(env, {key}=...) anew"
        )
    return (
        f"env.spec.to_json() cannot write {'; '.join(named)}: JSON holds names, numbers, lists "
        f"and dicts only. For {key if len(arguments) == 1 else 'these'}: {'; '.join(advice)}. "
        f"In this process, gym.make(env.spec) (no JSON) re-makes the env, keeping them as they "
        f"are."
    )


def _shown(value: Any) -> str:
    """``value`` as a message shows it: its repr, or its type when the repr is long."""
    held = SharedSource.unwrap(value)  # the spec holds the user's model in a SharedSource
    if len(repr(held)) <= 80:
        return repr(held)
    if isinstance(held, (list, tuple)):  # make_vec's wrappers: name each item's kind
        return f"[{', '.join(_shown(item) for item in held)}]"
    return f"a {type(held).__name__}"


def _unwritable_make(arguments: list[tuple[str, Any]], vector: bool) -> str:
    """The error for the ``(key, value)`` arguments of ``gym.make`` (``gym.make_vec`` when
    ``vector``) recorded in the spec that JSON cannot hold."""
    maker = "gym.make_vec" if vector else "gym.make"
    named = "; ".join(f"{maker}'s {key}={_shown(value)}" for key, value in arguments)
    advice = [
        "make the vector env without wrappers= to write its spec, and wrap the sub-envs again "
        "where the spec is read (a function cannot be written as JSON)"
        if key == "wrappers" and vector
        else f"pass {key} as a plain value to {maker}"
        for key, _ in arguments
    ]
    return (
        f"env.spec.to_json() cannot write {named}: JSON holds names, numbers, lists and dicts "
        f"only, and the spec records the arguments the env was made with. To write the spec, "
        f"{'; '.join(advice)}. In this process, {maker}(env.spec) (no JSON) re-makes the env, "
        "keeping them as they are."
    )
