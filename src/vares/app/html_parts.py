"""The pieces every HTML report is made of: the style, tables, inline figures, the page head."""

from __future__ import annotations

import base64
import datetime
import gc
import html
import io
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .._version import __version__

__all__ = [
    "REPORT_DPI",
    "STYLE",
    "figure",
    "number",
    "page",
    "picture",
    "report_drawing",
    "status_text",
    "table",
]

#: Resolution of the pictures drawn into a report (a 6.5-inch figure is 650 pixels wide, shown at
#: most 520): pass it to the plots, which rasterise the cells for it.
REPORT_DPI = 100
#: zlib level of the embedded PNGs. A 100k-cell field on the pattern at 100 dpi, level 6
#: (Pillow's default) → 4 → 1: 41 → 20 → 15 ms, 157 → 171 → 203 KiB; a 4.6k-cell one 17 → 14 →
#: 11 ms, 89 → 94 → 111 KiB. Level 4 takes most of the time off for a file 5–9 % larger.
_COMPRESS_LEVEL = 4

STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1100px; color: #222; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; }
table { border-collapse: collapse; margin: 0.5em 0 1em; }
td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; }
th { background: #f2f4f7; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
.status-ok { color: #17702a; font-weight: bold; } .status-bad { color: #b00020; font-weight: bold; }
.warning { background: #fff4d6; border-left: 4px solid #e0a800; padding: 0.4em 0.8em;
  margin: 0.3em 0; }
figure { display: inline-block; margin: 0.5em; vertical-align: top; }
figure img { max-width: 520px; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #555; }
"""


@contextmanager
def report_drawing() -> Iterator[None]:
    """Around drawing a report: the garbage collector leaves the objects that were there before
    (modules, numba's type system: some 250,000) alone until the end. A report's figures are
    short-lived reference cycles, enough of them to set off a full collection, which walked all
    of those: 0.12 s of a report. Where something else has frozen objects already, nothing
    changes."""
    if gc.get_freeze_count():
        yield
        return
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def _png(fig, close: bool) -> str:
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    options = {"compress_level": _COMPRESS_LEVEL}
    fig.savefig(buffer, format="png", dpi=REPORT_DPI, pil_kwargs=options)
    if close:
        plt.close(fig)
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def figure(fig, caption: str, ident: str, close: bool = True) -> str:
    """A matplotlib figure, drawn and embedded (and closed, unless it is to be drawn again)."""
    return _embedded(_png(fig, close), caption, ident)


def picture(path: Path, caption: str, ident: str) -> str:
    """A PNG file the run has written already, embedded (not drawn again)."""
    return _embedded(base64.b64encode(Path(path).read_bytes()).decode("ascii"), caption, ident)


def _embedded(png: str, caption: str, ident: str) -> str:
    return (
        f'<figure id="{ident}"><img alt="{html.escape(caption)}" '
        f'src="data:image/png;base64,{png}"><figcaption>{html.escape(caption)}'
        "</figcaption></figure>"
    )


def table(rows, header=None, ident: str | None = None) -> str:
    attr = f' id="{ident}"' if ident else ""
    out = [f"<table{attr}>"]
    if header:
        out.append("<tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr>")
    for row in rows:
        cells = []
        for k, cell in enumerate(row):
            text = html.escape(str(cell))
            cells.append(f"<th>{text}</th>" if k == 0 else f'<td class="num">{text}</td>')
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</table>")
    return "".join(out)


def number(value: float, digits: int = 5) -> str:
    return f"{value:.{digits}g}"


def page(title: str, heading: str, status: str, warnings: list[str]) -> list[str]:
    """The head of a report: title, version, date, status and the warnings."""
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>vares report: {html.escape(title)}</title><style>{STYLE}</style>",
        "</head><body>",
        f"<h1>{html.escape(heading)}</h1>",
        f"<p>vares {__version__}, {datetime.datetime.now():%Y-%m-%d %H:%M}. Status: {status}</p>",
        "<h2>Warnings</h2>",
    ]
    if warnings:
        return parts + [f'<div class="warning">{html.escape(w)}</div>' for w in warnings]
    return [*parts, "<p id='no-warnings'>None.</p>"]


def status_text(converged: bool, reason: str | None) -> str:
    if converged:
        return '<span class="status-ok">converged</span>'
    return f'<span class="status-bad">not converged: {html.escape(str(reason))}</span>'
