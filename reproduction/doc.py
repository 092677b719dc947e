"""Markdown + HTML rendering of the report (report.py): blocks rendered both ways, a minimal
Markdown-table reader, the page template (print CSS, and the load script the test suite reads
in headless Chromium). No Markdown library needed.

Every image is copied into ``<folder>/images/`` and linked relative to the folder, so the folder
can be moved or zipped; every text goes through report_text.reader_text (no machine paths, no
thesis line numbers, no development history)."""
from __future__ import annotations

import html
import re
import shutil
from pathlib import Path

from reproduction.text import reader_text


class Doc:
    """Blocks rendered both as Markdown and as HTML."""

    def __init__(self, base: Path, roots=()):
        self.base, self.blocks, self.roots, self.copied = base, [], list(roots), {}

    def _copy(self, path: Path) -> str:
        """Copy an image into ``images/`` (a name made unique from its folders); its link."""
        path = Path(path).resolve()
        if path not in self.copied:
            for root, _ in self.roots:
                if Path(root) in path.parents:
                    rel = path.relative_to(root)
                    break
            else:
                rel = Path(path.name)
            name = "_".join(p for p in rel.parts if p not in ("runs", "reference_output"))
            target = self.base / "images" / name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(path, target)
            self.copied[path] = f"images/{name}"
        return self.copied[path]

    def heading(self, level, text):
        self.blocks.append(("h", level, text))

    def para(self, text):
        self.blocks.append(("p", text))

    def code(self, text):
        self.blocks.append(("code", text))

    def image(self, path: Path, caption):
        self.blocks.append(("img", self._copy(path), caption))

    def figure(self, paths, caption, anchor):
        """One thesis figure: its PNG(s) side by side, an anchor and a caption."""
        self.blocks.append(("fig", [self._copy(p) for p in paths], caption, anchor))

    def anchor_heading(self, level, text, anchor):
        self.blocks.append(("ah", level, text, anchor))

    def raw(self, html_text, markdown_text):
        """Pre-rendered HTML (and its Markdown equivalent)."""
        self.blocks.append(("raw", html_text, markdown_text))

    def note(self, text):
        """Small print under a table (column explanations)."""
        self.blocks.append(("note", text))

    def items(self, lines):
        self.blocks.append(("ul", list(lines)))

    def markdown_table(self, text):
        """Copy a Markdown file's content (tables and paragraphs)."""
        self.blocks.append(("md", text))

    # -- rendering
    def to_markdown(self) -> str:
        out = []
        for b in self.blocks:
            if b[0] == "h":
                out.append("#" * b[1] + " " + b[2])
            elif b[0] == "p":
                out.append(b[1])
            elif b[0] == "code":
                out.append("```\n" + b[1] + "\n```")
            elif b[0] == "img":
                out.append(f"![{b[2]}]({b[1]})\n\n*{b[2]}*")
            elif b[0] == "ul":
                out.append("\n".join(f"- {line}" for line in b[1]))
            elif b[0] == "md":
                out.append(_demote_headings(b[1]))
            elif b[0] == "fig":
                out.append("".join(f"![{b[3]}]({p}) " for p in b[1]) + f"\n\n*{b[2]}*")
            elif b[0] == "ah":
                out.append(f'<a id="{b[3]}"></a>\n\n' + "#" * b[1] + " " + b[2])
            elif b[0] == "raw":
                out.append(b[2])
            elif b[0] == "note":
                out.append(f"*{b[1]}*")
        return reader_text("\n\n".join(out) + "\n", self.roots)

    def to_html(self, title) -> str:
        body = []
        for b in self.blocks:
            if b[0] == "h":
                body.append(f"<h{b[1]}>{_inline(b[2])}</h{b[1]}>")
            elif b[0] == "p":
                body.append(f"<p>{_inline(b[1])}</p>")
            elif b[0] == "code":
                body.append(f"<pre><code>{html.escape(b[1])}</code></pre>")
            elif b[0] == "img":
                body.append(f'<figure><img src="{html.escape(b[1])}" alt="{html.escape(b[2])}">'
                            f"<figcaption>{_inline(b[2])}</figcaption></figure>")
            elif b[0] == "ul":
                body.append("<ul>" + "".join(f"<li>{_inline(x)}</li>" for x in b[1]) + "</ul>")
            elif b[0] == "md":
                body.append(_markdown_to_html(_demote_headings(b[1])))
            elif b[0] == "fig":
                imgs = "".join(f'<img src="{html.escape(p)}" alt="{html.escape(b[3])}">'
                               for p in b[1])
                body.append(f'<figure id="{b[3]}" class="n{min(len(b[1]), 2)}">{imgs}'
                            f"<figcaption>{_inline(b[2])}</figcaption></figure>")
            elif b[0] == "ah":
                body.append(f'<h{b[1]} id="{b[3]}">{_inline(b[2])}</h{b[1]}>')
            elif b[0] == "raw":
                body.append(b[1])
            elif b[0] == "note":
                body.append(f'<p class="note">{_inline(b[1])}</p>')
        return HTML_TEMPLATE.format(title=html.escape(title),
                                    body=reader_text("\n".join(body), self.roots))


def _inline(text) -> str:
    text = html.escape(text)
    text = re.sub(r"`([^`]+)`", r"<code>\1</code>", text)
    text = re.sub(r"\[([^]]+)\]\(#([\w-]+)\)", r'<a href="#\2">\1</a>', text)
    text = re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", text)
    return re.sub(r"(?<![\w*])\*([^*]+)\*(?![\w*])", r"<i>\1</i>", text)


def _demote_headings(text) -> str:
    return re.sub(r"^(#+) ", lambda m: "#" * min(6, len(m.group(1)) + 3) + " ", text, flags=re.M)


def _separator(line) -> bool:
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    return line.startswith("|") and all(c and set(c) <= set("-: ") for c in cells)


def _table_start(lines, i) -> bool:
    """A pipe table starts here: a '|' row followed by its delimiter row (as in GitHub
    Markdown), so a wrapped line that begins with a norm '||u||' stays text."""
    return lines[i].startswith("|") and i + 1 < len(lines) and _separator(lines[i + 1])


def _markdown_to_html(text) -> str:
    """Headings, pipe tables, bullet lists, fenced code and paragraphs (consecutive lines
    joined) -- the subset our tables and benchmarks/readings.md use."""
    out, lines, i, para = [], text.splitlines(), 0, []

    def flush():
        if para:
            out.append(f"<p>{_inline(' '.join(para))}</p>")
            para.clear()

    while i < len(lines):
        line = lines[i]
        if _table_start(lines, i):
            flush()
            rows = []
            while i < len(lines) and lines[i].startswith("|"):
                cells = [c.strip() for c in lines[i].strip().strip("|").split("|")]
                if not all(set(c) <= set("-: ") for c in cells):
                    rows.append(cells)
                i += 1
            head, *rest = rows
            out.append("<table><tr>" + "".join(f"<th>{_inline(c)}</th>" for c in head) + "</tr>"
                       + "".join("<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in r) + "</tr>"
                                 for r in rest) + "</table>")
            continue
        if line.startswith("```"):
            flush()
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            out.append(f"<pre><code>{html.escape(chr(10).join(lines[i + 1:j]))}</code></pre>")
            i = j + 1
            continue
        m = re.match(r"^(#+) (.*)", line)
        bullet = re.match(r"^\s*[-*] (.*)", line)
        if m:
            flush()
            out.append(f"<h{len(m.group(1))}>{_inline(m.group(2))}</h{len(m.group(1))}>")
        elif bullet:
            flush()
            items = [bullet.group(1)]
            i += 1
            while i < len(lines) and lines[i].strip() and not lines[i].startswith("#") \
                    and not _table_start(lines, i):
                nxt = re.match(r"^\s*[-*] (.*)", lines[i])
                if nxt:
                    items.append(nxt.group(1))
                else:
                    items[-1] += " " + lines[i].strip()
                i += 1
            out.append("<ul>" + "".join(f"<li>{_inline(x)}</li>" for x in items) + "</ul>")
            continue
        elif line.strip():
            para.append(line.strip())
        else:
            flush()
        i += 1
    flush()
    return "\n".join(out)


HTML_TEMPLATE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: "DejaVu Sans", sans-serif; max-width: 62em; margin: 2em auto;
        line-height: 1.4; font-size: 11pt; padding: 0 1em; }}
header.title {{ border-bottom: 2px solid #333; margin-bottom: 1em; }}
header.title h1 {{ margin-bottom: 0.2em; }}
img {{ max-width: 100%; max-height: 460px; width: auto; height: auto; }}
figure {{ margin: 1em 0; break-inside: avoid; }}
figure.n2 img {{ max-width: 49%; vertical-align: top; }}
@media print {{ img {{ max-height: 11cm; }} }}
figcaption {{ color: #333; font-size: 90%; margin-top: 0.3em; }}
table {{ border-collapse: collapse; margin: 0.6em 0; font-size: 85%; break-inside: auto; }}
tr {{ break-inside: avoid; }}
td, th {{ border: 1px solid #bbb; padding: 0.15em 0.4em; text-align: right; vertical-align: top; }}
td.l, th.l {{ text-align: left; }}
table.summary td {{ text-align: left; }}
.v-reproduced {{ color: #1a7f37; font-weight: bold; }}
.v-differs {{ color: #b3261e; font-weight: bold; }}
.v-not {{ color: #666; font-weight: bold; }}
.v-reading {{ color: #2f6f3a; font-weight: bold; }}
.v-assumed {{ color: #8a6d00; font-weight: bold; }}
.v-invisible {{ color: #a04f00; font-weight: bold; }}
ul.counts {{ columns: 3; list-style: none; padding-left: 0; font-weight: bold; }}
nav.toc li {{ break-inside: avoid; }}
td.ratio small {{ color: #555; display: block; font-size: 80%; }}
td.good {{ background: #e6f4ea; }} td.bad {{ background: #fce8e6; }}
p.note {{ font-size: 85%; color: #444; margin-top: -0.3em; }}
nav.toc ol {{ columns: 2; column-gap: 3.5em; font-size: 92%; }}
pre {{ background: #f4f4f4; padding: 0.5em; overflow-x: auto; white-space: pre-wrap; }}
ul.assumptions {{ font-size: 82%; color: #333; }}
h2 {{ border-bottom: 1px solid #999; break-after: avoid; }} h3, h4 {{ break-after: avoid; }}
@page {{ size: A4; margin: 14mm 12mm; }}
@media print {{ body {{ max-width: none; margin: 0; font-size: 9.5pt; }}
  h2 {{ break-before: page; }} h2.first {{ break-before: auto; }} }}
</style>
<script>
// marks every image as loaded or broken (checked by the test suite in headless Chromium)
window.addEventListener("load", function () {{
  var imgs = document.images, ok = 0;
  for (var i = 0; i < imgs.length; i++) {{
    var good = imgs[i].complete && imgs[i].naturalWidth > 0;
    imgs[i].setAttribute("data-loaded", good ? "yes" : "no");
    if (good) ok++;
  }}
  document.body.setAttribute("data-images", ok + "/" + imgs.length);
}});
</script></head>
<body>
{body}
</body></html>
"""
