"""NavState: the typed, thread-safe blackboard through which EasyNav components talk."""

from __future__ import annotations

import copy
import threading
from collections.abc import Callable, Iterable
from typing import Any, TypeVar

T = TypeVar("T")

_GROUPS_PREFIX = "__group__."


class NavStateTypeError(TypeError):
    """A key was written or read with a type other than the one fixed by its first write."""


class NavStateKeyError(KeyError):
    """A key that was never written was read."""

    def __str__(self) -> str:  # KeyError quotes its argument; keep the message readable.
        return str(self.args[0])


def _type_name(t: type) -> str:
    return f"{t.__module__}.{t.__qualname__}" if t.__module__ != "builtins" else t.__qualname__


class NavState:
    """Key → value store; the type of a key is fixed by its first write.

    Thread contract: every method takes one internal lock, so any method may be called from the
    RT loop, the non-RT loop and ROS callbacks at once. ``get`` returns the stored object itself
    (no copy): use it for data your own thread writes. ``get_safe`` returns a copy taken under the
    lock: use it for data written by the other loop. Stored values must be replaced, not mutated
    in place, by their writers (``set`` a new object), so a reader holding a reference from ``get``
    never sees a half-written value.

    Exceptions: :class:`NavStateTypeError` (a ``TypeError``) names the key and both types;
    :class:`NavStateKeyError` (a ``KeyError``) names a missing key.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._values: dict[str, Any] = {}
        self._types: dict[str, type] = {}
        self._groups: dict[str, tuple[str, ...]] = {}
        self._printers: dict[type, Callable[[Any], str]] = {}

    # -- writing ---------------------------------------------------------------------------
    def set(self, key: str, value: Any) -> None:
        """Store ``value`` under ``key``; the first write fixes the key's type."""
        vtype = type(value)
        with self._lock:
            known = self._types.get(key)
            if known is None:
                self._types[key] = vtype
            elif known is not vtype:
                raise NavStateTypeError(
                    f"NavState key '{key}' holds {_type_name(known)}, "
                    f"cannot write {_type_name(vtype)}"
                )
            self._values[key] = value

    def set_group(self, name: str, keys: Iterable[str]) -> None:
        """Declare group ``name`` with member ``keys``; the member list is also stored as a value.

        Keys may be added later with :meth:`add_to_group`.
        """
        members = tuple(dict.fromkeys(keys))
        with self._lock:
            self._groups[name] = members
            self._types.setdefault(_GROUPS_PREFIX + name, tuple)
            self._values[_GROUPS_PREFIX + name] = members

    def add_to_group(self, name: str, key: str) -> None:
        """Add ``key`` to group ``name`` (creating the group if needed)."""
        with self._lock:
            members = self._groups.get(name, ())
            if key in members:
                return
            members = members + (key,)
            self._groups[name] = members
            self._types.setdefault(_GROUPS_PREFIX + name, tuple)
            self._values[_GROUPS_PREFIX + name] = members

    def erase(self, key: str) -> None:
        """Remove a key (its type is forgotten too)."""
        with self._lock:
            self._values.pop(key, None)
            self._types.pop(key, None)

    # -- reading ---------------------------------------------------------------------------
    def has(self, key: str) -> bool:
        """True when ``key`` was written."""
        with self._lock:
            return key in self._values

    def get(self, key: str, expected_type: type[T] | None = None) -> T:
        """The stored value itself (no copy). ``expected_type`` checks its type."""
        with self._lock:
            return self._get_locked(key, expected_type)

    def get_safe(self, key: str, expected_type: type[T] | None = None) -> T:
        """A deep copy of the stored value, taken under the lock."""
        with self._lock:
            return copy.deepcopy(self._get_locked(key, expected_type))

    def get_or(self, key: str, default: T) -> T:
        """The stored value, or ``default`` when the key is missing (type-checked otherwise)."""
        with self._lock:
            if key not in self._values:
                return default
            if default is not None:
                return self._get_locked(key, type(default))
            return self._values[key]

    def _get_locked(self, key: str, expected_type: type | None) -> Any:
        try:
            value = self._values[key]
        except KeyError:
            raise NavStateKeyError(f"NavState has no key '{key}'") from None
        if expected_type is not None and self._types[key] is not expected_type:
            raise NavStateTypeError(
                f"NavState key '{key}' holds {_type_name(self._types[key])}, "
                f"read as {_type_name(expected_type)}"
            )
        return value

    def get_group(self, name: str) -> dict[str, Any]:
        """The members of group ``name`` that have values: ``{key: value}``."""
        with self._lock:
            members = self._groups.get(name)
            if members is None:
                raise NavStateKeyError(f"NavState has no group '{name}'")
            return {k: self._values[k] for k in members if k in self._values}

    def groups(self) -> dict[str, tuple[str, ...]]:
        """Every group and its member keys."""
        with self._lock:
            return dict(self._groups)

    def get_by_type(self, value_type: type[T]) -> dict[str, T]:
        """Every value of exactly ``value_type``: ``{key: value}``."""
        with self._lock:
            return {k: self._values[k] for k, t in self._types.items() if t is value_type}

    def get_no_group(self, value_type: type[T]) -> dict[str, T]:
        """Every value of ``value_type`` whose key is in no group.

        The default way plugins read perceptions: grouping a sensor hides it from them.
        """
        with self._lock:
            grouped = {k for members in self._groups.values() for k in members}
            return {
                k: self._values[k]
                for k, t in self._types.items()
                if t is value_type and k not in grouped
            }

    def keys(self) -> list[str]:
        """Every key written so far (group member lists excluded)."""
        with self._lock:
            return [k for k in self._values if not k.startswith(_GROUPS_PREFIX)]

    # -- debugging -------------------------------------------------------------------------
    def register_printer(self, value_type: type, printer: Callable[[Any], str]) -> None:
        """Use ``printer(value)`` for values of ``value_type`` in :meth:`debug_string`."""
        with self._lock:
            self._printers[value_type] = printer

    def debug_string(self) -> str:
        """One line per key: ``key [type]: value`` (pluggable per-type printers)."""
        with self._lock:
            items = [
                (k, self._types[k], self._values[k])
                for k in sorted(self._values)
                if not k.startswith(_GROUPS_PREFIX)
            ]
            printers = dict(self._printers)
            groups = dict(self._groups)
        lines = []
        for key, vtype, value in items:
            printer = printers.get(vtype)
            try:
                text = printer(value) if printer else _default_print(value)
            except Exception as exc:  # a faulty printer must not break the debug topic
                text = f"<printer failed: {exc}>"
            lines.append(f"{key} [{vtype.__qualname__}]: {text}")
        for name, members in sorted(groups.items()):
            lines.append(f"group {name}: {', '.join(members)}")
        return "\n".join(lines)


def _default_print(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 200 else text[:197] + "..."
