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

#: Every sub-command and its actions (none for one without): read here, before any of
#: :mod:`pidcore.cli` is loaded, to name the command a Ctrl-C interrupted as the user typed
#: it (``pidcore dem sweep``, not ``pidcore dem``); :mod:`pidcore.cli` registers these.
COMMANDS: dict[str, tuple[str, ...]] = {
    "analyze": (), "dem": ("run", "sweep"), "specimen": ("check", "kept"),
    "bench": ("signal", "read", "store", "dem"), "report": (), "model": ("damper", "figures"),
    "app": (), "samples": ("make",), "calibrate": (), "store": ("list", "verify", "remove"),
}


def command_name(words: list[str]) -> str:
    """The sub-command a command line (``words``, after the program's name) names, for its
    messages: its first word that is no option, with the action after it where it is one of
    the command's (``dem sweep``); ``COMMAND`` where it names none."""
    for i, word in enumerate(words):
        if not word.startswith("-"):
            action = words[i + 1] if i + 1 < len(words) else None
            return f"{word} {action}" if action in COMMANDS.get(word, ()) else word
    return "COMMAND"


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
        print(f"pidcore {command_name(sys.argv[1:])}: interrupted; nothing was done",
              file=sys.stderr)
        return 130
    return console_main()
