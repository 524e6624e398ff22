"""The catalogue: which distribution of this project provides each known plugin name.

Used to tell a user which package to install when a params file names a plugin that is not
installed. Installed plugins are found through entry points, never through this table.
"""

from __future__ import annotations

CATALOGUE: dict[str, str] = {
    # Dummy and fault-injection plugins
    "easynav_controller/DummyController": "easynav-core",
    "easynav_localizer/DummyLocalizer": "easynav-core",
    "easynav_planner/DummyPlanner": "easynav-core",
    "easynav_maps_manager/DummyMapsManager": "easynav-core",
    "easynav_recovery/DummyRecoveryManager": "easynav-core",
    "easynav_controller/FaultyController": "easynav-faulty",
    "easynav_localizer/FaultyLocalizer": "easynav-faulty",
    "easynav_planner/FaultyPlanner": "easynav-faulty",
    "easynav_maps_manager/FaultyMapsManager": "easynav-faulty",
    # Simple stack
    "easynav_simple_maps_manager/SimpleMapsManager": "easynav-maps",
    "easynav_simple_localizer/AMCLLocalizer": "easynav-localizers",
    "easynav_simple_planner/SimplePlanner": "easynav-planners",
    "easynav_simple_controller/SimpleController": "easynav-controllers",
    # Recovery systems
    "easynav_simple_recovery/SimpleRecoveryManager": "easynav-recovery",
    "easynav_diagnostic_recovery/DiagnosticRecoveryManager": "easynav-recovery",
    # Sub-plugins of the diagnostic recovery manager (their own entry-point groups)
    "easynav_collision_safety_reflex/CollisionSafetyReflex": "easynav-recovery",
    "easynav_no_path_evaluator/NoPathEvaluator": "easynav-recovery",
    "easynav_controller_stuck_evaluator/ControllerStuckEvaluator": "easynav-recovery",
    "easynav_obstacle_too_close_evaluator/ObstacleTooCloseEvaluator": "easynav-recovery",
    "easynav_safety_channel_evaluator/SafetyChannelEvaluator": "easynav-recovery",
    "easynav_costmap_localizer/AmclConvergenceEvaluator": "easynav-recovery",
    "easynav_advance_recovery/AdvanceRecovery": "easynav-recovery",
    "easynav_cancel_mission_recovery/CancelMissionRecovery": "easynav-recovery",
    "easynav_costmap_localizer/AmclRelocalizeMitigation": "easynav-recovery",
    "easynav_human_assistance_recovery/HumanAssistanceRecovery": "easynav-recovery",
    "easynav_safe_retreat_recovery/SafeRetreatRecovery": "easynav-recovery",
    "easynav_shutdown_recovery/ShutdownRecovery": "easynav-recovery",
    # Costmap stack and others (catalogued so the error names the package once they exist)
    "easynav_costmap_maps_manager/CostmapMapsManager": "easynav-maps",
    "easynav_costmap_localizer/AMCLLocalizer": "easynav-localizers",
    "easynav_costmap_planner/CostmapPlanner": "easynav-planners",
    "easynav_regulated_pp_controller/RegulatedPurePursuitController": "easynav-controllers",
    "easynav_mppi_controller/MPPIController": "easynav-controllers",
    "easynav_vff_controller/VffController": "easynav-controllers",
    "easynav_octomap_maps_manager/OctomapMapsManager": "easynav-maps",
    "easynav_bonxai_maps_manager/BonxaiMapsManager": "easynav-maps",
    "easynav_fusion_localizer/FusionLocalizer": "easynav-localizers",
    "easynav_costmap_maps_manager/CostmapMapsManager/ObstaclesFilter": "easynav-maps",
    "easynav_costmap_maps_manager/CostmapMapsManager/InflationFilter": "easynav-maps",
    "easynav_costmap_maps_manager/CostmapMapsManager/KeepoutFilter": "easynav-maps",
    "easynav_costmap_maps_manager/CostmapMapsManager/SpeedFilter": "easynav-maps",
    "easynav_mpc_controller/MPCController": "easynav-controllers",
    "easynav_serest_controller/SerestController": "easynav-controllers",
    "easynav_mhamcl_localizer/MHAMCLLocalizer": "easynav-localizers",
    "easynav_gps_localizer/GpsLocalizer": "easynav-localizers",
    "easynav_gtsam_localizer/GtsamLocalizer": "easynav-localizers",
    "easynav_ompl_planner/OMPLPlanner": "easynav-planners",
    # Routes
    "easynav_routes_maps_manager/RoutesMapsManager": "easynav-maps",
    "easynav_routes_maps_manager/RoutesCostmapFilter": "easynav-maps",
    # Elevation maps
    "easynav_gridmap_maps_manager/GridmapMapsManager": "easynav-maps",
    "easynav_gridmap_astar_planner/GridMapAStarPlanner": "easynav-planners",
    "easynav_gridmap_rrtstar_planner/GridMapRRTStarPlanner": "easynav-planners",
    # NavMap stack
    "easynav_navmap_maps_manager/NavMapMapsManager": "easynav-maps",
    "easynav_navmap_maps_manager/NavMapMapsManager/ObstaclesFilter": "easynav-maps",
    "easynav_navmap_maps_manager/NavMapMapsManager/InflationFilter": "easynav-maps",
    "easynav_navmap_planner/AStarPlanner": "easynav-planners",
    "easynav_navmap_localizer/AMCLLocalizer": "easynav-localizers",
}
