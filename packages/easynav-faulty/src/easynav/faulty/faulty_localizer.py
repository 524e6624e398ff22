"""FaultyLocalizer (easynav_localizer/FaultyLocalizer): a fixed pose that goes wrong."""

from __future__ import annotations

import math

from easynav.core.nav_state import NavState
from easynav.core.plugins import LocalizerMethodBase
from easynav.core.tf import get_tf_buffer
from easynav.core.types import Header, Odometry, Pose
from easynav.faulty.fault_injector import FaultInjector
from easynav.faulty.parameters import finite_parameter


class FaultyLocalizer(LocalizerMethodBase):
    """Works as a localizer that always finds the robot at ``(x, y, yaw)``, then injects a fault.

    Normal ``update_rt``: writes NavState ``robot_pose`` = :class:`Odometry` (pose ``(x, y,
    yaw)`` in the map frame, child the robot footprint frame, zero twist and covariances)
    stamped with the node clock. ``update`` (non-RT) does nothing: a fixed pose needs no
    correction. It broadcasts no TF and ignores ``on_last_known_pose`` and ``initialpose``: the
    pose is fixed by its parameters.

    Faults (``<alias>.fault``, counted in ``update_rt`` calls, see :class:`FaultInjector`):

    =================== =========================================================================
    ``throw``           ``update_rt`` raises :class:`InjectedFaultError`
    ``hang``            ``update_rt`` blocks ``hang_time`` s, then works normally
    ``freeze``          writes the pose with the stamp of the last normal update (it gets older)
    ``stop_publishing`` writes nothing: ``robot_pose`` keeps the last pose, which gets older
    ``nan``             writes a pose whose ``x`` and ``y`` are NaN, stamped now
    ``jump``            writes the pose moved ``jump_distance`` m ahead (along ``yaw``), stamped
                        now: a finite, fresh but wrong pose
    =================== =========================================================================

    Parameters (``<alias>.``): ``x``, ``y`` (m, 0.0), ``yaw`` (rad, 0.0), ``jump_distance``
    (m, 1.0), ``fault`` ("none"), ``fault_after`` (10), ``hang_time`` (s, 1.0).

    Thread contract: ``initialize`` in the configuring thread; ``update_rt`` in the RT thread,
    ``update`` in the non-RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter; ``update_rt`` raises
    :class:`InjectedFaultError` with the ``throw`` fault.
    """

    FAULTS = ("throw", "hang", "freeze", "stop_publishing", "nan", "jump")

    def __init__(self) -> None:
        super().__init__()
        self.injector = FaultInjector(self, self.FAULTS)
        self.x = 0.0
        self.y = 0.0
        self.yaw = 0.0
        self.jump_distance = 1.0
        self.last_stamp: float | None = None

    def on_initialize(self) -> None:
        self.x = finite_parameter(self, "x", 0.0, "m, the fixed pose")
        self.y = finite_parameter(self, "y", 0.0, "m, the fixed pose")
        self.yaw = finite_parameter(self, "yaw", 0.0, "rad, the fixed pose")
        self.jump_distance = finite_parameter(
            self, "jump_distance", 1.0, "m, how far the jump fault moves the pose"
        )
        self.injector.read_parameters()
        self.last_stamp = None

    def update_rt(self, nav_state: NavState) -> None:
        fault = self.injector.update()
        if fault == "throw":
            self.injector.throw("update_rt")
        if fault == "hang":
            self.injector.hang()
        if fault == "stop_publishing":
            return
        now = self.now()
        x, y, stamp = self.x, self.y, now
        if fault == "freeze":
            if self.last_stamp is None:
                self.last_stamp = now  # frozen from the first update (fault_after 0)
            stamp = self.last_stamp
        elif fault == "nan":
            x = y = math.nan
        elif fault == "jump":
            x += self.jump_distance * math.cos(self.yaw)
            y += self.jump_distance * math.sin(self.yaw)
        else:
            self.last_stamp = now
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        nav_state.set(
            "robot_pose",
            Odometry(
                header=Header(stamp, tf_info.map_frame),
                child_frame_id=tf_info.robot_footprint_frame,
                pose=Pose.from_xy_yaw(x, y, self.yaw),
            ),
        )

    def update(self, nav_state: NavState) -> None:
        """Nothing to correct: the pose is fixed. Non-RT thread."""
