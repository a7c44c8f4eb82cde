"""Figures of a report page: drawn on ``matplotlib.figure.Figure`` objects (no pyplot, so any backend works)
and saved beside the page as ``<out>/figures/<prefix><name>.png`` (shown) and ``.pdf`` (linked),
by :class:`FigureWriter`, which also removes its own figures of an earlier page that are not drawn again."""

from __future__ import annotations

import re
from pathlib import Path

from slamtrials.atomicfile import atomic_write
from slamtrials.report import campaign_figures as cf
from slamtrials.report import html as h

__all__ = ["FigureWriter", "safe_name", "FIGURES_DIR", "DPI"]

#: The folder of the figures, beside the page.
FIGURES_DIR = "figures"
#: Resolution of the saved figures: a figure ``w`` inches wide is ``100 w`` pixels wide.
DPI = 100


def safe_name(name: str) -> str:
    """``name`` (a world's, say) as a file-name part: letters, digits, ``.``, ``_`` and ``-``, no leading dot."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", str(name)).strip(".") or "x"


class FigureWriter:
    """Saves figures as ``<out>/figures/<prefix><name>.png|pdf`` and removes its own stale ones at the end.

    Parameters
    ----------
    out:
        The page's folder.
    prefix:
        What every file name of this page starts with (``report_``, ``compare_``), so that two pages can
        share a folder and :meth:`clean` removes only this one's.
    pdf:
        Also save every figure as PDF (linked under it).

    Attributes
    ----------
    written:
        The files saved so far (PNG, and PDF when asked).
    """

    def __init__(self, out: Path, prefix: str, pdf: bool = True):
        self.out = out
        self.folder = out / FIGURES_DIR
        self.prefix = prefix
        self.pdf = pdf
        self.written: list[Path] = []

    def new(self, width: float, height: float):
        """A new figure ``width`` x ``height`` inches (``DPI`` pixels an inch) with constrained layout."""
        from matplotlib.figure import Figure

        return Figure(figsize=(width, height), dpi=DPI, layout="constrained")

    def save(self, fig, name: str, caption: str, *, id: str | None = None, alt: str | None = None) -> str:
        """Save ``fig`` as ``<prefix><name>`` and return the page's ``<figure>`` of it with ``caption``."""
        base = self.folder / f"{self.prefix}{safe_name(name)}"
        engine = fig.get_layout_engine()
        if engine is not None:  # lay out once, not once per file format
            engine.execute(fig)
            fig.set_layout_engine("none")
        if self.pdf:
            paths = cf.save_figure(fig, base, dpi=DPI)
        else:
            paths = [
                atomic_write(
                    base.with_name(base.name + ".png"), lambda handle: fig.savefig(handle, format="png", dpi=DPI)
                )
            ]
        self.written.extend(paths)
        png, pdf = paths[0], (paths[1] if len(paths) > 1 else None)
        rel = lambda p: p.relative_to(self.out).as_posix()  # noqa: E731
        return h.figure(rel(png), caption, alt=alt, pdf=rel(pdf) if pdf else None, id=id)

    def clean(self) -> None:
        """Remove this page's PNG and PDF files in the figures folder that this writer did not save."""
        keep = set(self.written)
        if self.folder.is_dir():
            for path in self.folder.glob(f"{self.prefix}*"):
                if path.suffix in (".png", ".pdf") and path not in keep:
                    path.unlink(missing_ok=True)
