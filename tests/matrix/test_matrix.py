"""The integration matrix: combinations from the plugins' declarations, and CI's slice of it.

The slice (every installed navigation plugin at least once) runs as slow tests; `make matrix`
runs every combination in every world and writes docs/matrix.md.
"""

from __future__ import annotations

import dataclasses

import pytest
from matrix import (
    AXES,
    MIN_TIMEOUT,
    WORLDS,
    Combination,
    Finding,
    Outcome,
    ci_slice,
    combinations,
    compose_params,
    covering_slice,
    load_findings,
    markdown,
    mission_timeout,
    navigation_plugins,
    params_world,
    plugin_sections,
    representative_sections,
    run_combination,
    slice_waypoints,
    unmatched_plugins,
    verdict,
)

from easynav.core.plugins.compatibility import compatible, needed_maps, provided_maps


def test_every_installed_navigation_plugin_is_in_a_combination_or_said_why_not():
    combos = combinations(("home",))
    used = {p for combo in combos for p in combo.plugins}
    unmatched = unmatched_plugins(combos)
    for kind, names in navigation_plugins().items():
        assert names, f"no {kind} installed"
        for name in names:
            assert (name in used) != (name in unmatched), name
    # The stacks the playground drives with are all in the matrix.
    for name in ("easynav_simple_maps_manager/SimpleMapsManager",
                 "easynav_costmap_maps_manager/CostmapMapsManager",
                 "easynav_costmap_planner/CostmapPlanner",
                 "easynav_costmap_localizer/AMCLLocalizer"):
        assert name in used


def test_no_combination_pairs_a_plugin_with_a_map_it_cannot_use():
    from matrix import plugin_class

    for combo in combinations(("home",)):
        provides = {rep for m in combo.maps_managers
                    for rep in provided_maps(plugin_class("maps manager", m))}
        for kind, name in zip(("localizer", "planner", "controller"), combo.plugins[-3:],
                              strict=True):
            assert compatible(needed_maps(plugin_class(kind, name)), provides), combo


def test_cis_slice_covers_every_plugin_at_home_where_it_can():
    combos = combinations()
    chosen = ci_slice()
    assert chosen == covering_slice(combos)  # what `run_matrix.py --slice` runs
    assert {p for c in chosen for p in c.plugins} == {p for c in combos for p in c.plugins}
    assert len(chosen) <= sum(len(names) for names in navigation_plugins().values())
    # Each in the first world that suits it: a combination that can run at home runs there.
    at_home = {c.plugins for c in combinations(("home",))}
    for combo in chosen:
        assert (combo.world == "home") == (combo.plugins in at_home), combo.name


def test_cis_slice_drives_the_first_40_m_of_a_long_tour():
    # home's tour (17 m) whole; the campus's first leg (30 m) of its 190 m.
    assert slice_waypoints("home") is None
    assert slice_waypoints("campus") == 1
    assert slice_waypoints("campus", metres=1.0) == 1  # the first waypoint at least
    assert slice_waypoints("campus", metres=1000.0) is None
    assert mission_timeout("campus", 1) == MIN_TIMEOUT < mission_timeout("campus")


def test_composed_params_take_each_plugin_from_its_representative_file():
    sections = representative_sections()
    combo = combinations(("home",))[0]
    document = compose_params(combo, sections)
    chosen = (combo.maps_managers[0], combo.localizer, combo.planner, combo.controller)
    for (node, types_key, _), plugin in zip(AXES, chosen, strict=True):
        params = document[node]["ros__parameters"]
        assert params[types_key][0] == "matrix"
        assert params["matrix"]["plugin"] == plugin
        if plugin in sections:
            expected = dict(sections[plugin]["section"])
            if "perception_group" in expected:  # read from the robot's sensors (test below)
                expected["perception_group"] = params["matrix"]["perception_group"]
            assert params["matrix"] == expected
    heartbeat = document["system_node"]["ros__parameters"]["safety"]["heartbeat"]
    assert heartbeat["period"] > 0


def test_each_world_takes_a_plugin_from_a_file_written_for_it_first():
    assert params_world("# Run: easynav demo --world campus --params p.yaml\n") == "campus"
    assert params_world("# Run: `easynav demo --params p.yaml` (or --world <world>).") is None
    planner = "easynav_simple_planner/SimplePlanner"
    combo = next(c for c in combinations(("campus",)) if c.planner == planner)

    def clearance(world):
        document = compose_params(dataclasses.replace(combo, world=world))
        return document["planner_node"]["ros__parameters"]["matrix"]["clearance_distance"]

    # The campus files keep paths a metre off the buildings; indoors, the playground's 0.2 m.
    assert clearance("campus") == 1.0
    assert clearance("home") == 0.2


def test_a_maps_manager_reading_a_sensor_group_the_robot_lacks_reads_its_laser():
    # The Bonxai section reads the 3D lidar's group (points3d); the playground's robot has a
    # 2D laser only (ungrouped), so the composed stack gives the voxel map the laser's points.
    sections = representative_sections()
    bonxai = "easynav_bonxai_maps_manager/BonxaiMapsManager"
    assert sections[bonxai]["section"]["perception_group"] == "points3d"
    combo = next(c for c in combinations(("home",)) if c.maps_managers == (bonxai,))
    document = compose_params(combo, sections)
    assert document["maps_manager_node"]["ros__parameters"]["matrix"]["perception_group"] == ""
    # A group that a sensor of the robot is in is kept.
    sensors = document["sensors_node"]["ros__parameters"]
    sensors["laser"]["group"] = "points3d"
    maps = document["maps_manager_node"]["ros__parameters"]
    maps["matrix"]["perception_group"] = "points3d"
    from matrix import _read_the_robots_sensors

    _read_the_robots_sensors(document)
    assert maps["matrix"]["perception_group"] == "points3d"


def test_a_localizer_gets_the_sensors_its_file_declares_where_the_robot_has_them():
    # The fusion localizer reads GNSS fixes through sensors_node (group gnss): the campus
    # robot has a receiver, so the composed stack declares it; the home robot has none.
    sections = representative_sections()
    fusion = "easynav_fusion_localizer/FusionLocalizer"
    combo = next(c for c in combinations(("campus",)) if c.localizer == fusion)
    sensors = compose_params(combo, sections)["sensors_node"]["ros__parameters"]
    assert "gps" in sensors["sensors"] and sensors["gps"]["group"] == "gnss"
    assert sensors["gps"]["type"] == "sensor_msgs/msg/NavSatFix"
    assert "laser" in sensors["sensors"]  # the playground's own
    indoors = compose_params(dataclasses.replace(combo, world="home"), sections)
    assert indoors["sensors_node"]["ros__parameters"]["sensors"] == ["laser"]


def test_the_files_written_for_a_world_agree_on_the_plugins_they_share():
    # A matrix world's files come first in name order; if two of them configured a plugin
    # differently, retuning one would silently change every row of that world.
    from matrix import _readable_params_files

    seen: dict[tuple[str, str], tuple[str, dict]] = {}
    for path, world, document in _readable_params_files():
        if world not in WORLDS:
            continue
        for _, section in plugin_sections(document):
            first = seen.setdefault((world, section["plugin"]), (path.name, section))
            assert section == first[1], (
                f"{world}: {path.name} and {first[0]} configure {section['plugin']} apart"
            )


def test_only_a_plugin_that_needs_a_sensor_brings_it_from_its_file():
    # The campus's Simple* sections come from the fusion file, whose sensors_node reads GNSS
    # for its localizer: an AMCL stack with those sections has no use for the receiver.
    amcl = "easynav_simple_localizer/AMCLLocalizer"
    combo = next(c for c in combinations(("campus",))
                 if c.localizer == amcl and c.planner == "easynav_simple_planner/SimplePlanner")
    sensors = compose_params(combo)["sensors_node"]["ros__parameters"]
    assert sensors["sensors"] == ["laser"]


def test_a_long_tour_has_the_time_it_needs_and_a_short_one_the_demos():
    # The campus's 180 m took up to 498 s simulated (MPPI): at a real-time factor of 0.8, more
    # than the demo's 600 s.
    assert mission_timeout("campus") > 498 / 0.8 * 1.5
    assert mission_timeout("home") == mission_timeout("tb3_sandbox") == MIN_TIMEOUT


def test_a_row_kept_with_other_params_runs_again():
    from run_matrix import params_fingerprint, stale_rows

    home = combinations(("home",))[:3]
    prints = {c.name: params_fingerprint(c) for c in home}
    assert len(set(prints.values())) == 3 and params_fingerprint(home[0]) == prints[home[0].name]
    kept = {home[0].name: {"params": prints[home[0].name]},
            home[1].name: {"params": "retuned"},
            home[2].name: {}}  # kept before rows had a fingerprint
    assert stale_rows(home, kept, prints) == {home[1].name, home[2].name}
    assert stale_rows(home, kept, {}) == set()  # no fingerprints: nothing to compare


def test_the_report_marks_a_stale_row_and_says_what_each_row_ran_with():
    combo = Combination("m/M", "l/L", "p/P", "c/C", "home")
    summary = {"success": True, "waypoints": 4, "reached": 4}
    stale = Outcome(combo, 0, summary, ran="11a8747 x2", stale=True)
    fresh = Outcome(combo, 0, summary, ran="3b39a3e x1")
    assert verdict(stale) == "green (**stale**: run with params changed since; to run again)"
    text = markdown([stale, fresh], "# header")
    assert "| 11a8747 x2 | green (**stale**" in text and "| 3b39a3e x1 | green |" in text
    assert "1 of 1 runs green; of the 0 failed, 0 explained (tests/matrix/findings.yaml); " \
           "and 1 stale runs (run with params changed since: to run again)." in text


def test_a_run_overloaded_faster_than_real_time_is_to_run_again_and_in_real_time_says_so():
    """The campus row of fusion + the costmap + OMPL + SeReST at x4: EasyNav's TF listener
    handled odom → robot 1.4 s after its stamp (median), the scans were drawn metres off the
    walls and the robot drove 447 m of a 195 m tour, green; at x1 it drove 196 m. Such a row is
    not evidence about the combination."""
    combo = Combination("m/M", "l/L", "p/P", "c/C", "campus")
    summary = {"success": True, "waypoints": 5, "reached": 5,
               "odometry_age": {"transforms": 65678, "median_ms": 1395.0, "p99_ms": 1760.0}}
    at_x4 = Outcome(combo, 0, summary, ran="522025f x4", speed_up=4.0)
    assert at_x4.overloaded_fast and at_x4.to_run_again
    assert verdict(at_x4) == (
        "**overloaded** at x4: EasyNav's TF listener handled odom → robot 1395 ms after its "
        "stamp (median, simulated), the run tested the machine, not the combination; to run "
        "again at x1")
    at_x1 = Outcome(combo, 0, summary, ran="522025f x1")
    assert not at_x1.overloaded_fast and not at_x1.to_run_again and at_x1.green
    assert verdict(at_x1) == (
        "green, but overloaded: EasyNav's TF listener handled odom → robot 1395 ms after its "
        "stamp (median, simulated; more than 100 ms)")
    missed = Outcome(combo, 1, dict(summary, success=False, reached=4))
    assert verdict(missed) == (
        "**FAILED** (not looked into yet): 4 of 5 waypoints reached; overloaded: EasyNav's TF "
        "listener handled odom → robot 1395 ms after its stamp (median, simulated; more than "
        "100 ms)")
    kept_up = dict(summary, odometry_age={"median_ms": 20.0, "p99_ms": 1230.0})
    assert Outcome(combo, 0, kept_up, speed_up=4.0).green  # a late tail alone is no overload
    assert Outcome(combo, 0, {"success": True}, speed_up=4.0).green  # not measured (old rows)
    text = markdown([at_x4, Outcome(combo, 0, kept_up, ran="3b39a3e x4", speed_up=4.0)], "# h")
    assert ("1 of 1 runs green; of the 0 failed, 0 explained (tests/matrix/findings.yaml); "
            "and 1 overloaded runs (faster than real time: to run again at x1).") in text
    both = Outcome(combo, 0, summary, speed_up=4.0, stale=True)  # counted once, as stale
    assert markdown([both], "# h").endswith(
        "0 of 0 runs green; of the 0 failed, 0 explained (tests/matrix/findings.yaml); and 1 "
        "stale runs (run with params changed since: to run again).\n")


def _kept_rows(path, rows):
    """Write ``rows`` (combination, summary, speed-up, params fingerprint) as a results file."""
    import json

    path.write_text("".join(json.dumps(
        {"name": c.name, "exit_code": 0, "summary": summary, "error": "", "speed_up": speed,
         "params": fingerprint}) + "\n" for c, summary, speed, fingerprint in rows))


def test_the_runner_runs_a_row_overloaded_faster_than_real_time_again_at_x1(tmp_path,
                                                                            monkeypatch,
                                                                            capsys):
    import run_matrix

    combos = combinations(("home",))[:6]
    overloaded, kept_up, overloaded_x1, stale_overloaded, never_ran, elsewhere = combos
    late = {"success": True, "odometry_age": {"median_ms": 900.0}}
    fingerprint = run_matrix.params_fingerprint
    results = tmp_path / "results.jsonl"
    _kept_rows(results, [
        (overloaded, late, 4.0, fingerprint(overloaded)),
        (kept_up, {"success": True}, 4.0, fingerprint(kept_up)),
        (overloaded_x1, late, 1.0, fingerprint(overloaded_x1)),  # a result
        (stale_overloaded, late, 4.0, "retuned"),
        (elsewhere, late, 4.0, fingerprint(elsewhere)),  # not among this call's combinations
    ])
    assert run_matrix.overloaded_rows(run_matrix.load_results(results)) == {
        overloaded.name, stale_overloaded.name, elsewhere.name}
    ran = []

    def run(name, run_dir, args, speed_up):
        ran.append((name, speed_up))
        return {"name": name, "exit_code": 0, "summary": {"success": True}, "error": ""}

    monkeypatch.setattr(run_matrix, "_run_in_process", run)
    monkeypatch.setattr(run_matrix, "combinations", lambda worlds: combos[:5])
    code = run_matrix.main(["--worlds", "home", "--speed-up", "4", "--results", str(results),
                            "--output", str(tmp_path / "matrix.md")])
    assert sorted(ran) == sorted([(overloaded.name, 1.0), (stale_overloaded.name, 1.0),
                                  (never_ran.name, 4.0)])
    assert capsys.readouterr().out.startswith(
        "5 combinations: 2 done in " + str(results) + ", 1 kept there with other params, 1 "
        "overloaded faster than real time (both to run again), 3 to run")
    assert code == 0  # every row green, none to run again
    report = (tmp_path / "matrix.md").read_text()
    assert ("| green, but overloaded: EasyNav's TF listener handled odom → robot 900 ms after "
            "its stamp") in report
    assert "**overloaded** at x" not in report  # the x4 rows ran again, green
    assert ": 5 of 5 runs done\n" in report

    # Asked for by name, a row runs at the speed asked for (retested at x4 after a fix).
    _kept_rows(results, [(overloaded, late, 4.0, fingerprint(overloaded))])
    ran.clear()
    run_matrix.main(["--worlds", "home", "--speed-up", "4", "--again", overloaded.name,
                     "--results", str(results), "--output", str(tmp_path / "matrix.md")])
    assert ran == [(overloaded.name, 4.0)]


def test_again_runs_only_the_rows_it_names(tmp_path, monkeypatch):
    import json

    import run_matrix

    combos = combinations(("home",))
    named, other = combos[0], combos[1]  # both kept, other stale: only the named one runs
    results = tmp_path / "results.jsonl"
    results.write_text("".join(json.dumps(
        {"name": c.name, "exit_code": 0, "summary": {"success": True}, "error": "",
         "params": run_matrix.params_fingerprint(c) if c is named else "retuned"}) + "\n"
        for c in (named, other)))
    ran = []

    def run(name, run_dir, args, speed_up):
        ran.append(name)
        return {"name": name, "exit_code": 0, "summary": {"success": True}, "error": ""}

    monkeypatch.setattr(run_matrix, "_run_in_process", run)
    run_matrix.main(["--worlds", "home", "--again", named.name, "--results", str(results),
                     "--output", str(tmp_path / "matrix.md")])
    assert ran == [named.name]


def test_a_multi_line_error_keeps_its_first_line_in_the_table():
    combo = Combination("m/M", "l/L", "p/P", "c/C", "home")
    crashed = Outcome(combo, 1, {}, "RuntimeError: no map\nTraceback (most recent call last):")
    assert verdict(crashed) == "**FAILED** (not looked into yet): RuntimeError: no map"
    row = markdown([crashed], "# header").splitlines()[4]
    assert row.endswith("| **FAILED** (not looked into yet): RuntimeError: no map |")


def test_merging_a_clones_results_appends_its_newer_runs(tmp_path):
    """A clone that ran on from a copy of the results file: its extra runs are appended (and
    win as the later lines of their names, or by when they finished); what both hold, and lines
    cut short, are not."""
    import json

    from run_matrix import load_results, merge_results

    def line(name, code):
        return json.dumps({"name": name, "exit_code": code})

    main = tmp_path / "main.jsonl"
    main.write_text("\n".join([line("a", 0), line("b", 1)]) + "\n")
    clone = tmp_path / "clone.jsonl"
    clone.write_text("\n".join([line("a", 0), line("b", 1), line("b", 0), line("c", 0),
                                 '{"name": "d", "exit_co']) + "\n")
    assert merge_results(main, [clone]) == 2
    assert merge_results(main, [clone]) == 0  # nothing new the second time
    kept = load_results(main)
    assert {name: row["exit_code"] for name, row in kept.items()} == {"a": 0, "b": 0, "c": 0}
    # Runs that say when they finished: the newer wins, whatever the order of the lines (a
    # clone's older run merged after main's newer one).
    newer = json.dumps({"name": "e", "exit_code": 0, "finished": "2026-11-30T08:00:00Z"})
    older = json.dumps({"name": "e", "exit_code": 1, "finished": "2026-11-29T08:00:00Z"})
    main.write_text(newer + "\n")
    clone.write_text(older + "\n")
    assert merge_results(main, [clone]) == 1
    assert load_results(main)["e"]["exit_code"] == 0


def test_two_maps_managers_side_by_side_only_where_a_plugin_needs_both():
    from matrix import plugin_class

    from easynav.core.plugins.compatibility import required_maps

    pairs = [c for c in combinations(("home",)) if len(c.maps_managers) == 2
             and not any(needed_maps(plugin_class("maps manager", m)) for m in c.maps_managers)]
    assert pairs, "the NavMap AMCL (NavMap + Bonxai) is in no combination"
    for combo in pairs:
        needs_both = [name for kind, name in zip(("localizer", "planner", "controller"),
                                                 combo.plugins[-3:], strict=True)
                      if required_maps(plugin_class(kind, name))]
        assert needs_both, combo.name
    # Their sections come from the file that configures the pair: the walls stay static.
    maps = compose_params(pairs[0])["maps_manager_node"]["ros__parameters"]
    bonxai = next(maps[a] for a in maps["map_types"] if "Bonxai" in maps[a]["plugin"])
    assert bonxai["insert_perceptions"] is False


def test_a_stack_member_planned_on_gets_the_filters_of_its_own_file():
    # The NavMap stack's file plans on the NavMap and leaves the Bonxai walls' costmap
    # uninflated; a row planning on that costmap inflates it as Bonxai's own file does.
    def bonxai_of(planner):
        combo = next(c for c in combinations(("home",)) if len(c.maps_managers) == 2
                     and c.planner == planner and "NavMap" in c.maps_manager)
        maps = compose_params(combo)["maps_manager_node"]["ros__parameters"]
        return next(maps[a] for a in maps["map_types"] if "Bonxai" in maps[a]["plugin"])

    on_costmap = bonxai_of("easynav_costmap_planner/CostmapPlanner")
    assert on_costmap["insert_perceptions"] is False  # still the stack's section
    assert on_costmap["filters"] == ["inflation"]
    assert on_costmap["inflation"]["plugin"].endswith("/InflationFilter")
    assert not bonxai_of("easynav_navmap_planner/AStarPlanner").get("filters")


def test_only_a_mission_stopped_from_outside_is_not_kept():
    from run_matrix import _stopped_half_way

    assert _stopped_half_way({"exit_code": 130, "summary": {}})
    assert _stopped_half_way({"exit_code": -15, "summary": {}})
    assert _stopped_half_way({"exit_code": 1, "summary": {"final_state": "INTERRUPTED"}})
    assert not _stopped_half_way({"exit_code": -9, "summary": {}})  # killed: out of memory?
    assert not _stopped_half_way({"exit_code": -11, "summary": {}})  # a crash is a result
    assert not _stopped_half_way({"exit_code": 1, "summary": {"final_state": "TIMEOUT"}})


def test_a_failed_row_says_why_when_a_finding_explains_it():
    combo = Combination("m/M", "l/L", "p/P", "c/C", "campus")
    failed = Outcome(combo, 1, {"collisions": 1, "waypoints": 5, "reached": 3},
                     "no result within 600 s")
    green = Outcome(combo, 0, {"success": True, "waypoints": 5, "reached": 5})
    found = Finding(("l/L", "c/C"), ("campus",), "the localizer drifts.")
    elsewhere = Finding(("l/L",), ("home",), "something else.")
    assert verdict(failed, [found, elsewhere]) == (
        "**FAILED**: 1 collision(s); 3 of 5 waypoints reached; no result within 600 s. "
        "Why: the localizer drifts."
    )
    assert verdict(failed, [elsewhere]).startswith("**FAILED** (not looked into yet): 1 coll")
    assert verdict(green, [found]) == "green"
    text = markdown([failed, green], "# header", findings=[found])
    assert "Why: the localizer drifts." in text
    assert "1 of 2 runs green; of the 1 failed, 1 explained" in text


def test_a_row_whose_localisation_was_lost_fails_though_every_waypoint_was_reached():
    combo = Combination("m/M", "l/L", "p/P", "c/C", "campus")
    lost = Outcome(combo, 0, {"success": True, "waypoints": 5, "reached": 5,
                              "localisation_mean": 23.9, "localisation_max": 88.7})
    accurate = Outcome(combo, 0, {"success": True, "waypoints": 5, "reached": 5,
                                  "localisation_mean": 0.39, "localisation_max": 0.93})
    assert not lost.green and accurate.green
    assert verdict(lost) == ("**FAILED** (not looked into yet): localisation lost: 88.7 m off "
                             "at worst (mean 23.9 m, more than 2 m fails a row)")
    assert "0 of 1 runs green; of the 1 failed" in markdown([lost], "# header")
    # A run with no estimate (crashed first) has no error to judge; one that also hit
    # something says so first.
    assert Outcome(combo, 0, {"success": True, "localisation_max": None}).green
    crashed = Outcome(combo, 1, {"collisions": 2, "waypoints": 5, "reached": 4,
                                 "localisation_max": 3.26}, "no result within 600 s")
    assert verdict(crashed) == (
        "**FAILED** (not looked into yet): 2 collision(s); 4 of 5 waypoints reached; "
        "localisation lost: 3.3 m off at worst (mean — m, more than 2 m fails a row); "
        "no result within 600 s")


def test_the_shipped_findings_name_installed_plugins_and_matrix_worlds():
    installed = {name for names in navigation_plugins().values() for name in names}
    for finding in load_findings():
        assert set(finding.plugins) <= installed, finding
        assert set(finding.worlds) <= set(WORLDS), finding


def test_a_malformed_finding_is_refused_naming_it(tmp_path):
    path = tmp_path / "findings.yaml"
    path.write_text("- plugins: [a/A]\n  cause: fine\n- plugins: a/A\n  cause: x\n")
    with pytest.raises(ValueError, match="finding 2: plugins must be a non-empty list"):
        load_findings(path)
    path.write_text("- plugins: [a/A]\n  why: typo\n")
    with pytest.raises(ValueError, match="finding 1: expected the keys plugins, worlds, cause"):
        load_findings(path)
    assert load_findings(tmp_path / "absent.yaml") == []


# CI's slice: every plugin at least once, at home where the combination can run there (roomy:
# every stack's tuning fits it), else on the campus's first leg; the full matrix
# (`make matrix`) drives every combination's whole tour in every world that suits it.
SLICE = ci_slice()


@pytest.mark.slow
@pytest.mark.ros
@pytest.mark.timeout(900)
@pytest.mark.parametrize("combo", SLICE, ids=[c.name for c in SLICE])
def test_slice_combination_completes_its_mission(combo: Combination, tmp_path):
    outcome = run_combination(combo, tmp_path, timeout=600.0,
                              waypoints=slice_waypoints(combo.world))
    summary = outcome.summary
    assert outcome.green, f"{combo.name}: {verdict(outcome)}\n{summary}"
    assert summary["collisions"] == 0 and summary["reached"] == summary["waypoints"]
