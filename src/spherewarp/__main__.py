"""``python -m spherewarp``: the same as the ``spherewarp`` command."""

from spherewarp.cli import run

if __name__ == "__main__":
    run()
