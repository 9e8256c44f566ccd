"""Sphinx configuration of the API reference: the docstrings, read by autodoc and napoleon.

Build it from the repository root (CI does, with warnings as errors):

    python -m sphinx -W --keep-going -b html docs/api build/api-html
"""

import re
import sys
from pathlib import Path

# The package from this checkout, whether or not it is installed.
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from sphinx.ext.napoleon.docstring import NumpyDocstring

from attitude import __version__  # from this checkout (see above)

project = "attitude"
author = "the attitude developers"
copyright = "the attitude developers, MIT licence"
version = release = __version__

extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon"]

# The docstrings are NumPy-style (Parameters, Returns, Raises sections) where they
# have sections at all; most are prose with ``literals``.
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False

autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": True}
# Types in the parameter list rather than in long signatures (NDArray[np.float64]...).
autodoc_typehints = "description"
autodoc_typehints_format = "short"
autodoc_preserve_defaults = True
# numpy's ArrayLike and NDArray by their names, not as what they stand for.
autodoc_type_aliases = {"ArrayLike": "numpy.typing.ArrayLike", "NDArray": "numpy.typing.NDArray"}

default_role = "code"  # `x` in a docstring reads as code, like ``x``
exclude_patterns = ["_build"]
html_theme = "alabaster"
html_title = f"attitude {version}: API reference"


# The docstrings write norms as plain text, |m| or |r|, which reStructuredText would
# read as substitution references: escape the bars outside ``literals``.
_NORM = re.compile(r"(?<![|\\])\|(?=[^\s|])([^|`]*?[^\s|\\])\|(?!_)")


def _escape_norms(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        parts = line.split("``")
        parts[::2] = [_NORM.sub(r"\\|\1\\|", part) for part in parts[::2]]
        lines[i] = "``".join(parts)


def _attribute_as_prose(self):
    """A property's docstring is prose whose first line may hold a colon ("Period of
    the body-frame motion m(t), seconds: 4K/|λ|."), not napoleon's Google-style
    ``type: description``; the type is shown from the annotation."""
    return NumpyDocstring(list(self._consume_to_end()), self._config, self._app).lines()


NumpyDocstring._parse_attribute_docstring = _attribute_as_prose


def setup(app):
    app.connect("autodoc-process-docstring", _escape_norms)
