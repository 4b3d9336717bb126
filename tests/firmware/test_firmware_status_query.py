"""The status query (query_status, iq0002) on the host build and on the real AVR binary in simavr: accepted in every
state with the state and laser as they are, and no output changes; it is a sign of life for the failsafe but neither
holds a movement past the command timeout nor ends a failsafe (the next real frame does). Expected reply lines come
from the spec's model (fwsupport.Replies); timings from the generated module."""

from __future__ import annotations

import drone_protocol as dp
import fwsupport as fw
import pytest

R = fw.R
QUERY = dp.query_status()


@pytest.fixture(scope="module", autouse=True)
def built() -> None:
    fw.make("firmware-host", "firmware-uno", "firmware-sim")


def answer(state: str, laser: bool) -> str:
    return R.line(R.accepted(QUERY), state, laser)


def in_each_state(query: bool) -> tuple[fw.Script, int]:
    """Through every state a bench reaches, with a query after each command (or the same time without one)."""
    script = fw.Script().step(5)

    def then(frame: bytes | None) -> None:
        if frame is not None:
            script.send(frame).step(5)
        if query:
            script.send(QUERY)
        script.step(5)

    for frame in (None, dp.laser_on(), dp.laser_off(), dp.arm()):
        then(frame)
    t_armed = script.arm().t_ms
    for frame in (None, dp.hold_altitude(), dp.move_up(), dp.land()):
        then(frame)
    return script, t_armed


def test_the_query_is_accepted_in_each_state_with_its_status_and_changes_no_output() -> None:
    script, t_armed = in_each_state(query=True)
    trace = script.run()
    queried = [x for x in trace.lines() if R.parse(x)[0] == R.accepted(QUERY)]
    assert queried == [answer("disarmed", False), answer("disarmed", True), answer("disarmed", False),
                       answer("arming", False), answer("armed", False), answer("hold_altitude", False),
                       answer("moving", False), answer("landing", False)]
    assert trace.lines(since_ms=t_armed)[:2] == [answer("armed", False),
                                                 R.line(R.accepted(dp.hold_altitude()), "hold_altitude", False)]
    without, _ = in_each_state(query=False)
    assert trace.changes == without.run().changes  # the same outputs at the same times, queried or not


def test_the_query_keeps_the_failsafe_away_but_does_not_hold_a_movement() -> None:
    script = fw.Script().arm().send(dp.move_forward()).step(5)
    t_move = script.t_ms
    for _ in range(2 * dp.FAILSAFE_TIMEOUT_MS // 200):
        script.step(200).send(QUERY)
    trace = script.step(5).run()
    assert all(c["state"] != "failsafe" for c in trace.changes)
    hold = trace.first_change(since_ms=t_move, state="hold_altitude")
    assert hold["t_ms"] == t_move - 5 + 1 + dp.COMMAND_TIMEOUT_MS  # the move's own timeout, queries or not
    assert trace.lines(since_ms=t_move + dp.COMMAND_TIMEOUT_MS + 5)[-1] == answer("hold_altitude", False)


def test_the_query_reports_a_failsafe_without_ending_it_and_the_next_command_does() -> None:
    script = fw.Script().arm().send(dp.laser_on()).step(5)
    t_silent = script.t_ms
    script.step(dp.FAILSAFE_TIMEOUT_MS + 20)
    t_query = script.t_ms
    script.send(QUERY).step(300).send(QUERY).step(5)
    t_back = script.t_ms
    trace = script.send(dp.laser_off()).step(5).run()
    assert trace.lines(since_ms=t_silent) == [R.line(R.failsafe(), "failsafe", False), answer("failsafe", False),
                                              answer("failsafe", False),
                                              R.line(R.accepted(dp.laser_off()), "disarmed", False)]
    kept = trace.state_at(t_back - 1)
    assert kept["state"] == "failsafe" and kept["throttle"] == dp.FAILSAFE_THROTTLE_US
    assert [c for c in trace.changes if t_query <= c["t_ms"] < t_back] == []
    assert trace.state_at(t_back + 1)["state"] == "disarmed"


def test_the_query_on_the_real_binary_changes_no_pulse_and_reports_the_failsafe() -> None:
    events = [(40.0, QUERY), (80.0, dp.laser_on()), (120.0, QUERY), (160.0, dp.arm())]
    events += [(160.0 + 300 * k, QUERY) for k in range(1, dp.ARMING_HOLD_MS // 300 + 2)]
    t_armed = 160.0 + 300 * (dp.ARMING_HOLD_MS // 300 + 2)
    events.append((t_armed, QUERY))
    t_failsafe_query = t_armed + dp.FAILSAFE_TIMEOUT_MS + 100
    events.append((t_failsafe_query, QUERY))
    result = fw.simulate(events, t_failsafe_query + 100)
    assert result.lines_between(30, 150) == [answer("disarmed", False), R.line(R.accepted(dp.laser_on()),
                                             "disarmed", True), answer("disarmed", True)]
    assert result.lines_between(t_armed, t_armed + 30) == [answer("armed", True)]
    assert result.lines_between(t_failsafe_query - 100, t_failsafe_query + 100) == [
        R.line(R.failsafe(), "failsafe", False), answer("failsafe", False)]
    throttle = dp.CHANNELS[dp.ChannelName.THROTTLE]
    # from boot the failsafe throttle, which the queries before the arm frame leave as it is
    before_arm = result.widths_us(fw.PINS["throttle"], 20, 160)
    assert before_arm and all(abs(w - dp.FAILSAFE_THROTTLE_US) <= 2.0 for w in before_arm)
    armed = result.widths_us(fw.PINS["throttle"], t_armed - 200, t_armed + dp.FAILSAFE_TIMEOUT_MS - 50)
    assert armed and all(abs(w - throttle.minimum) <= 2.0 for w in armed)
    after = result.widths_us(fw.PINS["throttle"], t_failsafe_query + 30, t_failsafe_query + 100)
    assert after and all(abs(w - dp.FAILSAFE_THROTTLE_US) <= 2.0 for w in after)
