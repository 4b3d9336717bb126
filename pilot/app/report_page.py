"""The flight report's page: inline SVG charts against one time axis, and the path picture as a data: URI, so
that the page needs nothing but itself (no script, no font, no request)."""

from __future__ import annotations

import base64
import html
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

from ..control.controller import State

WIDTH, LEFT, RIGHT = 960, 110, 20  # the charts' size and margins, pixels
PLOT = WIDTH - LEFT - RIGHT
STATE_COLOURS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1", "#ff9da7",
                 "#9c755f", "#bab0ac", "#86bcb6")


@dataclass
class Flight:
    """What the report reads out of log.jsonl."""

    ticks: list[dict[str, Any]] = field(default_factory=list)
    link: list[dict[str, Any]] = field(default_factory=list)
    result: dict[str, Any] = field(default_factory=dict)

    @property
    def end(self) -> float:
        times = [r["t"] for r in self.ticks + self.link]
        return max(times, default=0.0) or 1.0

    def failure(self) -> str:
        """Why the flight did not end well, from its result and its last transitions ("" when it did)."""
        reasons = []
        for key in ("wall_hits", "crashes"):
            if self.result.get(key):
                reasons.append(f"{key.replace('_', ' ')}: {self.result[key]}")
        for t in self.result.get("transitions", []):
            if t.get("to") == State.LAND.value and t.get("from") != State.FIRE.value:  # after firing: the end
                reasons.append(f"landed at {t.get('t_ms', 0) / 1000:.1f} s from {t.get('from')}: {t.get('why', '')}")
        if not any(r.get("laser") for r in self.ticks):
            reasons.append("the laser never came on")
        return "; ".join(reasons)


def _x(t: float, end: float) -> float:
    return LEFT + PLOT * max(0.0, min(1.0, t / end))


def _svg(ident: str, height: int, body: list[str], end: float, title: str) -> str:
    ticks = [f'<line x1="{_x(s, end):.1f}" x2="{_x(s, end):.1f}" y1="0" y2="{height - 16}" class="grid"/>'
             f'<text x="{_x(s, end):.1f}" y="{height - 3}" class="axis">{s:g} s</text>'
             for s in _seconds(end)]
    return (f'<h2>{html.escape(title)}</h2><svg id="{ident}" width="{WIDTH}" height="{height}" '
            f'viewBox="0 0 {WIDTH} {height}" shape-rendering="crispEdges" role="img" aria-label="{html.escape(title)}">'
            + "".join(ticks) + "".join(body) + "</svg>")


def _seconds(end: float) -> list[float]:
    step = next(s for s in (1, 2, 5, 10, 20, 30, 60, 120, 300, 600, 1e9) if end / s <= 12)
    return [k * step for k in range(int(end // step) + 1)]


def timeline(f: Flight) -> str:
    states = list(dict.fromkeys(r["state"] for r in f.ticks))
    colour = {s: STATE_COLOURS[i % len(STATE_COLOURS)] for i, s in enumerate(states)}
    body = []
    for a, b in zip(f.ticks, [*f.ticks[1:], None]):
        t1 = b["t"] if b is not None else a["t"] + 0.05
        x0, x1 = _x(a["t"], f.end), _x(t1, f.end)
        body.append(f'<rect x="{x0:.1f}" y="4" width="{max(0.5, x1 - x0):.1f}" height="26" '
                    f'fill="{colour[a["state"]]}" data-state="{html.escape(a["state"])}"><title>'
                    f'{a["t"]:.2f} s {html.escape(a["state"])}</title></rect>')
    legend = "".join(f'<span class="key" style="background:{colour[s]}"></span>{html.escape(s)} ' for s in states)
    return _svg("timeline", 50, body, f.end, "State timeline") + f'<p class="legend">{legend}</p>'


def commands(f: Flight) -> str:
    names = [r["command"] for r in f.ticks if r.get("command")]
    kinds = sorted({n[:2] for n in names})
    row = {k: i for i, k in enumerate(kinds)}
    height = 24 + 16 * max(1, len(kinds))
    body = [f'<text x="4" y="{14 + 16 * i}" class="axis">{html.escape(k)}</text>' for k, i in row.items()]
    body += [f'<circle cx="{_x(r["t"], f.end):.1f}" cy="{10 + 16 * row[r["command"][:2]]}" r="2" class="cmd">'
             f'<title>{r["t"]:.2f} s {html.escape(r["command"])}</title></circle>'
             for r in f.ticks if r.get("command")]
    counts = ", ".join(f"{html.escape(k)} {n}" for k, n in Counter(n[:2] for n in names).most_common())
    return _svg("commands", height, body, f.end, f"Commands ({len(names)} sent: {counts or 'none'})")


def _line(ident: str, title: str, points: list[tuple[float, float]], end: float, top: float, label: str) -> str:
    height, plot_h = 110, 80
    xy = " ".join(f"{_x(t, end):.1f},{8 + plot_h * (1 - min(v, top) / top):.1f}" for t, v in points)
    body = [f'<text x="4" y="14" class="axis">{html.escape(label)}</text>',
            f'<text x="4" y="{8 + plot_h}" class="axis">0</text>',
            f'<polyline points="{xy}" class="series"/>']
    return _svg(ident, height, body, end, title)


def confidence(f: Flight) -> str:
    pts = [(r["t"], (r["detection"] or {}).get("confidence", 0.0) if (r["detection"] or {}).get("found") else 0.0)
           for r in f.ticks]
    return _line("confidence", "Detection confidence", pts, f.end, 1.0, "1.0")


def laser(f: Flight) -> str:
    pts: list[tuple[float, float]] = []
    for r in f.ticks:
        v = 1.0 if r.get("laser") else 0.0
        if pts:
            pts.append((r["t"], pts[-1][1]))
        pts.append((r["t"], v))
    lit = sum(b["t"] - a["t"] for a, b in zip(f.ticks, f.ticks[1:]) if a.get("laser"))
    return _line("laser", f"Laser (confirmed on {lit:.1f} s)", pts, f.end, 1.0, "on")


def link_health(f: Flight) -> str:
    """Replies a second, refusals and failsafes a second, and the link's own events (garbage, reopening)."""
    seconds = int(f.end) + 1
    replies, refused = [0] * seconds, [0] * seconds
    for r in f.ticks:
        for text in r.get("replies", []):
            s = min(seconds - 1, int(r["t"]))
            replies[s] += 1
            refused[s] += text.startswith(("REJECTED", "FAILSAFE"))
    top = float(max([*replies, 1]))
    body = [f'<text x="4" y="14" class="axis">{top:g}/s</text>', '<text x="4" y="88" class="axis">0</text>']
    for name, series in (("replies", replies), ("refused", refused)):
        xy = " ".join(f"{_x(s + 0.5, f.end):.1f},{8 + 80 * (1 - v / top):.1f}" for s, v in enumerate(series))
        body.append(f'<polyline points="{xy}" class="{name}"/>')
    events = [e for e in f.link if e["link"] not in ("tx", "rx")]
    body += [f'<line x1="{_x(e["t"], f.end):.1f}" x2="{_x(e["t"], f.end):.1f}" y1="8" y2="88" class="event">'
             f'<title>{e["t"]:.2f} s {html.escape(e["link"])}: {html.escape(str(e["data"]))}</title></line>'
             for e in events]
    title = (f"Link health: {sum(replies)} replies, {sum(refused)} refused or failsafe, {len(events)} link events "
             "(replies a second in blue, refusals in red, events as grey lines)")
    return _svg("link", 110, body, f.end, title)


STYLE = """body{font:14px sans-serif;margin:20px;color:#222}h1{font-size:20px}h2{font-size:15px;margin:18px 0 4px}
.grid{stroke:#ddd}.axis{font-size:11px;fill:#555}.series,.replies{fill:none;stroke:#4e79a7;stroke-width:1.5}
.refused{fill:none;stroke:#e15759;stroke-width:1.5}.event{stroke:#999;stroke-dasharray:3 2}.cmd{fill:#333}
.key{display:inline-block;width:12px;height:12px;margin:0 4px 0 10px;vertical-align:middle}
.fail{color:#b00;font-weight:bold}.ok{color:#070;font-weight:bold}img{max-width:960px;border:1px solid #ccc}"""


def page(f: Flight, name: str, path_png: bytes | None) -> str:
    failure = f.failure()
    verdict = (f'<p id="failure" class="fail">Failure: {html.escape(failure)}</p>' if failure else
               '<p id="failure" class="ok">No failure: the laser came on and the flight ended without a hit.</p>')
    reason = html.escape(str(f.result.get("reason", "no result recorded (the flight did not end cleanly)")))
    path = (f'<h2>Path</h2><img id="path" alt="the path from above" '
            f'src="data:image/png;base64,{base64.b64encode(path_png).decode()}">' if path_png else
            '<h2>Path</h2><p id="path">No path picture (a real flight has no position).</p>')
    return (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>Flight report: '
            f'{html.escape(name)}</title><style>{STYLE}</style></head><body>'
            f'<h1>Flight report: {html.escape(name)}</h1><p>{len(f.ticks)} ticks over {f.end:.1f} s; ended: '
            f'<span id="reason">{reason}</span></p>{verdict}'
            + timeline(f) + commands(f) + confidence(f) + laser(f) + link_health(f) + path + "</body></html>\n")
