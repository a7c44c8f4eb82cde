"""Small HTML building blocks of the report pages: one self-contained page, every text escaped.

A page is plain HTML5 with its style sheet inline and no script; figures are ``<img>`` elements that
refer to PNG files beside the page (relative paths), each with a link to its PDF. Every piece of text
that comes from data (world names, notes, errors, config values) goes through :func:`esc`, and
attribute values through :func:`attr`, so a world called ``<script>`` shows as text.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import PurePosixPath
from typing import Any

__all__ = [
    "esc",
    "attr",
    "Cell",
    "fmt_number",
    "fmt_seconds",
    "fmt_duration",
    "fmt_percent",
    "number_cell",
    "seconds_cell",
    "table",
    "scrolling",
    "figure",
    "section",
    "notes",
    "explanation",
    "details",
    "pre",
    "definition_list",
    "page",
    "STYLE",
]

STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 0 auto; max-width: 1320px;
       padding: 0 1.2em 3em; color: #1d1d1f; line-height: 1.45; }
h1 { font-size: 1.6em; margin: 1em 0 0.2em; } h2 { font-size: 1.25em; margin-top: 2em; border-bottom: 1px solid #ddd; }
h3 { font-size: 1.05em; margin: 1.2em 0 0.4em; }
p.lead { color: #555; margin-top: 0; }
table { border-collapse: collapse; margin: 0.6em 0 1em; font-size: 0.88em; }
th, td { border: 1px solid #d0d0d0; padding: 0.25em 0.55em; vertical-align: top; }
th { background: #f2f2f4; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.bad td { background: #fff1f0; } tr.warn td { background: #fffbe6; } tr.good td { background: #f0fff4; }
figure { margin: 0.8em 0 1.4em; } figure img { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { font-size: 0.86em; color: #444; max-width: 70em; }
caption { caption-side: top; text-align: left; font-size: 0.86em; color: #444; padding-bottom: 0.3em; }
.gallery { display: flex; flex-wrap: wrap; gap: 1em; } .gallery figure { flex: 1 1 520px; }
.notes { background: #fffbe6; border: 1px solid #f0d060; padding: 0.5em 1em; border-radius: 4px; }
.notes li { margin: 0.2em 0; }
pre { background: #f6f8fa; padding: 0.8em; overflow-x: auto; font-size: 0.82em; max-height: 40em; }
dl { display: grid; grid-template-columns: max-content auto; gap: 0.2em 1em; } dt { font-weight: 600; } dd { margin: 0; }
nav { font-size: 0.9em; } nav a { margin-right: 0.9em; }
details summary { cursor: pointer; color: #0645ad; }
details.explain { margin: 0.3em 0 1.2em; } details.explain > summary { font-size: 0.9em; }
.muted { color: #777; }
p.explain { font-size: 0.88em; color: #333; max-width: 70em; }
"""


def esc(value: Any) -> str:
    """``value`` as text, HTML-escaped (quotes too)."""
    return html.escape("" if value is None else str(value), quote=True)


def attr(value: Any) -> str:
    """``value`` escaped for a double-quoted attribute."""
    return html.escape("" if value is None else str(value), quote=True)


def fmt_number(value: Any, digits: int = 3) -> str:
    """A number with ``digits`` decimals; ``-`` for None and NaN; integers and text as they are."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    try:
        number = float(value)
    except (TypeError, ValueError):
        return str(value)
    if math.isnan(number):
        return "-"
    if math.isinf(number):
        return "inf" if number > 0 else "-inf"
    return f"{number:.{digits}f}"


def fmt_seconds(value: Any) -> str:
    """A time in seconds for a table column: one decimal below 10 s (``8.6``), whole seconds from 10 s
    (``166``); ``-`` for None and NaN."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        return "-"
    if not math.isfinite(number):
        return "-"
    return f"{number:.1f}" if abs(number) < 9.95 else f"{number:.0f}"


def fmt_duration(seconds: Any) -> str:
    """A duration for text, rounded to what a reader needs: ``< 0.1 s``, ``8.6 s``, ``43 s``, ``2 min 46 s``,
    ``3 h 05 min``."""
    try:
        number = float(seconds)
    except (TypeError, ValueError):
        return "-"
    if not math.isfinite(number):
        return "-"
    if 0.0 < number < 0.05:
        return "< 0.1 s"
    if number < 59.5:
        return f"{fmt_seconds(number)} s"
    whole = int(round(number))
    if whole < 3600:
        return f"{whole // 60} min {whole % 60:02d} s"
    minutes = int(round(number / 60.0))
    return f"{minutes // 60} h {minutes % 60:02d} min"


def fmt_percent(share: Any) -> str:
    """A share (0..1) as a percentage with no needless digits: ``0.95`` -> ``95 %``; ``?`` when not a number."""
    try:
        return f"{100 * float(share):g} %"
    except (TypeError, ValueError):
        return "?"


@dataclass(frozen=True)
class Cell:
    """A table cell: ``text`` (escaped when rendered), or trusted ``markup``; ``numeric`` aligns it right."""

    text: Any = ""
    numeric: bool = False
    markup: str | None = None
    title: str | None = None


def number_cell(value: Any, digits: int = 3) -> Cell:
    """A right-aligned cell of ``value`` with ``digits`` decimals (:func:`fmt_number`)."""
    return Cell(fmt_number(value, digits), numeric=True)


def seconds_cell(value: Any) -> Cell:
    """A right-aligned cell of a time in seconds, or of a cost figure (s, ms or MiB), rounded by
    :func:`fmt_seconds`: one decimal below 10, whole numbers above; ``-`` where not measured."""
    return Cell(fmt_seconds(value), numeric=True)


def _cell(value: Any, tag: str = "td") -> str:
    if not isinstance(value, Cell):
        numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
        value = Cell(fmt_number(value) if numeric else value, numeric)
    content = value.markup if value.markup is not None else esc(value.text)
    title = f' title="{attr(value.title)}"' if value.title else ""
    cls = ' class="num"' if value.numeric and tag == "td" else ""
    return f"<{tag}{cls}{title}>{content}</{tag}>"


def table(
    header: Sequence[Any],
    rows: Iterable[Sequence[Any]],
    *,
    id: str | None = None,
    caption: str | None = None,
    row_classes: Sequence[str | None] | None = None,
    groups: Sequence[tuple[str, int]] = (),
) -> str:
    """A ``<table>``: ``header`` cells, then ``rows`` of cells (plain values are escaped; floats get 3 decimals).

    ``groups`` is an optional header row above ``header`` of ``(label, columns spanned)``; ``row_classes``
    give each body row a class (``bad``, ``warn``, ``good``).
    """
    ident = ' id="' + attr(id) + '"' if id else ""
    out = [f"<table{ident}>"]
    if caption:
        out.append(f"<caption>{esc(caption)}</caption>")
    out.append("<thead>")
    if groups:
        out.append("<tr>" + "".join(f'<th colspan="{int(span)}">{esc(label)}</th>' for label, span in groups) + "</tr>")
    out.append("<tr>" + "".join(_cell(c, "th") for c in header) + "</tr></thead><tbody>")
    for i, row in enumerate(rows):
        cls = row_classes[i] if row_classes is not None and i < len(row_classes) else None
        opening = '<tr class="' + attr(cls) + '">' if cls else "<tr>"
        out.append(opening + "".join(_cell(c) for c in row) + "</tr>")
    out.append("</tbody></table>")
    return "\n".join(out)


def scrolling(markup: str) -> str:
    """Trusted ``markup`` (a wide table) in a block as wide as the page that scrolls sideways when it is wider."""
    return f'<div style="overflow-x:auto">{markup}</div>'


def figure(
    png: str | PurePosixPath,
    caption: str,
    *,
    alt: str | None = None,
    pdf: str | PurePosixPath | None = None,
    id: str | None = None,
) -> str:
    """A ``<figure>`` with the image at relative path ``png``, its caption and a link to ``pdf``."""
    link = f' <a href="{attr(pdf)}">PDF</a>' if pdf else ""
    ident = f' id="{attr(id)}"' if id else ""
    return (
        f'<figure{ident}><img src="{attr(png)}" alt="{attr(alt or caption)}" loading="eager">'
        f"<figcaption>{esc(caption)}{link}</figcaption></figure>"
    )


def section(title: str, *parts: str, id: str | None = None, intro: str | None = None) -> str:
    """A ``<section>`` with an ``<h2>`` title, an optional intro paragraph (escaped) and trusted ``parts``."""
    ident = f' id="{attr(id)}"' if id else ""
    head = f"<h2>{esc(title)}</h2>" + (f"<p>{esc(intro)}</p>" if intro else "")
    return f"<section{ident}>{head}\n" + "\n".join(p for p in parts if p) + "\n</section>"


def notes(items: Iterable[str], *, id: str | None = None) -> str:
    """A highlighted list of remarks (escaped); empty string when there are none."""
    items = [i for i in items if i]
    if not items:
        return ""
    ident = f' id="{attr(id)}"' if id else ""
    return f'<div class="notes"{ident}><ul>' + "".join(f"<li>{esc(i)}</li>" for i in items) + "</ul></div>"


def explanation(text: str, *, id: str | None = None) -> str:
    """A paragraph of explanatory prose (escaped), in the page's smaller explanatory style."""
    ident = f' id="{attr(id)}"' if id else ""
    return f'<p class="explain"{ident}>{esc(text)}</p>'


def details(summary: str, *parts: str, id: str | None = None, css_class: str | None = None) -> str:
    """A collapsed ``<details>`` block: ``summary`` (escaped) is what shows, the trusted ``parts`` open on a click."""
    ident = f' id="{attr(id)}"' if id else ""
    cls = f' class="{attr(css_class)}"' if css_class else ""
    return f"<details{ident}{cls}><summary>{esc(summary)}</summary>" + "\n".join(p for p in parts if p) + "</details>"


def pre(text: str, *, id: str | None = None) -> str:
    """Preformatted text (escaped)."""
    ident = f' id="{attr(id)}"' if id else ""
    return f"<pre{ident}>{esc(text)}</pre>"


def definition_list(items: Iterable[tuple[str, Any]]) -> str:
    """A ``<dl>`` of ``(term, value)`` pairs (both escaped)."""
    return "<dl>" + "".join(f"<dt>{esc(k)}</dt><dd>{esc(v)}</dd>" for k, v in items) + "</dl>"


def page(title: str, body: Sequence[str], *, subtitle: str | None = None, nav: Sequence[tuple[str, str]] = ()) -> str:
    """A whole HTML5 page: inline style, the ``<h1>`` title, a subtitle, a table of contents, the trusted ``body`` parts."""
    links = "".join(f'<a href="#{attr(anchor)}">{esc(label)}</a>' for anchor, label in nav)
    return "\n".join(
        [
            "<!DOCTYPE html>",
            '<html lang="en"><head><meta charset="utf-8">',
            '<meta name="viewport" content="width=device-width, initial-scale=1">',
            '<meta name="generator" content="slamtrials">',
            f"<title>{esc(title)}</title>",
            f"<style>{STYLE}</style>",
            "</head><body>",
            f"<h1>{esc(title)}</h1>",
            f'<p class="lead">{esc(subtitle)}</p>' if subtitle else "",
            f"<nav>{links}</nav>" if links else "",
            *body,
            "</body></html>",
            "",
        ]
    )
