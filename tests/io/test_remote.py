"""spherewarp.io.remote against a real FTP server (pyftpdlib on 127.0.0.1, tests/ftpserver.py)."""

from __future__ import annotations

import pytest

from spherewarp.io import remote

pytest.importorskip("fsspec")
pytest.importorskip("pyftpdlib")


def test_a_file_is_written_whole_under_its_name(ftp):
    url = remote.child(ftp.url, "a/b/notes.txt")
    remote.make_folder(remote.child(ftp.url, "a/b"))
    remote.write_atomic(url, b"hello")
    remote.write_atomic(url, b"again")  # replaced in place
    assert remote.read_text(url) == "again" and remote.size(url) == 5
    assert sorted(p.name for p in (ftp.root / "a" / "b").iterdir()) == ["notes.txt"]  # no temp
    assert remote.identity(url)["size"] == 5
    remote.remove_tree(remote.child(ftp.url, "a"))
    assert not (ftp.root / "a").exists() and not remote.exists(url)
    assert remote.size(url) is None


def test_reachable_names_what_cannot_be_read_or_written(ftp):
    (ftp.root / "in.bin").write_bytes(b"x")
    here, missing = remote.child(ftp.url, "in.bin"), remote.child(ftp.url, "nothing.bin")
    refused = "ftp://127.0.0.1:1/in.bin"  # no server there
    assert remote.reachable([here, missing, refused], [ftp.url, "ftp://127.0.0.1:1/out"]) == [
        missing, refused, "ftp://127.0.0.1:1/out",
    ]  # fmt: skip
    assert not [p for p in ftp.root.iterdir() if "spherewarp" in p.name]  # the probe is gone
