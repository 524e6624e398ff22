"""TrackedKeySet: a set of packed voxel keys that says when it changed.

The voxel maps keep the occupied voxels of the robot's height band as a set, updated by every
cloud, and the maps manager projects that band on the 2D map each cycle. Turning the set into
an array and projecting it took a quarter of the EasyNav process's CPU in a Bonxai stack
(py-spy, TurtleBot3 sandbox), although in a static world the band rarely changes once the walls
are seen. Here the array is made once per change, and :attr:`version` lets a reader keep what it
derived from it (the projection) until the next change.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable

import numpy as np

# Versions are unique across sets: a set made anew (a rebuilt band) never repeats the version a
# reader kept from the one it replaces.
_versions = itertools.count(1)


class TrackedKeySet:
    """Packed voxel keys (Python ints) with a change counter and a cached array.

    Thread contract: one owner mutates it (the maps manager's non-RT thread); the array returned
    by :meth:`array` is read-only and never changed afterwards, so it may be handed to others.
    Exceptions: none.
    """

    def __init__(self, keys: Iterable[int] = ()) -> None:
        self._keys: set[int] = set(keys)
        self.version = next(_versions)
        self._array: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self._keys)

    def __contains__(self, key: int) -> bool:
        return key in self._keys

    def add_all(self, keys: list[int]) -> None:
        """Add ``keys``; a new version when any was missing."""
        before = len(self._keys)
        self._keys.update(keys)
        if len(self._keys) != before:
            self._changed()

    def remove_all(self, keys: list[int]) -> None:
        """Remove ``keys`` (absent ones ignored); a new version when any was there."""
        before = len(self._keys)
        self._keys.difference_update(keys)
        if len(self._keys) != before:
            self._changed()

    def array(self) -> np.ndarray:
        """The keys as a read-only int64 array (in no set order), made once per version."""
        if self._array is None:
            array = np.fromiter(self._keys, dtype=np.int64, count=len(self._keys))
            array.flags.writeable = False
            self._array = array
        return self._array

    def _changed(self) -> None:
        self.version = next(_versions)
        self._array = None
