"""One writer per store: a lock file next to it naming its holder, and the temporary
store a killed coordinator leaves behind."""

from __future__ import annotations

import datetime
import json
import os
import shutil
import socket
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from os import PathLike
from pathlib import Path
from typing import Any

from fivdisc.errors import SweepError
from fivdisc.files import write_atomic


def lock_path(path: Path) -> Path:
    return path.with_name(path.name + ".lock")


def owner_path(path: Path) -> Path:
    return path.with_name(path.name + ".lock.owner")


def temporary_path(path: Path, pid: int) -> Path:
    """Where the coordinator of process `pid` creates the store before renaming it into
    place; recorded in the lock's owner record, so that only it is ever removed."""
    return path.with_name(f"{path.name}.tmp-fivdisc-{pid}")


def owner_of(path: Path) -> dict[str, Any] | None:
    """The lock holder's record next to the store, or None if there is none or it is damaged."""
    try:
        owner = json.loads(owner_path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return owner if isinstance(owner, dict) else None


def describe_owner(path: Path) -> str:
    """The lock holder recorded next to the store, as text."""
    try:
        owner = owner_of(path) or {}
        return (f"process {owner['pid']} on host {owner['host']} (running since "
                f"{owner['since']}: {owner['command']})")
    except (KeyError, TypeError):
        return "another process (it recorded no details)"


def remove_stale_temporary(path: Path) -> None:
    """Remove the temporary store a dead holder of the lock recorded, and nothing else.

    Called with the lock held: an owner record still there belongs to a holder that
    died (a live holder keeps the lock); the name is checked against the one its
    process id gives, so that a damaged record cannot point elsewhere."""
    owner = owner_of(path)
    if owner is None or not isinstance(owner.get("pid"), int):
        return
    stale = temporary_path(path, owner["pid"])
    if owner.get("temporary") == stale.name and stale.is_dir() and not stale.is_symlink():
        shutil.rmtree(stale, ignore_errors=True)


def holder_of(path: Path) -> str | None:
    """Who holds the store's lock now, or None."""
    from filelock import FileLock, Timeout

    path = path.resolve()
    if not lock_path(path).exists():
        return None
    lock = FileLock(lock_path(path), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        return describe_owner(path)
    lock.release()
    return None


@contextmanager
def store_lock(path: str | PathLike[str]) -> Iterator[None]:
    """Hold the lock of a sweep store: one coordinator writes a store at a time.

    The lock is a file next to the store, where a symbolic link to it leads
    (``STORE.lock``, held through ``filelock``; the operating system releases it when its
    process dies, however it dies), and the holder's process id, host, start time,
    command and temporary store (:meth:`SweepStore.open` creates a store under that name)
    are written to ``STORE.lock.owner``. A temporary store recorded there by a holder
    that died is removed.

    Raises
    ------
    SweepError
        Another process holds the lock; the message names it.
    """
    from filelock import FileLock, Timeout

    given, path = Path(path), Path(path).resolve()
    lock = FileLock(lock_path(path), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        raise SweepError(
            f"{given} is in use by {describe_owner(path)}: wait for that sweep to end or "
            "stop it, then rerun"
        ) from None
    try:
        remove_stale_temporary(path)
        owner = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "since": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
            "command": " ".join(sys.argv),
            "temporary": temporary_path(path, os.getpid()).name,
        }
        write_atomic(owner_path(path), lambda p: p.write_text(json.dumps(owner),
                                                               encoding="utf-8"))
        yield
    finally:
        owner_path(path).unlink(missing_ok=True)
        lock.release()
