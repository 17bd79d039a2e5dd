"""Extreme option values end in one error line naming the option, never an internal error."""

from __future__ import annotations

import pytest
from _cli import fails, ok

from spherewarp.demo import sample_path


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["mobius", "--matrix", "1e308,0,0,1"], "singular in double precision"),
        (["zoom", "--at", "0,0", "--factor", "5e-324"], "--factor"),
        (["zoom", "--at", "0,0", "--factor", "1e-300"], "--factor"),
        (["rotate", "--yaw", "3", "--size", "65536x32768"], "--size"),
        (["rotate", "--yaw", "3", "--size", "32768x16384"], "--max-pixels"),
        (["rotate", "--yaw", "3", "--max-pixels", "1000"], "--max-pixels"),
        (["lattes", "--alpha", "8"], "--exact"),
        (["droste", "--center", "0,0", "--inner-radius", "1e-300"], "--scale"),
    ],
)
def test_extreme_values_give_one_error_line(tmp_path, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    err = fails(None, args[0], sample_path(), *args[1:], "-o", "out.png")
    assert needle in err, err
    assert not (tmp_path / "out.png").exists()


def test_lattes_alpha_8_renders_with_exact(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ok(None, "lattes", sample_path(), "--alpha", "8", "--exact", "--size", "128x64", "-o", "l.png")
    assert (tmp_path / "l.png").exists()
