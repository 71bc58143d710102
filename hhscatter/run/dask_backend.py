"""Dask backend: run a scene's chunks as tasks on a ``dask.distributed`` cluster.

``hhscatter simulate SCENE --out OUT --scheduler tcp://HOST:PORT`` sends every
(point, chunk) of the run as one task to an existing cluster;
``--scheduler local`` starts a ``LocalCluster`` of ``--workers`` single-threaded
worker processes for the run and stops it afterwards. Nothing else changes:
the tables are byte-identical to a run on the local process pool.

Requirements on a real cluster: every worker has hhscatter (same version) and
can write to ``OUT``: a shared filesystem path, or a URL such as
``s3://bucket/runs/x`` that pyarrow or fsspec can open on the workers. Workers
write their part files themselves and send back only a small summary per
chunk, so the client's bandwidth and memory do not grow with N.

Install the optional extra: ``pip install 'hhscatter[dask]'``.
"""

from __future__ import annotations

import contextlib
import logging

from hhscatter.errors import ConfigError, SetupError
from hhscatter.run.worker import default_workers

#: the address protocols of dask.distributed's communication layer
SCHEMES = ("tcp", "tls", "inproc", "ucx", "ws", "wss")


def check_available() -> None:
    """check_available() -> None; SetupError naming the extra if dask.distributed is missing."""
    try:
        import distributed  # noqa: F401  # deferred: distributed loads on first use
    except ImportError:
        raise SetupError(
            "scheduler: dask.distributed is not installed; pip install 'hhscatter[dask]' "
            "(or run without --scheduler to use the local process pool)"
        ) from None


def check_scheduler(scheduler: str, workers: int | None) -> None:
    """check_scheduler(scheduler, workers) -> None; ConfigError on a bad value, before any work."""
    check_available()
    if scheduler == "local":
        return
    scheme = scheduler.split("://", 1)[0] if "://" in scheduler else None
    if scheme not in SCHEMES:
        raise ConfigError(
            f"scheduler must be 'local' or an address like tcp://host:8786 (protocols: "
            f"{', '.join(SCHEMES)}), got {scheduler!r}"
        )
    if workers is not None:
        raise ConfigError("workers: the number of workers is the cluster's when --scheduler is an address")


@contextlib.contextmanager
def dask_client(scheduler: str, workers: int | None = None):
    """dask_client(scheduler, workers=None) -> context manager yielding a ``distributed.Client``.

    ``scheduler='local'``: a LocalCluster with ``workers`` processes (default:
    all cores), one thread each: the engine is compute-bound Python + JIT code,
    and one orbit batch per process is what the local pool runs too.
    Otherwise the address of a running scheduler; ``workers`` must be unset
    there (the cluster decides).
    """
    check_scheduler(scheduler, workers)
    from distributed import (  # deferred: distributed loads on first use
        Client,
        LocalCluster,
    )

    if scheduler == "local":
        cluster = LocalCluster(
            n_workers=workers or default_workers(),
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
            silence_logs=logging.ERROR,
        )
        try:
            with Client(cluster) as client:
                yield client
        finally:
            cluster.close()
        return
    try:
        client = Client(scheduler, timeout="20s")
    except Exception as exc:  # noqa: BLE001 - any failure to connect is the address's: say so, no traceback
        raise ConfigError(f"scheduler: cannot connect to {scheduler} ({type(exc).__name__}: {exc})") from None
    try:
        if not client.nthreads():
            try:
                client.wait_for_workers(1, timeout=60)
            except TimeoutError:
                raise ConfigError(f"scheduler: {scheduler} has no workers (waited 60 s)") from None
        yield client
    finally:
        client.close()
