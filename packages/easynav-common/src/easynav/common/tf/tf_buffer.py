"""TFBuffer: one robot's transform tree, filled from ``tf``/``tf_static``, read by the loops.

Written by hand because tf2 (buffer, listener) has no PyPI wheel. It follows tf2's behaviour:
a time window per dynamic frame, interpolation between samples (lerp for translation, slerp for
rotation), chaining through the common ancestor of the two frames, and "latest common time"
lookups when no time is given.
"""

from __future__ import annotations

import logging
import math
import threading
import time as _time
from typing import Any

import numpy as np

from easynav.common.tf.errors import (
    ConnectivityError,
    ExtrapolationError,
    FrameLookupError,
)
from easynav.common.tf.frame_history import FrameHistory
from easynav.common.tf.transform_math import (
    IDENTITY,
    TransformTuple,
    compose,
    inverse,
    normalized,
)
from easynav.core.robot.tf_info import TFInfo
from easynav.core.types import Header, Transform, TransformStamped

_MAX_DEPTH = 1000  # a tree deeper than this is a loop in the data, not a robot
#: After a clear with ``refuse_after``, the refusal ends after this long on the monotonic clock
#: at most (the listener ends it sooner, when its clock gets there): a backlog drains in well
#: under that (1.3 s seen under heavy load), and transforms stamped on another clock than the
#: listener's (a misconfigured driver) are not refused for good.
_REFUSAL_MAX_WALL = 5.0  # s
_monotonic = _time.monotonic  # the module's own name, for tests to replace
_WARN_PERIOD_S = 5.0


def _strip(frame: str) -> str:
    # tf2 ignores a leading slash ("/map" == "map"); so do we.
    return frame[1:] if frame.startswith("/") else frame


class TFBuffer:
    """Transforms between the frames of one robot over the last ``cache_time`` seconds.

    Times are ROS times in float seconds. A lookup ``time`` of None or 0 means "the latest time
    at which every transform on the chain is known" (tf2's ``TimePointZero``); static transforms
    hold at every time. The buffer also holds the robot's :class:`TFInfo` (as the original
    RTTFBuffer does).

    Thread contract: every public method takes one internal lock and may be called from any
    thread: lookups from the RT and non-RT loops, ``set_transform`` from ROS callbacks.

    Exceptions: lookups raise :class:`FrameLookupError` (a frame never received),
    :class:`ConnectivityError` (frames in different trees) or :class:`ExtrapolationError`
    (time outside the window held), all :class:`TransformError` (a ``LookupError``); messages
    name the frames, the requested time and the available range. ``set_transform`` never
    raises for bad data: it logs a warning naming the frames and returns False.
    """

    def __init__(self, cache_time: float = 10.0, logger: Any = None) -> None:
        if not (isinstance(cache_time, (int, float)) and math.isfinite(cache_time)) or (
            cache_time <= 0.0
        ):
            raise ValueError(f"TF cache_time = {cache_time!r} must be finite and > 0 (seconds)")
        self._cache_time = float(cache_time)
        self._lock = threading.Lock()
        self._frames: dict[str, FrameHistory] = {}  # child frame -> its history
        self._parents: set[str] = set()  # frames seen only as parents are valid frames too
        self._chains: dict[tuple[str, str], tuple[tuple[FrameHistory, ...], ...]] = {}
        self._tf_info = TFInfo()
        self._has_tf_info = False
        self._logger = logger if logger is not None else logging.getLogger("easynav.tf")
        self._last_warning: dict[tuple[str, str, str], float] = {}
        self._refuse_after: float | None = None  # see clear()
        self._refuse_until = 0.0  # monotonic seconds

    # -- configuration ----------------------------------------------------------------------
    @property
    def cache_time(self) -> float:
        """Seconds of history kept per dynamic frame."""
        return self._cache_time

    def set_cache_time(self, cache_time: float) -> None:
        """Change the window (applies to samples stored from now on)."""
        if not math.isfinite(cache_time) or cache_time <= 0.0:
            raise ValueError(f"TF cache_time = {cache_time!r} must be finite and > 0 (seconds)")
        with self._lock:
            self._cache_time = float(cache_time)

    def set_logger(self, logger: Any) -> None:
        """Where warnings about rejected transforms go (a ``logging`` or rclpy logger)."""
        with self._lock:
            self._logger = logger

    def set_tf_info(self, tf_info: TFInfo) -> None:
        """Store the robot's frame names (system_node does it on configure)."""
        if not isinstance(tf_info, TFInfo):
            raise TypeError(f"set_tf_info expects a TFInfo, got {type(tf_info).__name__}")
        with self._lock:
            self._tf_info = tf_info
            self._has_tf_info = True

    @property
    def has_tf_info(self) -> bool:
        """True once :meth:`set_tf_info` was called (else :meth:`get_tf_info` gives defaults)."""
        return self._has_tf_info

    def get_tf_info(self) -> TFInfo:
        """The robot's frame names, prefix applied (an immutable snapshot)."""
        with self._lock:
            return self._tf_info

    def clear(self, keep_static: bool = False, refuse_after: float | None = None) -> None:
        """Forget every transform (a new system starting in this process), or with
        ``keep_static`` only the dynamic ones (simulated time jumped back). Static transforms
        stay then, as in tf2's clear: they hold at every time, and their publishers send them
        once per subscription (transient local), so they would not come again.

        ``refuse_after`` (where the old time line begins): dynamic transforms stamped after
        it are refused from now on, until :meth:`end_refusal` (the listener calls it when its
        clock gets there) or ``_REFUSAL_MAX_WALL`` seconds have passed. A transform of the old
        time line still queued when the clock jumped back (a subscription's backlog, a
        localizer's write computed just before) would otherwise be stored after the clear:
        the newest for as long as the jump, and for a jump longer than the window every
        transform of the new time line refused as older than it."""
        with self._lock:
            kept = {c: h for c, h in self._frames.items() if keep_static and h.static}
            self._frames.clear()
            self._frames.update(kept)
            self._parents.clear()
            self._parents.update(h.parent for h in kept.values())
            self._chains.clear()
            self._refuse_after = refuse_after
            self._refuse_until = _monotonic() + _REFUSAL_MAX_WALL

    @property
    def refusing_after(self) -> float | None:
        """The stamp after which dynamic transforms are refused (see :meth:`clear`), or None."""
        return self._refuse_after

    def end_refusal(self) -> None:
        """Take dynamic transforms of any stamp again (see :meth:`clear`)."""
        with self._lock:
            self._refuse_after = None

    # -- writing ----------------------------------------------------------------------------
    def set_transform(
        self, transform_stamped: TransformStamped, authority: str, is_static: bool = False
    ) -> bool:
        """Store ``header.frame_id <- child_frame_id`` at ``header.stamp``.

        Returns False (with a warning naming the frames and ``authority``) when the transform is
        not finite, has a zero quaternion or bad frame names, is older than the window, or is
        dynamic and stamped on the time line before a clock change (:meth:`clear`'s
        ``refuse_after``).
        """
        tr = transform_stamped.transform
        t = tr.translation
        q = tr.rotation
        values = (
            float(t[0]), float(t[1]), float(t[2]),
            float(q[0]), float(q[1]), float(q[2]), float(q[3]),
        )  # fmt: skip
        return self.set_transform_values(
            transform_stamped.header.frame_id,
            transform_stamped.child_frame_id,
            transform_stamped.header.stamp,
            values,
            authority,
            is_static,
        )

    def set_transform_values(
        self,
        parent: str,
        child: str,
        stamp: float,
        values: TransformTuple,
        authority: str,
        is_static: bool = False,
    ) -> bool:
        """:meth:`set_transform` from plain values ``(tx, ty, tz, qx, qy, qz, qw)``."""
        parent = _strip(parent)
        child = _strip(child)
        try:
            problem = self._check(parent, child, stamp, values)
        except (TypeError, ValueError) as exc:
            problem = f"unreadable values ({exc})"
        if problem is not None:
            self._warn(parent, child, authority, f"rejected: {problem}")
            return False
        clean = normalized(values)
        if clean is None:
            self._warn(
                parent, child, authority, f"rejected: not finite or zero quaternion {values}"
            )
            return False
        with self._lock:
            refuse_after = self._refuse_after
            if refuse_after is not None and _monotonic() > self._refuse_until:
                refuse_after = self._refuse_after = None
            refused = refuse_after is not None and not is_static and stamp > refuse_after
            if not refused:
                history = self._frames.get(child)
                if history is None or history.parent != parent or history.static != is_static:
                    history = FrameHistory(child, parent, is_static, authority)
                    self._frames[child] = history
                    self._parents.add(parent)
                    self._chains.clear()  # the tree changed shape: cached chains are wrong now
                history.authority = authority
                stored = history.insert(float(stamp), clean, self._cache_time)
                oldest = history.oldest
        if refused:
            self._warn(parent, child, authority,
                       f"refused: stamp {stamp:.3f} is on the time line before the clock "
                       f"changed (after {refuse_after:.3f})")
            return False
        if not stored:
            self._warn(
                parent,
                child,
                authority,
                f"ignored: stamp {stamp:.3f} is older than the {self._cache_time:g} s window "
                f"(oldest kept {oldest:.3f})",
            )
        return stored

    @staticmethod
    def _check(parent: str, child: str, stamp: float, values: TransformTuple) -> str | None:
        if not parent or not child:
            return "empty frame name"
        if parent == child:
            return f"frame '{child}' cannot be its own parent"
        if not math.isfinite(stamp) or stamp < 0.0:
            return f"stamp {stamp} is not a finite non-negative time"
        if len(values) != 7:
            return f"expected 7 values (tx, ty, tz, qx, qy, qz, qw), got {len(values)}"
        return None

    def _warn(self, parent: str, child: str, authority: str, text: str) -> None:
        # Throttled per frame pair and kind: a broken publisher at 100 Hz must not flood the log.
        key = (parent, child, text.split(":", 1)[0])
        now = _monotonic()
        with self._lock:
            last = self._last_warning.get(key)
            if last is not None and now - last < _WARN_PERIOD_S:
                return
            self._last_warning[key] = now
            logger = self._logger
        logger.warning(f"TF '{parent}' -> '{child}' from '{authority}' {text}")

    # -- reading ----------------------------------------------------------------------------
    def frame_exists(self, frame: str) -> bool:
        """True when ``frame`` was received as a parent or a child."""
        frame = _strip(frame)
        with self._lock:
            return frame in self._frames or frame in self._parents

    def frames(self) -> list[str]:
        """Every frame known, sorted."""
        with self._lock:
            return sorted(set(self._frames) | self._parents)

    def all_frames_as_string(self) -> str:
        """One line per child frame: parent, static or time range, authority (for debugging)."""
        with self._lock:
            lines = []
            for child in sorted(self._frames):
                h = self._frames[child]
                span = "static" if h.static else f"[{h.oldest:.3f}, {h.newest:.3f}] s"
                lines.append(f"{child} <- {h.parent}: {span} ({h.authority})")
        return "\n".join(lines)

    def can_transform(
        self, target_frame: str, source_frame: str, time: float | None = None
    ) -> bool:
        """True when :meth:`lookup_transform` would succeed."""
        try:
            self.lookup_transform_values(target_frame, source_frame, time)
        except (FrameLookupError, ConnectivityError, ExtrapolationError):
            return False
        return True

    def lookup_transform(
        self, target_frame: str, source_frame: str, time: float | None = None
    ) -> TransformStamped:
        """The transform mapping points in ``source_frame`` into ``target_frame`` at ``time``.

        ``header.frame_id`` is the target, ``child_frame_id`` the source, ``header.stamp`` the
        time used (the latest common time when ``time`` is None or 0; 0 for a static chain).
        """
        stamp, (tx, ty, tz, qx, qy, qz, qw) = self.lookup_transform_values(
            target_frame, source_frame, time
        )
        return TransformStamped(
            header=Header(stamp=stamp, frame_id=_strip(target_frame)),
            child_frame_id=_strip(source_frame),
            transform=Transform(
                translation=np.array((tx, ty, tz)), rotation=np.array((qx, qy, qz, qw))
            ),
        )

    def lookup_transform_values(
        self, target_frame: str, source_frame: str, time: float | None = None
    ) -> tuple[float, TransformTuple]:
        """:meth:`lookup_transform` as ``(stamp, (tx, ty, tz, qx, qy, qz, qw))``: no arrays."""
        target = target_frame[1:] if target_frame.startswith("/") else target_frame
        source = source_frame[1:] if source_frame.startswith("/") else source_frame
        with self._lock:
            chain = self._chains.get((target, source))
            if chain is None:
                chain = self._build_chain(target, source)
                self._chains[(target, source)] = chain
            source_side, target_side = chain
            if time is None or time == 0.0:
                stamp = self._latest_common_time(source_side, target_side)
            else:
                stamp = float(time)
            acc = IDENTITY
            for history in source_side:
                value = history.value_at(stamp)
                if value is None:
                    raise self._extrapolation(target, source, stamp, history)
                acc = compose(value, acc)
            if target_side:
                up = IDENTITY
                for history in target_side:
                    value = history.value_at(stamp)
                    if value is None:
                        raise self._extrapolation(target, source, stamp, history)
                    up = compose(value, up)
                acc = compose(inverse(up), acc)
        return stamp, acc

    def lookup_transform_values_near(
        self, target_frame: str, source_frame: str, time: float
    ) -> tuple[float, TransformTuple]:
        """:meth:`lookup_transform_values` at ``time``, or the latest when ``time`` is outside
        the window (a stamp newer than the last transform received, or older than the cache).
        Raises the other lookup errors (unknown frames, separate trees)."""
        try:
            return self.lookup_transform_values(target_frame, source_frame, time)
        except ExtrapolationError:
            return self.lookup_transform_values(target_frame, source_frame, None)

    def latest_common_time(self, target_frame: str, source_frame: str) -> float:
        """The newest time at which the whole chain is known (0.0 for a static chain)."""
        target = _strip(target_frame)
        source = _strip(source_frame)
        with self._lock:
            source_side, target_side = self._build_chain(target, source)
            return self._latest_common_time(source_side, target_side)

    # -- internals (called under the lock) ---------------------------------------------------
    @staticmethod
    def _latest_common_time(
        source_side: tuple[FrameHistory, ...], target_side: tuple[FrameHistory, ...]
    ) -> float:
        latest = math.inf
        for history in source_side:
            if not history.static and history.stamps[-1] < latest:
                latest = history.stamps[-1]
        for history in target_side:
            if not history.static and history.stamps[-1] < latest:
                latest = history.stamps[-1]
        return 0.0 if latest == math.inf else latest

    def _path_to_root(self, frame: str, target: str, source: str) -> list[str]:
        path = [frame]
        current = frame
        while True:
            history = self._frames.get(current)
            if history is None:
                return path
            current = history.parent
            if len(path) > _MAX_DEPTH or current in path:
                raise ConnectivityError(
                    f"Cannot transform '{source}' to '{target}': the TF tree has a loop through "
                    f"'{current}' ({' -> '.join(path[-5:])} -> {current})"
                )
            path.append(current)

    def _build_chain(
        self, target: str, source: str
    ) -> tuple[tuple[FrameHistory, ...], tuple[FrameHistory, ...]]:
        for frame in (source, target):
            if frame not in self._frames and frame not in self._parents:
                known = sorted(set(self._frames) | self._parents)
                raise FrameLookupError(
                    f"Cannot transform '{source}' to '{target}': frame '{frame}' does not exist "
                    f"in the TF tree (known frames: {', '.join(known) if known else 'none'})"
                )
        source_path = self._path_to_root(source, target, source)
        target_path = self._path_to_root(target, target, source)
        target_index = {frame: i for i, frame in enumerate(target_path)}
        for i, frame in enumerate(source_path):
            j = target_index.get(frame)
            if j is not None:
                return (
                    tuple(self._frames[f] for f in source_path[:i]),
                    tuple(self._frames[f] for f in target_path[:j]),
                )
        raise ConnectivityError(
            f"Cannot transform '{source}' to '{target}': they are in different TF trees "
            f"('{source}' has root '{source_path[-1]}', '{target}' has root '{target_path[-1]}')"
        )

    @staticmethod
    def _extrapolation(
        target: str, source: str, stamp: float, history: FrameHistory
    ) -> ExtrapolationError:
        oldest, newest = history.oldest, history.newest
        if stamp > newest:
            where = f"{stamp - newest:.3f} s after the newest data"
        else:
            where = f"{oldest - stamp:.3f} s before the oldest data"
        return ExtrapolationError(
            f"Cannot transform '{source}' to '{target}' at time {stamp:.3f}: transform "
            f"'{history.parent}' -> '{history.child}' is available for "
            f"[{oldest:.3f}, {newest:.3f}] ({where})"
        )
