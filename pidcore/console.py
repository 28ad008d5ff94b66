"""The ``pidcore`` command's entry point, which ``python -m pidcore`` (:mod:`pidcore.__main__`)
runs too.

The CLI's own modules take ~0.2 s to load, before :func:`pidcore.cli.main` installs its
Ctrl-C handler; the installed script imported them itself (``pidcore.cli:console_main``), so a
Ctrl-C then ended in Python's traceback and a death by SIGINT (status -2). Here only the
standard library is loaded before the import is guarded (``pidcore/__init__.py`` imports
nothing).
"""

from __future__ import annotations

import sys


def main() -> int:
    """Run the command line (:func:`pidcore.cli.console_main`); a Ctrl-C while it loads
    exits 130 with one line, as any other interruption."""
    try:
        from .cli import console_main
    except KeyboardInterrupt:
        import signal

        # the command is over: a second Ctrl-C during the shutdown must not turn the 130
        # into a death by SIGINT
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        command = next((word for word in sys.argv[1:] if not word.startswith("-")), "COMMAND")
        print(f"pidcore {command}: interrupted; nothing was done", file=sys.stderr)
        return 130
    return console_main()
