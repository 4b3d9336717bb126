"""Conformance vectors: every command at its edges, and malformed frames with the error they must give."""

from __future__ import annotations

import string

from .model import Category, Direction, Spec, Vector, check_text


def build_vectors(spec: Spec) -> tuple[Vector, ...]:
    """Every vector's frame as it goes on the wire: in crc8 mode a complete frame carries its correct check."""
    return tuple(_dedupe([_on_wire(spec, v) for v in _frames(spec)] + _check_vectors(spec)))


def _on_wire(spec: Spec, v: Vector) -> Vector:
    if spec.integrity == "none" or len(v.frame) != spec.frame_length:
        return v
    frame = v.frame + check_text(v.frame).encode()
    return Vector(frame, v.note, v.command, v.category, v.direction, v.value, v.error, v.position)


def _check_vectors(spec: Spec) -> list[Vector]:
    """crc8 mode: checks that do not match, are not hex, or are lower case; a digit corrupted into another in range;
    the frame with half its check or a byte too many. Each check digit is compared as it arrives (as the C++
    StreamParser does), so the error is at the first wrong digit, and comes before the range check."""
    if spec.integrity == "none":
        return []
    n = spec.frame_length
    first = spec.commands[0]
    frame = first.direction.frame(first.category.code, first.direction.default_frame_value).encode()
    check = check_text(frame).encode()
    wrong = b"%02X" % ((int(check, 16) + 1) % 256)
    def bad(given: bytes, note: str) -> Vector:  # the first check digit that differs is the error's position
        at = next(i for i in range(len(given)) if given[i] != check[i])
        return _invalid(frame + given, "bad_check", n + at, note)

    out = [
        bad(wrong, "a check that does not match the frame"),
        bad(b"g" + check[1:], "a check that is not hex"),
        bad(check[:1] + b"-", "a check whose second digit is not hex"),
        _invalid(frame + check + b"0", "too_long", n + 2, "a frame and its check, one byte too many"),
        _invalid(frame + check[:1], "too_short", n + 1, "a frame missing half its check"),
    ]
    if check.lower() != check:
        out.append(bad(check.lower(), "a check in lower case"))
    for pos in range(2, n):  # one corrupted value digit: still digits, so only the check catches it
        digit = frame[pos:pos + 1]
        other = b"7" if digit != b"7" else b"3"
        corrupted = frame[:pos] + other + frame[pos + 1:]
        d = first.direction
        right = check_text(corrupted).encode()
        if d.minimum <= int(corrupted[2:]) <= d.maximum:
            at = next(i for i in range(2) if check[i] != right[i])
            out.append(_invalid(corrupted + check, "bad_check", n + at, f"byte {pos} corrupted, caught by the check"))
            break
    return out


def _frames(spec: Spec) -> list[Vector]:
    out: list[Vector] = []
    for cmd in spec.commands:
        cat, d = cmd.category, cmd.direction
        cases = [("minimum", d.minimum), ("maximum", d.maximum)]
        if d.default is not None:
            cases.append(("default", d.default))
        for note, value in cases:
            out.append(_valid(cat, d, value, f"{d.command} at its {note}"))
        if d.minimum > 0:
            out.append(_invalid(d.frame(cat.code, d.minimum - 1).encode(), "out_of_range", 2,
                                f"{d.command} just below its minimum"))
        if d.maximum < 10 ** d.field.width - 1:
            out.append(_invalid(d.frame(cat.code, d.maximum + 1).encode(), "out_of_range", 2,
                                f"{d.command} just above its maximum"))
    out.extend(_malformed(spec))
    return out


def _valid(cat: Category, d: Direction, value: int, note: str) -> Vector:
    return Vector(d.frame(cat.code, value).encode(), note, d.command, cat.code, d.code, value, "", -1)


def _invalid(frame: bytes, error: str, position: int, note: str) -> Vector:
    return Vector(frame, note, "", "", "", 0, error, position)


def _malformed(spec: Spec) -> list[Vector]:
    width = spec.digits_width
    first = spec.commands[0]
    good = first.direction.frame(first.category.code, first.direction.default_frame_value).encode()
    codes = {c.code for c in spec.categories}
    out = []
    for bad in ("x", "1", "M", " "):
        if bad not in codes:
            out.append(_invalid(bad.encode() + good[1:], "bad_category", 0, f"category {bad!r} does not exist"))
    out.append(_invalid(b"\x00" + good[1:], "bad_category", 0, "a NUL byte as category"))
    out.append(_invalid(b"\xff" + good[1:], "bad_category", 0, "a byte above ASCII as category"))
    for cat in spec.categories:
        taken = {d.code for d in cat.directions}
        # a space is never a code: the fallback when a category takes every printable character
        bad = next(c for c in "zqZ9" + string.ascii_letters + string.punctuation + " " if c not in taken)
        d = cat.directions[0]
        frame = d.frame(cat.code, d.default_frame_value).encode()
        out.append(_invalid(frame[:1] + bad.encode() + frame[2:], "bad_direction", 1,
                            f"direction {bad!r} is not one of category {cat.code!r}"))
        for pos in range(2, spec.frame_length):
            for junk in (b"a", b" ", b"-"):
                broken = frame[:pos] + junk + frame[pos + 1:]
                out.append(_invalid(broken, "bad_digit", pos, f"{junk.decode()!r} at byte {pos} is not a digit"))
    for n in range(spec.frame_length):
        out.append(_invalid(good[:n], "too_short", n, f"a frame of {n} bytes"))
    if spec.integrity == "none":
        out.append(_invalid(good + b"0", "too_long", spec.frame_length, "a frame of one byte too many"))
    # The seed's own mistakes: the laser frame written with a '1', "mf0005 moves 5 ft", and -5 encoded.
    for cat in spec.categories:
        if cat.filler and "1" not in codes:
            d = cat.directions[0]
            out.append(_invalid(b"1" + d.frame(cat.code, d.default_frame_value).encode()[1:], "bad_category", 0,
                                "the laser frame as the seed's code comment writes it"))
    if not first.direction.minimum <= 5 <= first.direction.maximum:
        out.append(_invalid(first.direction.frame(first.category.code, 5).encode(), "out_of_range", 2,
                            "createCommand's example value 5 (a distance, not a speed)"))
    out.append(_invalid(good[:2] + b"0" * (width - 2) + b"-5", "bad_digit", spec.frame_length - 2,
                        "createCommand's encoding of -5"))
    return out


def _dedupe(vectors: list[Vector]) -> list[Vector]:
    seen: set[bytes] = set()
    out = []
    for v in vectors:
        if v.frame not in seen:
            seen.add(v.frame)
            out.append(v)
    return out
