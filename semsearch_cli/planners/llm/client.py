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
  recorded);
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

from ...errors import ScenarioError
from ...files import cache_dir
from ...optional import lazy_module

openai = lazy_module("openai")  # optional: pip install 'semsearch[llm]'

NO_KEY = "not-needed"  # what the client sends when api_key_env is unset (local servers ignore the key)
SLOT_WAIT_S = 0.01  # s between looks for a free request slot


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


def require_openai(where: str) -> None:
    """A :class:`ScenarioError` naming ``where`` when the ``openai`` package is not installed."""
    if openai is None:
        raise ScenarioError(where, "name", "the llm planner talks to its model through the openai package, which is not "
                            "installed: pip install 'semsearch[llm]'")


class Chat:
    """Chat completions on ``base_url`` with ``model``: :meth:`ask` sends messages and returns a
    :class:`Reply`, whatever happens."""

    def __init__(self, base_url: str, model: str, api_key_env: str, temperature: float, max_tokens: int, timeout_s: float,
                 retries: int, max_concurrent: int):
        require_openai("<llm planner>")
        self.model, self.temperature, self.max_tokens = model, temperature, max_tokens
        self.client = openai.OpenAI(base_url=base_url, api_key=os.environ.get(api_key_env) or NO_KEY, timeout=timeout_s,
                                    max_retries=retries)
        self.slots = Slots(base_url, max_concurrent)

    def ask(self, messages: list[dict]) -> Reply:
        """The reply to ``messages``; its seconds count from when a request slot was free (the wait
        for one is not the model's)."""
        t0 = time.perf_counter()
        try:
            with self.slots:
                t0 = time.perf_counter()
                resp = self.client.chat.completions.create(model=self.model, messages=messages, temperature=self.temperature,
                                                           max_tokens=self.max_tokens)
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


def _count(v) -> int:
    """A token count as the server gave it, 0 when it is not a whole number."""
    return int(v) if isinstance(v, int) and not isinstance(v, bool) and v >= 0 else 0


def prompt_path(name: str) -> Path:
    """A shipped prompt template (``semsearch_cli/data/prompts/<name>.txt``)."""
    return Path(__file__).resolve().parents[2] / "data" / "prompts" / f"{name}.txt"
