"""``python -m spherewarp``: the same as the ``spherewarp`` command."""

from spherewarp.cli import main

if __name__ == "__main__":
    main()
