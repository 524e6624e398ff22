"""FaultyLocalizer (easynav_localizer/FaultyLocalizer): a fixed pose that goes wrong."""

from __future__ import annotations

import math

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import ROBOT_POSE
from easynav.core.plugins import LocalizerMethodBase, Param
from easynav.core.types import Header, Odometry, Pose
from easynav.faulty.fault_injector import FaultInjector


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

    Parameters: :attr:`PARAMETERS`.

    Thread contract: ``initialize`` in the configuring thread; ``update_rt`` in the RT thread,
    ``update`` in the non-RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter; ``update_rt`` raises
    :class:`InjectedFaultError` with the ``throw`` fault.
    """

    FAULTS = ("throw", "hang", "freeze", "stop_publishing", "nan", "jump")
    PARAMETERS = (
        Param("x", 0.0, "the fixed pose: x", "m"),
        Param("y", 0.0, "the fixed pose: y", "m"),
        Param("yaw", 0.0, "the fixed pose: yaw", "rad"),
        Param("jump_distance", 1.0, "how far the jump fault moves the pose", "m"),
        *FaultInjector.parameters(FAULTS),
    )
    WRITES = (ROBOT_POSE,)

    def __init__(self) -> None:
        super().__init__()
        self.injector = FaultInjector(self, self.FAULTS)
        self.x = 0.0
        self.y = 0.0
        self.yaw = 0.0
        self.jump_distance = 1.0
        self.last_stamp: float | None = None

    def on_initialize(self) -> None:
        self.on_parameter_changed("", None)
        self.injector.read_parameters()
        self.last_stamp = None

    def on_parameter_changed(self, name: str, value: object) -> None:
        """The pose and jump distance apply from the next update."""
        p = self.params
        self.x, self.y, self.yaw, self.jump_distance = p.x, p.y, p.yaw, p.jump_distance

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
            ROBOT_POSE,
            Odometry(
                header=Header(stamp, tf_info.map_frame),
                child_frame_id=tf_info.robot_footprint_frame,
                pose=Pose.from_xy_yaw(x, y, self.yaw),
            ),
        )

    def update(self, nav_state: NavState) -> None:
        """Nothing to correct: the pose is fixed. Non-RT thread."""
