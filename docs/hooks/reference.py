"""MkDocs hook: fills the reference pages from the code (:mod:`slamtrials.cli.reference`)."""

from __future__ import annotations

from typing import Any

MARKERS = {
    "<!-- cli-reference -->": "cli_reference",
    "<!-- config-reference -->": "config_reference",
    "<!-- api-reference -->": "api_reference",
}


def on_page_markdown(markdown: str, **_: Any) -> str:
    """Replace each marker of :data:`MARKERS` with the text its generator writes."""
    from slamtrials.cli import reference

    for marker, name in MARKERS.items():
        if marker in markdown:
            markdown = markdown.replace(marker, getattr(reference, name)())
    return markdown
