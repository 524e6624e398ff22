"""HeartbeatState: period on the monotonic clock, sequence, fields of the Heartbeat message."""

import pytest

from easynav.system.safety import RT_LATE, HeartbeatFields, HeartbeatState


def beats(state, times, rt_status=0, late=0):
    return [(t, state.poll(t, rt_status, late)) for t in times]


def test_first_poll_is_due_then_one_per_period_without_drift():
    state = HeartbeatState(0.1, safety_mode=True, configuration_hash="abc")
    times = [10.0 + 0.005 * i for i in range(201)]  # 1 s of a 200 Hz RT loop
    sent = [(t, f) for t, f in beats(state, times) if f is not None]
    assert len(sent) == 11
    assert [f.sequence for _, f in sent] == list(range(1, 12))
    assert sent[-1][0] == pytest.approx(11.0)  # no drift over the second


def test_fields_of_the_message():
    state = HeartbeatState(0.5, safety_mode=False)
    state.set_configuration_hash("f" * 64)
    fields = state.poll(1.0, RT_LATE, 7)
    assert fields == HeartbeatFields(
        sequence=1,
        rt_status=RT_LATE,
        late_cycles=7,
        safety_mode=False,
        configuration_hash="f" * 64,
    )


def test_a_stall_sends_one_heartbeat_and_restarts_the_schedule():
    state = HeartbeatState(0.1, safety_mode=False)
    state.poll(0.0, 0, 0)
    assert state.poll(1.0, 0, 0).sequence == 2  # one, not ten catch-up heartbeats
    assert state.poll(1.05, 0, 0) is None
    assert state.poll(1.1, 0, 0).sequence == 3


def test_period_zero_is_off_and_restart_keeps_the_sequence():
    assert HeartbeatState(0.0, False).poll(1.0, 0, 0) is None
    state = HeartbeatState(0.1, False)
    state.poll(0.0, 0, 0)
    state.restart()
    assert state.poll(0.01, 0, 0).sequence == 2  # due at once after an activation


def test_invalid_period():
    with pytest.raises(ValueError, match="safety.heartbeat.period"):
        HeartbeatState(-1.0, False)
