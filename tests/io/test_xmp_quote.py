"""The XMP writer's attribute quoting is ``xml.sax.saxutils.quoteattr``'s (without importing it)."""

from __future__ import annotations

from xml.sax.saxutils import quoteattr

import pytest

from spherewarp.io.xmp import _quoteattr


@pytest.mark.parametrize(
    "text",
    ["", "equirectangular", "1024", "a&b<c>d", 'say "hi"', "it's", "both \" and '", "a\nb\rc\td"],
)
def test_quoteattr_as_the_standard_library(text):
    assert _quoteattr(text) == quoteattr(text)
