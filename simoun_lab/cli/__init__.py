"""The lab's command lines, one thin module each: argument parsing and ``main()`` over the lab.

``sweep`` (``simoun-sweep``), ``report`` (``simoun-report``), ``analyze`` (``simoun-analyze``)
and ``study`` (``simoun-study``); each also runs as ``python -m simoun_lab.cli.<name>``. They
share the conventions of :mod:`simoun_agent.cli.flags` with ``simoun-train`` and
``simoun-eval``.
"""

from simoun_wrappers._homes import missing_name


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
