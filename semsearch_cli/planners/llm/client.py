"""The language model behind the ``llm`` planner: any server that speaks OpenAI's chat completions
(a hosted API; a local vLLM, llama.cpp or Ollama server), through the ``openai`` client library.

What a lab relies on, and where it is done:

- timeouts and retries: the client library's own (``timeout_s`` per request; ``retries`` more
  attempts on a connection error, a timeout, 408, 409, 429 and 5xx, with exponential backoff from
  0.5 s up to 8 s, and a server's ``Retry-After`` honoured);
- a cap on requests in flight across every worker process of this machine (:class:`Slots`:
  ``max_concurrent`` lock files per endpoint, held with ``flock`` while a request is out);
- the API key read from the environment variable ``api_key_env`` when the client is made, and
  kept nowhere else: not in rows, transcripts or meta.json (a request's headers are never
  recorded); a key written into ``base_url`` (``http://user:KEY@host``, ``?api_key=``) is
  refused when the scenario loads (:func:`url_fault`);
- nothing a server does raises out of :meth:`Chat.ask` (any ``Exception``; a run's wall-clock
  limit, a ``BaseException``, still ends the run): a reply, or the reason there is none
  (``error``), always comes back, so the planner counts it.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import time
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import urlsplit

from ...credentials import WHERE_THE_KEY_GOES, redact, url_credential
from ...errors import MissingExtra
from ...files import cache_dir
from ...optional import lazy_module

openai = lazy_module("openai", "llm")  # optional: pip install 'semsearch[llm]'

NO_KEY = "not-needed"  # what the client sends when api_key_env is unset (local servers ignore the key)
SLOT_WAIT_S = 0.01  # s between looks for a free request slot
PREFLIGHT_TIMEOUT_S = 5.0  # s the check of an endpoint before a batch waits for the server (no retries)
MISSING = str(MissingExtra("the llm planner", "llm"))  # the openai package, not installed


@dataclass
class Reply:
    """One call to the model: its text (None when it gave none), the reason it gave none
    (``error``: an HTTP status, a timeout, a reply without a message), its tokens as the server
    counted them (0 when it did not say), the model that answered (the server's id) and the
    seconds the call took (retries included)."""

    text: str | None
    error: str = ""
    tokens_in: int = 0
    tokens_out: int = 0
    model: str = ""
    latency_s: float = 0.0


class Slots:
    """At most ``n`` requests in flight to one endpoint from every process on this machine: ``n``
    lock files under ``cache_dir()/llm-slots/<endpoint>``, one held (``flock``) per request.
    A process that dies lets go of its slot (the kernel drops its locks)."""

    def __init__(self, endpoint: str, n: int):
        self.folder = cache_dir() / "llm-slots" / hashlib.sha256(endpoint.encode()).hexdigest()[:16]
        self.n = n
        self._fh = None

    def __enter__(self) -> "Slots":
        self.folder.mkdir(parents=True, exist_ok=True)
        while True:
            for k in range(self.n):
                fh = open(self.folder / f"slot-{k}.lock", "a")
                try:
                    fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except OSError:
                    fh.close()
                    continue
                self._fh = fh
                return self
            time.sleep(SLOT_WAIT_S)

    def __exit__(self, *exc) -> None:
        fh, self._fh = self._fh, None
        if fh is not None:
            fcntl.flock(fh, fcntl.LOCK_UN)
            fh.close()


def openai_installed() -> bool:
    """Whether the ``openai`` package (the llm extra) is installed."""
    return openai is not None


def require_openai() -> None:
    """:class:`~semsearch_cli.errors.MissingExtra` when the ``openai`` package is not installed
    (a batch refuses before its first run; a worker without it records the run as one that could
    not run, which the same command runs again)."""
    if openai is None:
        raise MissingExtra("the llm planner", "llm")


def url_fault(base_url: str) -> str | None:
    """What is wrong with ``base_url`` as written (a credential in it, no scheme, no host), or
    None. A credential (:func:`~semsearch_cli.credentials.url_credential`: a user name and
    password before the host, a query parameter such as ``api_key=``) is refused, as the address
    is written into the planner's label, and so into rows, reports and file names; the message
    shows the address masked, never the key."""
    secret = url_credential(base_url, bare=True)
    if secret:
        return f"{redact(base_url)!r} holds {secret}: {WHERE_THE_KEY_GOES}"
    try:
        parts = urlsplit(base_url.strip())
        port = parts.port  # a port outside 0-65535 raises here
    except ValueError as exc:  # a bracket left open (http://[::1), a port of letters or past 65535
        return f"{base_url!r} is not an address ({exc}); write it whole, e.g. http://localhost:8000/v1 or http://[::1]:8000/v1"
    if port == 0:
        return f"{base_url!r} names port 0; give the server's port (1-65535), e.g. http://localhost:8000/v1"
    if parts.scheme not in ("http", "https") or not parts.netloc:
        example = "http://" + base_url.strip().split("://")[-1].rstrip("/") if base_url.strip() else "http://localhost:8000"
        if not example.endswith("/v1"):
            example += "/v1"
        return (f"{base_url!r} is not an http:// or https:// address with a host; write it whole, e.g. {example}")
    return None


def preflight(base_url: str, model: str, api_key_env: str, key_named: bool) -> tuple[str, str] | None:
    """One look at the endpoint before a batch's first run (docs/llm.md, Before the first run): the
    address (http or https, a host), the key's variable set when the scenario names one, the server
    reachable within :data:`PREFLIGHT_TIMEOUT_S` s, its list of models (``GET base_url/models``)
    holding ``model`` when the server lists models. Returns the parameter at fault and what
    failed, in a sentence, or None.
    A ``base_url`` whose path does not end in ``/v1`` and that answers 404 is named as such."""
    bad = url_fault(base_url)
    if bad:
        return "base_url", bad
    key = os.environ.get(api_key_env)
    if key_named and not key:
        return "api_key_env", (f"api_key_env names the variable {api_key_env}, which is not set in this environment: export "
                f"{api_key_env}=<your key> (or leave api_key_env out for a local server that takes no key)")
    client = openai.OpenAI(base_url=base_url, api_key=key or NO_KEY, timeout=PREFLIGHT_TIMEOUT_S, max_retries=0)
    at = base_url.rstrip("/") + "/models"
    try:
        listed = [str(getattr(m, "id", "")) for m in client.models.list().data]
    except openai.APIStatusError as exc:
        code = exc.status_code
        if code in (401, 403):
            why = (f"the variable {api_key_env} (api_key_env) is not set" if not key else
                   f"the key in {api_key_env} (api_key_env) was refused")
            return "base_url" if not key_named else "api_key_env", f"the server at {base_url} answered HTTP {code} (not authorised): {why}"
        if code == 404 and not urlsplit(base_url).path.rstrip("/").endswith("/v1"):
            return "base_url", (f"the server at {base_url} answered HTTP 404 at {at}: an OpenAI-compatible server serves under /v1, "
                    f"and base_url does not end in /v1 (e.g. {base_url.rstrip('/')}/v1)")
        if code in (404, 405, 501):  # a server that does not list its models: it answered, which is what can be checked
            return None
        return "base_url", f"the server at {base_url} answered HTTP {code} at {at}"
    except openai.APITimeoutError:
        return "base_url", f"no answer from {base_url} within {PREFLIGHT_TIMEOUT_S:g} s"
    except openai.APIConnectionError as exc:
        cause = exc.__cause__ or exc
        return "base_url", f"no connection to {base_url} ({type(cause).__name__}: {str(cause)[:160]})"
    except Exception:  # noqa: BLE001  (a reply that is not a list of models: the server answered, it lists nothing)
        return None
    if listed and model not in listed:
        shown = ", ".join(listed[:10]) + (f" and {len(listed) - 10} more" if len(listed) > 10 else "")
        return "model", f"the server at {base_url} does not serve the model {model!r}; it lists {shown}"
    return None


class Chat:
    """Chat completions on ``base_url`` with ``model``: :meth:`ask` sends messages and returns a
    :class:`Reply`, whatever happens."""

    def __init__(self, base_url: str, model: str, api_key_env: str, temperature: float, max_tokens: int, timeout_s: float,
                 retries: int, max_concurrent: int, seed: int | None = None):
        require_openai()
        self.model, self.temperature, self.max_tokens, self.seed = model, temperature, max_tokens, seed
        self.client = openai.OpenAI(base_url=base_url, api_key=os.environ.get(api_key_env) or NO_KEY, timeout=timeout_s,
                                    max_retries=retries)
        self.slots = Slots(base_url, max_concurrent)

    def ask(self, messages: list[dict], keep_to: dict | None = None) -> Reply:
        """The reply to ``messages``; its seconds count from when a request slot was free (the wait
        for one is not the model's). ``keep_to``: what the reply is asked to keep to, as the
        request's fields (:func:`constraint`)."""
        t0 = time.perf_counter()
        extra = {} if self.seed is None else {"seed": self.seed}
        try:
            with self.slots:
                t0 = time.perf_counter()
                resp = self.client.chat.completions.create(model=self.model, messages=messages, temperature=self.temperature,
                                                           max_tokens=self.max_tokens, **extra, **(keep_to or {}))
            usage = getattr(resp, "usage", None)
            tin = _count(getattr(usage, "prompt_tokens", 0))
            tout = _count(getattr(usage, "completion_tokens", 0))
            choices = getattr(resp, "choices", None) or []
            msg = getattr(choices[0], "message", None) if choices else None
            text = getattr(msg, "content", None)
            model = str(getattr(resp, "model", "") or "")
            if not isinstance(text, str):
                return Reply(None, "the server's reply holds no message", tin, tout, model, time.perf_counter() - t0)
            return Reply(text, "", tin, tout, model, time.perf_counter() - t0)
        except openai.APIStatusError as exc:
            return Reply(None, f"HTTP {exc.status_code} from the server", latency_s=time.perf_counter() - t0)
        except openai.APITimeoutError:
            return Reply(None, "no reply within timeout_s", latency_s=time.perf_counter() - t0)
        except openai.APIConnectionError as exc:
            return Reply(None, f"no connection to the server ({type(exc.__cause__ or exc).__name__})",
                         latency_s=time.perf_counter() - t0)
        except Exception as exc:  # noqa: BLE001  (a body that is not a chat completion: not JSON, another shape, nested too deep)
            return Reply(None, f"the server's reply is not a chat completion ({type(exc).__name__})",
                         latency_s=time.perf_counter() - t0)


def constraint(reply_format: str, schema: dict, grammar: str) -> dict | None:
    """The request's fields that ask the server to keep its reply to the choices offered:
    ``json_schema``, OpenAI's structured outputs (``response_format`` of type ``json_schema``,
    which OpenAI, vLLM and llama.cpp's ``llama-server`` take); ``json_object``, llama.cpp's form
    (``response_format`` of type ``json_object`` with the ``schema``: ``llama-server`` and
    ``llama_cpp.server``, which refuses the first); ``grammar``, a GBNF grammar in the request's
    body (llama.cpp's two servers); ``text``: none."""
    if reply_format == "json_schema":
        return {"response_format": {"type": "json_schema", "json_schema": {"name": "reply", "strict": True, "schema": schema}}}
    if reply_format == "json_object":
        return {"response_format": {"type": "json_object", "schema": schema}}
    if reply_format == "grammar":
        return {"extra_body": {"grammar": grammar}}
    return None


def _count(v) -> int:
    """A token count as the server gave it, 0 when it is not a whole number."""
    return int(v) if isinstance(v, int) and not isinstance(v, bool) and v >= 0 else 0


def prompt_path(name: str) -> Path:
    """A shipped prompt template (``semsearch_cli/data/prompts/<name>.txt``)."""
    return Path(__file__).resolve().parents[2] / "data" / "prompts" / f"{name}.txt"
