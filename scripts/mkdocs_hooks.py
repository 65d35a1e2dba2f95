"""mkdocs hooks of the documentation site (mkdocs.yml ``hooks:``).

legkin's docstrings cross-reference in Sphinx's roles (``:func:`fk```, ``:mod:`.tripod```), which mkdocstrings
renders as text followed by code; the site drops the role and keeps the code.
"""

from __future__ import annotations

import re
from typing import Any

_ROLE = re.compile(r":(?:func|meth|mod|class|data|attr|exc|obj|const):(?=<code>|`)")


def on_page_content(html: str, **kwargs: Any) -> str:
    """The page's HTML with every Sphinx role prefix (``:func:`` before a code span) removed."""
    return _ROLE.sub("", html)
