"""Peak memory of reading one file, measured in a fresh interpreter."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

# VmHWM (peak resident set) belongs to the new process image; ru_maxrss would carry the
# parent's peak over the exec. The baseline is taken after the imports, so the figure is what
# reading the file added.
_SCRIPT = """\
import sys
import numpy, pandas, pidcore.io, pidcore.errors
def hwm():
    for line in open('/proc/self/status'):
        if line.startswith('VmHWM:'):
            return int(line.split()[1]) * 1024
base = hwm()
try:
    m = pidcore.io.read_measurement(sys.argv[1])
    said = f"samples {m.channels[0].n_samples}"
except pidcore.errors.InputFileError as exc:
    said = f"refused {exc}"
print(hwm() - base, said)
"""


def read_peak_memory(path: Path) -> tuple[int, str]:
    """(bytes the peak resident set grew by while ``read_measurement(path)`` ran, what it
    said: ``"samples N"`` of its first channel, or ``"refused <message>"``)."""
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    out = subprocess.run([sys.executable, "-c", _SCRIPT, str(path)], capture_output=True,
                         text=True, env=env, check=True, timeout=300).stdout
    grown, said = out.strip().split(" ", 1)
    return int(grown), said
