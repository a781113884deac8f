"""The user documentation builds with `mkdocs build --strict`: every page in the nav, no broken link.

MkDocs turns a link to a missing page or anchor, or a page left out of the nav, into a
warning; --strict makes any warning fail the build, so a renamed heading fails here.
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MKDOCS = ROOT / ".venv" / "bin" / "mkdocs"


def build(config: Path, site: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(MKDOCS), "build", "--strict", "--config-file", str(config), "--site-dir", str(site)],
        cwd=config.parent, capture_output=True, text=True, timeout=120,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
    )  # fmt: skip


def test_the_docs_build_strictly_without_warnings(tmp_path: Path) -> None:
    built = build(ROOT / "mkdocs.yml", tmp_path / "site")

    assert built.returncode == 0, built.stderr
    assert "WARNING" not in built.stderr, built.stderr
    pages = {"engineers", "operators", "admins", "pattern-format", "api", "architecture"}
    assert all((tmp_path / "site" / page / "index.html").exists() for page in pages)


def test_a_broken_link_fails_the_build(tmp_path: Path) -> None:
    docs = tmp_path / "docs"
    docs.mkdir()
    for page in (ROOT / "docs").glob("*.md"):
        (docs / page.name).write_text(page.read_text())
    (docs / "index.md").write_text((docs / "index.md").read_text() + "\n[gone](no-such-page.md)\n")
    config = tmp_path / "mkdocs.yml"
    config.write_text((ROOT / "mkdocs.yml").read_text())

    built = build(config, tmp_path / "site")

    assert built.returncode != 0
    assert "no-such-page.md" in built.stderr


def test_the_readme_is_short_and_links_only_to_pages_that_exist() -> None:
    readme = (ROOT / "README.md").read_text()
    links = re.findall(r"\]\((docs/[^)#]+)", readme)

    assert len(readme.splitlines()) < 120
    assert links, "the README links into docs/"
    assert [link for link in links if not (ROOT / link).is_file()] == []
