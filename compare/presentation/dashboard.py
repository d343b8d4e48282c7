"""The regression dashboard: a static site drawn from a history store, opened from the file system.

``index.html``: the presets with their latest verdict and verdict history, what changed at each
preset's latest commit against its previous one (verdict, statuses, metrics moved beyond their floors,
change points), and the most recent change points.  One page per preset: overview charts (worst gated
NRMSE over its tolerance, modal maximum relative error, natural frequencies against the first
commit, integration error over tolerance, wall times), its change points, its runs, and per quantity
the NRMSE over commits with its tolerance line and the reference solver's RMS and peak-to-peak (as
changes from the first run; tooltips give the values).

Charts are inline SVG written here: no script, no network, no files beside the pages.  A change point
(see :func:`gearcheck.compare.presentation.history.change_points`) is an element of class ``change-point`` carrying
``data-commit`` (the full commit id) and ``data-metric``; charts mark it with a diamond, a dashed guide
and the short commit id.  The site is a function of the store alone (no rendering time in it), so
rendering a store twice gives the same bytes, and it is written whole or not at all.
"""

from __future__ import annotations

import html
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from gearcheck.compare.presentation import history
from gearcheck.compare.presentation.html_page import page
from gearcheck.shared.outputs import OutputDirectory

PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#17becf", "#bcbd22", "#7f7f7f")
TOLERANCE_COLOR = "#d62728"
CHANGE_COLOR = "#c51b7d"
STATUS_COLOR = {"PASS": "#2ca02c", "FAIL": "#d62728", "INCONCLUSIVE": "#ff7f0e", "pass": "#2ca02c",
                "fail": "#d62728", "unresolved": "#ff7f0e", "negligible": "#999999"}
WIDTH, HEIGHT = 560, 230
LEFT, RIGHT, TOP, BOTTOM = 64, 16, 30, 52  # plot margins in the SVG
MAX_POINTS = 150  # above this many commits a line is drawn without its points (change points stay marked)
STRIP = 50  # commits in a preset's verdict strip on the front page
RECENT = 20  # change-point rows on the front page
MOVED_SHOWN = 15  # moved metrics listed per preset on the front page
RUNS_SHOWN = 50  # runs listed on a preset page
SHORT = 7  # characters of a commit id shown


@dataclass
class Line:
    """One series of a chart: its values over the chart's commits (None: not recorded)."""

    label: str
    values: list
    color: str
    metric: str = ""
    marks: list = field(default_factory=list)  # change-point indices into values
    statuses: list | None = None  # per-point status, colouring its point
    tips: list | None = None  # per-point tooltip text


def render(store, out_dir) -> Path:
    """Write the dashboard of the history store ``store`` into the folder ``out_dir`` (whole or not at all)
    and return its path."""
    metrics, runs, order = history.read(store), history.runs(store), history.commits(store)
    presets = _presets(metrics, runs)
    pages = {"index.html": _index(Path(store).name, order, presets)}
    pages.update({p.page: _preset_page(p) for p in presets})
    with OutputDirectory(out_dir, what="-o") as place:
        for name, text in pages.items():
            (place.path / name).write_text(text, encoding="utf-8", newline="\n")
    return Path(out_dir)


@dataclass
class Preset:
    """One train's history, as the pages show it."""

    name: str
    page: str
    runs: pd.DataFrame  # its runs in commit order
    series: dict  # (item, metric) -> values over its runs
    info: dict  # (item, metric) -> kind, unit, position, strictest tolerance, gated (ever), statuses over its runs
    changes: list  # change points: dicts of index, item, metric, before, after, unit

    @property
    def commits(self) -> list[str]:
        return list(self.runs["commit"])

    def line(self, item: str, metric: str, label: str, color: str) -> Line:
        """A recorded metric as a chart line, with its change points, statuses (when gated) and tooltips."""
        values = self.series.get((item, metric), [None] * len(self.runs))
        info = self.info.get((item, metric), {})
        marks = sorted(c["index"] for c in self.changes if (c["item"], c["metric"]) == (item, metric))
        tips = [None if v is None else f"{t}: {label} {_num(v)}{_unit(info.get('unit'))}"
                for t, v in zip(self._tips(), values)]
        return Line(label, list(values), color, f"{item} {metric}", marks,
                    info.get("statuses") if info.get("gated") else None, tips)

    def aggregate(self, label: str, values: list, metric: str, tolerance: float | None = 1.0) -> Line:
        """A line of a per-run aggregate (a ratio to its ``tolerance``), with its own change points."""
        tips = [None if v is None else f"{t}: {label} {_num(v)}" for t, v in zip(self._tips(), values)]
        return Line(label, values, PALETTE[0], metric, history.change_points(values, tolerance=tolerance), tips=tips)

    def relative(self, item: str, metric: str, label: str, color: str) -> Line:
        """:meth:`line` as the change from its first recorded value, in %."""
        line = self.line(item, metric, label, color)
        first = next((v for v in line.values if v), None)
        line.values = [None if v is None or not first else 100.0 * (v / first - 1.0) for v in line.values]
        return line

    def chart(self, lines: list, **options) -> str:
        return _chart([c[:SHORT] for c in self.commits], self.commits, lines, **options)

    def _tips(self) -> list[str]:
        return [f"{c[:SHORT]} {d}" for c, d in zip(self.commits, self.runs["date"])]


def _presets(metrics: pd.DataFrame, runs: pd.DataFrame) -> list[Preset]:
    out, used = [], set()
    for name in sorted(set(runs["train"])):
        page = "preset-" + (re.sub(r"[^A-Za-z0-9_.-]+", "-", name).strip("-.") or "train")
        while page + ".html" in used:
            page += "-"
        used.add(page + ".html")
        its_runs = runs[runs["train"] == name].reset_index(drop=True)
        place = {c: i for i, c in enumerate(its_runs["commit"])}
        series, info = {}, {}
        its = metrics[metrics["train"] == name]
        columns = ("commit", "position", "item", "metric", "kind", "unit", "value", "tolerance", "status", "gated")
        for commit, position, item, metric, kind, unit, value, tolerance, status, gated in zip(
                *(its[c].tolist() for c in columns)):
            key, i = (item, metric), place[commit]
            if key not in series:
                series[key] = [None] * len(place)
                info[key] = {"kind": kind, "unit": unit, "tolerance": None, "gated": False,
                             "statuses": [None] * len(place)}
            series[key][i] = None if pd.isna(value) else float(value)
            entry = info[key]
            entry["position"], entry["gated"] = position, entry["gated"] or bool(gated)
            entry["statuses"][i] = None if pd.isna(status) else status
            if not pd.isna(tolerance):  # the strictest tolerance the metric had
                entry["tolerance"] = min(tolerance, entry["tolerance"] or math.inf)
        series = dict(sorted(series.items(), key=lambda kv: (info[kv[0]]["position"], kv[0])))
        changes = []
        for key, values in series.items():
            kwargs = history.rule(key[0], info[key]["unit"], info[key]["tolerance"])
            if kwargs is None:
                continue
            for i in history.change_points(values, **kwargs):
                before = next(v for v in reversed(values[:i]) if v is not None)
                changes.append({"index": i, "item": key[0], "metric": key[1], "before": before,
                                "after": values[i], "unit": info[key]["unit"]})
        out.append(Preset(name, page + ".html", its_runs, series, info, changes))
    return out


# ---------------------------------------------------------------- front page

def _index(store_name: str, order: list[str], presets: list[Preset]) -> str:
    body = [f"<h1>gearcheck regression dashboard</h1><p class=\"muted\">History store <code>{_e(store_name)}</code>: "
            f"{len(order)} commit{'s' if len(order) != 1 else ''}, {len(presets)} preset"
            f"{'s' if len(presets) != 1 else ''}"]
    if order:
        body.append(f"; latest commit <code>{_e(order[-1][:SHORT])}</code>")
    body.append(".</p>")
    if not presets:
        body.append("<p>No runs recorded yet.</p>")
        return page("gearcheck regression dashboard", "".join(body))
    body.append("<h2>Latest verdicts</h2><table><tr><th>preset</th><th>verdict</th><th>commit</th><th>date</th>"
                "<th>failures</th><th>unresolved</th><th>verdicts over commits (oldest left)</th></tr>")
    for p in presets:
        last = p.runs.iloc[-1]
        body.append(f"<tr><td><a href=\"{_e(p.page)}\">{_e(p.name)}</a></td><td>{_badge(last['verdict'])}</td>"
                    f"<td><code>{_e(last['commit'][:SHORT])}</code></td><td class=\"nowrap\">{_e(last['date'])}</td>"
                    f"<td>{_failures(last)}</td><td>{_list(last['unresolved'])}</td>"
                    f"<td>{_strip(p.runs)}</td></tr>")
    body.append("</table><h2>Since the previous commit</h2>"
                "<p class=\"muted\">Each preset's latest run against its previous one: a metric moved when it "
                f"changed by more than its floor ({history.TOLERANCE_SHARE:g} × its tolerance, "
                f"{100 * history.RELATIVE_FLOOR:g} % of a physical value); a change point is a move beyond the "
                "metric's noise over its history as well.</p>"
                "<table><tr><th>preset</th><th>commits</th><th>verdict</th><th>status changes</th>"
                "<th>metrics moved</th><th>change points at the latest commit</th></tr>")
    details = []
    for p in presets:
        if len(p.runs) < 2:
            body.append(f"<tr><td>{_e(p.name)}</td><td><code>{_e(p.commits[-1][:SHORT])}</code></td>"
                        f"<td colspan=\"4\" class=\"muted\">first run: nothing to compare</td></tr>")
            continue
        prev, last = p.runs.iloc[-2], p.runs.iloc[-1]
        status_changes, moved = _since_previous(p)
        latest = [c for c in p.changes if c["index"] == len(p.runs) - 1]
        verdict = (_badge(last["verdict"]) if prev["verdict"] == last["verdict"]
                   else f"{_badge(prev['verdict'])} &rarr; {_badge(last['verdict'])}")
        body.append(f"<tr><td><a href=\"{_e(p.page)}\">{_e(p.name)}</a></td>"
                    f"<td><code>{_e(prev['commit'][:SHORT])}</code> &rarr; <code>{_e(last['commit'][:SHORT])}</code>"
                    f"</td><td>{verdict}</td><td class=\"num\">{len(status_changes)}</td>"
                    f"<td class=\"num\">{len(moved)}</td><td class=\"num\">{len(latest)}</td></tr>")
        if status_changes or moved:
            details.append(_moved_table(p, status_changes, moved, latest))
    body.append("</table>")
    body.extend(details)
    body.append("<h2>Recent change points</h2>")
    groups = sorted({(p.runs.iloc[c["index"]]["order"], p.name): (p, c["index"]) for p in presets
                     for c in p.changes}.items(), reverse=True)[:RECENT]
    if not groups:
        body.append("<p>No change points in the history.</p>")
    else:
        body.append("<table><tr><th>commit</th><th>date</th><th>preset</th><th>metrics</th><th>largest moves</th>"
                    "</tr>")
        for (_, name), (p, index) in groups:
            these = sorted((c for c in p.changes if c["index"] == index), key=lambda c: -_rel(c))
            run = p.runs.iloc[index]
            examples = ", ".join(f"{_e(c['item'])} {_e(c['metric'])} ({_pct(c)})" for c in these[:3])
            body.append(f"<tr class=\"change-point\" data-commit=\"{_e(run['commit'])}\" data-train=\"{_e(name)}\">"
                        f"<td><code>{_e(run['commit'][:SHORT])}</code></td><td class=\"nowrap\">{_e(run['date'])}</td>"
                        f"<td class=\"nowrap\"><a href=\"{_e(p.page)}\">{_e(name)}</a></td>"
                        f"<td class=\"num\">{len(these)}</td><td>{examples}</td></tr>")
        body.append("</table>")
    return page("gearcheck regression dashboard", "".join(body))


def _since_previous(p: Preset) -> tuple[list, list]:
    """Status changes (item, metric, before, after) and metrics moved beyond their floors (change dicts)
    between a preset's last two runs."""
    statuses, moved = [], []
    for key, values in p.series.items():
        info = p.info[key]
        before, after = info["statuses"][-2], info["statuses"][-1]
        if info["gated"] and before != after:
            statuses.append((*key, before, after))
        kwargs = history.rule(key[0], info["unit"], info["tolerance"])
        if kwargs is not None and None not in values[-2:] and history.change_points(values[-2:], **kwargs):
            moved.append({"index": len(values) - 1, "item": key[0], "metric": key[1], "before": values[-2],
                          "after": values[-1], "unit": info["unit"]})
    return statuses, moved


def _moved_table(p: Preset, statuses: list, moved: list, latest: list) -> str:
    out = [f"<h3>{_e(p.name)}</h3>"]
    if statuses:
        out.append("<table><tr><th>status changed</th><th>before</th><th>after</th></tr>")
        out.extend(f"<tr><td>{_e(item)} {_e(metric)}</td><td>{_e(before or '-')}</td><td>{_e(after or '-')}</td></tr>"
                   for item, metric, before, after in statuses)
        out.append("</table>")
    if moved:
        marked = {(c["item"], c["metric"]) for c in latest}
        shown = sorted(moved, key=lambda c: -_rel(c))[:MOVED_SHOWN]
        out.append(f"<table><tr><th>metric moved ({len(shown)} largest of {len(moved)})</th><th>before</th>"
                   "<th>after</th><th>move</th><th>change point</th></tr>")
        commit = p.commits[-1]
        for c in shown:
            cp = (c["item"], c["metric"]) in marked
            attrs = (f" class=\"change-point\" data-commit=\"{_e(commit)}\" data-metric=\"{_e(c['item'])} "
                     f"{_e(c['metric'])}\"" if cp else "")
            out.append(f"<tr{attrs}><td>{_e(c['item'])} {_e(c['metric'])}</td><td class=\"num\">{_num(c['before'])}"
                       f"</td><td class=\"num\">{_num(c['after'])}{_unit(c['unit'])}</td>"
                       f"<td class=\"num\">{_pct(c)}</td><td>{'yes' if cp else ''}</td></tr>")
        out.append("</table>")
    return "".join(out)


def _strip(runs: pd.DataFrame) -> str:
    """A row of squares, one per run (the last STRIP), coloured by verdict."""
    shown = runs.iloc[-STRIP:]
    parts = [f"<svg width=\"{9 * len(shown)}\" height=\"12\" viewBox=\"0 0 {9 * len(shown)} 12\" role=\"img\">"]
    for n, (_, run) in enumerate(shown.iterrows()):
        parts.append(f"<rect x=\"{9 * n}\" y=\"2\" width=\"8\" height=\"8\" fill=\"{_color(run['verdict'])}\">"
                     f"<title>{_e(run['commit'][:SHORT])} {_e(run['date'])}: {_e(run['verdict'])}</title></rect>")
    return "".join(parts) + "</svg>"


# ---------------------------------------------------------------- preset pages

def _preset_page(p: Preset) -> str:
    last = p.runs.iloc[-1]
    body = [f"<p><a href=\"index.html\">&larr; all presets</a></p><h1>{_e(p.name)} {_badge(last['verdict'])}</h1>",
            f"<p>{len(p.runs)} run{'s' if len(p.runs) != 1 else ''}; latest <code>{_e(last['commit'][:SHORT])}</code> "
            f"({_e(last['date'])}) on {_e(last['machine'] or '?')}: gearcheck {_e(last['gearcheck_version'] or '?')}, "
            f"MuJoCo {_e(last['mujoco_version'] or '?')}, NumPy {_e(last['numpy_version'] or '?')}.</p>",
            "<h2>Overview</h2><div class=\"grid\">"]
    for title, svg in _overview(p):
        body.append(_figure(title, svg))
    body.append("</div><h2>Change points</h2>")
    for index in sorted({c["index"] for c in p.changes}, reverse=True):
        commit, date = p.commits[index], p.runs.iloc[index]["date"]
        these = [c for c in p.changes if c["index"] == index]
        largest = max(these, key=_rel)
        body.append(f"<details><summary><code>{_e(commit[:SHORT])}</code> {_e(date)}: {len(these)} metric"
                    f"{'s' if len(these) != 1 else ''} moved (largest: {_e(largest['item'])} {_e(largest['metric'])} "
                    f"{_pct(largest)})</summary><table><tr><th>metric</th><th>before</th><th>after</th><th>move</th>"
                    "</tr>")
        for c in these:
            body.append(f"<tr class=\"change-point\" data-commit=\"{_e(commit)}\" data-metric=\"{_e(c['item'])} "
                        f"{_e(c['metric'])}\"><td>{_e(c['item'])} {_e(c['metric'])}</td>"
                        f"<td class=\"num\">{_num(c['before'])}</td><td class=\"num\">{_num(c['after'])}"
                        f"{_unit(c['unit'])}</td><td class=\"num\">{_pct(c)}</td></tr>")
        body.append("</table></details>")
    if not p.changes:
        body.append("<p>None: no metric moved beyond its noise.</p>")
    body.append("<h2>Runs</h2><table><tr><th>commit</th><th>date</th><th>verdict</th><th>failures</th>"
                "<th>unresolved</th><th>machine</th><th>gearcheck</th><th>MuJoCo</th><th>NumPy</th><th>train file</th>"
                "</tr>")
    for _, run in p.runs.iloc[::-1].iloc[:RUNS_SHOWN].iterrows():
        body.append(f"<tr><td><code>{_e(run['commit'][:SHORT])}</code></td><td class=\"nowrap\">{_e(run['date'])}</td>"
                    f"<td>{_badge(run['verdict'])}</td><td>{_failures(run)}</td>"
                    f"<td>{_list(run['unresolved'])}</td><td>{_e(run['machine'] or '')}</td>"
                    f"<td>{_e(run['gearcheck_version'] or '')}</td><td>{_e(run['mujoco_version'] or '')}</td>"
                    f"<td>{_e(run['numpy_version'] or '')}</td><td><code>{_e((run['train_sha256'] or '')[:12])}</code>"
                    "</td></tr>")
    body.append("</table><h2>Quantities</h2><p class=\"muted\">NRMSE of the two solvers with its tolerance "
                "(points coloured by status), and the change of the reference solver's RMS and peak-to-peak from "
                "the first run (hover a point for its value).</p>")
    for item in dict.fromkeys(k[0] for k in p.series if (k[0], "nrmse") in p.series):
        info = p.info[(item, "nrmse")]
        status = info["statuses"][-1]
        body.append(f"<div class=\"card\"><h3>{_e(item)} <span class=\"muted\">{_e(info['kind'])}</span> "
                    f"{_badge(status) if status else ''}</h3><div class=\"grid\">")
        body.append(_figure("NRMSE", p.chart([p.line(item, "nrmse", "NRMSE", PALETTE[0])], log=True,
                                             limits=_tolerance(info))))
        amplitude = [p.relative(item, "reference.rms", "reference RMS", PALETTE[0]),
                     p.relative(item, "reference.peak_to_peak", "reference peak-to-peak", PALETTE[1])]
        body.append(_figure("Amplitude, change from the first run (%)", p.chart(amplitude, unit="%")))
        body.append("</div></div>")
    return page(f"{p.name}: gearcheck regression dashboard", "".join(body))


def _overview(p: Preset) -> list:
    """The overview charts of a preset: (title, SVG)."""
    n, out = len(p.runs), []

    def worst(keys, per_item=False):  # per run: the largest value / tolerance (summed per item when per_item)
        best = [None] * n
        for i in range(n):
            ratios = {}
            for key in keys:
                v, tol = p.series[key][i], p.info[key]["tolerance"]
                if v is not None and tol:
                    name = key[0] if per_item else key
                    ratios[name] = ratios.get(name, 0.0) + v / tol
            best[i] = max(ratios.values(), default=None)
        return best

    gated = [k for k in p.series if k[1] == "nrmse" and p.info[k]["gated"]]
    if gated:
        line = p.aggregate("worst NRMSE / tolerance", worst(gated), "worst-nrmse-ratio")
        out.append(("Worst gated NRMSE / tolerance", p.chart([line], log=True, limits=[(1.0, "tolerance")])))
    modal = [k for k in p.series if k[1] == "rel_error"]
    if modal:
        tol = min((p.info[k]["tolerance"] for k in modal if p.info[k]["tolerance"]), default=None)
        values = [max((p.series[k][i] for k in modal if p.series[k][i] is not None), default=None) for i in range(n)]
        line = p.aggregate("max modal rel. error", values, "modes max-rel-error", tol)
        out.append(("Modal max relative error", p.chart([line], log=True, limits=[(tol, "tolerance")] if tol else [])))
    lines = [p.relative(*key, key[0], PALETTE[j % len(PALETTE)])
             for j, key in enumerate(k for k in p.series if k[1] == "reference.frequency")]
    if lines:
        out.append(("Natural frequencies (reference), change from the first run (%)", p.chart(lines, unit="%",
                                                                                        legend=False)))
    bounds = [k for k in p.series if k[1].startswith("integration_error.")]
    if bounds:
        line = p.aggregate("integration error / tolerance", worst(bounds, per_item=True), "integration-error-ratio")
        out.append(("Integration error estimate / tolerance (worst quantity)",
                    p.chart([line], log=True, limits=[(1.0, "unresolved")])))
    # the timing trend in CPU time, which a shared runner's load moves far less than the wall time (stores from
    # before CPU time was recorded: wall time)
    times = [k for k in p.series if k[0] == "cpu_time"] or [k for k in p.series if k[0] == "wall_time"]
    if times:
        title = "CPU time (s)" if times[0][0] == "cpu_time" else "Wall time (s)"
        out.append((title, p.chart([p.line(*k, k[1].removesuffix("_s"), PALETTE[j % len(PALETTE)])
                                    for j, k in enumerate(times)], unit="s")))
    return out


def _tolerance(info: dict) -> list:
    return [(info["tolerance"], "tolerance")] if info.get("tolerance") else []


# ---------------------------------------------------------------- SVG charts

def _chart(labels: list, commits: list, lines: list, unit: str = "", log: bool = False, limits=(),
           legend: bool = True) -> str:
    """An SVG line chart over commits: ``lines`` (Line), horizontal ``limits`` [(value, label)] in the
    tolerance colour, change points marked."""
    n = len(labels)
    values = [v for line in lines for v in line.values if v is not None and math.isfinite(v)]
    levels = [v for v, _ in limits]
    lo, hi, ticks, log = _axis(values + levels, log)
    x0, x1, y0, y1 = _plot_box()
    keys, height = _legend_layout(lines if legend else [])
    x, y = _scales(n, lo, hi, log)
    out = [f"<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{height}\" "
           f"viewBox=\"0 0 {WIDTH} {height}\" role=\"img\" class=\"chart\">",
           f"<rect x=\"{x0}\" y=\"{y0}\" width=\"{x1 - x0}\" height=\"{y1 - y0}\" fill=\"#fafafa\" stroke=\"#bbb\"/>"]
    out += _value_ticks(ticks, log, y)
    out += _commit_labels(labels, x)
    out += _limit_lines(limits, y)
    out += _change_guides(lines, labels, commits, x)
    for line in lines:
        out += _series(line, commits, x, y)
    for lx, ly, line in keys:
        out.append(f"<line x1=\"{lx}\" x2=\"{lx + 18}\" y1=\"{ly}\" y2=\"{ly}\" stroke=\"{line.color}\" "
                   f"stroke-width=\"2\"/><text x=\"{lx + 22}\" y=\"{ly + 4}\" font-size=\"11\">{_e(line.label)}</text>")
    if unit and unit != "1":
        out.append(f"<text x=\"4\" y=\"{y0 - 6}\" font-size=\"10\" fill=\"#555\">{_e(unit)}</text>")
    return "".join(out) + "</svg>"


def _plot_box() -> tuple[int, int, int, int]:
    """The plotting area of a chart: left, right, top and bottom (SVG units, y down)."""
    return LEFT, WIDTH - RIGHT, TOP, HEIGHT - BOTTOM


def _legend_layout(lines: list) -> tuple[list, int]:
    """Where each line's legend key goes, [(x, y, line)], flowed left to right in as many rows as it takes below
    the plot, and the chart's height with them."""
    x0 = _plot_box()[0]
    keys, lx, ly = [], x0, HEIGHT - 12
    for line in lines:
        if lx + 30 + 7 * len(line.label) > WIDTH and lx > x0:
            lx, ly = x0, ly + 16
        keys.append((lx, ly, line))
        lx += 30 + 7 * len(line.label)
    return keys, ly + 12


def _scales(n: int, lo: float, hi: float, log: bool):
    """(x, y): a commit's index and a value (from ``lo`` to ``hi``, by decades on a ``log`` axis) as SVG
    coordinates; a single commit sits in the middle."""
    x0, x1, y0, y1 = _plot_box()

    def x(i):
        return (x0 + x1) / 2 if n == 1 else x0 + (x1 - x0) * i / (n - 1)

    def y(v):
        if log:
            v = math.log10(max(v, lo))
            a, b = math.log10(lo), math.log10(hi)
        else:
            a, b = lo, hi
        return y1 - (y1 - y0) * (v - a) / (b - a)

    return x, y


def _value_ticks(ticks: list, log: bool, y) -> list[str]:
    """A grid line and a label at each tick of the value axis."""
    x0, x1 = _plot_box()[:2]
    return [f"<line x1=\"{x0}\" x2=\"{x1}\" y1=\"{_f(y(t))}\" y2=\"{_f(y(t))}\" stroke=\"#e3e3e3\"/>"
            f"<text x=\"{x0 - 4}\" y=\"{_f(y(t) + 4)}\" font-size=\"10\" text-anchor=\"end\">"
            f"{_e(_tick(t, log))}</text>" for t in ticks]


def _commit_labels(labels: list, x) -> list[str]:
    """The commits' labels under the plot: at most 8 + 1, 60 px apart, the last one always."""
    n = len(labels)
    y1 = _plot_box()[3]
    out = []
    step = max(1, math.ceil(n / 8))
    for i in range(n):
        if (i % step == 0 and n - 1 - i >= step) or i == n - 1:
            anchor = "end" if i == n - 1 and n > 1 else "middle"
            out.append(f"<text x=\"{_f(x(i))}\" y=\"{y1 + 14}\" font-size=\"10\" text-anchor=\"{anchor}\" "
                       f"font-family=\"monospace\">{_e(labels[i])}</text>")
    return out


def _limit_lines(limits, y) -> list[str]:
    """Each limit [(value, label)] as a dashed horizontal line in the tolerance colour, labelled at its right."""
    x0, x1 = _plot_box()[:2]
    return [f"<line class=\"limit\" x1=\"{x0}\" x2=\"{x1}\" y1=\"{_f(y(value))}\" y2=\"{_f(y(value))}\" "
            f"stroke=\"{TOLERANCE_COLOR}\" stroke-width=\"2\" stroke-dasharray=\"6 3\"/>"
            f"<text x=\"{x1 - 4}\" y=\"{_f(y(value) - 4)}\" font-size=\"10\" text-anchor=\"end\" "
            f"fill=\"{TOLERANCE_COLOR}\">{_e(label)} {_num(value)}</text>" for value, label in limits]


def _change_guides(lines: list, labels: list, commits: list, x) -> list[str]:
    """A dashed vertical guide, labelled with the short commit id, at every commit where a line has a change
    point."""
    x0, x1, y0, y1 = _plot_box()
    out = []
    for i in sorted({i for line in lines for i in line.marks}):
        anchor = "end" if x(i) > x1 - 40 else "start" if x(i) < x0 + 40 else "middle"
        out.append(f"<line class=\"change-guide\" x1=\"{_f(x(i))}\" x2=\"{_f(x(i))}\" y1=\"{y0}\" y2=\"{y1}\" "
                   f"stroke=\"{CHANGE_COLOR}\" stroke-dasharray=\"3 3\"/>"
                   f"<text class=\"change-label\" data-commit=\"{_e(commits[i])}\" x=\"{_f(x(i))}\" y=\"{y0 - 6}\" "
                   f"font-size=\"10\" text-anchor=\"{anchor}\" fill=\"{CHANGE_COLOR}\" font-family=\"monospace\">"
                   f"&#9670; {_e(labels[i])}</text>")
    return out


def _series(line: Line, commits: list, x, y) -> list[str]:
    """One line: its path (broken where a value is missing), then its points: a diamond at a change point, a dot
    coloured by its status elsewhere (only failed or unresolved ones above :data:`MAX_POINTS` commits)."""
    n = len(commits)
    path, pen = [], "M"
    for i, v in enumerate(line.values):
        if v is None or not math.isfinite(v):
            pen = "M"
            continue
        path.append(f"{pen}{_f(x(i))} {_f(y(v))}")
        pen = "L"
    out = [f"<path d=\"{' '.join(path)}\" fill=\"none\" stroke=\"{line.color}\" stroke-width=\"1.6\">"
           f"<title>{_e(line.label)}</title></path>"]
    for i, v in enumerate(line.values):
        if v is None or not math.isfinite(v):
            continue
        status = line.statuses[i] if line.statuses else None
        tip = f"<title>{_e(line.tips[i])}</title>" if line.tips and line.tips[i] else ""
        if i in line.marks:
            cx, cy = x(i), y(v)
            out.append(f"<path class=\"change-point\" data-commit=\"{_e(commits[i])}\" "
                       f"data-metric=\"{_e(line.metric)}\" d=\"M{_f(cx)} {_f(cy - 7)} L{_f(cx + 7)} {_f(cy)} "
                       f"L{_f(cx)} {_f(cy + 7)} L{_f(cx - 7)} {_f(cy)} Z\" fill=\"{CHANGE_COLOR}\" "
                       f"stroke=\"#fff\">{tip}</path>")
        elif n <= MAX_POINTS or status in ("fail", "unresolved"):
            fill = STATUS_COLOR.get(status, line.color) if status else line.color
            out.append(f"<circle cx=\"{_f(x(i))}\" cy=\"{_f(y(v))}\" r=\"3\" fill=\"{fill}\">{tip}</circle>")
    return out


def _axis(values: list, log: bool) -> tuple[float, float, list, bool]:
    """Axis limits and ticks: decades for a log axis (when every value is positive), else round steps."""
    positive = [v for v in values if v > 0]
    if log and positive:
        a = math.floor(math.log10(min(positive)))
        b = max(math.ceil(math.log10(max(positive))), a + 1)
        every = max(1, math.ceil((b - a) / 6))
        return 10.0 ** a, 10.0 ** b, [10.0 ** e for e in range(a, b + 1, every)], True
    if not values:
        return 0.0, 1.0, [0.0, 0.5, 1.0], False
    lo, hi = min(values), max(values)
    if hi - lo <= 1e-9 * max(abs(lo), abs(hi)):
        pad = abs(lo) * 0.05 or 1.0
        lo, hi = lo - pad, hi + pad
    raw = (hi - lo) / 4
    magnitude = 10.0 ** math.floor(math.log10(raw))
    step = next(m * magnitude for m in (1, 2, 2.5, 5, 10) if m * magnitude >= raw)
    lo, hi = math.floor(lo / step) * step, math.ceil(hi / step) * step
    ticks = [lo + k * step for k in range(round((hi - lo) / step) + 1)]
    return lo, hi, ticks, False


# ---------------------------------------------------------------- HTML pieces

def _figure(title: str, svg: str) -> str:
    return f"<figure><figcaption>{_e(title)}</figcaption>{svg}</figure>"


def _badge(verdict: str) -> str:
    return f"<span class=\"badge\" style=\"background:{_color(verdict)}\">{_e(verdict)}</span>"


def _color(verdict: str) -> str:
    return STATUS_COLOR.get(verdict, "#777777")


def _list(items) -> str:
    return ", ".join(_e(str(i)) for i in items) if items else ""


def _failures(run) -> str:
    """A run's failures, and how many baseline metrics moved (a FAIL of its own)."""
    moved = run["moved"] or []
    parts = [_list(run["failures"])] if run["failures"] else []
    if moved:
        parts.append(f"baseline moved ({len(moved)} metrics)")
    return "; ".join(parts)


def _rel(change: dict) -> float:
    before = change["before"]
    return abs(change["after"] - before) / abs(before) if before else math.inf


def _pct(change: dict) -> str:
    rel = _rel(change)
    sign = "+" if change["after"] >= change["before"] else "&minus;"
    return "new" if math.isinf(rel) else f"{sign}{100 * rel:.3g} %"


def _unit(unit) -> str:
    return "" if unit in ("1", None) else f" {_e(unit)}"


def _num(value) -> str:
    return "-" if value is None else f"{value:.4g}"


def _tick(value: float, log: bool) -> str:
    return f"{value:.0e}" if log else f"{value:.4g}"


def _f(value: float) -> str:
    return f"{value:.1f}"


def _e(text) -> str:
    return html.escape(str(text), quote=True)
