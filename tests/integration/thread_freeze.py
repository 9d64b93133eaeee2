"""Stopping one thread of a running process the way a debugger does (PTRACE_SEIZE +
PTRACE_INTERRUPT): the process's other threads run on. Tests use it to stand for a thread stuck
on a hung disk or a lock, and to show that the others do not wait for it."""

import ctypes
import os
from pathlib import Path

PTRACE_DETACH = 17
PTRACE_SEIZE = 0x4206
PTRACE_INTERRUPT = 0x4207
WALL = 0x40000000

_libc = ctypes.CDLL(None, use_errno=True)
_libc.ptrace.argtypes = [ctypes.c_long, ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p]


def _ptrace(request, tid):
    if _libc.ptrace(request, tid, None, None) != 0:
        error = ctypes.get_errno()
        raise OSError(error, f"ptrace({request:#x}, {tid}): {os.strerror(error)}")


def freeze_thread(tid):
    """Stops the one thread `tid` until thaw_thread()."""
    _ptrace(PTRACE_SEIZE, tid)
    _ptrace(PTRACE_INTERRUPT, tid)
    os.waitpid(tid, WALL)  # until it is stopped


def thaw_thread(tid):
    _ptrace(PTRACE_DETACH, tid)


def thread_named(pid, name):
    """The id of `pid`'s thread called `name` (pthread_setname_np), or None."""
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            if (task / "comm").read_text().strip() == name:
                return int(task.name)
        except FileNotFoundError:  # a thread that ended meanwhile
            continue
    return None
