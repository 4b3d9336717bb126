"""The flight-safe policy on the real AVR binary in simavr, in one simulated flight: replies carry the state and
the laser; ik0000 is refused in the air; the self-test is refused while armed; il0000 lands (alt-hold, throttle
at its low speed for the landing time) then disarms with the laser off; after a failsafe the drone is disarmed
and must arm again.
"""

from __future__ import annotations

import drone_protocol as dp
import fwsupport as fw
import pytest

R = fw.R
TOL_US = 2.0


@pytest.fixture(scope="module", autouse=True)
def built() -> None:
    fw.make("firmware-uno", "firmware-sim")


def test_policy_in_one_flight_on_the_real_binary() -> None:
    events: list[tuple[float, bytes]] = [(50.0, dp.arm())]
    events += [(50.0 + 300 * k, dp.servo_reset()) for k in range(1, 8)]
    t = 50.0 + dp.ARMING_HOLD_MS + 150
    marks: dict[str, float] = {}

    def at(name: str, frame: bytes, gap: float = 60.0) -> None:
        nonlocal t
        marks[name] = t
        events.append((t, frame))
        t += gap

    at("laser", dp.laser_on())
    at("test_armed", dp.first_test())
    at("hold", dp.hold_altitude())
    at("disarm_air", dp.disarm())
    at("land", dp.land(), 0.0)
    landing_ms, hold_ms = fw.SPEC.landing_ms, dp.ARMING_HOLD_MS
    for k in range(1, (landing_ms + hold_ms) // 300 + 2):
        events.append((t + 300 * k, dp.land()))  # the keep-alive while landing and disarming
    t += landing_ms + hold_ms + 400
    marks["silence"] = t  # nothing sent from here: failsafe
    t += dp.FAILSAFE_TIMEOUT_MS + 100
    at("after_failsafe", dp.hold_altitude())
    result = fw.simulate(events, t + 20)

    def lines(name: str, span: float = 60.0) -> list[str]:
        return result.lines_between(marks[name], marks[name] + span)

    assert lines("laser") == [R.line(R.accepted(dp.laser_on()), "armed", True)]
    assert lines("test_armed") == [R.line(R.rejected("armed"), "armed", True)]
    assert lines("hold") == [R.line(R.accepted(dp.hold_altitude()), "hold_altitude", True)]
    assert lines("disarm_air") == [R.line(R.rejected("airborne"), "hold_altitude", True)]
    assert lines("land", 30)[0] == R.line(R.accepted(dp.land()), "landing", True)
    land = marks["land"]
    throttle = result.widths_us(fw.PINS["throttle"], land + 25, land + landing_ms - 5)
    assert throttle and all(abs(w - dp.CHANNELS[dp.ChannelName.THROTTLE].low) <= TOL_US for w in throttle)
    mode = result.widths_us(fw.PINS["mode"], land + 25, land + landing_ms - 5)
    assert mode and all(abs(w - dp.MODE_ALT_HOLD_US) <= TOL_US for w in mode)
    assert result.laser_at(land + landing_ms - 5) == 1
    # then the disarm sequence: laser off, stabilize, throttle minimum, yaw full left
    assert result.laser_at(land + landing_ms + 5) == 0
    yaw = result.widths_us(fw.PINS["yaw"], land + landing_ms + 25, land + landing_ms + hold_ms - 5)
    assert yaw and all(abs(w - dp.CHANNELS[dp.ChannelName.YAW].minimum) <= TOL_US for w in yaw)
    states = [R.parse(x)[1] for x in result.lines_between(land, marks["silence"])]
    assert states[0] == "landing" and "disarming" in states and states[-1] == "disarmed", states
    fs = result.lines_between(marks["silence"], marks["after_failsafe"])
    assert fs == [R.line(R.failsafe(), "failsafe", False)]
    assert lines("after_failsafe") == [R.line(R.rejected("not_armed"), "disarmed", False)]
