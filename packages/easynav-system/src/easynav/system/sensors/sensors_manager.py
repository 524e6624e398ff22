"""SensorsManager: the logic of sensors_node, over one SensorChannel per configured sensor."""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

from easynav.common.sensors.point_perception import PointPerception
from easynav.common.sensors.point_perceptions_ops import PointPerceptionsOps
from easynav.common.tf import TFBuffer, get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.system.sensors.errors import SensorsConfigurationError
from easynav.system.sensors.fused_cloud_publisher import FusedCloudPublisher
from easynav.system.sensors.sensor_channel import SensorChannel
from easynav.system.sensors.sensor_parameters import FORGET_TIME, SENSOR_IDS, read_sensor_parameters
from easynav.system.sensors.sensors_diagnostics import SensorsDiagnostics


class SensorsManager:
    """Turns the configured sensor topics into perceptions in NavState (one key per sensor).

    ``configure`` reads ``forget_time`` and ``sensors`` and makes one
    :class:`~easynav.system.sensors.sensor_channel.SensorChannel` per sensor (its ``topic``,
    ``type``, optional ``group`` and ``plugin``, its handler and subscription). Each message is
    converted by the channel and stored under the sensor id; a sensor with a ``group`` is put in
    that group, which hides it from ``NavState.get_no_group``. Data age (old data must not pass
    for current): every RT cycle a perception older than ``forget_time`` is replaced by a copy
    with ``valid`` False; a message arriving already older than that (or stamped more than
    ``forget_time`` in the future) is stored invalid and never used. ``new_data`` is True on a
    perception during the RT cycle after it arrived and False afterwards. The non-RT cycle
    writes the diagnostic (:class:`~.sensors_diagnostics.SensorsDiagnostics`) and publishes the
    fused cloud (:class:`~.fused_cloud_publisher.FusedCloudPublisher`).

    Thread contract: ``configure``/``cleanup`` in the configuring thread with no loop running;
    the subscription callbacks (:meth:`handle_message`) and :meth:`cycle_rt` in the RT thread;
    :meth:`cycle` in the non-RT thread; :meth:`has_new_data` from any thread. Shared state (the
    channels, the new-data sets, each channel's stored perception) is under one lock, so
    callbacks spun by another executor are safe too.

    Exceptions: ``configure`` raises
    :class:`~easynav.system.sensors.errors.SensorsConfigurationError` naming the parameter
    (``sensors_node.forget_time``, ``sensors_node.<id>.type``...). Nothing else raises: a bad
    message is a warning naming the sensor.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._channels: dict[str, SensorChannel] = {}
        self._node: Any = None
        self._nav_state: NavState | None = None
        self._node_name = "sensors_node"
        self._forget_time = 1.0
        self._clock: Callable[[], float] = _no_clock
        self._tf_buffer: TFBuffer | None = None
        self._logger: Any = logging.getLogger("easynav.sensors")
        # Sensor ids with fresh data not yet reported by cycle_rt, and those reported by the
        # last cycle_rt (whose new_data turns False at the next one).
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
        """Read the parameters, make the channels and subscribe on ``node``. Configuring thread.

        ``params`` is a :class:`~easynav.core.plugins.ParameterAccess` of sensors_node (names
        without the node prefix). ``node`` None (tests, tools) subscribes and publishes nothing;
        feed messages with :meth:`handle_message`. ``clock`` returns ROS time in seconds
        (default: ``node``'s clock, simulated with ``use_sim_time``). ``tf_buffer`` defaults to
        :func:`~easynav.common.tf.get_tf_buffer` of ``node``'s namespace (as system_node's).
        Raises :class:`~easynav.system.sensors.errors.SensorsConfigurationError` naming the
        parameter, after undoing what was done (no subscription or key left behind).
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
            # Every sensor's parameters are checked before anything is subscribed.
            for sensor_id in sensor_ids:
                self._channels[sensor_id] = SensorChannel.from_parameters(
                    params, sensor_id, node, self._forget_time, self._clock, self._node_name,
                    self._logger,
                )  # fmt: skip
            for channel in self._channels.values():
                if channel.group:  # hidden from get_no_group before its first message too
                    nav_state.add_to_group(channel.group, channel.sensor_id)
            if node is not None:
                for channel in self._channels.values():
                    channel.subscribe(node, _make_callback(self, channel.sensor_id))
                self._cloud.create(node)
        except Exception:
            self.cleanup()
            raise

    def _read_forget_time(self, params: Any) -> float:
        return read_sensor_parameters(
            (FORGET_TIME,), params, self._node_name, warn=self._logger.warning
        ).forget_time

    def _read_sensor_ids(self, params: Any) -> list[str]:
        values = read_sensor_parameters(
            (SENSOR_IDS,), params, self._node_name, warn=self._logger.warning
        )
        ids = list(values.sensors or [])
        parameter = f"{self._node_name}.sensors"
        if not all(ids):
            raise SensorsConfigurationError(
                f"{parameter} = {ids!r} must be a list of non-empty strings"
            )
        duplicated = sorted({v for v in ids if ids.count(v) > 1})
        if duplicated:
            raise SensorsConfigurationError(
                f"{parameter} lists {', '.join(duplicated)} more than once"
            )
        return ids

    def cleanup(self) -> None:
        """Destroy subscriptions and the publisher; erase this manager's keys from NavState.
        Configuring thread, no loop running. Does not raise.

        Erasing matters: a sensor removed from the configuration would otherwise leave a valid
        perception behind that nobody expires. Group memberships it added are removed too.
        """
        node, nav_state = self._node, self._nav_state
        with self._lock:
            channels = list(self._channels.values())
            self._channels = {}  # a late callback finds no channel and is ignored
            self._pending_new.clear()
            self._flagged_new.clear()
        for channel in channels:
            channel.unsubscribe(node)
        self._cloud.destroy(node)
        if nav_state is not None:
            ours = {c.sensor_id for c in channels}
            for group, members in nav_state.groups().items():
                if ours & set(members):
                    nav_state.set_group(group, [m for m in members if m not in ours])
            for channel in channels:
                channel.erase(nav_state)
        self._diagnostics.reset()

    # -- data path (RT thread) --------------------------------------------------------------------
    def handle_message(self, sensor_id: str, msg: Any) -> None:
        """Convert and store one message of ``sensor_id`` (the subscription callback). RT thread.

        Never raises: conversion errors and handler bugs become warnings naming the sensor; a
        message of an unknown (or no longer configured) sensor is ignored.
        """
        with self._lock:
            channel = self._channels.get(sensor_id)
        nav_state = self._nav_state
        if channel is None or nav_state is None:
            return
        perception = channel.convert(msg)  # outside the lock: the slow part
        if perception is None:
            return
        with self._lock:
            if self._channels.get(sensor_id) is not channel:
                return  # reconfigured meanwhile
            if not channel.store(nav_state, perception):
                return
            if perception.valid:  # old data must not trigger the RT cycle
                self._pending_new.add(sensor_id)
                if isinstance(perception, PointPerception):
                    self._cloud.points_changed()

    def has_new_data(self) -> bool:
        """True when fresh data arrived that :meth:`cycle_rt` has not reported yet. Any thread."""
        return bool(self._pending_new)

    def cycle_rt(self, now: float) -> bool:
        """Expire old perceptions; True when fresh data arrived since the last call. RT thread.
        Does not raise."""
        nav_state = self._nav_state
        if nav_state is None:
            return False
        with self._lock:
            arrived = self._pending_new
            self._pending_new = set()
            # Perceptions reported as new in the previous cycle are not new any more.
            for sensor_id in self._flagged_new - arrived:
                channel = self._channels.get(sensor_id)
                if channel is not None:
                    channel.end_new_data(nav_state)
            self._flagged_new = arrived
            for channel in self._channels.values():
                if channel.expire(nav_state, now) and isinstance(
                    channel.perception, PointPerception
                ):
                    self._cloud.points_changed()
        return bool(arrived)

    # -- non-RT -----------------------------------------------------------------------------------
    def cycle(self, now: float) -> None:
        """Diagnostics (on changes) and the fused cloud (while subscribed). Non-RT thread.
        A sensor without a transform to the footprint frame is left out of the cloud with a
        warning, not raised."""
        if self._nav_state is None:
            return
        self._diagnostics.update(self._nav_state, self.sensor_status(now), self._forget_time)
        # Looked up at each call, not bound once: tests and tools may wrap fused_points.
        self._cloud.publish(self.fused_points)

    def sensor_status(self, now: float) -> dict[str, str]:
        """``{sensor_id: "ok" | "no_data" | "stale"}`` at ``now``, in configuration order. Any
        thread. Does not raise."""
        with self._lock:
            channels = list(self._channels.values())
        return {c.sensor_id: c.status(now) for c in channels}

    def fused_points(self) -> tuple[Any, str, float | None]:
        """``(points, frame, stamp)``: the valid ungrouped point perceptions of this manager,
        fused into ``robot_footprint_frame`` (what the navigation sees). Non-RT thread."""
        buffer = self._tf_buffer if self._tf_buffer is not None else get_tf_buffer()
        frame = buffer.get_tf_info().robot_footprint_frame
        with self._lock:
            perceptions = {
                c.sensor_id: c.perception
                for c in self._channels.values()
                if isinstance(c.perception, PointPerception) and not c.group
            }
        ops = PointPerceptionsOps(perceptions, tf_buffer=buffer, logger=self._logger).fuse(frame)
        return ops.as_points(), frame, ops.stamp

    # -- introspection ----------------------------------------------------------------------------
    @property
    def forget_time(self) -> float:
        """The configured ``forget_time`` (s). Any thread."""
        return self._forget_time

    @property
    def sensor_ids(self) -> list[str]:
        """The configured sensor ids, in configuration order. Any thread."""
        with self._lock:
            return list(self._channels)

    def channel(self, sensor_id: str) -> SensorChannel:
        """The channel of a sensor (KeyError naming it when unknown). Any thread."""
        with self._lock:
            channel = self._channels.get(sensor_id)
        if channel is None:
            raise KeyError(f"sensor '{sensor_id}' is not configured")
        return channel

    def handler(self, sensor_id: str) -> Any:
        """The handler object of a sensor (KeyError naming it when unknown). Any thread."""
        return self.channel(sensor_id).handler


def _no_clock() -> float:
    raise RuntimeError("SensorsManager used before configure()")


def _make_callback(manager: SensorsManager, sensor_id: str) -> Callable[[Any], None]:
    # Through the manager, not the channel: after a reconfigure the callback must find no
    # channel (or the new one), never store into NavState for a channel that was dropped.
    def callback(msg: Any) -> None:
        manager.handle_message(sensor_id, msg)

    return callback
