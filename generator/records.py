"""`@record`: what `@dataclass(frozen=True)` gives the generator's model (the fields' `__init__`, `__repr__`,
`__eq__`, `__hash__`, no assignment after `__init__`), from generic methods instead of code compiled per class.

dataclasses compiles each method of each class from text when the class is made: about 27 ms of every run of
the generator for its 33 frozen classes, as much as reading and checking the spec.
"""

from __future__ import annotations

import operator
from dataclasses import FrozenInstanceError
from typing import TYPE_CHECKING, Any, Callable, TypeVar

T = TypeVar("T")

if TYPE_CHECKING:  # typing has it from Python 3.11; the generator runs on 3.9
    from typing_extensions import dataclass_transform
else:
    def dataclass_transform(**_: object) -> Callable[[T], T]:
        return lambda decorated: decorated


@dataclass_transform(frozen_default=True)
def record(cls: type[T]) -> type[T]:
    """The class with the methods of a frozen dataclass of its annotated fields (in order, defaults last)."""
    names = tuple(cls.__dict__.get("__annotations__", {}))  # noqa: RUF063 (in order; strings: not evaluated)
    defaults = {name: cls.__dict__[name] for name in names if name in cls.__dict__}
    count = len(names)
    put = object.__setattr__

    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        if len(args) == count and not kwargs:  # the common call: every field by position
            for name, value in zip(names, args):
                put(self, name, value)
            return
        if len(args) > count:
            raise TypeError(f"{cls.__name__}() takes {count} fields but {len(args)} were given")
        values = dict(zip(names, args))
        for name, value in kwargs.items():
            if name not in names or name in values:
                problem = "multiple values for" if name in values else "an unexpected keyword"
                raise TypeError(f"{cls.__name__}() got {problem} argument '{name}'")
            values[name] = value
        for name in names:
            value = values.get(name, defaults.get(name, values))
            if value is values:
                raise TypeError(f"{cls.__name__}() missing a required argument: '{name}'")
            put(self, name, value)

    get = operator.attrgetter(*names) if count > 1 else None

    def fields(self: Any) -> tuple[Any, ...]:  # hashing a Spec (lru_cache keys) calls this thousands of times
        return get(self) if get is not None else tuple(getattr(self, name) for name in names)

    def __repr__(self: Any) -> str:
        return f"{type(self).__qualname__}({', '.join(f'{name}={getattr(self, name)!r}' for name in names)})"

    def __eq__(self: Any, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return bool(fields(self) == fields(other))

    def __hash__(self: Any) -> int:
        return hash(fields(self))

    def __setattr__(self: Any, name: str, value: Any) -> None:
        raise FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self: Any, name: str) -> None:
        raise FrozenInstanceError(f"cannot delete field {name!r}")

    for method in (__init__, __repr__, __eq__, __hash__, __setattr__, __delattr__):
        method.__qualname__ = f"{cls.__qualname__}.{method.__name__}"
        setattr(cls, method.__name__, method)
    return cls
