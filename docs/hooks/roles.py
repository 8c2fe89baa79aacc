"""A mkdocs hook: the docstrings cross-reference in Sphinx's roles (:class:`~a.B`, :func:`f`),
which mkdocstrings prints as they are; show each as the plain name in code."""

import re

ROLE = re.compile(r":(?:class|func|meth|attr|mod|data|exc):<code>~?([\w.]+)</code>")


def on_page_content(html, **kwargs):
    return ROLE.sub(lambda m: f"<code>{m.group(1).rsplit('.', 1)[-1] if '~' in m.group(0) else m.group(1)}</code>", html)
