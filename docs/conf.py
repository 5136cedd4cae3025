"""Sphinx configuration of ngwear's documentation site (``bash scripts/docs.sh`` → ``docs/_build/html``).

Markdown pages (MyST), an executed gallery of plain Python demos (Sphinx-Gallery), the reference generated
from the code (scene keys, CLI, API, result files).  Offline: the theme's fonts and scripts are its own, and
MathJax is served from the build (npm package ``mathjax``, installed by ``scripts/bootstrap.sh``).
"""
import os
import shutil
import sys
from pathlib import Path

import pyvista

import ngwear

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
import gallery_files  # noqa: E402

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
pyvista.OFF_SCREEN = True

project = "ngwear"
author = "the ngwear developers"
copyright = "the ngwear developers"
release = version = ngwear.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
    "sphinxarg.ext",
    "ngwear_reference",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "node_modules", "demos", "**/out"]
root_doc = "index"

myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist", "attrs_inline"]
myst_heading_anchors = 3

autosummary_generate = True
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True}
autodoc_typehints = "description"
napoleon_google_docstring = False
napoleon_numpy_docstring = True

# MathJax 3 from docs/node_modules, copied into _static/mathjax by copy_mathjax below.
MATHJAX = HERE / "node_modules" / "mathjax" / "es5"
MATHJAX_PARTS = ["tex-chtml.js", "input/tex/extensions", "output/chtml/fonts/woff-v2", "ui", "a11y", "sre", "adaptors"]
mathjax_path = "mathjax/tex-chtml.js"
mathjax3_config = {"tex": {"tags": "ams"}}

sphinx_gallery_conf = {
    "examples_dirs": "demos",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/\d\d_",
    "ignore_pattern": r"__init__\.py|conftest\.py",
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib", "gallery_files.png_files"),
    "reset_modules": ("matplotlib", "gallery_files.reset"),
    "reset_modules_order": "both",
    "abort_on_example_error": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "min_reported_time": 1,
    "first_notebook_cell": None,
    "write_computation_times": False,     # its page loads Bootstrap and DataTables from a CDN
    "run_stale_examples": True,
}

html_theme = "pydata_sphinx_theme"
html_title = f"ngwear {version}"
html_static_path = ["_static"]
html_css_files = ["ngwear.css"]
html_show_sourcelink = False
html_favicon = "_static/favicon.png"
html_context = {"default_mode": "auto"}
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "navbar_align": "left",
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
    "secondary_sidebar_items": {"**": ["page-toc"], "reference/scene": [], "reference/files": [],
                                "reference/dependencies": [], "guide/performance": []},
}
html_sidebars = {"index": [], "getting-started": []}


def copy_mathjax(app, exception) -> None:
    """Copy the parts of MathJax the pages load (the TeX input, the CHTML fonts, the menu) into _static."""
    if exception is not None or app.builder.format != "html":
        return
    for part in MATHJAX_PARTS:
        source, target = MATHJAX / part, Path(app.outdir) / "_static" / "mathjax" / part
        target.parent.mkdir(parents=True, exist_ok=True)
        if source.is_dir():
            shutil.copytree(source, target, dirs_exist_ok=True)
        else:
            shutil.copyfile(source, target)


def setup(app):
    if not MATHJAX.is_dir():
        raise RuntimeError(f"{MATHJAX} is missing: run scripts/bootstrap.sh (npm ci --prefix docs installs MathJax)")
    for generated in (HERE / "gallery", HERE / "reference" / "api"):   # made anew by every build: nothing stale
        shutil.rmtree(generated, ignore_errors=True)
    app.connect("build-finished", copy_mathjax)
    app.connect("builder-inited", gallery_files.thumbnails, priority=900)     # after Sphinx-Gallery's examples
