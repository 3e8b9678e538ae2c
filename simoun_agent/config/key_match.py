"""Close matches for a misspelled config key, found by its words as well as its letters.

``difflib`` alone compares letters, so ``agent.learning_rate`` came out closest to
``agent.n_step``. Here every known key is scored by the words the typed key shares with the
key's name and with its field docstring (``agent.lr``: "Adam learning rate of ..."), the
typed words standing as one phrase in that docstring ("frame skip" in action_repeat's), the
typed words' initials standing for the name (learning_rate -> lr), and difflib's ratio of the
names as a tie-breaker.

Example:
    >>> close_keys("agent.learning_rate", {"agent.lr": "Adam learning rate",
    ...                                    "agent.n_step": "steps of reward summed"})
    ['agent.lr']
"""

from __future__ import annotations

import difflib
import re

STOPWORDS = frozenset(
    "a an and as at be by e.g else eq for from in into is it its none of on or per the this "
    "to with".split()
)
"""Words of a docstring that say nothing about what the field is."""

NAME_WEIGHT = 2.0
"""A word shared with the key's name counts twice one shared with its docstring."""

EXACT = 100.0
"""Score of a key whose words are the typed ones (``agent.batch-size`` for agent.batch_size)."""

KEEP_WITHIN = 0.5
"""Keys scoring within this of the best are all suggested (critic_tau and encoder_tau)."""


def words(text: str) -> list[str]:
    """Lower-case words of a key or docstring: ``"agent.batch_size"`` -> agent, batch, size."""
    return re.findall(r"[a-z0-9]+", text.lower())


def same_word(typed: str, known: str) -> bool:
    """Equal, or (from 4 letters on) one a prefix of the other or nearly the same spelling:
    seeds ~ seed, temp ~ temperature, bach ~ batch."""
    if typed == known:
        return True
    if min(len(typed), len(known)) < 4:
        return False
    if typed.startswith(known) or known.startswith(typed):
        return True
    return difflib.SequenceMatcher(None, typed, known).ratio() >= 0.8


SYNONYMS = {
    "frame": ("image",),
    "frames": ("image",),
    "img": ("image",),
    "resolution": ("image", "size"),
    "res": ("image", "size"),
    "pixels": ("image", "size"),
    "width": ("image", "size"),
    "height": ("image", "size"),
}
"""Words a user types for a key's word that neither its name nor its docstring uses:
``--frame-size`` and ``--resolution`` mean ``--image-size``."""

SYNONYM_DISCOUNT = 1.0
"""A key matched only through :data:`SYNONYMS` scores this much below the same match typed."""


def score(typed: str, key: str, doc: str) -> float:
    """How well ``key`` (with field docstring ``doc``) fits the unknown ``typed`` key; 0 for
    no relation at all."""
    typed_section, _, typed_name = typed.rpartition(".")
    section, _, name = key.rpartition(".")
    typed_words = words(typed_name)
    name_words = words(name)
    # the key itself, spelled with dashes or capitals, or with another separator between the
    # section and the name (agent-lr, agent_lr for agent.lr)
    if typed_words == name_words or words(typed) == words(key):
        return EXACT
    doc_words = [word for word in words(doc) if word not in STOPWORDS]
    in_name = sum(any(same_word(t, w) for w in name_words) for t in typed_words)
    in_doc = sum(any(same_word(t, w) for w in doc_words) for t in typed_words)
    initials = "".join(word[0] for word in typed_words)
    acronym = len(typed_words) >= 2 and initials == "".join(name_words)
    # the typed words as a phrase of the docstring name the field: "frame skip", "learning rate"
    phrase = len(typed_words) >= 2 and f" {' '.join(typed_words)} " in f" {' '.join(words(doc))} "
    spelling = difflib.SequenceMatcher(None, typed_name.lower(), name).ratio()
    if not (in_name or in_doc or acronym or spelling >= 0.75):
        return 0.0
    # a phrase counts its words as if they were the name's, not a second time as doc words
    as_name = in_name + acronym + (len(typed_words) - in_name if phrase else 0)
    total = NAME_WEIGHT * as_name + (0 if phrase else in_doc) + spelling
    # a key typed with a section (agent.) most likely belongs to it
    return total - (0.5 if typed_section and typed_section != section else 0.0)


def meaning_score(typed: str, key: str, doc: str) -> float:
    """:func:`score`, or that of ``typed`` with its words read through :data:`SYNONYMS` (less
    :data:`SYNONYM_DISCOUNT`) when that is higher."""
    best = score(typed, key, doc)
    section, dot, name = typed.rpartition(".")
    said = words(name)
    meant = [word for typed_word in said for word in SYNONYMS.get(typed_word, (typed_word,))]
    if meant != said:
        as_meant = score(f"{section}{dot}{'_'.join(dict.fromkeys(meant))}", key, doc)
        best = max(best, as_meant - SYNONYM_DISCOUNT)
    return best


def close_keys(typed: str, docs: dict[str, str], n: int = 3) -> list[str]:
    """Up to ``n`` keys of ``docs`` (key -> field docstring) that ``typed`` most likely meant,
    best first; empty when none is related."""
    scores = {key: meaning_score(typed, key, doc) for key, doc in docs.items()}
    ranked = sorted((key for key in scores if scores[key] > 0), key=lambda k: -scores[k])
    if not ranked:
        return []
    best = scores[ranked[0]]
    return [key for key in ranked if scores[key] >= best - KEEP_WITHIN][:n]


def did_you_mean(typed: str, docs: dict[str, str]) -> str:
    """``" (did you mean agent.lr?)"``, or an empty string when nothing is close."""
    matches = close_keys(typed, docs)
    return f" (did you mean {' or '.join(matches)}?)" if matches else ""
