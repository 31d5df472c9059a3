"""Where the runs of a sweep execute: one interface, two back-ends.

`LocalExecutor` (the default) runs them in this process (``--jobs 1``) or in a local process
pool; `DaskExecutor` hands them to Dask distributed, either a scheduler someone already runs
(``--scheduler tcp://HOST:PORT``, e.g. a SLURM allocation made with dask-jobqueue) or a
`LocalCluster` it starts on 127.0.0.1 (``--dask-local N``). Both yield each run's `Outcome` as it
finishes; a run that raises becomes an outcome with its error, never an exception of the sweep,
so one broken run cannot stop the others. The sweep (`swarm_sim.compare.sweep`, ``swarm-batch``)
does the bookkeeping (results file, resume, progress), so it is the same whatever the back-end.
"""

from __future__ import annotations

import argparse
import ctypes
import multiprocessing
import re
import signal
import traceback
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

from swarm_sim.cli import number

LOOPBACK = "127.0.0.1"
_ADDRESS = re.compile(r"^(tcp|tls|ucx)://[^\s/:]+:\d{1,5}$")


@dataclass(frozen=True)
class Outcome:
    """One run's end: its `value`, or the `error` it raised (``Type: message``)."""

    index: int
    """Position of the run in the submitted sequence."""
    value: Any = None
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None


def guarded(fn: Callable[[Any], Any], arg: Any) -> tuple[bool, Any]:
    """``fn(arg)`` as (True, value), or (False, "Type: message") if it raised: the same for every
    back-end, and nothing that might not pickle crosses a process boundary."""
    try:
        return True, fn(arg)
    except Exception as exc:  # a run's failure is data, recorded with the run
        frame = traceback.extract_tb(exc.__traceback__)[-1:] or None
        where = f" (at {frame[0].filename}:{frame[0].lineno})" if frame else ""
        return False, f"{type(exc).__name__}: {exc}{where}"


def _indexed(fn: Callable[[Any], Any], item: tuple[int, Any]) -> tuple[int, tuple[bool, Any]]:
    return item[0], guarded(fn, item[1])


def _outcome(index: int, result: tuple[bool, Any]) -> Outcome:
    ok, value = result
    return Outcome(index, value) if ok else Outcome(index, error=value)


class Executor:
    """Runs ``fn(arg)`` for every arg; subclasses decide where."""

    name = "executor"
    workers = 1

    def map(self, fn: Callable[[Any], Any], args: Sequence[Any]) -> Iterator[Outcome]:
        """Each run's outcome as it finishes (any order). `fn` must be a module-level function
        (it is pickled for other processes and machines)."""
        raise NotImplementedError

    def close(self) -> None:
        """Release workers and connections (idempotent)."""

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()


def _pool_worker() -> None:
    """A pool worker leaves stopping to its parent: it ignores Ctrl-C (the terminal sends it to the
    whole group; the parent then ends the pool), dies quietly of the parent's SIGTERM
    (`stop_on_signals`' handler, inherited through fork, would print a traceback per worker) and
    of the parent's death (Linux's PR_SET_PDEATHSIG), so a stopped sweep leaves no worker behind."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGHUP, signal.SIG_DFL)
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: the parent's pool still terminates its workers
        pass


class LocalExecutor(Executor):
    """`jobs` == 1: in this process, in order; more: a fork process pool of `jobs` workers."""

    name = "local"

    def __init__(self, jobs: int = 1) -> None:
        if jobs < 1:
            raise ValueError(f"jobs: expected >= 1, got {jobs}")
        self.workers = jobs

    def map(self, fn: Callable[[Any], Any], args: Sequence[Any]) -> Iterator[Outcome]:
        if self.workers == 1 or len(args) <= 1:
            for i, arg in enumerate(args):
                yield _outcome(i, guarded(fn, arg))
            return
        with multiprocessing.get_context("fork").Pool(min(self.workers, len(args)), initializer=_pool_worker) as pool:
            for i, result in pool.imap_unordered(partial(_indexed, fn), enumerate(args)):
                yield _outcome(i, result)


class DaskExecutor(Executor):
    """Dask distributed: the scheduler at `address`, or a `LocalCluster` of `local_workers`
    single-threaded worker processes whose scheduler and workers listen on 127.0.0.1 only (no
    dashboard)."""

    name = "dask"

    def __init__(self, address: str | None = None, *, local_workers: int | None = None) -> None:
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise RuntimeError("Dask sweeps need the 'distributed' package: pip install 'swarmforage[dask]'") from None
        if (address is None) == (local_workers is None):
            raise ValueError("give either a scheduler address or a number of local workers")
        self.cluster = None
        if address is None:
            if local_workers < 1:
                raise ValueError(f"--dask-local: expected >= 1 workers, got {local_workers}")
            self.cluster = LocalCluster(
                n_workers=local_workers, threads_per_worker=1, processes=True, host=LOOPBACK,
                dashboard_address=None, silence_logs=50,
            )
            address = self.cluster.scheduler_address
        self.client = Client(address, timeout="30s")
        self.address = address
        self.workers = max(1, len(self.client.scheduler_info().get("workers", {})))

    def map(self, fn: Callable[[Any], Any], args: Sequence[Any]) -> Iterator[Outcome]:
        from distributed import as_completed

        tag = uuid.uuid4().hex[:8]
        futures = [self.client.submit(guarded, fn, arg, key=f"swarm-run-{tag}-{i}", pure=False)
                   for i, arg in enumerate(args)]
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for future in as_completed(futures):
                i = index[future.key]
                try:
                    result = future.result()
                except Exception as exc:  # the worker died (KilledWorker) or the run was cancelled
                    result = (False, f"{type(exc).__name__}: {exc}")
                yield _outcome(i, result)
        finally:
            self.client.cancel([f for f in futures if not f.done()])

    def close(self) -> None:
        if getattr(self, "client", None) is not None:
            self.client.close()
            self.client = None
        if self.cluster is not None:
            self.cluster.close()
            self.cluster = None


def scheduler_address(text: str) -> str:
    """argparse type of ``--scheduler``: ``tcp://HOST:PORT`` (or tls://, ucx://)."""
    if not _ADDRESS.match(text):
        raise argparse.ArgumentTypeError(f"expected tcp://HOST:PORT, got {text!r}")
    return text


def add_executor_arguments(parser: argparse.ArgumentParser) -> None:
    """``--jobs J`` (local pool), ``--scheduler ADDRESS`` or ``--dask-local N`` (Dask)."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--jobs", type=number(int, 1, 1024), default=1,
                       help="runs in parallel in a local process pool (default 1: in this process)")
    group.add_argument("--scheduler", type=scheduler_address, metavar="tcp://HOST:PORT",
                       help="run on the Dask distributed scheduler at this address")
    group.add_argument("--dask-local", type=number(int, 1, 1024), metavar="N",
                       help="run on a Dask LocalCluster of N worker processes on 127.0.0.1")


def executor_from_args(args: argparse.Namespace) -> Executor:
    """The executor the ``add_executor_arguments`` options ask for."""
    if getattr(args, "scheduler", None):
        return DaskExecutor(args.scheduler)
    if getattr(args, "dask_local", None):
        return DaskExecutor(local_workers=args.dask_local)
    return LocalExecutor(getattr(args, "jobs", 1) or 1)


class Progress:
    """A tqdm bar on stderr (runs done, failures, time left; drawn only on a terminal) and the
    sweep's log lines printed around it."""

    def __init__(self, total: int, desc: str) -> None:
        import sys

        from tqdm import tqdm

        self.total, self.done, self.failed = total, 0, 0
        self.bar = tqdm(total=total, desc=desc, unit="run", file=sys.stderr, disable=None, dynamic_ncols=True)

    def write(self, text: str, log: Callable[[str], None] = partial(print, flush=True), *,
              numbered: bool = True) -> None:
        """`log` a line about the run that just ended (``[done/total]`` first if `numbered`)."""
        with self.bar.external_write_mode():
            log(f"[{self.done + 1}/{self.total}] {text}" if numbered else text)

    def update(self, ok: bool = True) -> None:
        self.done += 1
        if not ok:
            self.failed += 1
            self.bar.set_postfix(failed=self.failed, refresh=False)
        self.bar.update(1)

    def close(self) -> None:
        self.bar.close()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()
