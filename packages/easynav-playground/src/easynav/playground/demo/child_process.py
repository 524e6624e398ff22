"""ChildProcess: one process of the demo (the playground or EasyNav), logged to a file."""

from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path


class ChildProcess:
    """A subprocess in its own session (a terminal Ctrl-C reaches only the demo, which then
    stops the children in order), with stdout and stderr in ``log_path``.

    Thread contract: owned by the demo's main thread.

    Raises:
        FileNotFoundError: the program does not exist (from :meth:`start`).
    """

    def __init__(self, name: str, argv: list[str], env: dict[str, str], log_path: Path) -> None:
        self.name = name
        self.argv = argv
        self.env = env
        self.log_path = Path(log_path)
        self._process: subprocess.Popen | None = None
        self._log = None

    def start(self) -> None:
        """Start the process."""
        self._log = open(self.log_path, "wb")  # noqa: SIM115 - closed in stop()
        self._process = subprocess.Popen(
            self.argv,
            env=self.env,
            stdout=self._log,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
        )

    @property
    def pid(self) -> int | None:
        """The process id once started."""
        return self._process.pid if self._process else None

    def exit_code(self) -> int | None:
        """None while running, else its exit code."""
        return None if self._process is None else self._process.poll()

    def stop(self, timeout: float = 15.0) -> int | None:
        """SIGINT (a controlled stop), then SIGTERM, then SIGKILL; returns the exit code."""
        proc = self._process
        if proc is None:
            return None
        try:
            for sig, wait in (
                (signal.SIGINT, timeout),
                (signal.SIGTERM, 5.0),
                (signal.SIGKILL, 5.0),
            ):
                if proc.poll() is not None:
                    break
                os.kill(proc.pid, sig)
                try:
                    proc.wait(wait)
                except subprocess.TimeoutExpired:
                    continue
        finally:
            if self._log is not None:
                self._log.close()
                self._log = None
        return proc.poll()

    def log_tail(self, lines: int = 20) -> str:
        """The last lines of the process's output."""
        try:
            text = self.log_path.read_text(errors="replace")
        except FileNotFoundError:
            return ""
        return "\n".join(text.splitlines()[-lines:])
