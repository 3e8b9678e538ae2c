"""The command lines, one thin module each: argument parsing and ``main()`` over the library.

``train`` (``simoun-train``) and ``eval`` (``simoun-eval``); each also runs as
``python -m simoun_agent.cli.<name>``. :mod:`~simoun_agent.cli.flags` and
:mod:`~simoun_agent.cli.config_flags` hold the conventions every command shares, the lab's
(:mod:`simoun_lab.cli`) included. The layers below (:mod:`simoun_agent.run` and the optional
parts) never import this package.
"""

from simoun_wrappers._homes import missing_name


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
