"""The command lines, one thin module each: argument parsing and ``main()`` over the library.

``train`` (``simoun-train``), ``eval`` (``simoun-eval``), ``sweep`` (``simoun-sweep``),
``report`` (``simoun-report``), ``analyze`` (``simoun-analyze``) and ``study``
(``simoun-study``); each also runs as ``python -m simoun_agent.cli.<name>``. The layers below
(:mod:`simoun_agent.run` and the optional parts) never import this package.
"""
