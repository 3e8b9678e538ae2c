"""Keywords given to the wrong config class: ``AgentConfig(device='cuda')`` or
``TrainConfig(lr=1e-3)``. Python's own refusal names the keyword but not the class whose field
it is; this one says where the setting lives, in Python and on the command line."""

from __future__ import annotations

import dataclasses
import difflib
from collections.abc import Callable
from typing import Any


def field_names(cls: type) -> list[str]:
    """The fields of the dataclass ``cls``."""
    return [f.name for f in dataclasses.fields(cls)]


def wrong_class_problem(
    cls: type, name: str, value: Any, other: type, other_form: Callable[[str, Any], str]
) -> str:
    """Why ``cls`` refuses the keyword ``name``: the field of ``other`` (written as
    ``other_form(name, value)``) when it is one, else its close match among ``cls``'s fields."""
    if name in field_names(other):
        return (
            f"{cls.__name__} has no field {name!r}: {name} is a setting of {other.__name__}; "
            f"{other_form(name, value)}"
        )
    close = difflib.get_close_matches(name, field_names(cls), n=1)
    hint = f"; did you mean {close[0]}?" if close else ""
    return (
        f"{cls.__name__}.__init__() got an unexpected keyword argument {name!r}{hint} (its "
        f"fields: dataclasses.fields({cls.__name__}))"
    )


def refuse_unknown(
    cls: type, kwargs: dict[str, Any], other: type, other_form: Callable[[str, Any], str]
) -> None:
    """A TypeError for the first keyword of ``kwargs`` that is no field of ``cls``."""
    known = set(field_names(cls))
    for name, value in kwargs.items():
        if name not in known:
            raise TypeError(wrong_class_problem(cls, name, value, other, other_form))
