"""Errors name the CLI option to use, never Python code (errors.SpherewarpError.cli_message)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from _cli import fails

from spherewarp.errors import ImageFormatError, OutputExistsError, SpherewarpError
from spherewarp.io import read_image, write_image

PYTHON = re.compile(r"=True|=False|\w\(|\[\.\.\.|np\.")


def _no_python(text: str) -> None:
    assert not PYTHON.search(text), text


def test_not_2_to_1_names_force(tmp_path: Path) -> None:
    src = write_image(tmp_path / "sq.png", np.zeros((20, 20, 3), np.uint8), gpano=False)
    err = fails(None, "rotate", src, "--yaw", "3", "-o", tmp_path / "o.png")
    assert "--force" in err
    _no_python(err)


def test_existing_output_names_overwrite(tmp_path: Path) -> None:
    src = write_image(tmp_path / "in.png", np.zeros((8, 16, 3), np.uint8))
    (tmp_path / "o.png").write_bytes(b"x")
    err = fails(None, "rotate", src, "--yaw", "3", "-o", tmp_path / "o.png")
    assert "--overwrite" in err
    _no_python(err)


def _raised(func, *args, **kwargs) -> SpherewarpError:
    with pytest.raises(SpherewarpError) as info:
        func(*args, **kwargs)
    return info.value


@pytest.mark.parametrize(
    ("name", "pixels", "cli"),
    [
        ("a.png", np.zeros((4, 8, 3), np.float32), ".exr or .tif"),
        ("a.jpg", np.zeros((4, 8, 3), np.uint16), ".png or .tif"),
        ("a.jpg", np.zeros((4, 8, 4), np.uint8), "--background"),
    ],
)
def test_write_image_errors_carry_both_wordings(tmp_path: Path, name, pixels, cli) -> None:
    exc = _raised(write_image, tmp_path / name, pixels)
    assert isinstance(exc, ImageFormatError)
    assert "convert_dtype(" in str(exc) or "pixels[" in str(exc)  # the Python advice stays
    assert cli in exc.cli_message
    _no_python(exc.cli_message)


def test_exists_and_max_pixels_errors_carry_both_wordings(tmp_path: Path) -> None:
    p = write_image(tmp_path / "a.png", np.zeros((4, 8, 3), np.uint8))
    exc = _raised(write_image, p, np.zeros((4, 8, 3), np.uint8))
    assert isinstance(exc, OutputExistsError) and "overwrite=True" in str(exc)
    assert "--overwrite" in exc.cli_message
    _no_python(exc.cli_message)
    exc = _raised(read_image, p, max_pixels=10)
    assert "max_pixels=" in str(exc)
    _no_python(exc.cli_message)


def test_lattes_degree_bound_names_exact(tmp_path: Path) -> None:
    src = write_image(tmp_path / "in.png", np.zeros((8, 16, 3), np.uint8))
    err = fails(None, "lattes", src, "--alpha", "8", "-o", tmp_path / "o.png")
    assert "--exact" in err and "method=" not in err
    _no_python(err)


def test_no_cli_message_says_python_in_brackets() -> None:
    """'(CLI: --x)' appended to a Python message is the old style: use ``cli=`` instead."""
    src = Path(__file__).resolve().parents[2] / "src" / "spherewarp"
    hits = [p for p in src.rglob("*.py") if "(CLI: --" in p.read_text(encoding="utf-8")]
    assert hits == []
