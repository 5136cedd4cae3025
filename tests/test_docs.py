"""The documentation site: generated from the code, built with warnings as errors, whole in a browser, offline.

The site is built once per test session into a temporary folder (``sphinx-build -W``; every gallery example runs).
In Debian's Chromium (Playwright) every page reachable from the index is opened — served from 127.0.0.1 — and
every internal link must resolve (anchors included), every image load, no page log an error or ask for anything
off the machine; opened from disk (file://) the index and a page with math work the same.  Screenshots:
``out/browser-artifacts/test_docs/`` and ``index.png`` beside the built site.
"""
import functools
import http.server
import re
import shutil
import sys
import threading
import urllib.request
from html.parser import HTMLParser
from urllib.parse import urldefrag, urlparse

import numpy as np
import pytest
from browser import Shots, Watch, chromium
from conftest import ROOT
from PIL import Image

pytest.importorskip("sphinx", reason="the site needs the docs extra (pip install 'ngwear[docs]')")
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
import ngwear_reference  # noqa: E402

from ngwear.model.reference import reference_table  # noqa: E402
from ngwear.model.sections import SECTIONS  # noqa: E402


def test_scene_reference_page_shows_every_declared_key():
    """docs/reference/scene.md has a generated table for every section, and together they are the declared table."""
    page = (DOCS / "reference" / "scene.md").read_text()
    sections = re.findall(r"```\{scene-keys\} (\S+)", page)
    assert sections == ["name", *SECTIONS]
    rows = [row for section in sections for row in ngwear_reference.scene_key_rows(section)]
    assert rows == reference_table().splitlines()[2:]


@pytest.mark.parametrize("name", ["result.npz", "summary.json", "checkpoint.npz"])
def test_result_file_keys_are_explained(name):
    """Every key a run writes into the file has its line on the reference page (the build fails otherwise)."""
    table = ngwear_reference.result_key_table(name)
    assert len(table.splitlines()) == 2 + len(ngwear_reference.written_keys()[name])


def markdown_tables(text: str) -> list[list[list[str]]]:
    """The pipe tables of a Markdown text outside code blocks: rows of cells, split where Markdown splits them."""
    tables, rows, fenced = [], [], False
    for line in text.splitlines() + [""]:
        fenced ^= line.lstrip().startswith("```")
        if not fenced and line.lstrip().startswith("|"):
            rows.append(re.split(r"(?<!\\)\|", line.strip().strip("|")))
        elif rows:
            tables.append(rows)
            rows = []
    return tables


def generated_tables() -> dict[str, str]:
    """The tables docs/_ext writes into the reference pages, by name."""
    return {**{f"scene-keys {s}": ngwear_reference.scene_key_table(s) for s in ["name", *SECTIONS]},
            **{f"result-keys {f}": ngwear_reference.result_key_table(f) for f in ngwear_reference.MEANING}}


def test_every_markdown_table_row_has_the_headers_cells():
    """A `|` left in a cell (`|φ|`, `|F_t|`) splits its row: the generated tables and every page's own."""
    pages = {str(p.relative_to(ROOT)): p.read_text() for p in [ROOT / "README.md", *DOCS.rglob("*.md")]
             if not {"node_modules", "_build", "gallery"} & set(p.parts)}
    problems = [f"{name}: {'|'.join(row)[:80]}… has {len(row)} cells, its header {len(table[0])}"
                for name, text in {**pages, **generated_tables()}.items() for table in markdown_tables(text)
                for row in table if len(row) != len(table[0])]
    assert len(generated_tables()) > 10 and not problems, "\n".join(problems)


def test_cli_help_becomes_rest_in_the_reference():
    """`code` becomes a literal; an address outside one too, so docutils does not make it a link."""
    assert ngwear_reference.rest("see `ngwear examples`, e.g. tcp://host:8786 (default)") == \
        "see ``ngwear examples``, e.g. ``tcp://host:8786`` (default)"
    parser = ngwear_reference.cli_parser()
    sweep = parser._subparsers._group_actions[0].choices["sweep"]
    assert "``tcp://host:8786``" in next(a.help for a in sweep._actions if a.dest == "scheduler")
    assert "``ngwear COMMAND --help``" in parser.description


def test_markdown_tables_split_rows_as_markdown_does():
    """The check above sees what a reader sees: an unescaped `|` in a cell makes one cell more."""
    text = "x\n\n| a | b |\n|---|---|\n| `x` | \\|φ\\| ≤ 1 |\n| y | |φ| |\n\n```\n| not | a | table |\n```\n"
    (table,) = markdown_tables(text)
    assert [len(row) for row in table] == [2, 2, 2, 4]


@pytest.mark.slow
@pytest.mark.xdist_group("site")
def test_site_builds_with_warnings_as_errors(site):
    html, record = site
    pages = sorted(html.rglob("*.html"))
    print(f"docs build: {record['seconds']} s, {len(pages)} HTML pages in {html}")
    gallery = sorted((DOCS / "demos").glob("[0-9][0-9]_*.py"))
    for example in gallery:
        text = (html / "gallery" / f"{example.stem}.html").read_text()
        assert "sphx-glr-single-img" in text or "sphx-glr-multi-img" in text, f"{example.name} shows no picture"
    reference = (html / "reference" / "scene.html").read_text()
    assert all(f"<code class=\"docutils literal notranslate\"><span class=\"pre\">{row.split('`')[1]}</span>" in
               reference for row in reference_table().splitlines()[2:])
    assert (html / "_static" / "mathjax" / "tex-chtml.js").is_file()
    for name in ("03_brake_pad", "04_pin_on_disc", "05_own_step_file"):   # 3D parts: thumbnails not a white page
        thumb = np.asarray(Image.open(html / "_images" / f"sphx_glr_{name}_thumb.png").convert("RGB"))
        assert (thumb.min(axis=-1) > 235).mean() < 0.6, name                # white before: 0.86 … 0.91
    cli = (html / "reference" / "cli.html").read_text()   # help texts as reST: code literal, addresses not links
    assert "<cite>" not in cli and 'href="tcp://' not in cli and ">tcp://host:8786<" in cli
    assert '<span class="pre">--help</span>' in cli
    for page in pages:               # nothing loaded from elsewhere: scripts, styles and images are the site's own
        assert not ragged_tables(page.read_text()), f"{page.relative_to(html)}: {ragged_tables(page.read_text())}"
        for tag in re.findall(r"<(?:script|link|img)\b[^>]*>", page.read_text()):
            assert not re.search(r"(?:src|href)=\"(?:https?:)?//", tag) or "rel=\"canonical\"" in tag, \
                f"{page.relative_to(html)}: {tag}"


class _Tables(HTMLParser):
    """The cell count (colspans summed) of each row of each table of an HTML page."""

    def __init__(self):
        super().__init__()
        self.tables, self.open = [], []

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.open.append([])
        elif tag == "tr" and self.open:
            self.open[-1].append(0)
        elif tag in ("td", "th") and self.open and self.open[-1]:
            self.open[-1][-1] += int(dict(attrs).get("colspan") or 1)

    def handle_endtag(self, tag):
        if tag == "table" and self.open:
            self.tables.append(self.open.pop())


def ragged_tables(page: str) -> list[list[int]]:
    """The cell counts of the tables of an HTML page whose rows do not all have the header's number of cells."""
    parser = _Tables()
    parser.feed(page)
    return [rows for rows in parser.tables if rows and any(n != rows[0] for n in rows)]


def test_ragged_tables_are_found():
    page = "<table><tr><th>a</th><th>b</th></tr><tr><td colspan='2'>c</td></tr></table>"
    assert ragged_tables(page) == []
    assert ragged_tables(page.replace("<td colspan='2'>c</td>", "<td>c</td>")) == [[2, 1]]


# ---------------------------------------------------------------- in the browser

IMAGES_JS = """async () => {
    const images = Array.from(document.images);
    for (const i of images) { i.loading = 'eager'; }
    await Promise.all(images.map(i => i.decode().catch(() => null)));
    return images.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src);
}"""
MATH_JS = """async () => {
    if (!document.querySelector('.math')) return -1;
    for (let t = 0; t < 200 && !(window.MathJax && MathJax.startup && MathJax.startup.promise); t++)
        await new Promise(r => setTimeout(r, 50));
    await MathJax.startup.promise;
    return document.querySelectorAll('mjx-container').length;
}"""


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


@pytest.fixture(scope="module")
def served(site):
    """The built site over HTTP on 127.0.0.1 (a free port): its base URL."""
    handler = functools.partial(_Quiet, directory=str(site[0]))
    with http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler) as httpd:
        thread = threading.Thread(target=httpd.serve_forever, daemon=True)
        thread.start()
        yield f"http://127.0.0.1:{httpd.server_address[1]}/"
        httpd.shutdown()


def check_page(page, url: str) -> tuple[list[str], set[str]]:
    """Open ``url``; (problems, the ids on the page).  The page's links are read by the caller."""
    response = page.goto(url, wait_until="load")
    if response is not None and response.status >= 400:          # file:// has no response
        return [f"{url}: HTTP {response.status}"], set()
    problems = [f"{url}: image not loaded: {src}" for src in page.evaluate(IMAGES_JS)]
    if page.evaluate(MATH_JS) == 0:
        problems.append(f"{url}: MathJax typeset no formula")
    ids = set(page.evaluate("() => Array.from(document.querySelectorAll('[id]')).map(e => e.id)"))
    return problems, ids


@pytest.mark.browser
@pytest.mark.xdist_group("site")
def test_every_page_link_and_image_in_chromium(site, served):
    html, _ = site
    shots = Shots("test_docs")
    pages, anchors, files, problems = {}, [], set(), []
    queue = [served, served + "gallery/01_paper_strip.html"]
    with chromium() as browser:
        page = browser.new_page(viewport={"width": 1280, "height": 900})
        watch = Watch(page)
        with shots.on_failure(page):
            while queue:
                url = queue.pop(0)
                if url in pages:
                    continue
                found, pages[url] = check_page(page, url)
                problems += found
                if url == served:
                    shutil.copyfile(shots(page, "index"), html.parent / "index.png")
                elif url.endswith("gallery/01_paper_strip.html"):
                    shots(page, "gallery-paper-strip")
                for link in page.evaluate("() => Array.from(document.querySelectorAll('a[href]')).map(a => a.href)"):
                    target, fragment = urldefrag(link)
                    if not target.startswith(served):
                        continue
                    if target.endswith(".html") or target.endswith("/"):
                        queue.append(target)
                        if fragment:
                            anchors.append((url, target, fragment))
                    else:
                        files.add(target)
            for url, target, fragment in anchors:
                if fragment not in pages.get(target, set()):
                    problems.append(f"{url}: link to a missing anchor {target}#{fragment}")
            for target in sorted(files):
                with urllib.request.urlopen(target) as answer:
                    if answer.status != 200:
                        problems.append(f"link to {target}: HTTP {answer.status}")
    print(f"{len(pages)} pages, {len(anchors)} anchored links, {len(files)} linked files; index: {html.parent}/index.png")
    assert not problems, "\n".join(problems)
    assert not watch.errors, watch.errors
    assert not watch.external, f"requests that left 127.0.0.1: {watch.external}"
    assert len(pages) >= 30


@pytest.mark.browser
@pytest.mark.xdist_group("site")
def test_pages_work_opened_from_disk(site):
    """file:// — no server, no network: the index shows its picture, the model page its formulas."""
    html, _ = site
    with chromium() as browser:
        page = browser.new_page()
        errors, external = [], []
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.on("request", lambda r: None if urlparse(r.url).scheme in ("file", "data", "blob") else
                external.append(r.url))
        for name in ("index.html", "guide/model.html"):
            problems, _ = check_page(page, (html / name).as_uri())
            assert not problems, problems
        formulas = page.evaluate(MATH_JS)
    assert formulas > 20, "MathJax, served from the site itself, typesets the model's equations"
    assert not errors and not external, (errors, external)
