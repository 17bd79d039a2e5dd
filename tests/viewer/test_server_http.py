"""The viewer's server at the level of raw HTTP: request framing, kept-alive
connections, the addresses it listens on, clients that go away."""

from __future__ import annotations

import json
import os
import signal
import socket
import struct
import subprocess
import sys

import pytest

from spherewarp.viewer.server import ViewerServer


@pytest.fixture(scope="module")
def srv():
    s = ViewerServer(None, None)
    yield s
    s.close()


def _exchange(port: int, data: bytes, host: str = "127.0.0.1") -> bytes:
    """Send ``data`` on one connection and read until the server closes it (a server
    that keeps the connection open fails on the socket's timeout)."""
    with socket.create_connection((host, port), timeout=20) as s:
        s.sendall(data)
        out = b""
        while chunk := s.recv(65536):
            out += chunk
    return out


def _request(port: int, method: str, target: str, body: bytes = b"", headers: str = "") -> bytes:
    head = f"{method} {target} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n{headers}"
    if body:
        head += f"Content-Length: {len(body)}\r\n"
    return head.encode() + b"\r\n" + body


def _replies(data: bytes) -> list[int]:
    """The status of each reply in ``data``."""
    return [int(part[:3]) for part in data.split(b"HTTP/1.1 ")[1:] if part[:3].isdigit()]


def _smuggled(port: int) -> bytes:
    """A render request, sent as the body of another request."""
    recipe = json.dumps({"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factor": 3}}]})
    return _request(port, "POST", "/api/render", recipe.encode())


@pytest.mark.parametrize(
    ("method", "target", "headers", "status"),
    [
        ("POST", "/api/stages", "Origin: http://evil.example\r\n", 403),
        ("POST", "/api/stages", "Sec-Fetch-Site: cross-site\r\n", 403),
        ("POST", "/api/render", "Origin: http://evil.example\r\n", 403),
        ("POST", "/api/nope", "", 404),
        ("POST", "/../api/render", "", 404),
        ("GET", "/api/state", "", 200),  # a body a GET does not read
        ("GET", "/image", "", 200),
        ("GET", "/no-such-file", "", 404),
    ],
)
def test_a_body_not_read_is_never_a_request(srv, method, target, headers, status):
    """The body of a request the server does not read (refused, or a GET's) is never
    parsed as the next request on the connection: the reply says
    ``Connection: close`` and the connection closes, so the render inside never runs."""
    inner = _smuggled(srv.port)
    out = _exchange(srv.port, _request(srv.port, method, target, inner, headers))
    assert _replies(out) == [status], out[:300]
    assert b"\r\nConnection: close\r\n" in out
    assert not srv.jobs


def test_a_refused_host_closes_the_connection(srv):
    inner = _smuggled(srv.port)
    req = (
        f"POST /api/stages HTTP/1.1\r\nHost: evil.example:{srv.port}\r\n"
        f"Content-Length: {len(inner)}\r\n\r\n"
    ).encode() + inner
    out = _exchange(srv.port, req)
    assert _replies(out) == [403] and b"DNS rebinding" in out
    assert not srv.jobs


@pytest.mark.parametrize(
    ("head", "why"),
    [
        ("POST /api/render HTTP/1.1\r\nHost: {h}\r\nHost: {h}\r\n", "more than one Host"),
        (
            "POST /api/render HTTP/1.1\r\nHost: {h}\r\nContent-Length: 0\r\n",
            "more than one Content-Length",
        ),
        ("POST /api/render HTTP/1.1\r\nHost: {h}\r\nTransfer-Encoding: chunked\r\n", "Transfer"),
        ("POST /api/render HTTP/1.1\r\nHost: {h}\r\nTransfer-Encoding: identity\r\n", "Transfer"),
        ("POST /api/stages HTTP/1.1\r\nHost: {h}\r\nContent-Length: +{n}\r\n", "Content-Length"),
        ("POST /api/stages HTTP/1.1\r\nHost: {h}\r\nContent-Length: 0_{n}\r\n", "Content-Length"),
        ("POST /api/stages HTTP/1.1\r\nHost: {h}\r\nContent-Length: 0x1f\r\n", "Content-Length"),
        ("GET http://evil.example/api/state HTTP/1.1\r\nHost: {h}\r\n", "request target"),
        ("POST http://{h}/api/render HTTP/1.1\r\nHost: {h}\r\n", "request target"),
    ],
)
def test_ambiguous_framing_is_refused(srv, head, why):
    """What two parsers could read differently (two Hosts or lengths, a transfer coding,
    a length ``int()`` reads but HTTP does not, an absolute-form target) is a 400, and
    the connection closes."""
    inner = _smuggled(srv.port)
    head = head.format(h=f"127.0.0.1:{srv.port}", n=len(inner))
    if "Content-Length" not in head or "Content-Length: 0\r\n" in head:
        head += f"Content-Length: {len(inner)}\r\n"
    out = _exchange(srv.port, head.encode() + b"\r\n" + inner)
    assert _replies(out) == [400], out[:300]
    assert why in json.loads(out.partition(b"\r\n\r\n")[2])["error"]
    assert not srv.jobs


def test_kept_alive_requests_still_work(srv):
    """Replies that read the whole request keep the connection: two requests on one."""
    body = json.dumps({"spherewarp": 1, "steps": [{"power": {"n": 2}}]}).encode()
    req = _request(srv.port, "POST", "/api/stages", body) + _request(
        srv.port, "GET", "/api/state", headers="Connection: close\r\n"
    )
    out = _exchange(srv.port, req)
    assert _replies(out) == [200, 200]
    assert b"Connection: close" not in out.split(b"HTTP/1.1 ")[1]


def _status(port: int, host_header: str, connect: str = "127.0.0.1", path: str = "/") -> int:
    out = _exchange(
        port,
        f"GET {path} HTTP/1.1\r\nHost: {host_header}\r\nConnection: close\r\n\r\n".encode(),
        host=connect,
    )
    return _replies(out)[0]


def _ipv6_loopback() -> bool:
    if not socket.has_ipv6:
        return False
    try:
        with socket.socket(socket.AF_INET6) as s:
            s.bind(("::1", 0))
    except OSError:
        return False
    return True


@pytest.mark.parametrize(
    ("bind", "connect", "names"),
    [
        ("0.0.0.0", "127.0.0.1", ["127.0.0.1", "localhost", "0.0.0.0"]),
        pytest.param(
            "::",
            "::1",
            ["[::1]", "localhost", "[::]"],
            marks=pytest.mark.skipif(not _ipv6_loopback(), reason="no IPv6 loopback here"),
        ),
    ],
)
def test_every_interface_answers_to_this_machines_names(bind, connect, names):
    """--host 0.0.0.0 (or ::) answers to the loopback names and this machine's own names
    and addresses, and still refuses any other Host (DNS rebinding)."""
    try:
        s = ViewerServer(None, None, host=bind)
    except OSError as exc:  # pragma: no cover - a sandbox without the wildcard address
        pytest.skip(f"cannot listen on {bind}: {exc}")
    try:
        p = s.port
        for name in [*names, socket.gethostname()]:
            assert _status(p, f"{name}:{p}", connect) == 200, name
            assert _status(p, f"{name}:{p}", connect, path="/api/state") == 200, name
        assert {*names, socket.gethostname().lower()} <= set(s.host_names)
        for bad in (f"evil.example:{p}", "evil.example", f"127.0.0.1:{p + 1}", ""):
            assert _status(p, bad, connect) == 403, bad
    finally:
        s.close()


@pytest.mark.skipif(not _ipv6_loopback(), reason="no IPv6 loopback here")
@pytest.mark.parametrize("host", ["::1", "[::1]"])
def test_ipv6_loopback(host):
    """--host ::1 listens on IPv6 (http.server's class is IPv4 only)."""
    s = ViewerServer(None, None, host=host)
    try:
        p = s.port
        assert s.url == f"http://[::1]:{p}/"
        assert _status(p, f"[::1]:{p}", connect="::1") == 200
        assert _status(p, f"[::1]:{p}", connect="::1", path="/api/state") == 200
        assert _status(p, f"localhost:{p}", connect="::1") == 200
        assert _status(p, f"evil.example:{p}", connect="::1") == 403
    finally:
        s.close()


def _view(tmp_path, *args: str) -> subprocess.CompletedProcess:
    """``spherewarp view`` that cannot start, with its own temporary folder."""
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    return subprocess.run(
        [sys.executable, "-m", "spherewarp", "view", "--no-browser", *args],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )


def test_cannot_listen_names_the_option_at_fault(tmp_path):
    """A host that is not this machine's (or no host at all) is '--host''s error, a
    port in use '--port''s; one line, and no temporary folder is left."""
    for host in ("192.0.2.77", "no-such-host.invalid"):
        p = _view(tmp_path, "--host", host)
        assert p.returncode == 2 and p.stdout == "" and "Traceback" not in p.stderr
        assert len(p.stderr.strip().splitlines()) == 1, p.stderr
        assert f"Invalid value for '--host': cannot listen on {host}:0" in p.stderr
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        p = _view(tmp_path, "--port", str(port))
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert f"Invalid value for '--port': cannot listen on 127.0.0.1:{port}" in p.stderr
    assert not [q for q in tmp_path.iterdir() if q.name.startswith("spherewarp-view-")]


def _reset(sock: socket.socket) -> None:
    """Close with a reset (RST), as a client that goes away mid-reply does."""
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    sock.close()


def test_clients_that_go_away_print_nothing(tmp_path):
    """A client that resets the connection mid-reply, or while the server waits for its
    next request, is no traceback on the command's stderr; the server goes on."""
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    cmd = [sys.executable, "-m", "spherewarp", "view", "--no-browser"]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = p.stdout.readline()
        assert line.startswith("spherewarp view: http://127.0.0.1:"), line
        port = int(line.split(":")[3].split("/")[0])
        for _ in range(4):
            # the test pattern takes a while to make (the first time): the client is gone
            # before the reply is written
            s = socket.create_connection(("127.0.0.1", port), timeout=20)
            s.sendall(_request(port, "GET", "/testpattern"))
            _reset(s)
            # a whole reply read, then a reset while the server reads the next request
            s = socket.create_connection(("127.0.0.1", port), timeout=20)
            s.sendall(_request(port, "GET", "/api/state"))
            got = b""
            while not got.endswith(b"}"):
                got += s.recv(65536)
            _reset(s)
            assert _status(port, f"127.0.0.1:{port}", path="/testpattern") == 200
    finally:
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=60)
    assert "Traceback" not in err and "Exception occurred" not in err, err
    assert err.strip().splitlines() == [
        "spherewarp: interrupted (no partially written file is left)"
    ]


def test_an_unexpected_error_is_one_line(srv, capsys):
    """An error of the server's own (not a client going away) is one line on stderr."""
    for exc in (ConnectionResetError(104, "reset"), BrokenPipeError(32, "pipe")):
        try:
            raise exc
        except OSError:
            srv.httpd.handle_error(None, ("127.0.0.1", 1))
    assert capsys.readouterr().err == ""
    try:
        raise ValueError("bad\nthing")
    except ValueError:
        srv.httpd.handle_error(None, ("127.0.0.1", 1))
    assert capsys.readouterr().err == "spherewarp view: error serving 127.0.0.1: ValueError: bad\n"
