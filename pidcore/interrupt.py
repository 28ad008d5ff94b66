"""Ctrl-C that never half-commits: a SIGINT flag shared by the CLI and the store.

SIGTERM (``kill PID``, ``timeout``, a service manager, a batch scheduler ending a job) is the
same interruption: the same flag, the same one line and nothing half-written, and exit status
143 (128 + 15) where Ctrl-C's is 130 (128 + 2). With Python's default handling it ended the
process on the spot (status -15): no word of what was saved, the store's working copy left
beside it, a sweep's workers left running. So does SIGHUP (the terminal or ssh session of a
running sweep closed), exit status 129, where it is not ignored (``nohup`` keeps it ignored).

Python's default SIGINT handler raises :class:`KeyboardInterrupt` at whatever bytecode runs
next. Raised inside a weakref callback it is printed as "Exception ignored" and swallowed (the
run carries on and commits); raised inside Numba's dispatcher it comes back as a
:class:`SystemError`. :func:`install` replaces the handler with one that first records the
interruption and then raises, so that a swallowed interrupt is still seen by
:func:`raise_if_interrupted`, which the store calls right before its atomic rename.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

#: Seconds a terminated process (a DEM worker or job) gets to end before it is killed.
TERMINATE_GRACE_S = 1.0

_interrupted = threading.Event()
#: The signal that interrupted (SIGINT where the flag was set by other means).
_signal_number = signal.SIGINT
#: Signals handled as an interruption (SIGHUP where the platform has it).
_SIGNALS = (signal.SIGINT, signal.SIGTERM) + tuple(
    getattr(signal, name) for name in ("SIGHUP",) if hasattr(signal, name))
#: Depth of :func:`deferred` blocks and Numba compiler-lock holds (:func:`defer_while_compiling`)
#: the main thread is in (the handler runs in that thread).
_deferring = 0
#: The listener that defers interrupts while Numba compiles (:func:`defer_while_compiling`;
#: registered once).
_compile_guard = None


class StopRequested(Exception):  # noqa: N818 - a request, not an error
    """Raised by long work that runs in a background thread (a DEM pool of the app's
    calibration) once its caller set the work's stop event: a Cancel, or the process
    exiting. The running work was stopped and discarded; what finished before is kept."""


def raise_if_stopped(stop: threading.Event | None, message: str) -> None:
    """Raise :class:`StopRequested` with ``message`` (what was stopped, what is kept) where
    the work's ``stop`` event is set; nothing where it is None or not set."""
    if stop is not None and stop.is_set():
        raise StopRequested(message)


def _handler(signum, frame) -> None:  # noqa: ARG001 - signal handler signature
    global _signal_number
    if not _interrupted.is_set():  # the first signal is the one the exit status says
        _signal_number = signum
    _interrupted.set()
    if _deferring:
        return  # raised by the deferred block's owner once its step is whole
    raise KeyboardInterrupt


def _unraisable_hook(unraisable) -> None:
    # An interrupt raised inside a weakref callback or __del__ cannot propagate; the flag is
    # already set, so say nothing here (the CLI prints its one line) instead of a traceback.
    if unraisable.exc_type is not None and issubclass(unraisable.exc_type, KeyboardInterrupt):
        return
    # Once SIGINT has arrived, the interrupted run's half-built objects are torn down: e.g.
    # llvmlite's ObjectRef.__del__ on a PipelineTuningOptions whose __init__ the interrupt cut
    # short ("AttributeError: ... no attribute '_as_parameter_'", after the CLI's one line).
    # Errors of a run the user stopped are not the user's business. Before an interrupt, an
    # unraisable error is a real one and is reported as usual.
    if _interrupted.is_set():
        return
    sys.__unraisablehook__(unraisable)


def install() -> Callable[[], None]:
    """Route SIGINT, SIGTERM and SIGHUP through the flag (main thread only; a no-op elsewhere).

    Returns a function that puts back the previous handler and unraisable hook (for callers
    such as tests that run the CLI in-process), or with ``ignore_signals=True`` ignores the
    signals from then on instead.
    """
    if threading.current_thread() is not threading.main_thread():
        return lambda *, ignore_signals=False: None  # noqa: ARG005 - restore's signature
    # a SIGTERM or SIGHUP ignored by whoever started the process stays ignored (as Python leaves a
    # SIGINT ignored at start-up alone)
    previous_handlers = {signum: signal.signal(signum, _handler) for signum in _SIGNALS
                         if signum == signal.SIGINT
                         or signal.getsignal(signum) is not signal.SIG_IGN}
    previous_hook = sys.unraisablehook
    sys.unraisablehook = _unraisable_hook

    def restore(*, ignore_signals: bool = False) -> None:
        # ignore_signals: a command that is over (console_main) goes straight from this
        # handler to SIG_IGN; putting Python's default back first left a moment in which a
        # Ctrl-C escaped as a traceback
        with deferred():
            for signum, previous in previous_handlers.items():
                signal.signal(signum, signal.SIG_IGN if ignore_signals else previous)
        sys.unraisablehook = previous_hook

    return restore


def interrupted() -> bool:
    """True once SIGINT has arrived since :func:`install` (or the last :func:`reset`)."""
    return _interrupted.is_set()


def reset() -> None:
    """Forget an earlier interruption (a new CLI run in the same process)."""
    global _signal_number
    _interrupted.clear()
    _signal_number = signal.SIGINT


def exit_status() -> int:
    """Exit status of an interrupted command: 128 + the signal's number, the shell's
    convention (130 for Ctrl-C, 143 for SIGTERM, 129 for SIGHUP)."""
    return 128 + int(_signal_number)


def ignore() -> None:
    """Ignore further interruptions for the rest of the process (a command that is over:
    one landing while the interpreter shuts down would end it by the signal, status -2 or
    -15, instead of the command's own status)."""
    for signum in _SIGNALS:
        signal.signal(signum, signal.SIG_IGN)


def silence_teardown() -> None:
    """Drop unraisable errors for the rest of a process whose command was interrupted.

    :func:`install`'s hook silences them only while the command runs; an object the
    interrupted run left half-built in a reference cycle is torn down by the collector at
    interpreter exit, after the command put Python's own hook back, which printed "Exception
    ignored in ..." after the one line of the interruption (once in a full test-suite run
    under load).
    """
    sys.unraisablehook = _quiet_hook


def _quiet_hook(unraisable) -> None:  # noqa: ARG001 - sys.unraisablehook signature
    return


def raise_if_interrupted() -> None:
    """Raise :class:`KeyboardInterrupt` if SIGINT arrived, even if it was swallowed since."""
    if _interrupted.is_set():
        raise KeyboardInterrupt


@contextmanager
def deferred() -> Iterator[None]:
    """A block that SIGINT cannot cut in two: inside it the handler only records the
    interruption; :func:`raise_if_interrupted` after the block delivers it.

    For a commit and its bookkeeping (the store's rename and its commit count): an interrupt
    landing between the two would leave the caller unable to say whether its work was
    saved. Only the main thread defers (the handler runs there); elsewhere a no-op.
    """
    global _deferring
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _deferring += 1
    try:
        yield
    finally:
        _deferring -= 1


def defer_while_compiling() -> None:
    """Let no interrupt cut a Numba compilation or cache load in two (idempotent; call before
    the first call of a jitted function).

    An interrupt raised while llvmlite built a module left it half-built, and its
    destructor crashed the process when the interrupted command dropped the exception: a
    segmentation fault after the CLI's one line (2 in ~730 runs of ``analyze`` interrupted
    at random moments). While the main thread holds Numba's compiler lock (the cache load
    and the compilation of a function, its callees included), the handler only records the
    interrupt (each hold is a :func:`deferred` level); it is raised as the outermost lock is
    released outside any other deferred block, when the compiled function is whole.
    Compiling from a cold cache may thus delay a Ctrl-C by its seconds.
    """
    global _compile_guard
    if _compile_guard is not None:
        return
    from numba.core import event

    class CompileGuard(event.Listener):
        """Defers the main thread's interrupts while it holds Numba's compiler lock."""

        def on_start(self, event) -> None:  # noqa: ARG002 - Listener signature
            global _deferring
            if threading.current_thread() is threading.main_thread():
                _deferring += 1

        def on_end(self, event) -> None:  # noqa: ARG002 - Listener signature
            global _deferring
            if threading.current_thread() is not threading.main_thread():
                return
            _deferring -= 1
            if (not _deferring and _interrupted.is_set()
                    and signal.getsignal(signal.SIGINT) is _handler):
                raise KeyboardInterrupt

    _compile_guard = CompileGuard()
    event.register("numba:compiler_lock", _compile_guard)


def is_interruption(exc: BaseException) -> bool:
    """True for a KeyboardInterrupt (or an error caused by one), or for any error once SIGINT
    has arrived.

    An interrupt raised inside C code comes back as another error: Numba's dispatcher gives
    ``SystemError: ... returned a result with an exception set``, and an import of one of its
    extension modules ``ImportError: numba._devicearray failed to import`` (seen once in
    ~20 runs of the test that interrupts ``pidcore analyze`` at random moments). The flag set
    by :func:`install`'s handler tells such an error from an unrelated one.
    """
    seen: BaseException | None = exc
    for _ in range(16):  # the chain of causes, bounded
        if seen is None:
            break
        if isinstance(seen, KeyboardInterrupt):
            return True
        seen = seen.__cause__ or seen.__context__
    return isinstance(exc, Exception) and _interrupted.is_set()


def mark_handled() -> None:
    """Tell CPython the interrupt was handled, so that the exit status stays the CLI's 130.

    A KeyboardInterrupt that passes through code a C extension runs with ``PyRun_String``
    during an import sets CPython's ``_Py_UnhandledKeyboardInterrupt`` even when it is caught
    later; at exit the interpreter then kills itself with SIGINT (status -2 instead of 130;
    seen here with Ctrl-C during the sub-command imports). Clearing it is best effort: other
    interpreters lack the symbol and need nothing.
    """
    try:
        import ctypes

        ctypes.c_int.in_dll(ctypes.pythonapi, "_Py_UnhandledKeyboardInterrupt").value = 0
    except (ImportError, AttributeError, ValueError, OSError):
        pass


def untouched(path: str | os.PathLike) -> str:
    """What an interrupt left of ``path`` it did not write: ``"X unchanged"``, or ``"X not
    created"`` where it never existed (a first run into a new store or folder was told it was
    'unchanged'). One wording for every command and the calibration runner."""
    return f"{path} unchanged" if Path(path).exists() else f"{path} not created"


def stop_processes(processes: Iterable, grace_s: float = TERMINATE_GRACE_S) -> None:
    """Terminate ``processes`` (:class:`multiprocessing.Process` objects), kill those still
    alive after ``grace_s`` in all, and wait until every one is gone.

    The kill is what bounds the wait: a process that inherited SIGTERM ignored (a fork server
    started while its parent ignored it, as ``console_main`` does once its command is over)
    went on with its DEM case, and a caller joining it waited for the case to end: minutes.
    """
    import time

    processes = list(processes)
    for process in processes:
        if process.is_alive():
            process.terminate()
    deadline = time.monotonic() + grace_s
    for process in processes:
        process.join(max(0.0, deadline - time.monotonic()))
        if process.is_alive():
            process.kill()
            process.join()
