"""The report's one HTML page (:func:`page`, what :func:`xairl.outputs.report.write_report` writes): the main findings first,
then a table of contents, the settings, the tables, the figures, the narrated decisions and the notes. A report runs
to 15,000 pixels, so every section and figure is linked from the contents; a table's long title (Table I's caption
holds its verdict) is shown as a short heading over the caption in full.
"""

from __future__ import annotations

import base64
import html
import json
import re
from pathlib import Path

from xairl.explanations.evidence import CARD_STYLE, card_html

#: a section heading longer than this is cut at its first clause, its full text shown under it
HEADING_CHARS = 70


def short_heading(text: str, limit: int = HEADING_CHARS) -> str:
    """``text`` up to its first clause (': ', '; ', ' (', '. ', ', by'), at most ``limit`` characters, cut at a word."""
    head = re.split(r": |; | \(|\. |, by ", text, maxsplit=1)[0]
    if len(head) <= limit:
        return head
    return head[:limit].rsplit(" ", 1)[0] + "\u2026"


def table_html(header: list[str], rows: list[list]) -> str:
    """An HTML table; floats with two decimals, everything else escaped."""

    def cell(v):
        return f"{v:.2f}" if isinstance(v, float) else html.escape(str(v))

    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell(v)}</td>" for v in r) + "</tr>" for r in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _img(path: Path) -> str:
    return "data:image/png;base64," + base64.b64encode(Path(path).read_bytes()).decode()


def _figures_body(exps, figures) -> tuple[str, list[tuple[str, str]]]:
    """The figures section's HTML (each dataset's size and additivity gap, then each figure) and its entries in the
    contents."""
    body = (
        "<p>"
        + ", ".join(
            f"{html.escape(label)}: {len(e.values)} states, largest additivity gap {e.additivity_gap.max():.1e}"
            for label, e in exps
        )
        + "</p>"
    )
    subs = []
    for k, (caption, png) in enumerate(figures, 1):
        body += (
            f"<figure id=f{k}><img src='{_img(png)}' alt='{html.escape(caption)}'><figcaption>"
            f"{html.escape(caption)}</figcaption></figure>"
        )
        subs.append((f"f{k}", short_heading(caption)))
    return body, subs


def _narratives_body(narratives) -> str:
    """The narrated decisions' HTML: what the marks mean, then one card a narrative."""
    body = (
        "<p class=meta>Each sentence is marked &#10003; verified, &#10007; contradicted or ? unchecked (a claim "
        "the verifier could not check); one that states nothing to check is left unmarked. Each narrative's verdict is <b>verified</b> (every claim checked, and "
        "true), <b>contradicted</b> (a claim is false) or <b>partly checked</b> (nothing false; the coverage is "
        "the share of its claims checked); beside it, what the features it names account for of the margin and "
        "what it leaves out. The waterfall builds the margin of the chosen action over the runner-up (the score, "
        "when nothing is chosen) from its background average, feature by feature.</p>"
    )
    for n, ev in narratives:
        where = "all states" if n.index is None else f"state {n.index}"
        meta = f"{where} &middot; template {html.escape(n.template)} &middot; {html.escape(n.source)}"
        body += card_html(n.text, {**ev, "status": n.status, "coverage": n.coverage, "account": n.account}, meta)
    return body


def page(title, *, findings, tables, notes, exps, figures, narratives, settings) -> str:
    """The page. ``findings``: the plugin's reading of the explanations (first); ``tables`` (title, HTML) and
    ``figures`` (caption, PNG) pairs; ``narratives`` (narrative, evidence) pairs; ``settings`` a dict."""
    sections: list[tuple[str, str, str, list[tuple[str, str]]]] = []  # (id, heading, body, [(sub id, sub heading)])

    def add(heading: str, body: str, subs=()) -> None:
        short = short_heading(heading)
        caption = "" if short == heading else f"<p class=caption>{html.escape(heading)}</p>"
        sections.append((f"s{len(sections) + 1}", short, caption + body, list(subs)))

    if findings:
        add("Main findings", "<ul class=findings>" + "".join(f"<li>{html.escape(x)}</li>" for x in findings) + "</ul>")
    add(
        "Settings",
        table_html(
            ["setting", "value"],
            [[k, json.dumps(v) if isinstance(v, (dict, list)) else v] for k, v in settings.items()],
        ),
    )
    for heading, table in tables:
        add(heading, table)
    add("Explanations and figures", *_figures_body(exps, figures))
    if narratives:
        add("Narrated decisions", _narratives_body(narratives))
    if notes:
        add("Notes", "<ul>" + "".join(f"<li>{html.escape(x)}</li>" for x in notes) + "</ul>")
    toc = "".join(
        f"<li><a href='#{sid}'>{html.escape(h)}</a>"
        + ("<ul>" + "".join(f"<li><a href='#{i}'>{html.escape(t)}</a></li>" for i, t in subs) + "</ul>" if subs else "")
        + "</li>"
        for sid, h, _, subs in sections
    )
    parts = [f"<h1>{html.escape(title)}</h1>"]
    first = sections[0] if findings else None  # the main findings before the contents: what a reader came for
    if first:
        parts.append(f"<h2 id={first[0]}>{html.escape(first[1])}</h2>{first[2]}")
    parts.append(f"<nav class=toc><h2>Contents</h2><ul>{toc}</ul></nav>")
    parts += [f"<h2 id={sid}>{html.escape(h)}</h2>{body}" for sid, h, body, _ in sections[1 if first else 0 :]]
    style = (
        "body{font-family:sans-serif;max-width:1200px;margin:2em auto;color:#222}table{border-collapse:collapse;"
        "margin:.5em 0}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}th{background:#eee}"
        "img{max-width:100%}.ok{color:#070;font-weight:bold}.bad{color:#b00;font-weight:bold}"
        ".caption{color:#444;margin:.2em 0 .5em}.toc ul{margin:.2em 0}.toc li{margin:.1em 0}"
        ".findings li{margin:.4em 0}" + CARD_STYLE
    )
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
        f"<style>{style}</style></head><body>{''.join(parts)}</body></html>"
    )
