"""SensorChannel: one configured sensor, from its topic to the perception it keeps in NavState."""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from easynav.common.sensors.point_perception import PointPerception
from easynav.core.nav_state import NavState
from easynav.core.warning_throttle import WarningThrottle
from easynav.system.sensors.errors import PerceptionConversionError, SensorsConfigurationError
from easynav.system.sensors.handler_registry import resolve_handler
from easynav.system.sensors.handlers import LaserScanHandler, PointCloud2Handler
from easynav.system.sensors.perception_handler import PerceptionHandler
from easynav.system.sensors.sensor_parameters import SENSOR_PARAMETERS, read_sensor_parameters

SENSOR_QUEUE_DEPTH = 5
# Handlers whose point output already keeps the PointPerception contract (and is measured).
_TRUSTED = (LaserScanHandler, PointCloud2Handler)


class SensorChannel:
    """One sensor of sensors_node: its parameters, handler, subscription and last perception.

    Constant after construction: ``sensor_id``, ``topic``, ``type_name`` (the full ROS message
    type of the handler), ``group`` ("" for none), ``handler`` and ``forget_time`` (s). A
    message goes through :meth:`convert` (handler, point checks, data age: the perception comes
    back with ``valid`` and ``new_data`` set) and then :meth:`store` (NavState under
    ``sensor_id``). :meth:`end_new_data` and :meth:`expire` replace the stored perception by a
    modified copy, never mutate it: a reader may hold the old object. Warnings name the sensor
    and are throttled per kind (a broken sensor at 30 Hz must not flood the log).

    Thread contract: :meth:`from_parameters`, :meth:`subscribe`, :meth:`unsubscribe` and
    :meth:`erase` in the configuring thread with no loop running; :meth:`convert` in the thread
    that spins the subscription (the RT loop's executor) without any lock, since conversion is
    the slow part; :meth:`store`, :meth:`end_new_data` and :meth:`expire` with the lock of the
    owning :class:`~easynav.system.sensors.sensors_manager.SensorsManager` held, so that an
    expiry never overwrites a newer perception being stored; :meth:`status` and the read-only
    properties from any thread (they read one reference).

    Exceptions: :meth:`from_parameters` and :meth:`subscribe` raise
    :class:`~easynav.system.sensors.errors.SensorsConfigurationError` naming the parameter;
    nothing else raises for a bad message or a faulty handler (a warning and a ``rejected``
    count instead).
    """

    def __init__(
        self,
        sensor_id: str,
        topic: str,
        group: str,
        handler: PerceptionHandler,
        forget_time: float,
        clock: Callable[[], float],
        node_name: str = "sensors_node",
        logger: Any = None,
    ) -> None:
        self.sensor_id = sensor_id
        self.topic = topic
        self.type_name = type(handler).ros_message_type
        self.group = group
        self.handler = handler
        self.forget_time = forget_time
        self._clock = clock
        self._node_name = node_name
        self._logger: Any = logger if logger is not None else logging.getLogger("easynav.sensors")
        self._throttle = WarningThrottle(period=5.0)
        self._subscription: Any = None
        self._perception: Any = None
        self._delayed = False
        self._messages = 0
        self._rejected = 0

    @classmethod
    def from_parameters(
        cls,
        params: Any,
        sensor_id: str,
        node: Any,
        forget_time: float,
        clock: Callable[[], float],
        node_name: str = "sensors_node",
        logger: Any = None,
    ) -> SensorChannel:
        """The channel of ``sensor_id``: reads ``<sensor_id>.topic/type/group/plugin``, resolves
        and configures the handler (which may read its own ``<sensor_id>.*``). Configuring thread.

        ``params`` is sensors_node's ParameterAccess, ``node`` None without ROS (handed to the
        handler's ``configure``). Raises
        :class:`~easynav.system.sensors.errors.SensorsConfigurationError` naming the parameter,
        also when the handler's ``configure`` fails with any other exception.
        """
        logger = logger if logger is not None else logging.getLogger("easynav.sensors")
        values = read_sensor_parameters(
            SENSOR_PARAMETERS, params, node_name, sensor_id, warn=logger.warning
        )
        if not values.topic:
            raise SensorsConfigurationError(
                f"{node_name}.{sensor_id}.topic is not set: the topic of sensor '{sensor_id}'"
            )
        handler_class = resolve_handler(
            sensor_id, values.type, values.plugin, node_name, warn=logger.warning
        )
        handler = handler_class()
        handler.logger = logger
        try:
            handler.configure(sensor_id, params, node)
        except SensorsConfigurationError:
            raise
        except Exception as exc:
            raise SensorsConfigurationError(
                f"{node_name}.{sensor_id}: handler {handler_class.__name__} failed to "
                f"configure: {type(exc).__name__}: {exc}"
            ) from exc
        return cls(sensor_id, values.topic, values.group, handler, forget_time, clock, node_name,
                   logger)  # fmt: skip

    # -- state (read-only) ------------------------------------------------------------------------
    @property
    def perception(self) -> Any:
        """The perception last written under ``sensor_id`` (None before any). Any thread."""
        return self._perception

    @property
    def delayed(self) -> bool:
        """True when the last stored message was already beyond ``forget_time``. Any thread."""
        return self._delayed

    @property
    def messages(self) -> int:
        """How many perceptions were stored (fresh or not). Any thread."""
        return self._messages

    @property
    def rejected(self) -> int:
        """How many messages were dropped (conversion, handler or NavState error). Any thread."""
        return self._rejected

    @property
    def subscription(self) -> Any:
        """The ROS subscription, None when not subscribed. Any thread."""
        return self._subscription

    # -- subscription (configuring thread) --------------------------------------------------------
    def subscribe(self, node: Any, callback: Callable[[Any], None]) -> None:
        """Subscribe ``callback`` to ``topic`` with sensor-data QoS (best effort, depth 5: a
        reliable publisher is compatible). Configuring thread.

        Raises :class:`~easynav.system.sensors.errors.SensorsConfigurationError` naming
        ``<node>.<sensor_id>.type`` when the message package is not installed.
        """
        try:
            message_class = self.handler.message_class()
        except ImportError as exc:
            raise SensorsConfigurationError(
                f"{self._node_name}.{self.sensor_id}.type = '{self.type_name}': {exc}"
            ) from exc
        self._subscription = node.create_subscription(
            message_class, self.topic, callback, _sensor_qos()
        )

    def unsubscribe(self, node: Any) -> None:
        """Destroy the subscription, if any (``node`` None: nothing to destroy). Configuring
        thread. Does not raise."""
        if self._subscription is not None and node is not None:
            node.destroy_subscription(self._subscription)
            self._subscription = None

    # -- data path (RT thread) --------------------------------------------------------------------
    def convert(self, msg: Any) -> Any:
        """The perception of ``msg`` with ``valid`` and ``new_data`` set by its age, or None when
        the message is rejected. RT thread, no lock held.

        A message already older than ``forget_time`` on arrival (or stamped more than that in the
        future) comes back invalid, with a warning: old data must not pass for current. Never
        raises: conversion errors and handler bugs become warnings naming the sensor (a faulty
        plugin must not stop the RT loop).
        """
        try:
            perception = self.handler.to_perception(msg, self.sensor_id)
            stamp = float(perception.stamp)
        except PerceptionConversionError as exc:
            self._rejected += 1
            self._warn("convert", f"message rejected: {exc}")
            return None
        except Exception as exc:  # a faulty plugin must not stop the RT loop
            self._rejected += 1
            self._warn(
                "handler",
                f"handler {type(self.handler).__name__} failed: {type(exc).__name__}: {exc}",
            )
            return None
        if isinstance(perception, PointPerception) and type(self.handler) not in _TRUSTED:
            perception = self._checked_points(perception)
            if perception is None:
                return None
        # Measured after the conversion, which may take a while for a large cloud.
        age = self._clock() - stamp
        fresh = math.isfinite(age) and -self.forget_time <= age <= self.forget_time
        if not fresh:
            if math.isfinite(age) and age < 0.0:
                why = f"stamped {-age:.3f} s in the future (clocks not synchronised?)"
            else:
                why = f"already {age:.3f} s old on arrival (delayed driver or clock?)"
            self._warn(
                "age",
                f"data {why}, beyond {self._node_name}.forget_time = {self.forget_time:g} s: "
                "not used",
            )
        perception.valid = fresh
        perception.new_data = fresh
        return perception

    def _checked_points(self, perception: PointPerception) -> PointPerception | None:
        # The PointPerception contract (no NaN/inf rows, (N, 3) float64, read-only) is kept by
        # the built-in converters; a plugin handler's output is checked here.
        try:
            points = np.asarray(perception.points, dtype=np.float64)
        except (TypeError, ValueError) as exc:  # ragged or not numbers: the callback never raises
            self._rejected += 1
            self._warn(
                "shape",
                f"handler {type(self.handler).__name__} returned points that are not an array of "
                f"numbers ({exc}): message rejected",
            )
            return None
        if points.ndim != 2 or points.shape[1] != 3:
            self._rejected += 1
            self._warn(
                "shape",
                f"handler {type(self.handler).__name__} returned points of shape {points.shape}, "
                "not (N, 3): message rejected",
            )
            return None
        finite = np.isfinite(points).all(axis=1)
        if not finite.all():
            dropped = int(points.shape[0] - np.count_nonzero(finite))
            self._warn("nan", f"dropped {dropped} points with NaN/inf coordinates")
            points = points[finite]
        if points is perception.points and points.flags.writeable:
            points = points.copy()  # read-only must not reach an array the handler keeps
        points.flags.writeable = False
        perception.points = points
        return perception

    def store(self, nav_state: NavState, perception: Any) -> bool:
        """Write ``perception`` (from :meth:`convert`) under ``sensor_id``; True when stored.
        RT thread, the manager's lock held.

        Never raises: a key that holds another type (written by someone else) is a warning and
        False.
        """
        try:
            nav_state.set(self.sensor_id, perception)
        except TypeError as exc:  # key written elsewhere with another type
            self._rejected += 1
            self._warn("navstate", f"cannot store the perception: {exc}")
            return False
        self._perception = perception
        self._messages += 1
        self._delayed = not perception.valid
        return True

    def end_new_data(self, nav_state: NavState) -> None:
        """The stored perception is not new any more (``new_data`` False). RT thread, the
        manager's lock held. Does not raise."""
        if self._perception is not None and self._perception.new_data:
            self._replace(nav_state, new_data=False)

    def expire(self, nav_state: NavState, now: float) -> bool:
        """Mark the stored perception invalid when older than ``forget_time`` at ``now``; True
        when it was valid until now. RT thread, the manager's lock held. Does not raise."""
        stored = self._perception
        if stored is not None and stored.valid and now - stored.stamp > self.forget_time:
            self._replace(nav_state, valid=False, new_data=False)
            return True
        return False

    def _replace(self, nav_state: NavState, **changes: Any) -> None:
        # NavState values are replaced, never mutated: readers may hold the old object.
        updated = dataclasses.replace(self._perception, **changes)
        nav_state.set(self.sensor_id, updated)
        self._perception = updated

    # -- status and cleanup -----------------------------------------------------------------------
    def status(self, now: float) -> str:
        """``"no_data"`` before any perception, ``"stale"`` when invalid or older than
        ``forget_time`` at ``now`` (also before the RT cycle expires it), else ``"ok"``. Any
        thread. Does not raise."""
        stored = self._perception
        if stored is None:
            return "no_data"
        if not stored.valid or now - stored.stamp > self.forget_time:
            return "stale"
        return "ok"

    def erase(self, nav_state: NavState) -> None:
        """Erase the key this channel wrote, if any: a sensor removed from the configuration
        would otherwise leave a valid perception that nobody expires. Configuring thread."""
        if self._perception is not None:
            nav_state.erase(self.sensor_id)

    def _warn(self, kind: str, text: str) -> None:
        self._throttle.warn(self._logger, kind, f"Sensor '{self.sensor_id}': {text}")


def _sensor_qos() -> Any:
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=SENSOR_QUEUE_DEPTH,
        reliability=ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.VOLATILE,
    )
