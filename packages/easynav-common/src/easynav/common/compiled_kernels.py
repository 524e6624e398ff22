"""Numba kernels compiled in a child process, so that a long-lived process only loads them.

Compiling a numba kernel leaves LLVM's compile-time state behind in the process for good: the
costmap stack with MPPI (ray casting, inflation, AMCL scoring, A*, MPPI's rollout) measured
322 MB resident after a first run that compiled its kernels, 240 MB after a run that loaded
them from numba's on-disk cache (``cache=True``), the same kernels doing the same work. The
difference is live memory (``malloc_trim`` gives back 1 MB of it), so it cannot be freed once
taken; it has to be taken elsewhere.

:func:`compile_in_child` hooks a cached numba dispatcher so that a signature it has never seen
is first looked up in numba's cache and, when absent, compiled by a short-lived child process
(``python -m easynav.common.compiled_kernels``) that writes the cache; the process then loads
it from there, as on every later run. Calls with known signatures pay nothing: the hook sits
where numba's dispatcher goes only when no compiled version matches the arguments.

The hook is off until :func:`enable_child_compilation` (the ``easynav run`` process turns it
on): tests and scripts compile in-process, as numba does. Whatever goes wrong in the child
(killed, no writable cache) ends in numba's own in-process compilation, never in an error.

The child compiles at normal priority. It is started from the thread whose kernel needs it,
usually one of EasyNav's SCHED_FIFO loops, and a process inherits its creator's scheduling: a
child compiling for seconds at SCHED_FIFO 70 or 80 keeps the other processes of its core (the
simulator, a second system, a test's ROS nodes) from running for as long (seen at a matrix
run's start: a compile child of the non-RT loop at 99 % of a core, SCHED_FIFO 70, 8 s in).
"""

from __future__ import annotations

import importlib
import logging
import os
import pickle
import subprocess
import sys
import threading

_LOG = logging.getLogger("easynav.compiled_kernels")
_enabled = False
_lock = threading.Lock()

#: Longest a child may take to compile one kernel (MPPI's rollout takes a few seconds).
CHILD_TIMEOUT = 600.0


def enable_child_compilation(enabled: bool = True) -> None:
    """Compile hooked kernels' new signatures in a child process from now on (or not).

    Thread contract: call at process start, before the kernels run.
    """
    global _enabled
    _enabled = enabled


def compile_in_child(dispatcher, locator: str):
    """Hook ``dispatcher`` (a numba ``njit(cache=True)`` dispatcher) and return it.

    ``locator`` is where a fresh interpreter finds the same dispatcher: ``"module:name"``,
    ``name`` being the dispatcher or a function without arguments that returns it (a kernel
    compiled on first use). A dispatcher without a disk cache is returned unhooked: a child
    could not hand its work over.

    Thread contract: the hook runs under numba's dispatch from any thread; children are
    started one at a time.
    """
    from numba.core.caching import NullCache

    if isinstance(getattr(dispatcher, "_cache", NullCache()), NullCache):
        return dispatcher
    numba_compile_for_args = dispatcher._compile_for_args

    def compile_for_args(*args, **kws):
        # Numba's dispatcher calls this only when no compiled version matches the arguments.
        if _enabled and not kws:
            signature = tuple(dispatcher.typeof_pyval(a) for a in args)
            with _lock:
                if not _load_from_cache(dispatcher, signature):
                    _compile_in_child(locator, signature)
        return numba_compile_for_args(*args, **kws)

    dispatcher._compile_for_args = compile_for_args
    return dispatcher


class CompiledKernel:
    """The numba kernel ``name`` of the module ``module`` (an ``njit(cache=True)`` dispatcher,
    hooked by :func:`compile_in_child`), imported (and so compiled or loaded from numba's
    cache) the first time it is asked for.

    ``get()`` is None when the module cannot be imported (numba is not installed: the caller
    runs its numpy or pure-Python reference instead). Thread contract: any thread; at worst two
    threads import the module at once, which Python's import lock makes safe. Exceptions: an
    ImportError of the kernel's module is the answer None, nothing else is caught.
    """

    def __init__(self, module: str, name: str) -> None:
        self.module = module
        self.name = name
        self._kernel = None  # None: not tried yet; False: unavailable

    def get(self):
        """The kernel, or None without numba."""
        if self._kernel is None:
            try:
                kernel = getattr(importlib.import_module(self.module), self.name)
                self._kernel = compile_in_child(kernel, f"{self.module}:{self.name}")
            except ImportError:
                self._kernel = False
        return self._kernel or None

    def available(self) -> bool:
        """Whether the compiled kernel can be used."""
        return self.get() is not None


def _load_from_cache(dispatcher, signature: tuple) -> bool:
    """Load ``signature``'s compiled version from numba's cache into ``dispatcher`` (as numba's
    ``Dispatcher.compile`` does first); False when the cache does not hold it."""
    if signature in dispatcher.overloads:
        return True
    cres = dispatcher._cache.load_overload(signature, dispatcher.targetctx)
    if cres is None:
        return False
    if not cres.objectmode:
        dispatcher.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
    dispatcher.add_overload(cres)
    return True


def _compile_in_child(locator: str, signature: tuple) -> None:
    payload = pickle.dumps((locator, signature))
    try:
        done = subprocess.run(
            [sys.executable, "-m", "easynav.common.compiled_kernels"],
            input=payload, capture_output=True, timeout=CHILD_TIMEOUT, check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as error:
        _LOG.warning("compiling %s in a child process failed (%s): compiling here", locator,
                     error)
        return
    if done.returncode != 0:
        _LOG.warning("compiling %s in a child process failed (exit %d): compiling here. %s",
                     locator, done.returncode, done.stderr.decode(errors="replace")[-500:])


def resolve(locator: str):
    """The dispatcher ``locator`` names (see :func:`compile_in_child`)."""
    module_name, _, name = locator.partition(":")
    found = getattr(importlib.import_module(module_name), name)
    if not hasattr(found, "overloads"):  # a function returning the dispatcher
        found = found()
    return found


def _leave_realtime_scheduling() -> None:
    """Put the calling thread back on the normal scheduling policy (SCHED_OTHER, nice
    unchanged) if it inherited a real-time one; nothing elsewhere than on Linux.

    Lowering one's own policy needs no privilege. The child calls it first thing, which is
    after the interpreter's start-up and this module's import (about 0.2 s, still at the
    inherited policy). The loops' threads do not set SCHED_RESET_ON_FORK instead: it would
    reset the threads they start too (MPPI's noise, MH-AMCL's search), and a normal thread
    preempted while it holds the GIL keeps the RT thread waiting. Thread contract: affects
    only the calling thread (``sched_setscheduler`` with pid 0). Exceptions: none.
    """
    if not hasattr(os, "sched_setscheduler"):
        return
    try:
        policy = os.sched_getscheduler(0) & ~getattr(os, "SCHED_RESET_ON_FORK", 0)
        if policy in (os.SCHED_FIFO, os.SCHED_RR):
            os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    except OSError as error:  # not expected: lowering is always allowed
        _LOG.warning("could not leave real-time scheduling: %s", error)


def _child_main() -> int:
    _leave_realtime_scheduling()  # before anything heavy: see the module's docstring
    locator, signature = pickle.loads(sys.stdin.buffer.read())
    dispatcher = resolve(locator)
    dispatcher.compile(signature)  # compiled and written to numba's cache
    return 0


if __name__ == "__main__":
    sys.exit(_child_main())
