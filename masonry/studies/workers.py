"""Whether a study's variants run serially or on a local Dask cluster: the rule, in one
place, for sweeps and optimisations (``docs/cli.md``, "masonry sweep").

A local cluster costs a fixed time before its first variant and after its last: its
worker processes start and each loads the pipeline, and they stop. Its workers do not
fork (a Dask worker is a daemonic process), so a variant there does not use a second
core of its own as a serial run does (:mod:`masonry.forking`). A study whose variants
are few or small ends sooner serially; a study large enough wins the start back.
"""

import logging
from contextlib import contextmanager

from masonry import forking
from masonry.mortars import split_laying
from masonry.params import Params, validate

DASK_MIN_BRICKS = 5_000
"""A study runs on a local Dask cluster, unless told, only when its variants' estimated
blocks add up to at least this many (about eight free webs of preset 3, 626 blocks
each). Measured on a shared 2-core machine (load average 6.5): four arches of 6 to 16
voussoirs took 11 to 13 s serially and 23 to 25 s on two workers, the cluster's start
and stop costing about 11 s; a preset 3 web took about 4.5 s serially, so a study of
this size takes about 35 s serially, enough for a second worker to win the start back
when it has a core of its own."""


def estimated_bricks(inputs: dict) -> float:
    """The blocks a variant's model would have (its scene's estimate), from its
    inputs."""
    params = validate(Params.of(**split_laying(inputs)[0]))
    return params.kind.estimate_blocks(params.geometry)


def local_workers(bricks, workers=None) -> int:
    """How many local processes run a study: 1 is serially, in this process; more is
    a Dask ``LocalCluster`` of that many single-threaded workers.

    Parameters
    ----------
    bricks : list of float
        Every variant's estimated blocks (:func:`estimated_bricks`).
    workers : int, optional
        The workers asked for (``--workers``), taken as they are: more than one runs on
        Dask whatever the study's size. None: one per core (:func:`masonry.forking.cores`)
        when the study has two variants or more whose blocks add up to
        :data:`DASK_MIN_BRICKS` or more, and the process has two cores or more; else 1.
    """
    if workers is not None:
        return workers
    cores = forking.cores()
    if len(bricks) < 2 or cores < 2 or sum(bricks) < DASK_MIN_BRICKS:
        return 1
    return cores


WORKER_LOG_LEVEL = logging.CRITICAL
"""What a local cluster's processes log (its workers, its scheduler): only what stops
them. Whatever goes wrong in a variant comes back as its row's error, and a worker lost
as a failed row (``KilledWorker``); their logs would only add tracebacks of connections
closed as the cluster stops."""


BENIGN_AT_SHUTDOWN = ("CommClosedError", "StreamClosedError")
"""Errors Dask logs, with their traceback, when one end of a connection closes before
the other as a cluster stops: nothing is lost (every variant's result is in by then)."""


class _Benign(logging.Filter):
    """Drops the records of :data:`BENIGN_AT_SHUTDOWN`."""

    def filter(self, record):
        kind = record.exc_info[0].__name__ if record.exc_info else ""
        text = f"{kind} {record.getMessage()}"
        return not any(name in text for name in BENIGN_AT_SHUTDOWN)


@contextmanager
def quiet_shutdown():
    """While a Dask client and cluster close: their logs of a connection closed first
    at the other end (:data:`BENIGN_AT_SHUTDOWN`) are dropped, from Dask's loggers and
    from asyncio's and tornado's (the root's handlers); every other record passes."""
    benign = _Benign()
    handlers = [*logging.getLogger("distributed").handlers, *logging.getLogger().handlers]
    for handler in handlers:
        handler.addFilter(benign)
    try:
        yield
    finally:
        for handler in handlers:
            handler.removeFilter(benign)
