"""MkDocs hook (mkdocs.yml ``hooks:``): the pages generated from the code at build
time, added to the build as virtual files (``File.generated``), never written to
``docs/`` or committed:

- ``reference/cli.md``: the ``pbrkit`` command tree (:mod:`site_cli`);
- ``reference/scene.md``: the scene-file keys (:mod:`site_scene`);
- ``gallery.md`` and ``gallery/*.png``: renders of the built-in scenes (:mod:`site_gallery`).

On the API pages the docstrings' Sphinx roles (``:func:`~pbrkit.x.f```), which
mkdocstrings shows as written, become plain code (``f``, as Sphinx shows them).

The site documents the checkout it is built from: ``src/`` comes first on
``sys.path``.  ``PBRKIT_DOCS_NO_GALLERY=1`` leaves the renders out (the page then
says so), for a quick build while writing."""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

from mkdocs.structure.files import File

import site_cli  # noqa: E402  (the hook's folder is on sys.path while MkDocs loads it)
import site_gallery  # noqa: E402
import site_scene  # noqa: E402


def on_files(files, config):
    """Add the generated pages and images to the build."""
    root = Path(config["config_file_path"]).resolve().parent
    if str(root / "src") not in sys.path:  # (MkDocs restores sys.path after loading a hook)
        sys.path.insert(0, str(root / "src"))
    pages = {"reference/cli.md": site_cli.page(root / "pyproject.toml"), "reference/scene.md": site_scene.page()}
    if os.environ.get("PBRKIT_DOCS_NO_GALLERY"):
        pages["gallery.md"] = "# Gallery\n\nLeft out of this build (`PBRKIT_DOCS_NO_GALLERY`).\n"
    else:
        images, pages["gallery.md"] = site_gallery.images()
        for name, data in images.items():
            files.append(File.generated(config, name, content=data))
    for name, text in pages.items():
        files.append(File.generated(config, name, content=text))
    return files


#: A Sphinx role before a code span, as the API pages show it: ":func:<code>~a.b</code>".
_ROLE = re.compile(r":(?:py:)?(?:func|mod|class|meth|data|attr|exc|obj|const):<code>(~?)([^<]*)</code>")


def on_page_content(html, page, config, files):
    """The API pages' Sphinx roles as code: ``~a.b.c`` as ``c``, others as written."""
    if not page.file.src_uri.startswith("reference/api/"):
        return html
    return _ROLE.sub(lambda m: f"<code>{m.group(2).rsplit('.', 1)[-1] if m.group(1) else m.group(2)}</code>", html)
