"""``vtool report`` rendering: a :class:`vtool.presets.report.Report` as HTML or PDF.

- HTML: one self-contained file (inline CSS, every figure an inline SVG, no
  script, no external link), readable printed in black and white: a check
  says ``pass`` / ``fail`` in words, not by colour alone.
- PDF: through matplotlib's ``PdfPages`` (:func:`vtool.app.figures.pdf_document`):
  each section's text and tables on A4 text pages (a fixed-width font,
  scaled down to fit a wide table), then each of its figures on a page of
  its own.

The content comes from :mod:`vtool.presets.report`; this module only draws.
Both files are written atomically (:mod:`vtool.files`).
"""

from __future__ import annotations

import html
from collections.abc import Iterator
from pathlib import Path

from vtool.presets.report import Check, Report, Section, Table

REPORT_FORMATS = ("html", "pdf")

CSS = """
body { font-family: sans-serif; max-width: 60em; margin: 2em auto; color: #000; }
h1 { font-size: 1.5em; } h2 { border-bottom: 1px solid #000; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.85em; }
th, td { border: 1px solid #666; padding: 0.2em 0.5em; text-align: left; }
th { background: #eee; } caption { text-align: left; font-weight: bold; padding: 0.3em 0; }
td.fail { font-weight: bold; } td.fail::before { content: "\\2716 "; } td.pass::before { content: "\\2714 "; }
figure { margin: 1em 0; page-break-inside: avoid; } figure svg { max-width: 100%; height: auto; }
figcaption { font-style: italic; } pre { font-size: 0.75em; overflow-x: auto; }
"""


def check_report_path(path: str | Path, field: str = "-o") -> Path:
    """``path`` if a report may be written there (suffix and folder checked before any run)."""
    from vtool.app.figures import check_output

    return check_output(path, field, REPORT_FORMATS)


# ----------------------------------------------------------------------------
# HTML


def _html_table(table: Table) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in table.header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>" for row in table.rows)
    return f"<table><caption>{html.escape(table.title)}</caption><tr>{head}</tr>{body}</table>"


def _html_checks(checks: tuple[Check, ...]) -> str:
    rows = "".join(
        f"<tr><td>{html.escape(c.name)}</td><td>{html.escape(c.criterion)}</td><td>{html.escape(c.value)}</td>"
        f"<td class=\"{c.outcome.replace('/', '')}\">{html.escape(c.outcome)}</td><td>{html.escape(c.margin)}</td></tr>"
        for c in checks)
    return ("<table class=\"checks\"><caption>checks</caption><tr><th>check</th><th>criterion</th><th>value</th>"
            f"<th>outcome</th><th>margin / note</th></tr>{rows}</table>")


def _inline_svg(charts) -> str:
    from vtool.app.figures import svg_text

    text = svg_text(charts)
    return text[text.index("<svg"):].strip()  # the XML declaration and DOCTYPE are not allowed inside HTML


def html_text(report: Report) -> str:
    """The report as one self-contained HTML document."""
    parts = [f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{html.escape(report.title)}"
             f"</title><style>{CSS}</style></head><body>",
             f"<h1>{html.escape(report.title)}</h1><p>{html.escape(report.subtitle)}</p>"]
    for section in report.sections:
        parts.append(f"<section><h2>{html.escape(section.title)}</h2>")
        parts += [f"<p>{html.escape(p)}</p>" for p in section.paragraphs]
        parts += [_html_table(t) for t in section.tables]
        parts += [f"<pre>{html.escape(block)}</pre>" for block in section.text]
        if section.checks:
            parts.append(_html_checks(section.checks))
        for figure in section.figures:
            parts.append(f"<figure>{_inline_svg(figure.charts)}<figcaption>{html.escape(figure.caption)}"
                         "</figcaption></figure>")
        parts.append("</section>")
    parts.append("</body></html>\n")
    return "\n".join(parts)


# ----------------------------------------------------------------------------
# PDF


def _text_table(table: Table) -> list[str]:
    widths = [max(len(h), *(len(r[i]) for r in table.rows)) if table.rows else len(h)
              for i, h in enumerate(table.header)]
    line = "  ".join(h.ljust(w) for h, w in zip(table.header, widths, strict=True))
    return [table.title, line, "-" * len(line)] + [
        "  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) for row in table.rows] + [""]


def section_lines(section: Section) -> list[str]:
    """A section's text and tables as fixed-width lines (the PDF's text pages)."""
    import textwrap

    lines = [section.title.upper(), ""]
    for paragraph in section.paragraphs:
        lines += textwrap.wrap(paragraph, 100) + [""]
    for table in section.tables:
        lines += _text_table(table)
    for block in section.text:
        lines += block.splitlines() + [""]
    if section.checks:
        lines += _text_table(Table("checks", ("check", "criterion", "value", "outcome", "margin / note"),
                                   tuple((c.name, c.criterion, c.value, c.outcome.upper(), c.margin)
                                         for c in section.checks)))
    if section.figures:
        lines.append(f"({len(section.figures)} figure{'s' if len(section.figures) > 1 else ''} on the following "
                     f"page{'s' if len(section.figures) > 1 else ''})")
    return lines


def pdf_pages(report: Report) -> Iterator[tuple[str, object]]:
    """(what, matplotlib figure) per PDF page: the sections' text flows over A4 pages; a section's figures
    follow its text, one page each."""
    from vtool.app.figures import build_figure, text_pages

    lines = [report.subtitle, ""]
    titles: list[str] = []

    def flush() -> Iterator[tuple[str, object]]:
        for page in text_pages(lines, report.title):
            yield f"text: {', '.join(titles)}", page

    for section in report.sections:
        lines += section_lines(section) + [""]
        titles.append(section.title)
        if section.figures:
            yield from flush()
            lines, titles = [], []
            for figure in section.figures:
                page = build_figure(figure.charts, figure.caption)
                yield f"figure: {figure.caption}", page
    if lines:
        yield from flush()


def pdf_bytes(report: Report) -> bytes:
    from vtool.app.figures import pdf_document

    return pdf_document((page for _, page in pdf_pages(report)), report.title)


def write_report(report: Report, path: str | Path, field: str = "-o") -> Path:
    """Render ``report`` to ``path`` (HTML or PDF by suffix), atomically."""
    from vtool.app.figures import output_format
    from vtool.files import write_atomic, write_atomic_bytes

    if output_format(path, field, REPORT_FORMATS) == "html":
        write_atomic(path, html_text(report), field)
    else:
        write_atomic_bytes(path, pdf_bytes(report), field)
    return Path(path)
