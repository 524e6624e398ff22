"""SensorsManager: the logic of sensors_node (subscriptions, data age; diagnostics and fused
cloud through their own objects)."""

from __future__ import annotations

import dataclasses
import logging
import math
import threading
from collections.abc import Callable
from typing import Any

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins.declarations import ParameterValueError, read_parameters
from easynav.core.sensors.point_perception import PointPerception
from easynav.core.sensors.point_perceptions_ops import PointPerceptionsOps
from easynav.core.sensors.warning_throttle import WarningThrottle
from easynav.core.tf import TFBuffer, get_tf_buffer
from easynav.system.sensors.errors import PerceptionConversionError, SensorsConfigurationError
from easynav.system.sensors.fused_cloud_publisher import FusedCloudPublisher
from easynav.system.sensors.handler_registry import resolve_handler
from easynav.system.sensors.handlers import LaserScanHandler, PointCloud2Handler
from easynav.system.sensors.sensor_parameters import (
    FORGET_TIME,
    SENSOR_IDS,
    SENSOR_PARAMETERS,
)
from easynav.system.sensors.sensor_state import SensorState
from easynav.system.sensors.sensors_diagnostics import SensorsDiagnostics

SENSOR_QUEUE_DEPTH = 5
# Handlers whose point output already keeps the PointPerception contract (and is measured).
_TRUSTED = (LaserScanHandler, PointCloud2Handler)


class SensorsManager:
    """Turns the configured sensor topics into perceptions in NavState (one key per sensor).

    ``configure`` reads ``forget_time`` and ``sensors`` (each with ``topic``, ``type``, optional
    ``group`` and ``plugin``) and subscribes with sensor-data QoS (best effort, depth 5: a
    reliable publisher is compatible). Each message is converted by the sensor's
    :class:`~easynav.system.sensors.perception_handler.PerceptionHandler` and stored under the
    sensor id; a sensor with a ``group`` is put in that group, which hides it from
    ``NavState.get_no_group``. Data age (old data must not pass for current): every RT
    cycle a perception older than ``forget_time`` is replaced by a copy with ``valid`` False;
    a message arriving already older than that (or stamped more than ``forget_time`` in the
    future) is stored invalid and never used. ``new_data`` is True on a perception during the
    RT cycle after it arrived and False afterwards.

    Thread contract: ``configure``/``cleanup`` in the configuring thread with no loop running;
    the subscription callbacks (:meth:`handle_message`) and :meth:`cycle_rt` in the RT thread;
    :meth:`cycle` in the non-RT thread; :meth:`has_new_data` from any thread. Shared state is
    under one lock, so callbacks spun by another executor are safe too.

    Exceptions: ``configure`` raises
    :class:`~easynav.system.sensors.errors.SensorsConfigurationError` naming the parameter
    (``sensors_node.forget_time``, ``sensors_node.<id>.type``...). Nothing else raises: a bad
    message is a warning naming the sensor.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._sensors: dict[str, SensorState] = {}
        self._node: Any = None
        self._nav_state: NavState | None = None
        self._node_name = "sensors_node"
        self._forget_time = 1.0
        self._clock: Callable[[], float] = _no_clock
        self._tf_buffer: TFBuffer | None = None
        self._logger: Any = logging.getLogger("easynav.sensors")
        self._throttle = WarningThrottle(period=5.0)
        self._pending_new: set[str] = set()
        self._flagged_new: set[str] = set()
        self._cloud = FusedCloudPublisher()
        self._diagnostics = SensorsDiagnostics()

    # -- lifecycle ------------------------------------------------------------------------------
    def configure(
        self,
        params: Any,
        node: Any,
        nav_state: NavState,
        clock: Callable[[], float] | None = None,
        tf_buffer: TFBuffer | None = None,
    ) -> None:
        """Read the parameters, choose the handlers and subscribe on ``node``.

        ``params`` is a :class:`~easynav.core.plugins.ParameterAccess` of sensors_node (names
        without the node prefix). ``node`` None (tests, tools) subscribes and publishes nothing;
        feed messages with :meth:`handle_message`. ``clock`` returns ROS time in seconds
        (default: ``node``'s clock, simulated with ``use_sim_time``). ``tf_buffer`` defaults to
        :func:`~easynav.core.tf.get_tf_buffer` of ``node``'s namespace (as system_node's).
        """
        self.cleanup()
        self._node = node
        self._nav_state = nav_state
        self._node_name = node.get_name() if node is not None else "sensors_node"
        if node is not None:
            self._logger = node.get_logger()
        if clock is not None:
            self._clock = clock
        elif node is not None:
            ros_clock = node.get_clock()
            self._clock = lambda: ros_clock.now().nanoseconds * 1e-9
        else:
            raise SensorsConfigurationError("SensorsManager.configure needs a node or a clock")
        if tf_buffer is None:
            tf_buffer = get_tf_buffer(node.get_namespace()) if node is not None else get_tf_buffer()
        self._tf_buffer = tf_buffer
        self._forget_time = self._read_forget_time(params)
        sensor_ids = self._read_sensor_ids(params)
        try:
            for sensor_id in sensor_ids:
                state = self._configure_sensor(params, sensor_id)
                self._sensors[sensor_id] = state
            for state in self._sensors.values():
                if state.group:
                    nav_state.add_to_group(state.group, state.sensor_id)
            if node is not None:
                self._subscribe_all()
                self._cloud.create(node)
        except Exception:
            self.cleanup()
            raise

    def _parameter(self, name: str) -> str:
        return f"{self._node_name}.{name}"

    def _read(self, declarations: Any, params: Any, prefix: str = "") -> Any:
        try:
            return read_parameters(declarations, params, prefix, warn=self._logger.warning)
        except ParameterValueError as exc:
            raise SensorsConfigurationError(f"{self._node_name}.{exc}") from None

    def _read_forget_time(self, params: Any) -> float:
        return self._read((FORGET_TIME,), params).forget_time

    def _read_sensor_ids(self, params: Any) -> list[str]:
        ids = list(self._read((SENSOR_IDS,), params).sensors or [])
        if not all(ids):
            raise SensorsConfigurationError(
                f"{self._parameter('sensors')} = {ids!r} must be a list of non-empty strings"
            )
        duplicated = sorted({v for v in ids if ids.count(v) > 1})
        if duplicated:
            raise SensorsConfigurationError(
                f"{self._parameter('sensors')} lists {', '.join(duplicated)} more than once"
            )
        return ids

    def _configure_sensor(self, params: Any, sensor_id: str) -> SensorState:
        values = self._read(SENSOR_PARAMETERS, params, sensor_id)
        topic, type_name = values.topic, values.type
        group, plugin = values.group, values.plugin
        if not topic:
            raise SensorsConfigurationError(
                f"{self._parameter(f'{sensor_id}.topic')} is not set: the topic of sensor "
                f"'{sensor_id}'"
            )
        handler_class = resolve_handler(
            sensor_id, type_name, plugin, self._node_name, warn=self._logger.warning
        )
        handler = handler_class()
        handler.logger = self._logger
        try:
            handler.configure(sensor_id, params, self._node)
        except SensorsConfigurationError:
            raise
        except Exception as exc:
            raise SensorsConfigurationError(
                f"{self._parameter(sensor_id)}: handler {handler_class.__name__} failed to "
                f"configure: {type(exc).__name__}: {exc}"
            ) from exc
        return SensorState(
            sensor_id=sensor_id,
            topic=topic,
            type_name=handler_class.ros_message_type,
            group=group,
            handler=handler,
        )

    def _subscribe_all(self) -> None:
        for state in self._sensors.values():
            try:
                message_class = state.handler.message_class()
            except ImportError as exc:
                raise SensorsConfigurationError(
                    f"{self._parameter(f'{state.sensor_id}.type')} = '{state.type_name}': {exc}"
                ) from exc
            state.subscription = self._node.create_subscription(
                message_class,
                state.topic,
                _make_callback(self, state.sensor_id),
                _sensor_qos(),
            )

    def cleanup(self) -> None:
        """Destroy subscriptions and the publisher; erase this manager's keys from NavState.

        Erasing matters: a sensor removed from the configuration would otherwise leave a valid
        perception behind that nobody expires. Group memberships it added are removed too.
        """
        node, nav_state = self._node, self._nav_state
        with self._lock:
            sensors = list(self._sensors.values())
            self._sensors = {}
            self._pending_new.clear()
            self._flagged_new.clear()
        for state in sensors:
            if state.subscription is not None and node is not None:
                node.destroy_subscription(state.subscription)
                state.subscription = None
        self._cloud.destroy(node)
        if nav_state is not None:
            ours = {s.sensor_id for s in sensors}
            for group, members in nav_state.groups().items():
                if ours & set(members):
                    nav_state.set_group(group, [m for m in members if m not in ours])
            for state in sensors:
                if state.stored is not None:
                    nav_state.erase(state.sensor_id)
        self._diagnostics.reset()
        self._throttle.reset()

    # -- data path (RT thread) --------------------------------------------------------------------
    def handle_message(self, sensor_id: str, msg: Any) -> None:
        """Convert and store one message of ``sensor_id`` (the subscription callback). RT thread.

        Never raises: conversion errors and handler bugs become warnings naming the sensor.
        """
        with self._lock:
            state = self._sensors.get(sensor_id)
        if state is None or self._nav_state is None:
            return
        try:
            perception = state.handler.to_perception(msg, sensor_id)
            stamp = float(perception.stamp)
        except PerceptionConversionError as exc:
            state.rejected += 1
            self._warn(sensor_id, "convert", f"message rejected: {exc}")
            return
        except Exception as exc:  # a faulty plugin must not stop the RT loop
            state.rejected += 1
            self._warn(
                sensor_id,
                "handler",
                f"handler {type(state.handler).__name__} failed: {type(exc).__name__}: {exc}",
            )
            return
        if isinstance(perception, PointPerception) and type(state.handler) not in _TRUSTED:
            perception = self._checked_points(sensor_id, state, perception)
            if perception is None:
                return
        now = self._clock()
        age = now - stamp
        fresh = math.isfinite(age) and -self._forget_time <= age <= self._forget_time
        if not fresh:
            if math.isfinite(age) and age < 0.0:
                why = f"stamped {-age:.3f} s in the future (clocks not synchronised?)"
            else:
                why = f"already {age:.3f} s old on arrival (delayed driver or clock?)"
            self._warn(
                sensor_id,
                "age",
                f"data {why}, beyond {self._parameter('forget_time')} = {self._forget_time:g} s: "
                "not used",
            )
        perception.valid = fresh
        perception.new_data = fresh
        with self._lock:
            if self._sensors.get(sensor_id) is not state:
                return  # reconfigured meanwhile
            try:
                self._nav_state.set(sensor_id, perception)
            except TypeError as exc:  # key written elsewhere with another type
                state.rejected += 1
                self._warn(sensor_id, "navstate", f"cannot store the perception: {exc}")
                return
            state.stored = perception
            state.messages += 1
            state.delayed = not fresh
            if fresh:
                self._pending_new.add(sensor_id)
                if isinstance(perception, PointPerception):
                    self._cloud.points_changed()

    def _checked_points(
        self, sensor_id: str, state: SensorState, perception: PointPerception
    ) -> PointPerception | None:
        # The PointPerception contract (no NaN/inf rows, (N, 3) float64, read-only) is kept by
        # the built-in converters; a plugin handler's output is checked here.
        points = np.asarray(perception.points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 3:
            state.rejected += 1
            self._warn(
                sensor_id,
                "shape",
                f"handler {type(state.handler).__name__} returned points of shape {points.shape}, "
                "not (N, 3): message rejected",
            )
            return None
        finite = np.isfinite(points).all(axis=1)
        if not finite.all():
            dropped = int(points.shape[0] - np.count_nonzero(finite))
            self._warn(sensor_id, "nan", f"dropped {dropped} points with NaN/inf coordinates")
            points = points[finite]
        if points is perception.points and points.flags.writeable:
            points = points.copy()
        points.flags.writeable = False
        perception.points = points
        return perception

    def has_new_data(self) -> bool:
        """True when fresh data arrived that :meth:`cycle_rt` has not reported yet. Any thread."""
        return bool(self._pending_new)

    def cycle_rt(self, now: float) -> bool:
        """Expire old perceptions; True when fresh data arrived since the last call. RT thread."""
        nav_state = self._nav_state
        if nav_state is None:
            return False
        forget_time = self._forget_time
        with self._lock:
            arrived = self._pending_new
            self._pending_new = set()
            # Perceptions reported as new in the previous cycle are not new any more.
            for sensor_id in self._flagged_new - arrived:
                state = self._sensors.get(sensor_id)
                if state is not None and state.stored is not None and state.stored.new_data:
                    self._replace(state, new_data=False)
            self._flagged_new = arrived
            for state in self._sensors.values():
                stored = state.stored
                if stored is not None and stored.valid and now - stored.stamp > forget_time:
                    self._replace(state, valid=False, new_data=False)
                    if isinstance(stored, PointPerception):
                        self._cloud.points_changed()
        return bool(arrived)

    def _replace(self, state: SensorState, **changes: Any) -> None:
        # NavState values are replaced, never mutated: readers may hold the old object.
        updated = dataclasses.replace(state.stored, **changes)
        self._nav_state.set(state.sensor_id, updated)
        state.stored = updated

    # -- non-RT -----------------------------------------------------------------------------------
    def cycle(self, now: float) -> None:
        """Diagnostics (on changes) and the fused cloud (while subscribed). Non-RT thread."""
        if self._nav_state is None:
            return
        self._diagnostics.update(self._nav_state, self.sensor_status(now), self._forget_time)
        # Looked up at each call, not bound once: tests and tools may wrap fused_points.
        self._cloud.publish(self.fused_points)

    def sensor_status(self, now: float) -> dict[str, str]:
        """``{sensor_id: "ok" | "no_data" | "stale"}`` at ``now``. Any thread."""
        with self._lock:
            states = list(self._sensors.values())
        status = {}
        for state in states:
            stored = state.stored
            if stored is None:
                status[state.sensor_id] = "no_data"
            elif not stored.valid or now - stored.stamp > self._forget_time:
                status[state.sensor_id] = "stale"
            else:
                status[state.sensor_id] = "ok"
        return status

    def fused_points(self) -> tuple[Any, str, float | None]:
        """``(points, frame, stamp)``: the valid ungrouped point perceptions of this manager,
        fused into ``robot_footprint_frame`` (what the navigation sees). Non-RT thread."""
        buffer = self._tf_buffer if self._tf_buffer is not None else get_tf_buffer()
        frame = buffer.get_tf_info().robot_footprint_frame
        with self._lock:
            perceptions = {
                s.sensor_id: s.stored
                for s in self._sensors.values()
                if isinstance(s.stored, PointPerception) and not s.group
            }
        ops = PointPerceptionsOps(perceptions, tf_buffer=buffer, logger=self._logger).fuse(frame)
        return ops.as_points(), frame, ops.stamp

    # -- introspection ----------------------------------------------------------------------------
    @property
    def forget_time(self) -> float:
        """The configured ``forget_time`` (s)."""
        return self._forget_time

    @property
    def sensor_ids(self) -> list[str]:
        """The configured sensor ids, in configuration order."""
        with self._lock:
            return list(self._sensors)

    def handler(self, sensor_id: str) -> Any:
        """The handler object of a sensor (KeyError naming it when unknown)."""
        with self._lock:
            state = self._sensors.get(sensor_id)
        if state is None:
            raise KeyError(f"sensor '{sensor_id}' is not configured")
        return state.handler

    def _warn(self, sensor_id: str, kind: str, text: str) -> None:
        self._throttle.warn(self._logger, (sensor_id, kind), f"Sensor '{sensor_id}': {text}")


def _no_clock() -> float:
    raise RuntimeError("SensorsManager used before configure()")


def _make_callback(manager: SensorsManager, sensor_id: str) -> Callable[[Any], None]:
    def callback(msg: Any) -> None:
        manager.handle_message(sensor_id, msg)

    return callback


def _sensor_qos() -> Any:
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=SENSOR_QUEUE_DEPTH,
        reliability=ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.VOLATILE,
    )
