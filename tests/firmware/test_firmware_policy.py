"""The flight-safe policy on the host build (virtual drone, stepped clock): every reply carries the state and
the laser the command left; the laser's on/off commands are deterministic and disarm and failsafe switch it
off; ik0000 is refused in the air and il0000 lands, then disarms; the self-test is refused while armed.

Expected reply lines come from the spec's model (fwsupport.Replies); timings from the generated module.
"""

from __future__ import annotations

import drone_protocol as dp
import fwsupport as fw
import pytest

R = fw.R


@pytest.fixture(scope="module", autouse=True)
def built() -> None:
    fw.make("firmware-host")


def line(frame: bytes, state: str, laser: bool) -> str:
    return R.line(R.accepted(frame), state, laser)


def refused(error: str, state: str, laser: bool) -> str:
    return R.line(R.rejected(error), state, laser)


def keep_alive(script: fw.Script, frame: bytes, ms: int, period_ms: int = 200) -> fw.Script:
    """`frame` every `period_ms` for `ms` (the failsafe stays away)."""
    for _ in range(ms // period_ms):
        script.step(period_ms).send(frame)
    return script.step(ms % period_ms)


def test_every_reply_reports_the_state_and_laser_the_command_left() -> None:
    script = fw.Script().step(5).send(dp.arm()).step(5)
    t_armed = script.arm().t_ms
    script.send(dp.laser_on()).step(5).send(dp.hold_altitude()).step(5).send(dp.move_forward()).step(5)
    trace = script.send(dp.disarm()).step(5).run()
    assert trace.lines(since_ms=5)[0] == line(dp.arm(), "arming", False)
    assert trace.lines(since_ms=t_armed) == [
        line(dp.laser_on(), "armed", True),
        line(dp.hold_altitude(), "hold_altitude", True),
        line(dp.move_forward(), "moving", True),
        refused("airborne", "moving", True),
    ]


def test_laser_on_and_off_set_the_laser_whatever_its_state_and_the_toggle_still_toggles() -> None:
    script = fw.Script().step(5)
    for frame in (dp.laser_on(), dp.laser_on(), dp.laser_off(), dp.laser_off(), dp.laser_toggle(),
                  dp.laser_toggle(), dp.laser_on(), dp.laser_toggle()):
        script.send(frame).step(5)
    trace = script.run()
    lasers = [R.parse(x)[2] for x in trace.lines(since_ms=5)]
    assert lasers == [True, True, False, False, True, False, True, False]
    assert [trace.state_at(5 + 5 * k + 1)["laser"] for k in range(8)] == lasers


def test_disarm_switches_the_laser_off_and_it_stays_off_while_disarming() -> None:
    script = fw.Script().arm().send(dp.laser_on()).step(5)
    t0 = script.t_ms
    script.send(dp.disarm()).step(5).send(dp.laser_on()).step(5).send(dp.laser_toggle()).step(5)
    trace = script.run()
    assert trace.lines(since_ms=t0) == [line(dp.disarm(), "disarming", False), refused("busy", "disarming", False),
                                        refused("busy", "disarming", False)]
    assert trace.first_change(since_ms=t0, state="disarming")["laser"] is False


def test_failsafe_switches_the_laser_off_disarms_and_needs_a_new_arming_sequence() -> None:
    script = fw.Script().arm().send(dp.laser_on()).step(5).send(dp.hold_altitude()).step(5)
    t_silent = script.t_ms
    script.step(dp.FAILSAFE_TIMEOUT_MS + 20)
    t_back = script.t_ms
    trace = script.send(dp.hold_altitude()).step(5).send(dp.arm()).step(5).run()
    fs = trace.first_change(since_ms=t_silent, state="failsafe")
    assert fs["laser"] is False and fs["armed"] is False and fs["throttle"] == dp.FAILSAFE_THROTTLE_US
    assert trace.lines(since_ms=t_silent) == [
        R.line(R.failsafe(), "failsafe", False),
        refused("not_armed", "disarmed", False),  # the first frame after it: disarmed, not armed
        line(dp.arm(), "arming", False),
    ]
    assert trace.state_at(t_back + 1)["state"] == "disarmed"


def test_disarm_in_the_air_is_refused_and_changes_nothing() -> None:
    script = fw.Script().arm().send(dp.hold_altitude()).step(5)
    t0 = script.t_ms
    script.send(dp.disarm()).step(5).send(dp.move_up()).step(5).send(dp.disarm()).step(5)
    trace = script.run()
    assert trace.lines(since_ms=t0) == [refused("airborne", "hold_altitude", False),
                                        line(dp.move_up(), "moving", False), refused("airborne", "moving", False)]
    assert all(c["state"] != "disarming" for c in trace.changes)


def test_land_descends_in_alt_hold_for_the_landing_time_then_disarms_and_keeps_alive_with_il() -> None:
    script = fw.Script().arm().send(dp.laser_on()).step(5).send(dp.move_forward()).step(5)
    t_land = script.t_ms
    script.send(dp.land()).step(5)
    keep_alive(script, dp.land(), fw.SPEC.landing_ms + dp.ARMING_HOLD_MS + 200)
    trace = script.run()
    landing = trace.first_change(since_ms=t_land, state="landing")
    assert landing["t_ms"] == t_land + 1 and landing["mode"] == dp.MODE_ALT_HOLD_US
    assert landing["throttle"] == dp.CHANNELS[dp.ChannelName.THROTTLE].low
    assert {k: landing[k] for k in ("roll", "pitch", "yaw")} == {k: fw.neutral()[k] for k in ("roll", "pitch", "yaw")}
    assert landing["armed"] is True
    disarming = trace.first_change(since_ms=t_land, state="disarming")
    assert disarming["t_ms"] == landing["t_ms"] + fw.SPEC.landing_ms  # the keep-alive il0000 did not restart it
    assert disarming["laser"] is False and disarming["mode"] == dp.MODE_STABILIZE_US
    yaw, throttle = dp.CHANNELS[dp.ChannelName.YAW], dp.CHANNELS[dp.ChannelName.THROTTLE]
    assert disarming["throttle"] == throttle.minimum and disarming["yaw"] == yaw.minimum
    done = trace.first_change(since_ms=t_land, state="disarmed")
    assert done["t_ms"] == disarming["t_ms"] + dp.ARMING_HOLD_MS and done["armed"] is False
    lines = trace.lines(since_ms=t_land)
    assert lines[0] == line(dp.land(), "landing", True)
    states = [R.parse(x)[1] for x in lines]
    assert set(states) == {"landing", "disarming", "disarmed"}, states
    assert all(R.parse(x)[0] == R.accepted(dp.land()) for x in lines if R.parse(x)[1] != "disarmed")


def test_land_is_refused_when_disarmed_and_movement_is_busy_while_landing() -> None:
    t0 = 5
    trace = fw.Script().step(t0).send(dp.land()).step(5).run()
    assert trace.lines(since_ms=t0) == [refused("not_armed", "disarmed", False)]
    script = fw.Script().arm().send(dp.hold_altitude()).step(5).send(dp.land()).step(5)
    t1 = script.t_ms
    trace = script.send(dp.move_forward()).step(5).send(dp.hold_altitude()).step(5).send(dp.arm()).step(5).run()
    assert trace.lines(since_ms=t1) == [refused("busy", "landing", False)] * 3


def test_self_test_is_refused_while_armed_in_the_air_and_while_landing() -> None:
    script = fw.Script().arm().send(dp.hold_altitude()).step(5)
    t0 = script.t_ms
    script.send(dp.first_test()).step(5).send(dp.land()).step(5).send(dp.first_test()).step(5)
    trace = script.run()
    assert trace.lines(since_ms=t0) == [refused("armed", "hold_altitude", False), line(dp.land(), "landing", False),
                                        refused("armed", "landing", False)]
    assert all(c["state"] != "self_test" for c in trace.changes)
