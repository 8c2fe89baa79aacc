"""One report document, built as a list of blocks (headings, paragraphs, tables, figures, code,
notes) and rendered twice from that structure: to Markdown (report.md) and to a self-contained
HTML page (report.html, images inlined). Neither rendering re-parses the other."""

from __future__ import annotations

import base64
import html
import os
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from .tables import cells
from ..files import atomic_text, temp_path  # noqa: F401 (atomic_text: the report modules import it from here)


@dataclass
class Code:
    """An inline code span inside a paragraph."""

    text: str


@dataclass
class Block:
    kind: str  # heading | para | code | table | figure | note
    text: str = ""
    level: int = 0
    parts: list = field(default_factory=list)  # para: str and Code spans
    df: pd.DataFrame | None = None
    mark_rows: bool = False
    fmt: str = "{:.2f}"
    path: Path | None = None
    lang: str = ""


class Document:
    """Blocks appended in reading order; :meth:`markdown` and :meth:`html` render them."""

    def __init__(self):
        self.blocks: list[Block] = []
        self.figures = 0

    def heading(self, level: int, text: str) -> None:
        self.blocks.append(Block("heading", text, level))

    def para(self, *parts) -> None:
        """A paragraph of plain strings and :class:`Code` spans."""
        self.blocks.append(Block("para", parts=list(parts)))

    def code(self, text: str, lang: str = "") -> None:
        self.blocks.append(Block("code", text, lang=lang))

    def table(self, df: pd.DataFrame, mark_rows: bool = False, fmt: str = "{:.2f}") -> None:
        """A table (index levels become leading columns); with ``mark_rows`` the best (smallest)
        value of each row is bold and the worst italic."""
        self.blocks.append(Block("table", df=df, mark_rows=mark_rows, fmt=fmt))

    def figure(self, path: Path, caption: str) -> None:
        self.blocks.append(Block("figure", caption, path=Path(path)))
        self.figures += 1

    def note(self, text: str) -> None:
        self.blocks.append(Block("note", text))

    # ---- Markdown ---------------------------------------------------------------------
    def markdown(self, out: Path) -> str:
        lines: list[str] = []
        for b in self.blocks:
            if b.kind == "heading":
                lines += ["#" * b.level + " " + b.text, ""]
            elif b.kind == "para":
                lines += ["".join(f"`{p.text}`" if isinstance(p, Code) else p for p in b.parts), ""]
            elif b.kind == "code":
                lines += [f"```{b.lang}", b.text, "```", ""]
            elif b.kind == "table":
                lines += [markdown_table(b.df, b.mark_rows, b.fmt), ""]
            elif b.kind == "figure":
                lines += [f"![{b.text}]({os.path.relpath(b.path, out)})", "", f"*{b.text}*", ""]
            elif b.kind == "note":
                lines += [f"> {b.text}", ""]
        return "\n".join(lines)

    # ---- HTML -------------------------------------------------------------------------
    def html(self, title: str, sortable: bool = False) -> str:
        """The page; with ``sortable`` a click on a table's header sorts its rows by that column
        (by the number a cell starts with, else its text; a second click reverses)."""
        e = html.escape
        body: list[str] = []
        for b in self.blocks:
            if b.kind == "heading":
                body.append(f"<h{b.level}>{e(b.text)}</h{b.level}>")
            elif b.kind == "para":
                body.append("<p>" + "".join(f"<code>{e(p.text)}</code>" if isinstance(p, Code) else e(p) for p in b.parts) + "</p>")
            elif b.kind == "code":
                body.append(f"<pre>{e(b.text)}</pre>")
            elif b.kind == "table":
                head, rows = cells(b.df, b.mark_rows, b.fmt)
                # words read from the left, numbers from the right: a column of words and its header align left
                words = [all(r[k][0][:1].isalpha() or not r[k][0] for r in rows) for k in range(len(head))]
                t = ["<div class=scroll><table>", "<tr>" + "".join(f"<th class=t>{e(h)}</th>" if w else f"<th>{e(h)}</th>"
                                                                   for h, w in zip(head, words)) + "</tr>"]
                for row in rows:
                    tds = []
                    for text, mark in row:
                        inner = e(text) if mark is None else f"<span class={mark}>{e(text)}</span>"
                        tds.append(f"<td class=t>{inner}</td>" if text[:1].isalpha() else f"<td>{inner}</td>")
                    t.append("<tr>" + "".join(tds) + "</tr>")
                body.append("\n".join(t + ["</table></div>"]))
            elif b.kind == "figure":
                mime = "image/gif" if b.path.suffix == ".gif" else "image/png"
                data = base64.b64encode(b.path.read_bytes()).decode() if b.path.is_file() else ""
                body.append(f'<figure><img src="data:{mime};base64,{data}" alt="{e(b.text)}"><figcaption>{e(b.text)}</figcaption></figure>')
            elif b.kind == "note":
                body.append(f"<blockquote>{e(b.text)}</blockquote>")
        style = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222;line-height:1.4}"
                 "table{border-collapse:collapse;font-size:12px;margin:.5em 0}td,th{border:1px solid #ccc;padding:2px 6px;"
                 "text-align:right;white-space:nowrap}.t{text-align:left}th{background:#f3f3f3}.scroll{overflow-x:auto;max-width:100%}"
                 ".best{color:#1a7f37;font-weight:bold}.worst{color:#c62828;font-style:italic}img{max-width:100%}"
                 "figcaption{color:#555;font-size:13px}pre{background:#f6f6f6;padding:.6em;white-space:pre-wrap;"
                 "overflow-wrap:anywhere;font-size:12px}code{background:#f3f3f3;overflow-wrap:anywhere}"
                 "blockquote{color:#555;border-left:3px solid #ccc;margin:1em 0;padding-left:1em}")
        script = f"<script>{SORT_JS}</script>\n" if sortable else ""
        return (f"<!doctype html><html><head><meta charset=utf-8><title>{e(title)}</title><style>{style}</style></head><body>\n"
                + "\n".join(body) + "\n" + script + "</body></html>\n")


# a table sorted by a click on its header: by the number a cell starts with, else by its text
SORT_JS = ("document.querySelectorAll('table').forEach(function(t){var hs=t.rows[0].cells;"
           "Array.prototype.forEach.call(hs,function(h,k){h.style.cursor='pointer';h.title='sort';"
           "h.addEventListener('click',function(){var rs=Array.prototype.slice.call(t.rows,1);"
           "var up=h.dataset.dir!=='up';h.dataset.dir=up?'up':'down';"
           "function v(r){var s=r.cells[k].textContent.trim();var n=parseFloat(s);return isNaN(n)?s:n;}"
           "rs.sort(function(a,b){var x=v(a),y=v(b);var c=(typeof x==='number'&&typeof y==='number')?x-y:"
           "String(x).localeCompare(String(y));return up?c:-c;});"
           "rs.forEach(function(r){r.parentNode.appendChild(r);});});});});")


def markdown_table(df: pd.DataFrame, mark_rows: bool = False, fmt: str = "{:.2f}") -> str:
    """A DataFrame as a Markdown table; marks: best **bold**, worst _italic_."""
    head, rows = cells(df, mark_rows, fmt)
    wrap = {None: "{}", "best": "**{}**", "worst": "_{}_"}
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        lines.append("| " + " | ".join(wrap[m].format(t) if t else t for t, m in row) + " |")
    return "\n".join(lines)


def write_table(tdir: Path, name: str, df: pd.DataFrame, formats) -> None:
    """tables/<name>.csv (atomic), when csv is among the formats."""
    if "csv" in formats:
        tdir.mkdir(parents=True, exist_ok=True)
        tmp = temp_path(tdir / f"{name}.csv")
        df.to_csv(tmp, index=not isinstance(df.index, pd.RangeIndex))
        os.replace(tmp, tdir / f"{name}.csv")
