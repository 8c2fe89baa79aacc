"""Credentials kept out of what semsearch writes.

An address (a planner's ``base_url``, a mirror, a scheduler) is written into labels, rows,
meta.json, tables, reports and file names, so a key written inside one would be written
everywhere. Such an address is refused where it is given, never stripped in silence:
:func:`url_credential` says what in it is a credential, :func:`redact` shows it with the
credential masked (for an error message, and as a last guard in a planner's label).

What counts as a credential in an address:

- a user name or a password before the host (``http://user:KEY@host``, ``http://KEY@host``);
- a query parameter (or a fragment's) of a non-empty value whose name, lower-cased with ``-``
  read as ``_``, is one of :data:`SECRET_NAMES` (``key``, ``api_key``, ``token``,
  ``access_token``, ``password``, ``sig``, ...) or ends in one of :data:`SECRET_SUFFIXES`
  (``_key``, ``_token``, ``_secret``, ...: ``subscription-key``, ``x-api-key``,
  ``X-Amz-Signature``). ``api-version`` and other parameters are not credentials.
"""

from __future__ import annotations

import re
from urllib.parse import unquote_plus

SECRET_NAMES = frozenset({
    "key", "apikey", "api_key", "token", "access_token", "refresh_token", "id_token", "auth", "auth_token",
    "authorization", "bearer", "password", "passwd", "pwd", "pass", "secret", "client_secret", "sig", "signature",
    "session", "session_id", "sessionid", "credential", "credentials", "private_token",
})
SECRET_SUFFIXES = ("_key", "_token", "_secret", "_password", "_signature", "_credential", "apikey")
MASK = "***"
_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")
# known prefixes of API keys (OpenAI, Anthropic, Hugging Face, Groq, GitHub, GitLab, Slack, Google, AWS)
KEY_PREFIXES = ("sk-", "sk_", "hf_", "gsk_", "ghp_", "gho_", "ghs_", "github_pat_", "glpat-", "xoxb-", "xoxp-", "AIza", "AKIA")
_KEY_TOKEN = re.compile("(" + "|".join(re.escape(p) for p in KEY_PREFIXES) + r")[A-Za-z0-9_\-]{4,}")


def _secret_name(name: str) -> bool:
    n = name.strip().lower().replace("-", "_")
    return n in SECRET_NAMES or n.endswith(SECRET_SUFFIXES)


def _split(text: str, bare: bool) -> tuple[str, str, str, str] | None:
    """(scheme and ``://``, authority, path, query and fragment) of an address, or None when
    ``text`` is no address (no ``scheme://``, unless ``bare``: ``user:key@host:8000/v1``)."""
    m = _SCHEME.match(text)
    if m is None and not bare:
        return None
    head = m.group(0) if m else ""
    rest = text[len(head):]
    cut = min((i for i in (rest.find(c) for c in "/?#") if i >= 0), default=len(rest))
    authority, tail = rest[:cut], rest[cut:]
    q = min((i for i in (tail.find(c) for c in "?#") if i >= 0), default=len(tail))
    return head, authority, tail[:q], tail[q:]


def url_credential(text, bare: bool = False) -> str | None:
    """What in the address ``text`` is a credential, in words (``"a user name and password before
    the host (user:***@)"``, ``"the query parameter 'api_key'"``), or None (also for anything
    that is not text, or not an address: without ``scheme://`` unless ``bare``). Never the
    credential itself."""
    if not isinstance(text, str):
        return None
    parts = _split(text.strip(), bare)
    if parts is None:
        return None
    _, authority, _, query = parts
    if "@" in authority:
        info = authority.rsplit("@", 1)[0]
        return ("a user name and password before the host (user:***@)" if ":" in info else
                "a user name (or key) before the host (***@)")
    for piece in re.split(r"[?#&;]", query):
        name, _, value = (unquote_plus(x) for x in piece.partition("="))
        if value and _secret_name(name):
            return f"the query parameter {name!r}"
    return None


_EMBEDDED = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*://[^\s,\[\]'\"<>]*")  # an address inside other text (a label)


def _redact_one(s: str, bare: bool) -> str:
    parts = _split(s, bare)
    if parts is None:
        return s
    head, authority, path, query = parts
    if "@" in authority:
        authority = MASK + "@" + authority.rsplit("@", 1)[1]

    def mask(m: re.Match) -> str:
        return m.group(1) + m.group(2) + "=" + (MASK if _secret_name(unquote_plus(m.group(2))) and m.group(3) else m.group(3))

    return head + authority + path + re.sub(r"([?&#;])([^=&#;]*)=([^&#;]*)", mask, query)


def redact(text) -> str:
    """``text`` as a message or a label may show it: every address in it with its credentials
    masked (``http://***@host/v1``, ``...?api_key=***``; text without ``://`` that holds ``@`` is
    read as one address, ``user:key@host``) and a known key token (``sk-...``) masked; anything
    else as ``str()`` gives it."""
    s = str(text)
    if "://" in s:
        s = _EMBEDDED.sub(lambda m: _redact_one(m.group(0), False), s)
    elif "@" in s:
        s = _redact_one(s, True)
    return _KEY_TOKEN.sub(lambda m: m.group(1) + MASK, s)


def looks_like_key(text) -> bool:
    """Whether ``text`` starts as a known kind of API key does (:data:`KEY_PREFIXES`)."""
    return isinstance(text, str) and _KEY_TOKEN.match(text.strip()) is not None


WHERE_THE_KEY_GOES = ("a key is never written into an address (labels, rows, meta.json, reports and file names carry it): "
                      "put the key in an environment variable and name the variable in api_key_env (default "
                      "OPENAI_API_KEY; export OPENAI_API_KEY=<your key>); the address is then the host alone, e.g. "
                      "https://api.example.com/v1 (docs/llm.md, Keys)")


def credential_in(text) -> str | None:
    """What credential any address inside ``text`` holds (:func:`url_credential` of each
    ``scheme://...`` in it: a planner label given whole, ``llm[base_url=http://u:KEY@host/v1]``),
    or None."""
    if not isinstance(text, str):
        return None
    return next((c for m in _EMBEDDED.finditer(text) if (c := url_credential(m.group(0)))), None)
