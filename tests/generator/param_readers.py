"""Readers of the two parameter-file formats the generated ArduCopter files are loaded by, and what each
ArduCopter line knows, written from the tools' and the firmware's sources (not from the generator's code).

- `.parm`: Mission Planner's and MAVProxy's NAME,VALUE lines (pymavlink's `mavparm` reads it in the tests; the
  strict reader below also demands the spec-field comment before each value).
- `.params`: QGroundControl's reader (ParameterManager::readParametersFromStream): a line starting with '#' is
  skipped; any other is split on tabs and used only with exactly 5 fields: vehicle id (must be the vehicle's, or
  the whole load stops), component id, name, value, MAV_PARAM_TYPE; a name the vehicle lacks or a type that differs
  from the vehicle's is skipped. Anything else is skipped without a word: the reader here counts those lines.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

_PARM_LINE = re.compile(r"(?P<name>[A-Z][A-Z0-9_]{0,15}),(?P<value>-?\d+(\.\d+)?)")
INT8, INT16 = 2, 4  # MAVLink's MAV_PARAM_TYPE_INT8 / _INT16: ArduPilot's AP_Int8 / AP_Int16


def _rc(suffixes: dict[str, int]) -> dict[str, int]:
    return {f"RC{n}_{s}": t for n in range(1, 9) for s, t in suffixes.items()}


_COMMON = {"RCMAP_ROLL": INT8, "RCMAP_PITCH": INT8, "RCMAP_THROTTLE": INT8, "RCMAP_YAW": INT8,
           "FS_THR_ENABLE": INT8, "FS_THR_VALUE": INT16, "THR_DZ": INT16,
           **{f"FLTMODE{n}": INT8 for n in range(1, 7)}}
# The parameters (and their types) of each line that the generated files may set, read in the releases' sources:
# ArduCopter 3.2.1's Parameters.pde / RC_Channel / AP_RCMapper, and 4.x's Parameters.cpp / RC_Channel.
KNOWN = {
    "3.2": {**_COMMON, **_rc({"MIN": INT16, "MAX": INT16, "TRIM": INT16, "REV": INT8})},
    "4": {**_COMMON, **_rc({"MIN": INT16, "MAX": INT16, "TRIM": INT16, "REVERSED": INT8}), "FLTMODE_CH": INT8},
}


def strict_parm(text: str) -> dict[str, tuple[float, str]]:
    """NAME,VALUE lines, each right after a `# <spec field> ...` line; '#' comments; no blank lines."""
    params: dict[str, tuple[float, str]] = {}
    previous = ""
    for number, line in enumerate(text.splitlines(), 1):
        if line.startswith("#"):
            previous = line
            continue
        match = _PARM_LINE.fullmatch(line)
        assert match, f"line {number} is not NAME,VALUE: {line!r}"
        assert match["name"] not in params, f"line {number}: {match['name']} set twice"
        assert previous.startswith("# "), f"line {number}: {match['name']} has no comment naming its spec field"
        params[match["name"]] = (float(match["value"]), previous[2:])
        previous = ""
    return params


@dataclass
class QgcLoad:
    """What QGroundControl's reader does with a file, for a vehicle with the given parameters and types."""

    loaded: dict[str, str] = field(default_factory=dict)
    ignored: list[str] = field(default_factory=list)  # lines it skips without a word (not 5 tab-separated fields)
    missing: list[str] = field(default_factory=list)
    type_errors: list[str] = field(default_factory=list)
    refused: str = ""  # the whole load stopped (another vehicle id)


def qgc_read(text: str, vehicle: dict[str, int], vehicle_id: int = 1, component_id: int = 1) -> QgcLoad:
    result = QgcLoad()
    for line in text.splitlines():
        if line.startswith("#"):
            continue
        fields = line.split("\t")
        if len(fields) != 5:
            result.ignored.append(line)
            continue
        line_vehicle, component, name, value, mav_type = fields
        if int(line_vehicle) != vehicle_id:
            result.refused = f"saved from System Id {line_vehicle}, but the current vehicle has {vehicle_id}"
            return result
        if int(component) != component_id or name not in vehicle:
            result.missing.append(name)
        elif int(mav_type) != vehicle[name]:
            result.type_errors.append(name)
        else:
            result.loaded[name] = value
    return result
