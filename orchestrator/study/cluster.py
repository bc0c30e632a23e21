"""The Dask cluster of a sweep: a locked-down LocalCluster, or an existing cluster by its address.

A Dask scheduler runs whatever code a connected client sends, as the user who
started the workers. The LocalCluster of a sweep therefore

* speaks TLS with credentials made for this sweep only
  (``distributed.Security.temporary()``: a throw-away certificate authority and
  certificate held in memory): the scheduler and the workers accept only peers
  that present a certificate of that authority, so another process on the
  machine (another user's, or a browser's page) can connect to the port but
  cannot run anything;
* listens on 127.0.0.1 only;
* keeps its scratch space (spilled data, worker files) in a private temporary
  folder of this sweep (mode 0700, ``dtcosim-dask-*``), removed when the cluster is
  closed or the process ends; not Dask's shared and predictable
  ``/tmp/dask-scratch-space``, where another user could plant or read files;
* starts no dashboard unless asked for (``dashboard_address``, ``dtcosim sweep
  --dashboard``). The scheduler and the workers always have an HTTP server for
  their health checks: it listens on a random 127.0.0.1 port and serves
  ``/health`` only (no metrics, no cluster information, no proxy to the
  workers).

An existing cluster (``--scheduler``) is used with the TLS settings of the Dask
configuration (``distributed.comm.tls.*``, e.g. the environment variables
``DASK_DISTRIBUTED__COMM__TLS__CA_FILE``, ``..._CLIENT__CERT``,
``..._CLIENT__KEY``); ``docs/studies.md`` says how to run one across machines.
A ``tcp://`` address works but is not authenticated, which the command line
says as a warning.
"""

from __future__ import annotations

import logging
import os
import shutil
import signal
import tempfile
import threading
import weakref

from ..inputs.study import StudyError

#: HTTP routes the scheduler and workers of a LocalCluster serve without a dashboard
HEALTH_ONLY = ["distributed.http.health"]
#: where ``--dashboard`` puts the dashboard unless given an address
DEFAULT_DASHBOARD = "127.0.0.1:8787"


def locked_down_local_cluster(workers: int | None = None, dashboard_address: str | None = None):
    """A LocalCluster of ``workers`` processes (one thread each) with TLS and temporary credentials.

    Parameters
    ----------
    workers : int, optional
        Default: the CPU count.
    dashboard_address : str, optional
        ``host:port`` of the dashboard; None: no dashboard (only ``/health`` on a random local port).

    Returns
    -------
    distributed.LocalCluster
        ``cluster.security`` holds the credentials; ``Client(cluster)`` uses them;
        ``cluster.remove_scratch()`` removes its scratch folder ``cluster.scratch`` (after
        ``cluster.close()``; done at the process's end otherwise).
    """
    import dask
    from distributed import LocalCluster, Security

    n = workers if workers else (os.cpu_count() or 1)
    scratch = tempfile.mkdtemp(prefix="dtcosim-dask-")  # mode 0700: this user's, and this sweep's only
    security = Security.temporary()
    config = {} if dashboard_address else {"distributed.scheduler.http.routes": HEALTH_ONLY,
                                           "distributed.worker.http.routes": HEALTH_ONLY}
    # Ctrl-C on a terminal signals the whole process group: the worker processes start with SIGINT ignored
    # (an ignored signal stays ignored across exec), so only this process acts on it and closes the cluster
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with dask.config.set({**config, "temporary-directory": scratch}):
            cluster = LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1", protocol="tls://",
                security=security, dashboard_address=dashboard_address, local_directory=scratch,
                # without a dashboard the scheduler's health server goes to a random local port, never 8787
                scheduler_kwargs={} if dashboard_address else {"dashboard_address": "127.0.0.1:0"},
                silence_logs=logging.ERROR,
            )
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    cluster.scratch = scratch
    cluster.remove_scratch = weakref.finalize(cluster, shutil.rmtree, scratch, True)
    return cluster


#: seconds to wait for an existing scheduler to answer (Dask retries a refused connection until then)
CONNECT_TIMEOUT_S = 20.0


def connect(scheduler: str, timeout_s: float | None = None):
    """A client of an existing scheduler, with the Dask configuration's TLS settings.

    ``timeout_s`` defaults to :data:`CONNECT_TIMEOUT_S`.

    Raises
    ------
    StudyError
        Naming ``--scheduler`` for an address that is not one or a scheduler that cannot be reached.
    """
    from distributed import Client, Security

    if "://" not in scheduler and ":" not in scheduler:
        raise StudyError("--scheduler", scheduler, "a scheduler address such as tls://10.0.0.5:8786")
    try:
        timeout_s = CONNECT_TIMEOUT_S if timeout_s is None else timeout_s
        return Client(scheduler, timeout=f"{timeout_s:g}s", security=Security())
    except (OSError, ValueError, TypeError, TimeoutError) as exc:
        reason = str(exc) or type(exc).__name__
        raise StudyError("--scheduler", scheduler, f"the address of a running Dask scheduler ({reason})") from None


def is_authenticated(scheduler: str) -> bool:
    """False for a plain-TCP address (anyone who reaches it can run code on its workers)."""
    return scheduler.startswith(("tls://", "ucx://"))
