"""A real FTP server for the tests (pyftpdlib, in its own process, on 127.0.0.1): a remote file
system that fsspec's ``ftp://`` reaches with the standard library's ftplib alone.

    python tests/ftpserver.py ROOT      # prints the port, then serves ROOT (anonymous, writable)
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


class FTPServer:
    """``ftp://127.0.0.1:PORT/`` serving the folder ``root`` (anonymous, read and write)."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self.proc = subprocess.Popen(
            [sys.executable, __file__, str(self.root)], stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL, text=True,
        )  # fmt: skip
        line = self.proc.stdout.readline()
        if not line.strip().isdigit():
            self.close()
            raise RuntimeError(f"the FTP server did not start: {line!r}")
        self.port = int(line)
        self.url = f"ftp://127.0.0.1:{self.port}"

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait(20)


def _serve(root: str) -> None:
    import logging

    from pyftpdlib.authorizers import DummyAuthorizer
    from pyftpdlib.handlers import FTPHandler
    from pyftpdlib.servers import FTPServer as Server

    logging.disable(logging.CRITICAL)
    authorizer = DummyAuthorizer()
    authorizer.add_anonymous(root, perm="elradfmwMT")
    handler = type("Handler", (FTPHandler,), {"authorizer": authorizer})
    server = Server(("127.0.0.1", 0), handler)
    server.max_cons = 256
    print(server.socket.getsockname()[1], flush=True)
    server.serve_forever()


if __name__ == "__main__":
    _serve(sys.argv[1])
