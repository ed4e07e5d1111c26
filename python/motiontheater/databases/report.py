"""The database report of a check: one object per finding as JSON, a CSV table, or one
self-contained HTML page with the table (sortable by every column), a small plot of each
finding's worst channel and a link that opens the viewer at its frame."""

from __future__ import annotations

import csv
import html
import io
import json
import os
from collections.abc import Sequence
from pathlib import Path

from .._io import Source, output
from .findings import SEVERITIES
from .survey import Curve, TakeCheck

REPORT_SUFFIXES = (".html", ".json", ".csv")
COLUMNS = ("take", "kind", "severity", "joints", "first", "last", "size", "unit", "channel", "detail", "fix")


def rows(checks: Sequence[TakeCheck], least: str = "low") -> list[dict]:
    """One object per finding of at least severity ``least``, take by take."""
    floor = SEVERITIES.index(least)
    return [f.as_dict() for c in checks for f in c.findings if f.rank >= floor]


def json_text(checks: Sequence[TakeCheck], least: str = "low") -> str:
    """The findings as a JSON list (see :func:`rows`)."""
    return json.dumps(rows(checks, least), indent=1, ensure_ascii=False) + "\n"


def csv_text(checks: Sequence[TakeCheck], least: str = "low") -> str:
    """The findings as a CSV table: a row each, joints and fixes separated by spaces."""
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(COLUMNS)
    for row in rows(checks, least):
        row = dict(row, joints=" ".join(row["joints"]), fix=" ".join(row["fix"]))
        writer.writerow(["" if row[c] is None else row[c] for c in COLUMNS])
    return text.getvalue()


def write_report(
    checks: Sequence[TakeCheck], target: str | os.PathLike, least: str = "low", views: dict[str, str] | None = None
) -> None:
    """Write the report by the target's suffix (.html, .json or .csv), whole or not at all.
    ``views`` maps a take to its viewer page (a path relative to the report) for the HTML links."""
    suffix = Path(target).suffix.lower()
    if suffix not in REPORT_SUFFIXES:
        raise ValueError(f"{os.fspath(target)}: a report is {', '.join(REPORT_SUFFIXES)}; got {suffix or 'no suffix'}")
    text = {".json": json_text, ".csv": csv_text}.get(suffix)
    body = text(checks, least) if text else page(checks, least, views or {})
    _write(target, body)


def _write(target: Source, text: str) -> None:
    with output(target) as f:
        f.write(text.encode("utf-8"))


SEVERITY_COLOURS = {"high": "#c0392b", "medium": "#d68910", "low": "#7f8c8d"}


def _plot(curve: Curve | None, first: int, last: int) -> str:
    """A small SVG of the curve, the finding's frames shaded."""
    if curve is None or not curve.frames:
        return ""
    width, height = 160, 36
    values = [v for v in curve.values if v is not None]
    if not values:
        return ""
    low, high = min(values), max(values)
    span = (high - low) or 1.0
    f0, f1 = curve.frames[0], curve.frames[-1]
    across = (f1 - f0) or 1

    def x(frame: float) -> float:
        return round((frame - f0) / across * (width - 2) + 1, 1)

    def y(value: float) -> float:
        return round(height - 2 - (value - low) / span * (height - 4), 1)

    runs: list[list[str]] = []
    run: list[str] = []
    for frame, value in zip(curve.frames, curve.values):
        if value is None:
            if run:
                runs.append(run)
            run = []
        else:
            run.append(f"{x(frame)},{y(value)}")
    if run:
        runs.append(run)
    lines = "".join(f'<polyline points="{" ".join(r)}"/>' for r in runs)
    shade = f'<rect x="{x(first - 0.5)}" y="0" width="{max(x(last + 0.5) - x(first - 0.5), 1.5)}" height="{height}"/>'
    label = f"{low:.3g} to {high:.3g} {curve.unit}, frames {f0}-{f1}"
    return (
        f'<svg class="plot" width="{width}" height="{height}" viewBox="0 0 {width} {height}" role="img">'
        f"<title>{html.escape(label)}</title>{shade}{lines}</svg>"
    )


def page(checks: Sequence[TakeCheck], least: str = "low", views: dict[str, str] | None = None) -> str:
    """The HTML report: a summary line and a table of every finding of at least ``least``."""
    views = views or {}
    floor = SEVERITIES.index(least)
    body = []
    counts = {s: 0 for s in SEVERITIES}
    for check in checks:
        for finding, curve in zip(check.findings, check.curves or (None,) * len(check.findings)):
            counts[finding.severity] += 1
            if finding.rank < floor:
                continue
            take = html.escape(finding.take)
            view = views.get(check.take)
            if view is not None and finding.first >= check.first_frame:
                joint = f"&joint={finding.joints[0]}" if len(finding.joints) == 1 else ""
                # a file cut short: its findings past the frames it holds open at the last it holds
                at = min(finding.first, check.first_frame + max(check.frames - 1, 0))
                href = html.escape(f"{view}#frame={at}{joint}", quote=True)
                take = f'<a href="{href}" title="open the viewer at frame {at}">{take}</a>'
            frames = (
                ""
                if finding.last < finding.first
                else f"{finding.first}"
                if finding.last == finding.first
                else f"{finding.first}&ndash;{finding.last}"
            )
            fix = ", ".join(name for name, _ in finding.fix) if finding.severity != "low" else ""
            body.append(
                f'<tr data-rank="{finding.rank}"><td data-key="{finding.rank}">'
                f'<span class="sev {finding.severity}">{finding.severity}</span></td>'
                f"<td>{html.escape(finding.kind)}</td><td>{take}</td>"
                f"<td>{html.escape(', '.join(finding.joints))}</td>"
                f'<td data-key="{finding.first}">{frames}</td>'
                f'<td data-key="{finding.size}">{finding.size:.4g} {html.escape(finding.unit)}</td>'
                f"<td>{html.escape(finding.detail)}</td><td>{_plot(curve, finding.first, finding.last)}</td>"
                f"<td>{html.escape(fix)}</td></tr>"
            )
    takes = len(checks)
    troubled = sum(1 for c in checks if any(f.severity != "low" for f in c.findings))
    summary = f"{takes} take{'s' if takes != 1 else ''} checked, {troubled} with medium or high findings: " + ", ".join(
        f"{counts[s]} {s}" for s in reversed(SEVERITIES)
    )
    shown = "" if floor == 0 else f" (findings below {least} are counted, not listed)"
    return _TEMPLATE.format(
        summary=html.escape(summary + shown), rows="\n".join(body), colours=_colours(), script=_SCRIPT
    )


def _colours() -> str:
    return "".join(f".sev.{s}{{background:{c}}}" for s, c in SEVERITY_COLOURS.items())


_SCRIPT = """
(function () {
  const table = document.getElementById("findings");
  const heads = table.tHead.rows[0].cells;
  function key(row, i) {
    const cell = row.cells[i];
    const k = cell.dataset.key;
    return k === undefined ? cell.textContent.toLowerCase() : Number(k);
  }
  function sort(i, descending) {
    const body = table.tBodies[0];
    const rows = Array.from(body.rows);
    rows.sort((a, b) => {
      const x = key(a, i), y = key(b, i);
      const order = x < y ? -1 : x > y ? 1 : 0;
      return descending ? -order : order;
    });
    for (const row of rows) body.appendChild(row);
    for (const h of heads) h.removeAttribute("aria-sort");
    heads[i].setAttribute("aria-sort", descending ? "descending" : "ascending");
  }
  Array.from(heads).forEach((h, i) => {
    if (h.dataset.sort === undefined) return;
    h.addEventListener("click", () => sort(i, h.getAttribute("aria-sort") === "ascending"));
  });
  sort(0, true);
})();
"""

_TEMPLATE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="generator" content="motiontheater check">
<title>motiontheater check</title>
<style>
body {{ font: 14px system-ui, sans-serif; margin: 1.5em; color: #222; }}
table {{ border-collapse: collapse; width: 100%; }}
th, td {{ border-bottom: 1px solid #ddd; padding: 4px 6px; text-align: left; vertical-align: middle; }}
th[data-sort] {{ cursor: pointer; user-select: none; }}
th[aria-sort=ascending]::after {{ content: " \\25B2"; }}
th[aria-sort=descending]::after {{ content: " \\25BC"; }}
.sev {{ color: white; border-radius: 3px; padding: 1px 5px; font-size: 12px; }}
{colours}
svg.plot polyline {{ fill: none; stroke: #2c3e50; stroke-width: 1.2; }}
svg.plot rect {{ fill: #f5b7b1; }}
</style></head>
<body>
<h1>motiontheater check</h1>
<p id="summary">{summary}</p>
<table id="findings">
<thead><tr><th data-sort>severity</th><th data-sort>kind</th><th data-sort>take</th><th data-sort>joints</th>
<th data-sort>frames</th><th data-sort>size</th><th>what</th><th>worst channel</th><th>fix</th></tr></thead>
<tbody>
{rows}
</tbody></table>
<script>{script}</script>
</body></html>
"""
