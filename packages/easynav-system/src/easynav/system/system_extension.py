"""SystemExtension: the hooks system_node calls on its extensions (goal manager, runtime
reconfiguration, safety supervisor)."""

from __future__ import annotations


class SystemExtension:
    """A part of system_node with hooks at the lifecycle transitions and in the cycles.

    Every hook is a no-op here: an extension overrides the ones it needs. system_node calls
    them on every extension, in the order they were added (:meth:`SystemNode.add_extension`).
    An exception raised by ``configure`` or ``before_activate`` fails the transition (its
    message is system_node's error message); from the other hooks it propagates as it would
    from system_node's own code.

    Thread contract: the lifecycle hooks run in the thread of the transition; ``cycle_rt_*``
    in the RT loop thread; ``cycle`` and ``between_cycles`` in the non-RT loop thread.
    """

    # -- lifecycle ----------------------------------------------------------------------------
    def before_configure(self) -> None:
        """Before system_node reads its parameters and configures its sub-nodes."""

    def configure(self) -> None:
        """After every sub-node configured (their plugins are loaded); raise to fail."""

    def cleanup(self) -> None:
        """After the sub-nodes were cleaned up, or after a configure that failed."""

    def before_activate(self) -> None:
        """Before the sub-nodes activate; raise to fail the activation."""

    def activate(self) -> None:
        """After the sub-nodes activated, before the cycles run."""

    def deactivate(self) -> None:
        """The cycles have stopped; the sub-nodes are still active (deactivate, shutdown)."""

    # -- RT cycle -----------------------------------------------------------------------------
    def cycle_rt_start(self) -> None:
        """At the start of each RT cycle, before the sensors."""

    def cycle_rt_before_publish(self) -> None:
        """After the controller and the recovery system, before the command is published."""

    def cycle_rt_end(self) -> None:
        """After the command was published."""

    # -- non-RT cycle -------------------------------------------------------------------------
    def cycle(self) -> None:
        """In each non-RT cycle, after the maps manager and before the planner (while active)."""

    def between_cycles(self) -> None:
        """After each non-RT cycle, active or not (outside the cycle's work)."""
