"""The ready line's one rule (spec `replies.ready`) and the odd lines every decoder must judge the same way.

Rule: after the prefix, exactly three fields, each after exactly one space (0x20): the protocol (1 to MAX_NAME of
[a-z0-9_]), the fingerprint (exactly its 16 lower-case hex digits) and the integrity mode (one the generator
knows). Nothing else is on the line but, in crc8 mode, its check, and the CR/LF bytes that end every reply.
A line that starts with the prefix and breaks the rule is a malformed ready reply, never a ready line."""

from __future__ import annotations

from .model import INTEGRITY_MODES, Spec, check_text
from .names import MAX_NAME
from .records import record

SEPARATOR = " "
PROTOCOL_CHARACTERS = "0123456789_abcdefghijklmnopqrstuvwxyz"
FINGERPRINT_CHARACTERS = "0123456789abcdef"
FINGERPRINT_LENGTH = 16
PROTOCOL_MAX = MAX_NAME

# What may stand where the rule wants one space: nothing, spaces, and every byte some language's idea of
# whitespace includes (C's isspace, Python's str.split, JavaScript's \s over Latin-1, Rust's is_ascii_whitespace).
GAPS = ("", "  ", "   ", "\t", "\v", "\f", "\r", "\n", "\x00", "\x1c", "\x1d", "\x1e", "\x1f", "\x85", "\xa0",
        " \t", "\t ", " \v", "\r ", " \x00")


@record
class ReadyVector:
    """One line (as received, its check and line end included) and what parsing it must give."""

    line: bytes
    kind: str  # "ready", "malformed" or "unknown"
    note: str
    fields: tuple[str, str, str] = ("", "", "")


def ready_rule() -> dict[str, object]:
    """The rule's parameters, as the templates print them into every codec."""
    return {"separator": SEPARATOR, "protocol_characters": PROTOCOL_CHARACTERS, "protocol_max": PROTOCOL_MAX,
            "fingerprint_characters": FINGERPRINT_CHARACTERS, "fingerprint_length": FINGERPRINT_LENGTH,
            "integrity_modes": INTEGRITY_MODES}


def ready_fields(spec: Spec) -> tuple[str, str, str]:
    return spec.name, spec.short_fingerprint, spec.integrity


def field_problem(index: int, word: str) -> str | None:
    """Why `word` cannot be field `index` of a ready line, or None: the rule, as the generator checks it."""
    if index == 0 and not (1 <= len(word) <= PROTOCOL_MAX and set(word) <= set(PROTOCOL_CHARACTERS)):
        return f"protocol {word!r} is not 1 to {PROTOCOL_MAX} of [a-z0-9_]"
    if index == 1 and not (len(word) == FINGERPRINT_LENGTH and set(word) <= set(FINGERPRINT_CHARACTERS)):
        return f"fingerprint {word!r} is not {FINGERPRINT_LENGTH} lower-case hex digits"
    if index == 2 and word not in INTEGRITY_MODES:
        return f"integrity {word!r} is not one of {', '.join(INTEGRITY_MODES)}"
    return None


def judge(spec: Spec, line: bytes) -> tuple[str, tuple[str, str, str]]:
    """What the rule says of one received line: ("ready", fields), ("malformed", _), ("bad_check", _) or
    ("unknown", _) when it does not start with the prefix. As for every reply, the CR/LF bytes that end the line
    are dropped first, then in crc8 mode the check after the last '*' is verified and dropped."""
    none = ("", "", "")
    body = line.rstrip(b"\r\n")
    if spec.integrity != "none":
        body, star, check = body.rpartition(b"*")
        if not star or check != check_text(body).encode():
            return "bad_check", none
    text = body.decode("latin-1")
    prefix = spec.reply("ready").prefix
    if not text.startswith(prefix):
        return "unknown", none
    words = text[len(prefix):].split(SEPARATOR)
    if len(words) != 4 or words[0] != "" or any(field_problem(i, w) for i, w in enumerate(words[1:])):
        return "malformed", none
    return "ready", (words[1], words[2], words[3])


def on_wire(spec: Spec, body: str, end: str = "\n") -> bytes:
    """A line as the firmware would send it: with its correct check in crc8 mode, then `end`."""
    data = body.encode("latin-1")
    if spec.integrity != "none":
        data += b"*" + check_text(data).encode()
    return data + end.encode("latin-1")


def variants(spec: Spec) -> list[tuple[str, str]]:
    """(body, note) of odd ready lines: every gap replaced by every odd gap, case, extra and missing fields,
    every truncation, and the fields' own edges. Bodies are Latin-1 text (one character per byte)."""
    prefix = spec.reply("ready").prefix
    fields = ready_fields(spec)
    good = prefix + "".join(SEPARATOR + f for f in fields)

    def line(protocol: str = fields[0], fingerprint: str = fields[1], integrity: str = fields[2]) -> str:
        return prefix + SEPARATOR + protocol + SEPARATOR + fingerprint + SEPARATOR + integrity

    out: list[tuple[str, str]] = [(good, "the firmware's own line")]
    for gap_index in range(5):  # 0: before the prefix, 1-3: before each field, 4: after the last
        for gap in GAPS:
            gaps = ["", SEPARATOR, SEPARATOR, SEPARATOR, ""]
            gaps[gap_index] = gap if gap_index in (1, 2, 3) else gaps[gap_index] + (gap or SEPARATOR)
            body = gaps[0] + prefix + "".join(g + f for g, f in zip(gaps[1:4], fields)) + gaps[4]
            out.append((body, f"gap {gap_index} is {gap!r}"))
    out += [
        (prefix.lower() + good[len(prefix):], "the prefix in lower case"),
        (line(*(f.upper() for f in fields)), "the fields in upper case"),
        (line(fields[0].upper()), "the protocol in upper case"),
        (good + SEPARATOR + "extra", "a fourth field"),
        (good + SEPARATOR + fields[2], "the integrity twice"),
        (prefix + SEPARATOR + fields[0] + SEPARATOR + fields[2], "no fingerprint"),
        (line(fingerprint=fields[1][:-1]), "a fingerprint one short"),
        (line(fingerprint=fields[1] + "0"), "a fingerprint one long"),
        (line("x" * (PROTOCOL_MAX + 1)), "a protocol too long"),
        (line("x" * PROTOCOL_MAX), "a protocol at its longest"),
        (line("other_protocol"), "another protocol"),
        (line(fingerprint="0123456789abcdef"), "another fingerprint"),
        (line("drone-protocol"), "a hyphen in the protocol"),
        (line(fields[0] + "\xe9"), "a byte above ASCII"),
        (good + "*", "a stray star"),
    ]
    out += [(line(integrity=m), f"integrity mode {m}") for m in INTEGRITY_MODES]
    out += [(good[:n], f"truncated to {n} characters") for n in range(len(good))]
    first: dict[str, str] = {}
    for body, note in out:
        first.setdefault(body, note)
    return list(first.items())


def build_ready_vectors(spec: Spec) -> tuple[ReadyVector, ...]:
    """The shared vectors of vectors.json: each odd line (with its correct check in crc8 mode) judged by the
    rule, plus the line ends every reply accepts and, in crc8 mode, a wrong check."""
    lines = [(on_wire(spec, body), note) for body, note in variants(spec)]
    good = variants(spec)[0][0]
    lines += [(on_wire(spec, good, end), note) for end, note in
              (("", "no line end"), ("\r\n", "a CR LF line end"), ("\r\r\n", "two CRs before the LF"))]
    if spec.integrity != "none":
        own = on_wire(spec, good)
        lines.append((own[:-3] + (b"01" if own.endswith(b"00\n") else b"00") + b"\n", "a wrong check"))
    out = []
    for line, note in lines:
        kind, fields = judge(spec, line)
        out.append(ReadyVector(line, kind, note, fields))
    return tuple(out)
