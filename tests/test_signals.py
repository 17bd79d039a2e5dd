"""spherewarp._signals: holding interrupts back over lines that must not be cut in two."""

from __future__ import annotations

import signal

import pytest

from spherewarp import _signals


def test_held_delivers_an_interrupt_after_the_block():
    done = []
    handler = signal.getsignal(signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):
        with _signals.held():
            signal.raise_signal(signal.SIGINT)
            done.append("the block ran to its end")
    assert done and signal.getsignal(signal.SIGINT) is handler


def test_exit_status_of_each_stop():
    import signal

    from spherewarp._signals import Terminated, exit_status

    assert exit_status(KeyboardInterrupt()) == (130, "interrupted")
    assert exit_status(Terminated()) == (143, "terminated")
    if hasattr(signal, "SIGHUP"):  # the terminal closed: unwound as SIGTERM is
        assert exit_status(Terminated(signal.SIGHUP)) == (129, "hung up")
