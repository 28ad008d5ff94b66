import sys

# one entry point for `python -m pidcore` and the installed `pidcore` script: the CLI is
# imported inside it, under its Ctrl-C guard (pidcore.console)
from .console import main

sys.exit(main())
