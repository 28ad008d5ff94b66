import sys

try:
    from .cli import console_main
except KeyboardInterrupt:
    # Ctrl-C while the CLI's own modules load (~0.2 s of a start; before main installs its
    # handler): Python's traceback and a death by SIGINT (status -2) said neither that
    # nothing had been done nor the 130 of every other interruption. Only `python -m
    # pidcore` passes here; the `pidcore` script imports pidcore.cli itself.
    _command = next((word for word in sys.argv[1:] if not word.startswith("-")), "COMMAND")
    print(f"pidcore {_command}: interrupted; nothing was done", file=sys.stderr)
    sys.exit(130)

sys.exit(console_main())
