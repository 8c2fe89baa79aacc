"""The Dask executor: runs on a Dask cluster (the ``distributed`` package), a lab's machines or a
SLURM allocation through dask-jobqueue, or a local cluster started for the batch.

The loaded scenario is scattered to every worker once (``broadcast``), and runs travel in chunks
of a few, so that scheduling costs little next to a run. Workers send back each run's rows and
its path; the client (this process) writes the path files and appends the rows to runs.csv as
chunks finish, exactly as with the process pool, so the output folder needs no file system shared
with the workers. A worker that dies loses nothing: the scheduler re-runs its chunks elsewhere,
and a chunk's rows are written only when it comes back, so each run lands in runs.csv once.
"""

from __future__ import annotations

import asyncio
import itertools
import os
import re
import shutil
import socket
import tempfile
import threading
import time
from pathlib import Path
from typing import Iterable, Iterator

from ..credentials import redact, url_credential
from ..errors import MissingExtra, ScenarioError
from ..kernels import share_compiling_note
from ..optional import lazy_module
from .execution import Executor, Watch, execute
from .executors import register_executor
from .specs import Loaded, RunSpec
from .store import save_run_files


CONNECT_S = 8  # s to reach a scheduler before the command gives up
SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")  # a scheduler's protocols; all but ucx run over TCP and are probed first
_ADDRESS = re.compile(r"(?:(?P<scheme>[A-Za-z][A-Za-z0-9+.-]*)://)?(?P<host>\[[0-9A-Fa-f:.]+\]|[^\s:/\[\]]+):(?P<port>\d{1,5})/?")
dask = lazy_module("dask", "dask")  # imported at first use (the dask extra; None without it)
distributed = lazy_module("distributed", "dask")


def _run_chunk(loaded: Loaded, specs: list[RunSpec], watch: Watch, note: str | None = None) -> list[tuple]:
    """On a worker: (spec stem, rows, result) of each run of a chunk. ``note``: the batch's
    compiling-note file (:func:`~semsearch_cli.kernels.share_compiling_note`; on another machine it
    is not there, and each worker says the note once in its own log)."""
    share_compiling_note(note)
    out = []
    for spec in specs:
        rows, res = execute(loaded, spec, watch)
        out.append((spec.stem, rows, res))
    return out


class DaskExecutor(Executor):
    """Runs on the Dask scheduler at ``address`` (``tcp://HOST:PORT``), or, without one, on a
    local cluster of ``workers`` single-threaded worker processes started for the batch.
    ``chunk`` runs travel together; at most two chunks per worker thread are in flight, so the
    list of runs is streamed, never held whole. Inside ``with``, one client (and local cluster)
    serves every batch, e.g. all the values of a sweep; otherwise each batch starts its own."""

    def __init__(self, workers: int = 2, address: str | None = None, chunk: int = 4):
        self.workers, self.address, self.chunk = workers, address, max(1, int(chunk))
        self._kept = None  # (client, local cluster or None) while inside ``with``

    def __enter__(self):
        self._kept = self._client()
        return self

    def __exit__(self, *exc) -> None:
        kept, self._kept = self._kept, None
        if kept is not None:
            _close(*kept)

    def _client(self):
        if self.address:
            try:
                left = _probe(self.address)
                return distributed.Client(self.address, set_as_default=False, timeout=left), None
            except ScenarioError:
                raise
            except Exception as exc:  # unreachable, refused, not a scheduler (whatever answered), a failed handshake
                why = _why(exc)
                raise ScenarioError("<command line>", "--scheduler", f"no Dask scheduler answers at {self.address!r} "
                                    f"({why}; waited at most {CONNECT_S} s); give tcp://HOST:PORT of a running "
                                    "scheduler, or leave --scheduler out for a local cluster") from None
        # distributed adds its defaults to dask.config when it is imported; it must be imported before the
        # set() below, which would otherwise insert a "distributed" section and, on leaving, delete it whole
        # (defaults and all: KeyError 'distributed' from the scheduler and the cluster as they closed)
        local_cluster = distributed.LocalCluster
        # Dask's nanny sets MALLOC_TRIM_THRESHOLD_=65536 in its workers, which fixes glibc's mmap threshold
        # so that every grid-sized temporary is mapped and unmapped: runs took 1.45x as long (28.3 s vs
        # 19.6 s of run time for 40 Hotel runs). Unset here, and NumPy's huge pages off as in our own
        # processes (semsearch_cli/__init__.py); docs/usage.md "Running on a cluster" for your own workers.
        with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
                              "distributed.nanny.pre-spawn-environ.NUMPY_MADVISE_HUGEPAGE": "0"}):
            cluster = local_cluster(n_workers=self.workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                                   silence_logs=50)  # CRITICAL: no heartbeat noise when the cluster closes
        return distributed.Client(cluster, set_as_default=False), cluster

    def rows(self, loaded: Loaded, specs: Iterable[RunSpec], out: Path, watch: Watch) -> Iterator[list[dict]]:
        owned = self._kept is None
        client, cluster = self._client() if owned else self._kept
        note = os.path.join(tempfile.mkdtemp(prefix="semsearch-note-"), "said")
        share_compiling_note(note)
        try:
            shared = client.scatter(loaded, broadcast=True)  # once per worker, not with every run
            try:
                yield from self._stream(client, shared, iter(specs), out, watch, note)
            finally:
                shared.release()  # a kept cluster serves the next batch without this one's scenario
        finally:
            share_compiling_note(None)
            shutil.rmtree(os.path.dirname(note), ignore_errors=True)
            if owned:
                _close(client, cluster)

    def _stream(self, client, shared, specs: Iterator[RunSpec], out: Path, watch: Watch, note: str | None = None) -> Iterator[list[dict]]:
        pending = distributed.as_completed(loop=client.loop)
        ahead = 2 * max(1, sum(client.nthreads().values()))

        def submit(n: int):
            for _ in range(n):
                part = list(itertools.islice(specs, self.chunk))
                if not part:
                    return
                pending.add(client.submit(_run_chunk, shared, part, watch, note, pure=False))

        try:
            submit(ahead)
            for fut in pending:
                done = fut.result()
                fut.release()
                submit(1)
                for stem, rows, res in done:
                    save_run_files(out, stem, res)  # a failed run: its transcripts alone
                    yield rows
        except BaseException:
            client.cancel(list(pending.futures))
            raise


def check_address(address: str) -> tuple[str, str, int]:
    """(scheme, host, port) of a scheduler's address, ``[SCHEME://]HOST:PORT`` (scheme tcp by
    default; an IPv6 host in brackets); a :class:`ScenarioError` naming ``--scheduler`` for any
    other form, an unknown scheme or a port outside 1-65535. Only the form is checked here."""
    text = str(address).strip()
    secret = url_credential(text, bare=True)
    if secret:  # Dask's own credentials are TLS certificates in its configuration, never in the address
        raise ScenarioError("<command line>", "--scheduler", f"{redact(text)!r} holds {secret}: a scheduler address is "
                            "tcp://HOST:PORT alone; a cluster's credentials are TLS certificates in Dask's configuration "
                            "(distributed.comm.tls), given with tls://HOST:PORT")
    m = _ADDRESS.fullmatch(text)
    if m is None:
        raise ScenarioError("<command line>", "--scheduler", f"{address!r} is not a scheduler address; give "
                            "tcp://HOST:PORT (e.g. tcp://10.0.0.5:8786, or tcp://[::1]:8786 for IPv6)")
    scheme, host, port = (m["scheme"] or "tcp").lower(), m["host"].strip("[]"), int(m["port"])
    if scheme not in SCHEMES:
        raise ScenarioError("<command line>", "--scheduler", f"unknown protocol {scheme!r} in {address!r}; valid: "
                            f"{', '.join(SCHEMES)} (tcp://HOST:PORT for most clusters)")
    if not 1 <= port <= 65535:
        raise ScenarioError("<command line>", "--scheduler", f"port {port} in {address!r} is outside 1-65535")
    return scheme, host, port


def _probe(address: str) -> float:
    """Reach the scheduler at ``address`` and complete Dask's handshake, within :data:`CONNECT_S`
    in all; returns the seconds left of it. A refused port fails at once (a plain TCP connect
    first: Dask's own connect retries a refusal until its timeout), and a port that accepts but
    never answers, or answers with something else, fails at the bound: Dask's client bounds the
    connect but not the handshake after it, and a client that fails there takes another 16 s to
    close when it is collected. Raises what went wrong (OSError, TimeoutError, ...)."""
    scheme, host, port = check_address(address)
    t0 = time.monotonic()

    def left() -> float:
        return CONNECT_S - (time.monotonic() - t0)

    if scheme != "ucx":
        socket.create_connection((host, port), timeout=CONNECT_S).close()
    args = distributed.security.Security().get_connection_args("client")  # as the client's (tls:// from dask.config)

    async def hello():
        comm = await asyncio.wait_for(distributed.comm.connect(address, timeout=max(0.1, left()), **args), max(0.1, left()))
        await comm.close()

    failed: list[BaseException] = []

    def run():  # in a thread of its own: the caller may be inside a running event loop (a notebook)
        try:
            asyncio.run(hello())
        except BaseException as exc:  # handed to the caller
            failed.append(exc)

    t = threading.Thread(target=run, daemon=True, name="semsearch-scheduler-probe")
    t.start()
    t.join(max(0.1, left()) + 1)
    if t.is_alive():
        raise TimeoutError("no handshake")
    if failed:
        raise failed[0]
    return max(1.0, left())


def _why(exc: BaseException) -> str:
    """What went wrong reaching a scheduler, in a few words."""
    if isinstance(exc, TimeoutError):
        return "no answer"
    if isinstance(exc, OSError):
        return exc.strerror or str(exc) or type(exc).__name__
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text[:160]}" if text else type(exc).__name__  # e.g. garbage read as a message's length


def _close(client, cluster) -> None:
    client.close()
    if cluster is not None:
        cluster.close()


def require_dask() -> None:
    """:class:`MissingExtra` unless the dask extra (``distributed``) is installed."""
    if distributed is None:
        raise MissingExtra("--executor dask", "dask")


@register_executor("dask")
def dask_executor(workers: int, start_method: str | None, address: str | None, chunk: int) -> DaskExecutor:
    """The Dask scheduler at ``address``, or a local cluster of ``workers`` processes."""
    require_dask()
    if address:
        check_address(address)  # a malformed address is refused before a client is made
    return DaskExecutor(workers, address, chunk)
