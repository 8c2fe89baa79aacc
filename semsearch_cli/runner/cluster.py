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

import itertools
from pathlib import Path
from typing import Iterable, Iterator

from ..errors import ScenarioError
from ..optional import lazy_module
from .execution import NO_PATH, Executor, Watch, execute
from .executors import register_executor
from .specs import Loaded, RunSpec
from .store import save_run_files


CONNECT_S = 8  # s to reach a scheduler before the command gives up
dask = lazy_module("dask")  # imported at first use (the dask extra; None without it)
distributed = lazy_module("distributed")


def _run_chunk(loaded: Loaded, specs: list[RunSpec], watch: Watch) -> list[tuple]:
    """On a worker: (spec stem, rows, result) of each run of a chunk."""
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
                return distributed.Client(self.address, set_as_default=False, timeout=CONNECT_S), None
            except (OSError, TimeoutError, ValueError, TypeError) as exc:  # unreachable, refused, a malformed address
                raise ScenarioError("<command line>", "--scheduler", f"no Dask scheduler answers at {self.address!r} "
                                    f"within {CONNECT_S} s ({type(exc).__name__}: {exc}); give tcp://HOST:PORT of a "
                                    "running scheduler, or leave --scheduler out for a local cluster") from None
        # Dask's nanny sets MALLOC_TRIM_THRESHOLD_=65536 in its workers, which fixes glibc's mmap threshold
        # so that every grid-sized temporary is mapped and unmapped: runs took 1.45x as long (28.3 s vs
        # 19.6 s of run time for 40 Hotel runs). Unset here, and NumPy's huge pages off as in our own
        # processes (semsearch_cli/__init__.py); docs/usage.md "Running on a cluster" for your own workers.
        with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
                              "distributed.nanny.pre-spawn-environ.NUMPY_MADVISE_HUGEPAGE": "0"}):
            cluster = distributed.LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                                   silence_logs=50)  # CRITICAL: no heartbeat noise when the cluster closes
        return distributed.Client(cluster, set_as_default=False), cluster

    def rows(self, loaded: Loaded, specs: Iterable[RunSpec], out: Path, watch: Watch) -> Iterator[list[dict]]:
        owned = self._kept is None
        client, cluster = self._client() if owned else self._kept
        try:
            shared = client.scatter(loaded, broadcast=True)  # once per worker, not with every run
            try:
                yield from self._stream(client, shared, iter(specs), out, watch)
            finally:
                shared.release()  # a kept cluster serves the next batch without this one's scenario
        finally:
            if owned:
                _close(client, cluster)

    def _stream(self, client, shared, specs: Iterator[RunSpec], out: Path, watch: Watch) -> Iterator[list[dict]]:
        pending = distributed.as_completed(loop=client.loop)
        ahead = 2 * max(1, sum(client.nthreads().values()))

        def submit(n: int):
            for _ in range(n):
                part = list(itertools.islice(specs, self.chunk))
                if not part:
                    return
                pending.add(client.submit(_run_chunk, shared, part, watch, pure=False))

        try:
            submit(ahead)
            for fut in pending:
                done = fut.result()
                fut.release()
                submit(1)
                for stem, rows, res in done:
                    if res.outcome not in NO_PATH:
                        save_run_files(out, stem, res)
                    yield rows
        except BaseException:
            client.cancel(list(pending.futures))
            raise


def _close(client, cluster) -> None:
    client.close()
    if cluster is not None:
        cluster.close()


@register_executor("dask")
def dask_executor(workers: int, start_method: str | None, address: str | None, chunk: int) -> DaskExecutor:
    """The Dask scheduler at ``address``, or a local cluster of ``workers`` processes."""
    if distributed is None:
        raise ScenarioError("<command line>", "--executor", "dask needs the distributed package: pip install 'semsearch[dask]'")
    return DaskExecutor(workers, address, chunk)
