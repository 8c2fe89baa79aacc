"""Reading a model's reply: a choice, or the reason it is not one (which the model is told when it
is asked again, and the transcript keeps). Nothing here guesses: a reply that does not name one
legal choice is invalid, never mapped to a default.

- an actor's reply names one number: the whole reply is that number (``3``, ``[3]``, ``3.``,
  ``"3"``), or its last line of the form ``Answer: 3`` (among its last 20 lines) gives it, so
  that a model that reasons first may; a reasoning model's ``<think>...</think>`` block is set
  aside; a number of more than 9 digits names no choice; a reply longer than 20,000 characters
  is not read;
- an estimator's reply is one JSON object (bare, or in a ```json fence) mapping shown choices'
  numbers to probabilities in [0, 1]; a target it leaves out counts as 0;
- a reply asked for under a JSON schema (``reply_format: json_schema``, :func:`schema`) is the
  object ``{"choice": N}`` (actor) or the probability table (estimator); an actor's reply that is
  not that object is read as above (a server that ignores the schema answers in words).

What a server is asked to keep to (:func:`schema`, :func:`grammar`) names only the choices
offered: a server that honours it cannot give an invalid reply, bar one cut short by
``max_tokens``.
"""

from __future__ import annotations

import json
import math
import re

from ..text import spell

MAX_REPLY = 20_000  # characters of a reply that are read (a longer one is invalid: "too long")
MAX_DIGITS = 9  # a number longer than this names no choice (and int() of thousands of digits refuses)
LAST_LINES = 20  # the lines at a reply's end where an "Answer: N" line is looked for
# each pattern is matched against one stripped line at most, never searched across a whole reply:
# no pattern here can take more than linear time in what it is given
BARE = re.compile(r"[\[\"'(]?[ \t]*(-?[0-9]+)[ \t]*[\]\"')]?[ \t]*\.?")
ANSWER = re.compile(r"\**[ \t]*answer[ \t]*\**[ \t]*[:=\-]?[ \t]*\**[ \t]*[\[\"'(]?[ \t]*(-?[0-9]+)[ \t]*[\]\"')]?[ \t]*\.?[ \t]*\**", re.I)


def strip_thinking(text: str) -> str:
    """``text`` without its ``<think>...</think>`` blocks (a reasoning model's), by plain search."""
    out, i, low = [], 0, text.lower()
    while True:
        a = low.find("<think>", i)
        if a < 0:
            return "".join(out) + text[i:]
        b = low.find("</think>", a)
        if b < 0:  # an unclosed block: everything after it is thinking
            return "".join(out) + text[i:a]
        out.append(text[i:a])
        i = b + len("</think>")


def _text(reply) -> tuple[str | None, str]:
    if reply is None or not isinstance(reply, str):
        return None, "the reply is empty"
    if len(reply) > MAX_REPLY:
        return None, f"the reply is too long ({len(reply):,} characters)"
    text = strip_thinking(reply).strip()
    if not text:
        return None, "the reply is empty"
    return text, ""


def _fenced(text: str) -> str:
    """The body of the first ```json fence in ``text`` (or of the first ``` fence), else ``text``."""
    a = text.find("```")
    if a < 0:
        return text
    b = text.find("```", a + 3)
    if b < 0:
        return text
    body = text[a + 3:b]
    return body[4:] if body[:4].lower() == "json" else body


def parse_number(reply, allowed) -> tuple[int | None, str]:
    """An actor's reply -> (the number it names, "") or (None, why not); ``allowed``: the numbers
    it may name (a range, a set)."""
    text, why = _text(reply)
    if text is None:
        return None, why
    m = BARE.fullmatch(text) if "\n" not in text else None
    found = [m.group(1)] if m else [a.group(1) for line in text.splitlines()[-LAST_LINES:]
                                     if (a := ANSWER.fullmatch(line.strip()))]
    if not found:
        return None, "the reply is not one number (answer with the number alone)"
    if len(found[-1].lstrip("-")) > MAX_DIGITS:
        return None, f"{found[-1][:12]}... is not one of the choices offered"
    n = int(found[-1])
    if n not in allowed:
        return None, f"{n} is not one of the choices offered"
    return n, ""


def parse_choice(reply, allowed) -> tuple[int | None, str]:
    """An actor's reply asked for under :func:`schema`: the object ``{"choice": N}``; a reply
    that is not a JSON object is read by :func:`parse_number` (a server that ignored the schema)."""
    text, why = _text(reply)
    if text is None:
        return None, why
    body = _fenced(text).strip()
    if not body.startswith("{"):
        return parse_number(reply, allowed)
    try:
        obj = json.loads(body)
    except (ValueError, RecursionError):
        return None, "the reply is not one JSON object {\"choice\": N}"
    if not isinstance(obj, dict) or set(obj) != {"choice"}:
        return None, "the reply is not the JSON object {\"choice\": N}"
    n = obj["choice"]
    if isinstance(n, bool) or not isinstance(n, int):
        return None, f"the choice {str(n)[:20]} is not a whole number"
    if n not in allowed:
        return None, f"{n} is not one of the choices offered"
    return n, ""


def schema(mode: str, allowed) -> dict:
    """The JSON schema of a reply that names only the choices offered: an actor's
    ``{"choice": N}``, N one of ``allowed``; an estimator's table, every choice of ``allowed`` a
    key with a probability from 0 to 1."""
    allowed = [int(a) for a in allowed]
    if mode == "actor":
        return {"type": "object", "properties": {"choice": {"type": "integer", "enum": allowed}}, "required": ["choice"],
                "additionalProperties": False}
    return {"type": "object", "properties": {str(a): {"type": "number", "minimum": 0, "maximum": 1} for a in allowed},
            "required": [str(a) for a in allowed], "additionalProperties": False}


def grammar(mode: str, allowed) -> str:
    """A GBNF grammar (llama.cpp's) of a reply that names only the choices offered: an actor's
    bare number, one of ``allowed``; an estimator's JSON table of every choice, each a
    probability written 0, 1, or 0. and up to four digits."""
    allowed = [int(a) for a in allowed]
    if mode == "actor":
        return "root ::= " + " | ".join(f'"{a}"' for a in allowed) + "\n"
    keys = ' "," ws '.join(f'"\\"{a}\\":" ws p' for a in allowed)
    return (f'root ::= "{{" ws {keys} ws "}}"\n'
            'p ::= "0" ("." [0-9] [0-9]? [0-9]? [0-9]?)? | "1" ("." "0" "0"? "0"? "0"?)?\n'
            'ws ::= " "?\n')


def parse_probabilities(reply, allowed) -> tuple[dict[int, float] | None, str]:
    """An estimator's reply -> ({choice: probability}, "") or (None, why not); ``allowed``: the
    choices' numbers that may be given a probability."""
    text, why = _text(reply)
    if text is None:
        return None, why
    body = _fenced(text).strip()
    try:
        obj = json.loads(body)
    except (ValueError, RecursionError):  # RecursionError: JSON nested thousands deep
        return None, "the reply is not one JSON object"
    if not isinstance(obj, dict):
        return None, "the reply is JSON, but not an object mapping targets to probabilities"
    out: dict[int, float] = {}
    for k, v in obj.items():
        key = k.strip().strip("[]") if isinstance(k, str) else k
        try:
            t = int(key)
        except (TypeError, ValueError):
            return None, f"{str(k)[:20]!r} is not a target's number"
        if str(t) != str(key) or t not in allowed:
            return None, f"{str(k)[:20]!r} is not one of the choices offered ({spell(sorted(allowed))})"
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not 0 <= v <= 1:
            return None, f"the probability of target {t} is {str(v)[:20]}, not a number from 0 to 1"
        out[t] = float(v)
    if not out:
        return None, "the object gives no target a probability"
    return out, ""
