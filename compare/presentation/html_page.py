"""The HTML page every report is written as (report.html, summary.html, the dashboard's pages): one
self-contained document, no script, no network, with one stylesheet.

Tables align left; a ``numbers`` table aligns all but its first column right, a ``num`` cell itself.
Rows carry a status (``pass``, ``fail``, ``unresolved``, ``negligible``) or a verdict (``PASS``, ``FAIL``,
``INCONCLUSIVE``) as their class; a ``banner`` is coloured by its verdict.
"""

from __future__ import annotations

import html

STYLE = """
body { font-family: sans-serif; margin: 24px; color: #222; max-width: 1240px; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.6em; } h3 { font-size: 1em; margin: 0.2em 0; }
table { border-collapse: collapse; margin: 0.5em 0 1em; font-size: 0.85em; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: left; vertical-align: top; }
th { background: #f2f2f2; } td.num, .numbers td, .numbers th { text-align: right; font-variant-numeric: tabular-nums; }
.numbers td:first-child, .numbers th:first-child { text-align: left; }
tr.pass, tr.PASS { background: #dfd; } tr.fail, tr.FAIL { background: #fdd; }
tr.unresolved, tr.INCONCLUSIVE { background: #ffd; } tr.negligible { color: #777; }
code { font-size: 0.95em; } .muted { color: #777; } .nowrap { white-space: nowrap; }
.badge { display: inline-block; padding: 1px 7px; border-radius: 3px; color: #fff; font-weight: 600; }
.banner { padding: 0.8em 1.2em; border-radius: 6px; color: #fff; margin: 1em 0; } .banner a { color: #fff; }
.banner .verdict { font-size: 2em; font-weight: bold; margin-right: 0.6em; } .banner p { margin: 0.4em 0 0; }
.banner.PASS { background: #2e7d32; } .banner.FAIL { background: #c62828; }
.banner.INCONCLUSIVE { background: #e08a00; }
.grid { display: grid; grid-template-columns: repeat(auto-fill, minmax(520px, 1fr)); gap: 10px 18px; }
.grid figure { margin: 0; } .grid svg { max-width: 100%; height: auto; }
figcaption { font-size: 0.9em; font-weight: 600; } img { max-width: 100%; }
.card { border: 1px solid #ddd; border-radius: 4px; padding: 8px; margin: 10px 0; }
tr.change-point td:first-child { border-left: 4px solid #c51b7d; }
summary { cursor: pointer; margin: 0.3em 0; } summary code { color: #c51b7d; font-weight: 600; }
details.section > summary { font-size: 1.2em; font-weight: 600; margin: 0.8em 0; }
svg { display: block; } svg text { font-family: system-ui, sans-serif; }
"""


def page(title: str, body: str) -> str:
    """The document titled ``title`` (text) around ``body`` (HTML)."""
    return (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{html.escape(title)}</title>"
            f"<style>{STYLE}</style></head><body>\n{body}\n</body></html>\n")
