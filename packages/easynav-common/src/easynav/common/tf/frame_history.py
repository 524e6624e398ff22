"""FrameHistory: the transforms received for one child frame (helper of TFBuffer)."""

from __future__ import annotations

from bisect import bisect_left

from easynav.common.tf.transform_math import TransformTuple, interpolate


class FrameHistory:
    """Parent frame and time-ordered transforms ``parent <- child`` of one child frame.

    A static frame keeps one transform valid at every time; a dynamic one keeps the samples of
    the last ``cache_time`` seconds (measured from its newest sample, as tf2 does).

    Thread contract: not locked; only the owning :class:`TFBuffer` touches it, under its lock.
    """

    __slots__ = ("child", "parent", "static", "stamps", "values", "authority")

    def __init__(self, child: str, parent: str, static: bool, authority: str) -> None:
        self.child = child
        self.parent = parent
        self.static = static
        self.stamps: list[float] = []
        self.values: list[TransformTuple] = []
        self.authority = authority

    def insert(self, stamp: float, value: TransformTuple, cache_time: float) -> bool:
        """Store a sample; False when it is older than the cache window (tf2's TF_OLD_DATA)."""
        if self.static:
            self.stamps = [stamp]
            self.values = [value]
            return True
        stamps = self.stamps
        if not stamps or stamp > stamps[-1]:
            stamps.append(stamp)
            self.values.append(value)
        else:
            if stamp < stamps[-1] - cache_time:
                return False
            i = bisect_left(stamps, stamp)
            if i < len(stamps) and stamps[i] == stamp:
                self.values[i] = value  # same stamp again: the newer message wins
                return True
            stamps.insert(i, stamp)
            self.values.insert(i, value)
        oldest_kept = stamps[-1] - cache_time
        if stamps[0] < oldest_kept:
            cut = bisect_left(stamps, oldest_kept)
            del stamps[:cut]
            del self.values[:cut]
        return True

    @property
    def newest(self) -> float:
        """Stamp of the newest sample (static frames: their stamp; they hold at any time)."""
        return self.stamps[-1]

    @property
    def oldest(self) -> float:
        """Stamp of the oldest sample kept."""
        return self.stamps[0]

    def value_at(self, time: float) -> TransformTuple | None:
        """The transform at ``time`` (interpolated); None when outside the held range."""
        if self.static:
            return self.values[0]
        stamps = self.stamps
        last = stamps[-1]
        if time >= last:
            return self.values[-1] if time == last else None
        if time < stamps[0]:
            return None
        i = bisect_left(stamps, time)
        t1 = stamps[i]
        if t1 == time:
            return self.values[i]
        t0 = stamps[i - 1]
        return interpolate(self.values[i - 1], self.values[i], (time - t0) / (t1 - t0))
