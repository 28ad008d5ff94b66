"""Files for the CLI and store tests: a synthetic shaker record written as an export, and a
file's digest (to prove a store was left byte-identical)."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

from pidcore.io import write_measurement
from pidcore.records import Channel, Measurement


def write_force_velocity(path: Path, force_n: np.ndarray, velocity_m_s: np.ndarray,
                         sample_rate_hz: float, fmt: str = "csv", *,
                         binary: bool = False) -> Path:
    """Write channels ``Force`` (N) and ``Velocity`` (m/s) as an export named by ``path``."""
    m = Measurement(path.name, (Channel("Force", "force", force_n, sample_rate_hz, "N"),
                                Channel("Velocity", "velocity", velocity_m_s, sample_rate_hz,
                                        "m/s")))
    write_measurement(m, path, fmt, binary=binary)
    return path


def file_sha256(path: Path) -> str:
    """SHA-256 of a file's bytes, hex."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()
