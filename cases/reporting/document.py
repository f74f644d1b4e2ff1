"""A report as a list of blocks, rendered to Markdown and to self-contained HTML."""
import base64
import html
import re
from pathlib import Path

from ..measuring.numbers import fmt, fmt_span, rel, rel_range  # noqa: F401 (a report's numbers)


MAX_COLUMNS = 10            # a table wider than this is split (a report reads in a minute)
GLOSSARY = "glossary.md"    # the one list of definitions, at the top of the reports folder
CONCLUSION_LINES = 3        # a report opens with at most this many lines


class Cell:
    """A table cell with a background colour in HTML (the scorecard's bands)."""

    def __init__(self, text, colour):
        self.text, self.colour = text, colour

    def markdown(self):
        return self.text

    def html(self):
        return f"<span style='display:block;background:{self.colour}'>{html.escape(self.text)}</span>"


class Link:
    """A table cell linking to ``md_href`` in Markdown and ``html_href`` in HTML."""

    def __init__(self, text, md_href, html_href=None):
        self.text, self.md_href, self.html_href = text, md_href, html_href or md_href

    def markdown(self):
        return f"[{self.text}]({self.md_href})"

    def html(self):
        return f"<a href='{html.escape(self.html_href)}'>{html.escape(self.text)}</a>"


class Table:
    """A table among a report's findings: sentences that would repeat with other numbers
    (one per model, per run) are its rows instead. ``title`` introduces it."""

    def __init__(self, title, header, rows):
        self.title, self.header, self.rows = title, list(header), [list(r) for r in rows]


_LINK = re.compile(r"\[([^\]]+)\]\(([^)\s]+)\)")
_BOLD = re.compile(r"\*\*(.+?)\*\*")


def _inline_html(text):
    """A sentence's Markdown links (to .md pages: their .html twins) and bold as HTML."""
    out = html.escape(text)

    def link(m):
        href = m.group(2)
        href = href[:-3] + ".html" if href.endswith(".md") else href
        return f"<a href='{href}'>{m.group(1)}</a>"
    return _BOLD.sub(r"<strong>\1</strong>", _LINK.sub(link, out))


def _md(c):
    """A Markdown table cell: a '|' inside it (|gamma|) escaped, so it cannot split the row."""
    return (c.markdown() if isinstance(c, (Link, Cell)) else str(c)).replace("|", "\\|")


def _html(c):
    return c.html() if isinstance(c, (Link, Cell)) else html.escape(str(c))


class Document:
    def __init__(self, title):
        self.title, self.blocks = title, []

    def h(self, level, text):
        self.blocks.append(("h", level, text))

    def p(self, text):
        self.blocks.append(("p", text))

    def ul(self, items):
        self.blocks.append(("ul", list(items)))

    def opening(self, lines, glossary=f"../{GLOSSARY}"):
        """The first CONCLUSION_LINES of ``lines`` as the report's opening paragraphs, a link
        to the glossary (``glossary``: its path from the report), and the rest under a
        heading of their own."""
        for line in lines[:CONCLUSION_LINES]:
            self.p(line)
        self.p(f"Definitions: [glossary]({glossary}).")
        if lines[CONCLUSION_LINES:]:
            self.h(2, "More findings")
            self.ul(lines[CONCLUSION_LINES:])

    def items(self, items):
        """Findings: runs of sentences as lists, each Table as its title and a table."""
        run = []
        for item in items:
            if isinstance(item, Table):
                if run:
                    self.ul(run)
                    run = []
                self.p(item.title)
                self.table(item.header, item.rows)
            else:
                run.append(item)
        if run:
            self.ul(run)

    def table(self, header, rows, keys=1):
        """A table; one wider than MAX_COLUMNS is split into several that each repeat the
        first ``keys`` columns (what names a row), a row left out of a part where its every
        other cell is empty (it has nothing there)."""
        header, rows = list(header), [list(r) for r in rows]
        width = MAX_COLUMNS - keys
        split = len(header) > MAX_COLUMNS
        for k in range(keys, max(len(header), keys + 1), width):
            cols = list(range(keys)) + list(range(k, min(k + width, len(header))))
            self.blocks.append(("table", [header[c] for c in cols],
                                [[r[c] for c in cols] for r in rows
                                 if not split or any(r[c] != "" for c in cols[keys:])]))

    def img(self, filename, alt):
        self.blocks.append(("img", filename, alt))

    def markdown(self):
        out = [f"# {self.title}", ""]
        for b in self.blocks:
            if b[0] == "h":
                out += ["#" * b[1] + " " + b[2], ""]
            elif b[0] == "p":
                out += [b[1], ""]
            elif b[0] == "ul":
                out += [f"- {i}" for i in b[1]] + [""]
            elif b[0] == "table":
                out += ["| " + " | ".join(map(_md, b[1])) + " |", "|" + "---|" * len(b[1])]
                out += ["| " + " | ".join(map(_md, r)) + " |" for r in b[2]] + [""]
            elif b[0] == "img":
                out += [f"![{b[2]}]({b[1]})", ""]
        return "\n".join(out)

    def html(self, folder):
        """HTML with every figure embedded as a data URI (one file to send around)."""
        e = html.escape
        out = ["<!DOCTYPE html>", "<html><head><meta charset='utf-8'>",
               f"<title>{e(self.title)}</title>",
               "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}"
               "table{border-collapse:collapse;font-size:12px}td,th{border:1px solid #bbb;"
               "padding:2px 6px;text-align:right}img{max-width:100%}</style></head><body>",
               f"<h1>{e(self.title)}</h1>"]
        for b in self.blocks:
            if b[0] == "h":
                out.append(f"<h{b[1]}>{e(b[2])}</h{b[1]}>")
            elif b[0] == "p":
                out.append(f"<p>{_inline_html(b[1])}</p>")
            elif b[0] == "ul":
                out.append("<ul>" + "".join(f"<li>{_inline_html(i)}</li>" for i in b[1])
                           + "</ul>")
            elif b[0] == "table":
                out.append("<table><tr>" + "".join(f"<th>{e(h)}</th>" for h in b[1]) + "</tr>")
                out += ["<tr>" + "".join(f"<td>{_html(c)}</td>" for c in r) + "</tr>"
                        for r in b[2]]
                out.append("</table>")
            elif b[0] == "img":
                data = base64.b64encode((Path(folder) / b[1]).read_bytes()).decode()
                out.append(f"<figure><img alt='{e(b[2])}' data-src='{e(b[1])}' "
                           f"src='data:image/png;base64,{data}'><figcaption>{e(b[2])}"
                           "</figcaption></figure>")
        out.append("</body></html>")
        return "\n".join(out)

    def write(self, folder, stem="report"):
        folder = Path(folder)
        (folder / f"{stem}.md").write_text(self.markdown() + "\n")
        (folder / f"{stem}.html").write_text(self.html(folder) + "\n")
