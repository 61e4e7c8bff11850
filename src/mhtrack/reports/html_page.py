"""One HTML page: sections of text, tables and Plotly figures, with Plotly's JavaScript
either inlined once in the page (``plotlyjs="inline"``, the default: one self-contained
file) or referenced as ``plotly-<version>.min.js`` beside the page (``"file"``: written
once and shared by every report in that folder, 4.8 MB less per page). No CDN, no fonts
or map tiles fetched: the page opens from disk with the network off.

Plotly (https://plotly.com/python/) draws the figures; this module writes no JavaScript of
its own. The page is deterministic: the same content gives the same bytes (figure ids are
given, never random).
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import plotly.graph_objects as go

#: The message when the optional extra is missing.
MISSING_PLOTLY = ('the HTML report needs Plotly: pip install "mhtrack[report]" '
                  "(or pip install plotly)")

#: Where Plotly's JavaScript goes: inlined in the page, or a file beside it.
PLOTLYJS_MODES = ("inline", "file")


def plotlyjs_name() -> str:
    """The file name of Plotly's JavaScript beside a page (``plotlyjs="file"``):
    versioned, so that pages of another Plotly version never share a wrong copy."""
    import plotly

    return f"plotly-{plotly.__version__}.min.js"


#: Plotly's options for every figure: wheel zoom, no logo link, PNG export button kept.
FIGURE_CONFIG: dict[str, Any] = {"scrollZoom": True, "displaylogo": False,
                                 "responsive": True}

STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 0;
       color: #1f2937; background: #f8fafc; }
header { background: #1e3a5f; color: white; padding: 14px 28px; }
header h1 { margin: 0; font-size: 22px; }
header p { margin: 4px 0 0; color: #cbd5e1; font-size: 14px; }
nav { padding: 8px 28px; background: #e2e8f0; font-size: 14px; }
nav a { margin-right: 18px; color: #1e3a5f; }
main { padding: 8px 28px 40px; max-width: 1400px; }
section { background: white; border: 1px solid #e2e8f0; border-radius: 6px;
          padding: 10px 18px 16px; margin: 16px 0; }
h2 { font-size: 18px; margin: 6px 0 10px; color: #1e3a5f; }
p.note { font-size: 13px; color: #475569; margin: 4px 0 10px; }
table { border-collapse: collapse; font-size: 14px; margin: 6px 0; }
th, td { border-bottom: 1px solid #e2e8f0; padding: 4px 12px 4px 6px; text-align: left;
         vertical-align: top; }
th { background: #f1f5f9; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.sub { padding-left: 24px; color: #475569; }
ul.sentences { font-size: 13px; color: #334155; }
"""


def require_plotly() -> None:
    """Raise :class:`ImportError` with :data:`MISSING_PLOTLY` when Plotly is absent."""
    try:
        import plotly  # noqa: F401
    except ImportError as e:
        raise ImportError(MISSING_PLOTLY) from e


def _is_number(text: str) -> bool:
    t = text.replace("±", " ").replace("–", "").replace("−", "-").split()
    if not t:
        return False
    try:
        float(t[0])
    except ValueError:
        return False
    return True


@dataclass
class Page:
    """An HTML report being assembled: call the ``add_*`` methods, then :meth:`render`."""

    title: str
    subtitle: str = ""
    parts: list[tuple[str, str, str]] = field(default_factory=list)  # (anchor, h2, body)
    figures: list[str] = field(default_factory=list)  #: figure div ids, in page order

    def section(self, heading: str, body: str = "") -> None:
        """A new section with ``heading`` (plain text) and ``body`` (HTML)."""
        anchor = f"s{len(self.parts) + 1}"
        self.parts.append((anchor, heading, body))

    def _append(self, body: str) -> None:
        if not self.parts:
            self.section(self.title)
        a, h, b = self.parts[-1]
        self.parts[-1] = (a, h, b + body)

    def note(self, text: str) -> None:
        """A paragraph of plain text in the current section."""
        self._append(f'<p class="note">{html.escape(text)}</p>\n')

    def table(self, header: Sequence[str] | None, rows: Sequence[Sequence[str]], *,
              numbers: bool = True) -> None:
        """A table of plain-text cells in the current section: numbers right-aligned
        (``numbers``), a first cell's leading spaces as an indent."""
        out = ["<table>"]
        if header:
            out.append("<tr>" + "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
                       + "</tr>")
        for r in rows:
            cells = []
            for j, c in enumerate(r):
                text = str(c)
                cls = ' class="num"' if numbers and j > 0 and _is_number(text) else ""
                if j == 0 and text.startswith("  "):
                    cls = ' class="sub"'
                cells.append(f"<td{cls}>{html.escape(text.strip())}</td>")
            out.append("<tr>" + "".join(cells) + "</tr>")
        self._append("\n".join(out) + "</table>\n")

    def sentences(self, lines: Sequence[str]) -> None:
        """A bulleted list of plain-text sentences in the current section."""
        items = "".join(f"<li>{html.escape(s)}</li>" for s in lines)
        self._append(f'<ul class="sentences">{items}</ul>\n')

    def figure(self, fig: go.Figure, name: str) -> None:
        """A Plotly figure in the current section; ``name`` makes its div id
        (``fig-<name>``), which must be unique in the page."""
        div_id = f"fig-{name}"
        if div_id in self.figures:
            raise ValueError(f"two figures named {name!r} in one page")
        self.figures.append(div_id)
        self._append(fig.to_html(full_html=False, include_plotlyjs=False, div_id=div_id,
                                 config=FIGURE_CONFIG) + "\n")

    def render(self, plotlyjs: str = "inline") -> str:
        """The whole page, Plotly's JavaScript inlined in the head (``"inline"``) or
        loaded from :func:`plotlyjs_name` beside the page (``"file"``)."""
        from plotly.offline import get_plotlyjs

        if plotlyjs not in PLOTLYJS_MODES:
            raise ValueError(f"plotlyjs must be one of {', '.join(PLOTLYJS_MODES)}, "
                             f"got {plotlyjs!r}")
        script = (f"<script type=\"text/javascript\">{get_plotlyjs()}</script>"
                  if plotlyjs == "inline" else
                  f"<script type=\"text/javascript\" src=\"{plotlyjs_name()}\"></script>")
        nav = "".join(f'<a href="#{a}">{html.escape(h)}</a>' for a, h, _ in self.parts)
        body = "".join(f'<section id="{a}"><h2>{html.escape(h)}</h2>\n{b}</section>\n'
                       for a, h, b in self.parts)
        sub = f"<p>{html.escape(self.subtitle)}</p>" if self.subtitle else ""
        return (
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            f"<title>{html.escape(self.title)}</title>\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<style>{STYLE}</style>\n"
            f"{script}\n</head>\n<body>\n"
            f"<header><h1>{html.escape(self.title)}</h1>{sub}</header>\n"
            f"<nav>{nav}</nav>\n<main>\n{body}</main>\n</body>\n</html>\n"
        )
