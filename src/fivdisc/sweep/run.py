"""Running a sweep: a local pool (threads or processes) or a Dask cluster, results
stored as they finish.

Workers only compute; the coordinator (the thread calling :func:`run_sweep`) writes
every result to the store, so the store has a single writer. Points already complete in
the store are skipped, which makes an interrupted sweep resumable by running it again.
A point whose local worker process dies (``os._exit``, a signal) is run again alone once
the pool is restarted; if its worker dies again, the point is stored as failed with how
the worker died, and the sweep goes on.

The local pool's threads integrate in parallel because the compiled core releases the
GIL; only the Python-side work of a point (setting up the model, reducing the run)
takes turns. ``benchmarks/bench_sweep_pool.py`` compares the two local pools.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from collections import deque
from collections.abc import Iterable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures import wait as wait_local
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from multiprocessing import get_context
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fivdisc.case import Case
from fivdisc.engine.integration import stop_thread_when
from fivdisc.errors import SweepError
from fivdisc.sweep.point import PointOutcome, run_point
from fivdisc.sweep.spec import Sweep
from fivdisc.sweep.store.lock import store_lock

if TYPE_CHECKING:
    from fivdisc.sweep.store.sweep_store import SweepStore

__all__ = ["DEFAULT_POOL", "POOLS", "SweepReport", "run_point", "run_sweep"]

# The kinds of local pool. Threads are the default: on 2 cores they start the first
# point about a second sooner (no worker loads fivdisc) and, once running, compute
# points of 0.2 s or longer as fast as processes; processes are faster on points of
# ~10 ms, whose Python side takes turns on threads, and survive a point that crashes
# its process (benchmarks/bench_sweep_pool.py; docs/sweep-files.md gives the numbers).
POOLS = ("thread", "process")
DEFAULT_POOL = "thread"

# Points submitted ahead per worker: enough to keep workers busy while the
# coordinator writes, few enough that an interruption discards little work.
_AHEAD_PER_WORKER = 2
_PARENT_POLL = 1.0  # [s]
# Results are gathered this long before a write: one region write per point costs the
# coordinator ~18 ms of CPU, one per 10 consecutive points ~35 ms. A killed
# coordinator loses at most this much finished work.
_WRITE_INTERVAL = 1.0  # [s]
_CONNECT_TIMEOUT = 10.0  # [s], to reach a Dask scheduler


@dataclass(frozen=True)
class SweepReport:
    """How a call of :func:`run_sweep` went.

    Attributes
    ----------
    store
        The Zarr store.
    n_points
        Points in the sweep.
    already_done
        Points found complete in the store when the call started.
    computed
        Points computed by this call.
    failed
        Failed points in the store (this and earlier calls), index -> message.
    wall_time
        Duration of the call [s].
    """

    store: Path
    n_points: int
    already_done: int
    computed: int
    failed: dict[int, str]
    wall_time: float


# --- executors -------------------------------------------------------------------------------


def _exit_with_parent(parent: int) -> None:
    # A coordinator killed by SIGKILL cannot stop its workers; they stop themselves.
    while os.getppid() == parent:
        time.sleep(_PARENT_POLL)
    os._exit(1)


def _init_local_worker(parent: int) -> None:
    from tqdm import tqdm

    # Ctrl-C reaches the whole process group; only the coordinator should act on it.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_with_parent, args=(parent,), daemon=True).start()
    # A worker shows no bars. tqdm's default lock is a named semaphore shared between
    # processes, which a worker terminated by an interrupted sweep would leave behind
    # (Python's resource tracker then reports it as leaked at the command's exit).
    tqdm.set_lock(threading.RLock())


class _WorkerDied(Exception):
    """A local worker process died (``os._exit``, a signal) while computing a point; the
    message says how."""


def _how_it_died(codes: Iterable[int | None]) -> str:
    """How a pool's worker died, from its processes' exit codes: the pool terminates the
    others (SIGTERM) once one has died."""
    dead = [c for c in codes if c not in (None, 0)]
    own = [c for c in dead if c != -signal.SIGTERM] or dead
    if not own:
        return "no exit status known"
    code = own[0]
    if code < 0:
        try:
            return f"killed by signal {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit status {code}"


class _LocalPool:
    """Workers on this machine: threads of this process or spawned processes.

    Threads share the coordinator's loaded modules, so the first point starts at once,
    and they die with it; a thread cannot be killed, so every thread's integration
    checks a stop event between kernel calls (:func:`stop_thread_when`). Processes
    isolate a point that crashes its process; they ignore Ctrl-C, die with the
    coordinator, and the pool can be started again after one died.

    Parameters
    ----------
    workers
        Threads or processes.
    kind
        ``"thread"`` or ``"process"``.
    """

    def __init__(self, workers: int, kind: str) -> None:
        self.workers = workers
        self.kind = kind
        self._stop = threading.Event()
        self._pool = self._start()

    def _start(self) -> ThreadPoolExecutor | ProcessPoolExecutor:
        if self.kind == "thread":
            return ThreadPoolExecutor(
                max_workers=self.workers,
                thread_name_prefix="fivdisc-sweep",
                initializer=stop_thread_when,
                initargs=(self._stop,),
            )
        # spawn, not fork: the coordinator runs threads (tqdm, zarr's I/O loop) that a
        # forked child would inherit in an arbitrary state.
        return ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=get_context("spawn"),
            initializer=_init_local_worker,
            initargs=(os.getpid(),),
        )

    def restart(self) -> None:
        """A new pool in place of one broken by a dead worker."""
        self._pool.shutdown(wait=True, cancel_futures=True)
        self._pool = self._start()

    def submit(self, index: int, case: Case, *work: Any) -> Any:
        return self._pool.submit(run_point, index, case, *work)

    def wait(self, futures: Iterable[Any], timeout: float | None) -> set[Any]:
        return wait_local(futures, timeout=timeout, return_when=FIRST_COMPLETED).done

    def wait_all(self, futures: Iterable[Any]) -> set[Any]:
        return wait_local(futures).done

    def outcome(self, future: Any, index: int) -> PointOutcome:
        exc = future.exception()
        if exc is None:
            return future.result()
        if isinstance(exc, BrokenProcessPool):
            # The exit codes are known once the broken pool has joined its processes.
            processes = list((getattr(self._pool, "_processes", None) or {}).values())
            self._pool.shutdown(wait=True)
            raise _WorkerDied(_how_it_died(p.exitcode for p in processes))
        # run_point catches every Exception, so this is e.g. a result that failed to
        # pickle, or a user reduction's SystemExit
        return PointOutcome(index, None, f"{type(exc).__name__}: {exc}")

    def close(self) -> None:
        self._pool.shutdown(wait=True)

    def abort(self) -> None:
        """Stop at once: queued points are dropped, running ones end unfinished (their
        results are never stored)."""
        if self.kind == "thread":
            # A running point's integration raises Stopped at its next kernel call
            # (about 0.05 s); waiting for that means no thread outlives the sweep.
            self._stop.set()
            self._pool.shutdown(wait=True, cancel_futures=True)
            return
        # ProcessPoolExecutor has no public way (before Python 3.14) to stop tasks that
        # are running; terminate its processes so an interrupted sweep exits at once.
        processes = list((getattr(self._pool, "_processes", None) or {}).values())
        self._pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.terminate()


class ClusterLost(SweepError):
    """The Dask cluster went away while the sweep was running on it."""


class _DaskPool:
    """The workers of an existing Dask distributed cluster."""

    def __init__(self, address: str) -> None:
        try:
            from distributed import Client
        except ImportError as exc:
            raise SweepError(
                f"--scheduler needs dask.distributed ({exc}); install it with "
                "`pip install fivdisc[distributed]`"
            ) from None
        if not address.strip():
            raise SweepError(
                f"scheduler = {address!r} is invalid: must be an address like tcp://host:8786"
            )
        self.address = address
        try:
            # Not the default scheduler of this process: the coordinator only submits.
            self._client = Client(address, timeout=_CONNECT_TIMEOUT, set_as_default=False)
        except ValueError as exc:  # malformed: no port, unknown scheme, ...
            raise SweepError(
                f"scheduler = {address!r} is invalid ({exc}): must be an address like "
                "tcp://host:8786"
            ) from None
        except (OSError, TimeoutError) as exc:
            raise SweepError(f"scheduler = {address!r}: cannot connect ({exc})") from None
        self.workers = max(1, sum(self._client.nthreads().values()))

    def _lost(self, exc: BaseException) -> ClusterLost:
        reason = " ".join(str(exc).split()[:12]) or type(exc).__name__
        return ClusterLost(f"lost the Dask cluster at {self.address} ({reason})")

    def submit(self, index: int, case: Case, *work: Any) -> Any:
        try:
            return self._client.submit(run_point, index, case, *work, pure=False)
        except Exception as exc:  # a closed client raises several types
            raise self._lost(exc) from None

    def wait(self, futures: Iterable[Any], timeout: float | None) -> set[Any]:
        from concurrent.futures import CancelledError

        from distributed import wait

        try:
            with self._client.as_current():  # wait() looks for a current client
                done = wait(list(futures), timeout=timeout, return_when="FIRST_COMPLETED").done
            return set(done)
        except TimeoutError:
            return set()
        except (CancelledError, OSError) as exc:  # the scheduler went away
            raise self._lost(exc) from None

    def outcome(self, future: Any, index: int) -> PointOutcome:
        from concurrent.futures import CancelledError

        try:
            if future.status == "finished":
                return future.result()
            if future.status != "error":  # cancelled or lost with the scheduler
                raise self._lost(RuntimeError(f"point {index} was {future.status}"))
            # run_point catches everything, so this is the cluster's failure, e.g. a worker
            # killed repeatedly while running the point: record it as the point's error.
            exc = future.exception()
        except (CancelledError, OSError) as lost:  # fetching the result found it gone
            raise self._lost(lost) from None
        return PointOutcome(index, None, f"{type(exc).__name__}: {exc}")

    def close(self) -> None:
        self._client.close()

    def abort(self) -> None:
        self._client.close()


# --- the loop --------------------------------------------------------------------------------


def run_sweep(
    spec: Sweep,
    store: str | PathLike[str],
    scheduler: str | None = None,
    workers: int | None = None,
    progress: bool = True,
    pool: str | None = None,
) -> SweepReport:
    """Compute the points of `spec` that `store` does not hold yet, storing each as it ends.

    A process pool starts its workers with ``spawn``: a script calling this with
    ``pool="process"`` must guard its entry point with ``if __name__ == "__main__":``.

    Parameters
    ----------
    spec
        The sweep.
    store
        Zarr store directory; created if missing. An existing store must hold the
        same sweep (same definition hash), whose complete points are skipped.
    scheduler
        Address of a Dask distributed scheduler (e.g. ``"tcp://127.0.0.1:8786"``) to
        run on; None runs on a local pool.
    workers
        Size of the local pool (default: the number of CPUs); local pool only.
    progress
        Show a progress bar (points, failures, time left) on stderr.
    pool
        The local pool: ``"thread"`` (the default), threads of
        this process, which integrate in parallel since the compiled core releases the
        GIL, and start at once; or ``"process"``, spawned processes, which keep a point
        that crashes its process (``os._exit``, a segmentation fault in a user
        reduction) from ending the sweep. Local pool only.

    Returns
    -------
    SweepReport
        Counts, failures and timing.

    Raises
    ------
    SweepError
        Bad `workers` or `pool`; a store holding another sweep, in use by another
        coordinator or of an earlier format with points missing (it is read, not
        written); no connection to `scheduler`, or the cluster lost during the sweep
        (finished points stay stored; rerunning resumes).
    KeyboardInterrupt
        On Ctrl-C, after the workers are stopped; complete points stay stored.
    """
    start = time.perf_counter()
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, int) or workers < 1
    ):
        raise SweepError(f"workers = {workers!r} is invalid: must be an integer >= 1")
    cpus = os.cpu_count() or 1
    if workers is not None and workers > cpus:
        raise SweepError(
            f"workers = {workers} is invalid: must be <= {cpus}, the number of CPUs (more "
            "workers than cores only take turns, and processes add some 300 MB each)"
        )
    if workers is not None and scheduler is not None:
        raise SweepError(
            f"workers = {workers} is invalid with a scheduler: the cluster's size is set "
            "where the cluster is started"
        )
    if pool is not None and pool not in POOLS:
        raise SweepError(f"pool = {pool!r} is invalid: must be 'thread' or 'process'")
    if pool is not None and scheduler is not None:
        raise SweepError(f"pool = {pool!r} is invalid with a scheduler: the cluster's "
                         "workers compute the points")
    work = _work(spec)
    # A cluster is reached before the store is touched, so that a bad address changes nothing.
    executor = _DaskPool(scheduler) if scheduler is not None else None
    try:
        with store_lock(store):
            started: dict[Any, int] = {}
            if executor is None and not os.path.lexists(store):
                # A new store: every point is to be done, so the first ones start now,
                # while the coordinator loads Zarr and creates the store (about a
                # second). An existing one is checked first: it may need no worker.
                executor = _LocalPool(workers or cpus, pool or DEFAULT_POOL)
                ahead = min(_AHEAD_PER_WORKER * executor.workers, spec.n_points)
                for index in range(ahead):
                    started[executor.submit(index, spec.cases[index], *work)] = index
            # Imported here: Zarr and xarray take ~0.5 s to load, which the first
            # points above do not wait for.
            from fivdisc.sweep.store.sweep_store import SweepStore

            target = SweepStore.open(store, spec)
            done = target.completed()
            missing = [int(i) for i in range(spec.n_points) if not done[i]]
            already = spec.n_points - len(missing)
            running = set(started.values())
            todo = deque(i for i in missing if i not in running)
            failed = target.errors(done)
            if missing and target.refusal:
                raise SweepError(target.refusal)
            if missing:
                if executor is None:
                    executor = _LocalPool(workers or cpus, pool or DEFAULT_POOL)
                try:
                    _drive(executor, spec, target, todo, started, already, failed, progress)
                except ClusterLost as exc:
                    stored = int(target.completed().sum())
                    raise SweepError(
                        f"{exc}; {stored} of {spec.n_points} points are stored in {store}: "
                        "restart the cluster and rerun the same command to compute the rest"
                    ) from None
    except BaseException:
        if executor is not None:
            executor.abort()
        raise
    if executor is not None:
        executor.close()
    return SweepReport(
        store=target.path,
        n_points=spec.n_points,
        already_done=already,
        computed=spec.n_points - already,
        failed=failed,
        wall_time=time.perf_counter() - start,
    )


def _work(sweep: Sweep) -> tuple[Any, ...]:
    """What every point computes, as run_point takes it after the point's case
    (picklable, for the workers)."""
    return (tuple(sweep.keep), sweep.sections, sweep.lyapunov)


def _drive(
    pool: _LocalPool | _DaskPool,
    sweep: Sweep,
    target: SweepStore,
    todo: deque[int],
    running: dict[Any, int],
    already: int,
    failed: dict[int, str],
    progress: bool,
) -> None:
    """Keep the pool fed (`running`: futures already submitted -> their points), and store
    results as they come back."""
    from tqdm import tqdm

    work = _work(sweep)
    ahead = _AHEAD_PER_WORKER * pool.workers
    unstored: list[PointOutcome] = []
    # Points that were running when a local worker died: each is run again alone, and
    # stored as failed if its worker dies again.
    suspects: deque[int] = deque()
    alone: int | None = None
    last_write = time.monotonic()
    with tqdm(
        total=sweep.n_points,
        initial=already,
        unit="point",
        desc="sweep",
        disable=not progress,
        dynamic_ncols=True,
    ) as bar:

        def write_unstored() -> None:
            nonlocal unstored, last_write
            target.write(unstored)
            failed.update((o.index, o.error) for o in unstored if o.error)
            bar.set_postfix(failed=len(failed), refresh=False)
            bar.update(len(unstored))
            unstored, last_write = [], time.monotonic()

        def collect(finished: Iterable[Any]) -> str | None:
            """Outcomes of `finished` into `unstored`; how a worker died, if one did."""
            nonlocal alone
            died = None
            for future in finished:
                index = running.pop(future)
                try:
                    unstored.append(pool.outcome(future, index))
                except _WorkerDied as death:
                    died = str(death)
                    if index == alone:
                        unstored.append(PointOutcome(index, None, (
                            f"the worker process died while computing this point ({died}), "
                            "also when it was run again alone")))
                    else:
                        suspects.append(index)
                if index == alone:
                    alone = None
            return died

        bar.set_postfix(failed=len(failed))
        try:
            while todo or running or suspects:
                if suspects and not running:
                    alone = suspects.popleft()
                    running[pool.submit(alone, sweep.cases[alone], *work)] = alone
                while todo and not suspects and alone is None and len(running) < ahead:
                    index = todo.popleft()
                    running[pool.submit(index, sweep.cases[index], *work)] = index
                due = last_write + _WRITE_INTERVAL - time.monotonic()
                finished = pool.wait(running, max(due, 0.0) if unstored else None)
                if collect(finished) is not None:
                    # The whole pool is broken: every running point fails the same way.
                    collect(pool.wait_all(running))
                    pool.restart()
                if unstored and (time.monotonic() - last_write >= _WRITE_INTERVAL or not running):
                    write_unstored()
        except BaseException:
            # Finished points are worth keeping whatever stopped the sweep (Ctrl-C, a dead
            # worker); rewriting any that an interrupted write already stored is harmless.
            # A failure here must not hide the original error.
            if unstored:
                with contextlib.suppress(Exception):
                    write_unstored()
            raise
