"""Griffe extension (``extensions:`` of mkdocstrings in ``mkdocs.yml``): discsim's docstrings read as Markdown.

- discsim's docstrings head their doctests ``Example:``, which the Google style of griffe does not know (it
  knows ``Examples:``) and would render as an admonition of Markdown text, with ``>>>`` lines read as quotes
  and ``[a]`` / ``[b]`` as links. The heading is renamed before the docstring is parsed, so doctests render
  as code.
- Sphinx roles (``:class:`~discsim.model.Box```, ``:func:`reconstruct```) become inline code (``Box``,
  ``reconstruct``): Markdown has no roles, and they would show as ":class:" text.
"""

from __future__ import annotations

import re

import griffe

_EXAMPLE = re.compile(r"^(\s*)Example:[ \t]*$", re.MULTILINE)
_ROLE = re.compile(r":(?:class|func|meth|data|attr|mod|exc|obj):`(~?)([^`]+)`")


def _role_to_code(match: re.Match) -> str:
    target = match.group(2).strip()
    return f"`{target.rsplit('.', 1)[-1] if match.group(1) else target}`"


class ExampleSections(griffe.Extension):
    """Read a docstring's ``Example:`` section as ``Examples:``, and its Sphinx roles as inline code."""

    def on_instance(self, *, obj, **kwargs) -> None:
        if obj.docstring is not None:
            text = _EXAMPLE.sub(r"\1Examples:", obj.docstring.value)
            obj.docstring.value = _ROLE.sub(_role_to_code, text)
