"""mkdocs hook: the README is the site's home page.

The README lives at the repository root (where GitHub and PyPI show it) and links to ``docs/X.md``;
the pages link back to ``../README.md``.  Here the README becomes ``index.md`` and both kinds of
link are rewritten to their places in the site, so that mkdocs checks them like any other link.
"""
from __future__ import annotations

import re
from pathlib import Path

from mkdocs.structure.files import File


def on_files(files, config):
    readme = Path(config["config_file_path"]).parent / "README.md"
    files.append(File.generated(config, "index.md", abs_src_path=str(readme)))
    return files


def on_page_markdown(markdown, page, config, files):
    if page.file.src_uri == "index.md":
        return re.sub(r"\]\(docs/", "](", markdown)
    return re.sub(r"\]\(\.\./README\.md", "](index.md", markdown)
