"""mkdocs hooks: the generated parts of the docs, filled in at build time from their one source
(docs/reference.py: the command and configuration references; docs/results.py: the results
tables). A page holds a marker, ``<!-- generated:cli -->`` and so on, where the part goes."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent)]

import reference  # noqa: E402
import results  # noqa: E402

GENERATED = {
    "<!-- generated:cli -->": reference.cli_markdown,
    "<!-- generated:config -->": reference.config_markdown,
    "<!-- results:headline -->": results.headline_table,
    "<!-- results:full -->": results.full_tables,
}


def on_page_markdown(markdown: str, **_: Any) -> str:
    for marker, make in GENERATED.items():
        if marker in markdown:
            markdown = markdown.replace(marker, make())
    return markdown
