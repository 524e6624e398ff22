"""ParameterFreeze: in safety mode the configuration is frozen once configured, so the
configuration fingerprint stays valid while EasyNav runs."""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from contextlib import contextmanager


def _same_value(old: object, new: object) -> bool:
    """Same type and value; NaN equals NaN; arrays element by element (ROS arrays come as
    lists, tuples, array.array or numpy arrays)."""
    if isinstance(old, str | bytes) or isinstance(new, str | bytes):
        return type(old) is type(new) and old == new
    if isinstance(old, bool) or isinstance(new, bool):
        return isinstance(old, bool) and isinstance(new, bool) and old == new
    if isinstance(old, float) or isinstance(new, float):
        if not (isinstance(old, float) and isinstance(new, float)):
            return False
        return old == new or (math.isnan(old) and math.isnan(new))
    if isinstance(old, int) or isinstance(new, int):
        return isinstance(old, int) and isinstance(new, int) and old == new
    if old is None or new is None:
        return old is None and new is None
    try:
        old_items, new_items = list(old), list(new)  # type: ignore[call-overload]
    except TypeError:
        return old == new
    return len(old_items) == len(new_items) and all(
        _same_value(a.item() if hasattr(a, "item") else a, b.item() if hasattr(b, "item") else b)
        for a, b in zip(old_items, new_items, strict=True)
    )


class ParameterFreeze:
    """Once EasyNav is configured in safety mode, its configuration cannot change.

    The nodes consult it from their parameter callbacks and from the recovery system's
    ``request_reconfigure()``/``request_restore_parameters()``:

    * :meth:`check_change`: while frozen, a change is rejected with a reason naming the
      parameter, except setting the value it already has (same type and value);
    * :meth:`check_declare`: new parameters can only be declared while not frozen;
    * :meth:`check_reconfiguration`: runtime reconfiguration requests are refused while frozen.

    system_node unfreezes it while configuring (:meth:`thawed`, or :meth:`unfreeze` and
    :meth:`freeze`) and freezes it when configured in safety mode; outside safety mode it is
    never frozen and every check passes.

    Thread contract: :meth:`freeze`/:meth:`unfreeze` from the lifecycle thread; the checks from
    any thread (parameter callbacks run in executor threads). A lock makes each call atomic.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._frozen = False

    @property
    def frozen(self) -> bool:
        """True while changes are rejected."""
        return self._frozen

    def freeze(self) -> None:
        """Reject changes from now on (configured in safety mode)."""
        with self._lock:
            self._frozen = True

    def unfreeze(self) -> None:
        """Accept changes and declarations (while configuring, or outside safety mode)."""
        with self._lock:
            self._frozen = False

    @contextmanager
    def thawed(self) -> Iterator[None]:
        """Unfrozen inside the block, frozen again afterwards if it was frozen before."""
        with self._lock:
            was_frozen = self._frozen
            self._frozen = False
        try:
            yield
        finally:
            if was_frozen:
                self.freeze()

    def check_change(
        self, node: str, name: str, old_value: object, new_value: object
    ) -> tuple[bool, str]:
        """``(ok, reason)`` for changing ``node/name`` from ``old_value`` to ``new_value``."""
        with self._lock:
            if not self._frozen or _same_value(old_value, new_value):
                return True, ""
        return False, (
            f"{node}/{name}: the configuration is frozen in safety mode; changing it from "
            f"{old_value!r} to {new_value!r} is rejected (reconfigure EasyNav to change it)"
        )

    def check_declare(self, node: str, name: str) -> tuple[bool, str]:
        """``(ok, reason)`` for declaring a new parameter ``node/name``."""
        with self._lock:
            if not self._frozen:
                return True, ""
        return False, (
            f"{node}/{name}: the configuration is frozen in safety mode; new parameters can "
            "only be declared while EasyNav configures"
        )

    def check_reconfiguration(self, request: str = "request_reconfigure") -> tuple[bool, str]:
        """``(ok, reason)`` for a recovery system's reconfiguration ``request`` (by name)."""
        with self._lock:
            if not self._frozen:
                return True, ""
        return False, f"{request}() refused: the configuration is frozen in safety mode"
