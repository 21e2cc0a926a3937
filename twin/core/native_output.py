"""Silence what native code (pybullet's C side) prints on the process's stdout or stderr.

pybullet prints a banner when imported and `argv[0]=` lines when connecting, straight to file descriptors
1 and 2: on stdout they would corrupt `--json` output, on stderr they make a one-line error two lines.
This module imports nothing heavy, so it can wrap the very import of pybullet.
"""
from __future__ import annotations

import contextlib
import os
import sys


@contextlib.contextmanager
def quiet_native_output(stdout: bool = True, stderr: bool = False):
    """Point the chosen descriptors at /dev/null meanwhile. Python exceptions are not affected (they
    propagate once the descriptors are back); whatever else is written to them meanwhile is lost, so keep
    the block short."""
    fds = [fd for fd, wanted in ((1, stdout), (2, stderr)) if wanted]
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, ValueError, OSError):
            pass
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
    except OSError:
        yield
        return
    saved: list[tuple[int, int]] = []
    try:
        for fd in fds:
            try:
                saved.append((fd, os.dup(fd)))
                os.dup2(devnull, fd)
            except OSError:
                pass
        yield
    finally:
        _flush_c_stdio()  # what C code buffered meanwhile goes to /dev/null, not to the restored descriptors
        for fd, copy in saved:
            os.dup2(copy, fd)
            os.close(copy)
        os.close(devnull)


def _flush_c_stdio() -> None:
    try:
        import ctypes

        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):  # no C library to ask (e.g. Windows): nothing buffered there
        pass
