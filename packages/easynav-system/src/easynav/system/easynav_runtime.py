"""EasyNavRuntime: one EasyNav process — context, nodes, executors, loops, stop and exit code."""

from __future__ import annotations

import gc
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass

import rclpy
from rclpy.signals import SignalHandlerOptions

from easynav.core.nav_state import NavState
from easynav.system.cycle_loop import CycleLoop
from easynav.system.executor import EXECUTOR_ENV, make_executor  # noqa: F401 (re-exported)
from easynav.system.process_tuning import tune_malloc
from easynav.system.system_node import SystemNode

#: SCHED_FIFO priority of the non-RT loop with ``use_real_time``: below the RT loop's 80.
NORT_PRIORITY = 70

@dataclass
class RuntimeResult:
    """How a run ended: exit code and reason."""

    exit_code: int
    reason: str


class EasyNavRuntime:
    """Hosts one EasyNav instance in this process (what ``easynav run`` does).

    - ``start()``: rclpy context with the params file, system_node and its sub-nodes, one
      single-threaded executor per loop (:func:`make_executor`; MultiThreadedExecutor is
      unusable in this rclpy), the RT
      loop (sensors_node and its subscriptions; SCHED_FIFO 80 when ``use_real_time``) and the
      non-RT loop (every other node: goal topics, lifecycle services, plugin topics; SCHED_FIFO
      70 when ``use_real_time``, so it is not preempted while it holds the GIL), then
      configure and activate. Returns False with ``error`` set when configure fails.
    - ``wait()``: blocks until a stop is requested (signal, recovery system, safety supervisor).
    - ``stop()``: controlled stop: deactivate (the controller brakes within the deceleration
      limits and its last command is an exact zero), loop threads joined, executors down,
      shutdown to Finalized (the plugins' entities destroyed), nodes destroyed, then
      ``rclpy.shutdown`` — in that order: ``rclpy.shutdown`` while an executor still runs, or
      entities destroyed while the EventsExecutor still serves them, abort the interpreter
      (exit code 134).

    Thread contract: all public methods from the owner's (main) thread. With
    ``install_signal_handlers`` the first SIGINT or SIGTERM is only noted by its handler and
    becomes a stop request in ``wait()`` or ``stop()`` (the handler takes no lock: it runs in
    the main thread, perhaps while that thread holds the one it would take); a second one exits
    at once with code 130, without a controlled stop.
    """

    def __init__(
        self,
        params_file: str | None = None,
        namespace: str = "",
        ros_args: list[str] | None = None,
        install_signal_handlers: bool = True,
    ) -> None:
        args = ["easynav", "--ros-args"]
        if params_file:
            args += ["--params-file", params_file]
        args += list(ros_args or [])
        tune_malloc()
        self.context = rclpy.Context()
        rclpy.init(args=args, context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        self.nav_state = NavState()
        self.namespace = namespace
        self.system_node = SystemNode(self.nav_state, namespace, context=self.context)
        self.requests = self.system_node.requests
        self.error = ""
        self.rt_executor = make_executor(self.context)
        self.nort_executor = make_executor(self.context)
        self.rt_executor.add_node(self.system_node.sensors_node)
        self.rt_executor.add_node(self.system_node.rt_io_node)
        for node in self.system_node.all_nodes():
            if node is not self.system_node.sensors_node:
                self.nort_executor.add_node(node)
        self.rt_loop: CycleLoop | None = None
        self.nort_loop: CycleLoop | None = None
        self._stopped = False
        self._froze_gc = False
        self._signals = 0
        self._signal_name: str | None = None  # the first signal's, set by its handler
        if install_signal_handlers and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, self._on_signal)
            signal.signal(signal.SIGTERM, self._on_signal)

    @property
    def logger(self):
        return self.system_node.get_logger()

    def add_rt_node(self, node) -> None:
        """Serve ``node``'s callbacks in the RT loop (safety status, TF). Before ``start``."""
        self.rt_executor.add_node(node)

    def _on_signal(self, signum, frame) -> None:
        self._signals += 1
        if self._signals > 1:
            # A second signal while stopping: leave now (the driver may keep the last command).
            # os.write, not sys.stderr: the main thread may be inside a write to stderr.
            os.write(2, b"easynav: second signal, exiting immediately\n")
            sys.exit(130)
        # Only noted here; wait() (or stop()) posts the shutdown. Python runs a handler in the
        # main thread between two bytecodes, which may be while that thread holds the lock of the
        # very event post_shutdown sets (Event.wait holds it on entry and exit): setting it here
        # deadlocked the process, one SIGTERM in ten with the dummy system, until a second
        # signal killed it without a controlled stop.
        self._signal_name = signal.Signals(signum).name

    def _post_signal_shutdown(self) -> None:
        name = self._signal_name
        if name is not None and self.requests.shutdown_reason is None:
            self.requests.post_shutdown(f"received {name}", 0)

    def start(self) -> bool:
        """Start the loops, then configure and activate. False (and ``error``) on failure."""
        # A short GIL switch interval keeps the RT thread's jitter low: with a CPU-bound Python
        # thread in the process, a waiting thread's wake-up measured p50 5 ms / p99 5.1 ms at
        # the default 5 ms interval, 12 µs / 104 µs at 0.5 ms.
        sys.setswitchinterval(float(os.environ.get("EASYNAV_SWITCH_INTERVAL", "0.0005")))
        node = self.system_node
        node.trigger_configure()
        if node.lifecycle_state() != "inactive":
            self.error = node.error_message or "configure failed"
            return False
        params = node.parameters
        self.rt_loop = CycleLoop(
            "easynav_rt",
            float(params["rt_freq"]),
            self.rt_executor,
            node.cycle_rt,
            float(params["spin_time_rt"]),
            wake=node.rt_wake_pending,
            realtime=bool(params["use_real_time"]),
            on_realtime_result=self._realtime_result,
            on_error=lambda exc: self.logger.error(f"RT cycle: {type(exc).__name__}: {exc}"),
        )
        # The non-RT loop is SCHED_FIFO too, below the RT loop: both share the GIL, and a thread of
        # normal priority that other processes preempt while it holds the GIL keeps the RT thread
        # waiting for the GIL (priority inversion). Measured on a loaded 2-core machine
        # (bench_rt_loop.py): p99 start-period error 27-57x the bare loop's with a normal non-RT
        # thread, 0.4-1.0x with SCHED_FIFO 70; nice -10 only brings it to 11x.
        self.nort_loop = CycleLoop(
            "easynav_nort",
            float(params["freq"]),
            self.nort_executor,
            lambda triggered: node.cycle(),
            float(params["spin_time_nort"]),
            realtime=bool(params["use_real_time"]),
            priority=NORT_PRIORITY,
            on_realtime_result=self._realtime_result,
            on_error=lambda exc: self.logger.error(f"non-RT cycle: {type(exc).__name__}: {exc}"),
        )
        self.rt_loop.start()
        self.nort_loop.start()
        node.trigger_activate()
        if node.lifecycle_state() != "active":
            self.error = node.error_message or "activate failed"
            return False
        # Objects alive now (nodes, plugins, maps) are never garbage: keep the cyclic collector
        # from walking them during cycles. (No explicit collection first: in a test process a
        # collection here once ran a finalizer of an earlier test's ROS objects for minutes.)
        gc.freeze()
        self._froze_gc = True
        self.logger.info("EasyNav is active")
        return True

    def _realtime_result(self, ok: bool, message: str) -> None:
        if ok:
            self.logger.info(message)
        else:
            self.logger.warning(message)

    def wait(self, timeout: float | None = None) -> bool:
        """Block until a stop is requested (True) or ``timeout`` passes (False).

        A SIGINT or SIGTERM received is posted as a stop request here (within 0.1 s)."""
        end = None if timeout is None else time.monotonic() + timeout
        event = self.requests.shutdown_event
        while True:
            self._post_signal_shutdown()
            remaining = None if end is None else end - time.monotonic()
            if remaining is not None and remaining <= 0:
                return event.is_set()
            # Short waits: a signal noted by the handler is posted within 0.1 s.
            if event.wait(0.1 if remaining is None else min(0.1, remaining)):
                return True

    def stop(self) -> RuntimeResult:
        """Controlled stop; returns the exit code and reason. Idempotent."""
        self._post_signal_shutdown()  # a signal received while no one waited
        reason = self.requests.shutdown_reason or "stop requested"
        code = self.requests.shutdown_exit_code
        if self._stopped:
            return RuntimeResult(code, reason)
        self._stopped = True
        node = self.system_node
        # Deactivate while the loops still spin (the robot brakes on the node clock, which a
        # simulator's /clock keeps moving); then the loops end after their current step and the
        # executors let go of every entity; only then does the shutdown transition destroy the
        # plugins' entities, then the nodes and the context. (Destroyed in this thread while a
        # loop spun, the EventsExecutor lost track of them and aborted the process when it was
        # freed, one test stop in three: see make_executor.)
        try:
            if node.lifecycle_state() == "active":
                node.trigger_deactivate()
        except Exception as exc:
            self.logger.error(f"controlled stop: {type(exc).__name__}: {exc}")
            code = code or 1
        for loop in (self.rt_loop, self.nort_loop):
            if loop is not None:
                loop.stop()
        for loop in (self.rt_loop, self.nort_loop):
            if loop is not None and loop.is_alive():
                loop.join(timeout=2.0)
        self.rt_executor.shutdown()
        self.nort_executor.shutdown()
        try:
            if node.lifecycle_state() in ("unconfigured", "inactive", "active"):
                node.trigger_shutdown()
        except Exception as exc:
            self.logger.error(f"controlled stop: {type(exc).__name__}: {exc}")
            code = code or 1
        for n in [*node.all_nodes(), node.rt_io_node]:
            n.destroy_node()
        if self.context.ok():
            rclpy.shutdown(context=self.context)
        if self._froze_gc:
            # Frozen objects are never collected: without this, a process that runs several
            # runtimes (tests, tools) would keep every stopped one alive, with its DDS participant
            # (8 threads, 11 fds, ghost nodes announced to every other participant). Measured:
            # +8 threads per stopped runtime before, none after. Any runtime still running in
            # this process only loses the freeze's saving on collector walks.
            self._froze_gc = False
            gc.unfreeze()
            gc.collect()
        return RuntimeResult(code, reason)
