"""`@record` behaves as `@dataclass(frozen=True)` does for the generator's model: construction by position, by
keyword and with defaults, its refusals, repr, equality, hashing and no assignment."""

from __future__ import annotations

import dataclasses
from typing import Any

import pytest

from generator.records import record


@record
class Point:
    x: int
    y: int
    label: str = ""


@dataclasses.dataclass(frozen=True)
class Twin:
    x: int
    y: int
    label: str = ""


class Other:
    pass


@pytest.mark.parametrize(("args", "kwargs"), [((1, 2), {}), ((1, 2, "a"), {}), ((1,), {"y": 2}),
                                              ((), {"label": "b", "y": 2, "x": 1})])
def test_a_record_is_made_and_shown_as_a_frozen_dataclass(args: tuple[Any, ...], kwargs: dict[str, Any]) -> None:
    point, twin = Point(*args, **kwargs), Twin(*args, **kwargs)
    assert repr(point) == repr(twin).replace("Twin", "Point")
    assert (point.x, point.y, point.label) == (twin.x, twin.y, twin.label)
    assert list(vars(point)) == list(vars(twin))
    assert point == Point(*args, **kwargs) and hash(point) == hash(Point(*args, **kwargs))
    others: list[object] = [Point(9, 9), twin, Other()]
    assert all(point != other for other in others)


@pytest.mark.parametrize(("args", "kwargs", "message"), [
    ((1,), {}, "missing a required argument: 'y'"),
    ((1, 2, "a", 4), {}, "takes 3 fields but 4 were given"),
    ((1, 2), {"x": 1}, "multiple values for argument 'x'"),
    ((1, 2), {"z": 1}, "an unexpected keyword argument 'z'"),
])
def test_a_record_refuses_wrong_arguments(args: tuple[Any, ...], kwargs: dict[str, Any], message: str) -> None:
    with pytest.raises(TypeError, match=message):
        Point(*args, **kwargs)
    with pytest.raises(TypeError):
        Twin(*args, **kwargs)


def test_a_record_cannot_be_changed() -> None:
    point = Point(1, 2)
    with pytest.raises(dataclasses.FrozenInstanceError):
        point.x = 3  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        del point.y
    assert point == Point(1, 2) and {point: 1}[Point(1, 2)] == 1


@record
class Single:
    x: int


def test_a_record_of_one_field_compares_and_hashes_by_it() -> None:
    assert Single(1) == Single(x=1) and Single(1) != Single(2) and hash(Single(1)) == hash((1,))
    assert repr(Single(1)) == "Single(x=1)"
