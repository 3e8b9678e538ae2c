"""Building command lines in tests: a base list of flags with some of them given new values;
and a small agent's keys for the study specs of tests.

The command lines refuse a flag given twice with different values, so a test that changes a
flag of a shared base list replaces it instead of appending a second value.
"""

TINY_AGENT = [
    "--device", "cpu",
    "--torch-threads", "1",
    "--agent.batch-size", "8",
    "--agent.num-filters", "4",
    "--agent.feature-dim", "8",
    "--agent.hidden-dim", "16",
    "--agent.aux-hidden-dim", "16",
]  # fmt: skip
"""A tiny agent on one CPU thread, as simoun-train flags: runs of a few seconds."""

SMALL_AGENT = """\
video = false
device = "cpu"
agent.batch_size = 8
agent.num_filters = 8
agent.feature_dim = 16
agent.hidden_dim = 32
agent.aux_hidden_dim = 32
"""
"""A small agent on the CPU, no video, as the [base] keys of a study spec's TOML: runs of a few
seconds."""


def override(base: list[str], *flags: str) -> list[str]:
    """``base`` without the flags (and their values) that ``flags`` gives, then ``flags``.

    Flags are ``--name value`` pairs, or a lone ``--name`` followed by another flag.

    >>> override(["--env", "a", "--seed", "1"], "--env", "b")
    ['--seed', '1', '--env', 'b']
    """
    given = {flag for flag in flags if flag.startswith("--")}
    kept, skip = [], False
    for position, item in enumerate(base):
        if skip:
            skip = False
            continue
        if item in given:
            following = base[position + 1] if position + 1 < len(base) else "--"
            skip = not following.startswith("--")
            continue
        kept.append(item)
    return [*kept, *flags]
