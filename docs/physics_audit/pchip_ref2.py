"""Round 14 audit: the pchip SDC model between and beyond the grid, recomputed with scipy.

Table 3 from /work/shared/reference/table3.csv (the shared transcription, not pidcore's copy);
the tensor product is rebuilt with scipy's PchipInterpolator in the order pidcore documents
(frequency, fill, acceleration), in Hz and in log10(Hz); the hole (1000 Hz, 1 g, 90 %) held at
the 75 % value. Checked: 300 random points, the log-frequency option, the acceleration section
the response solver uses, that every point beyond the box is refused (and clip_to_range equals
the value at the clamped point), and that no value leaves the range of its 8 surrounding grid
values (pchip does not overshoot).

  python pchip_ref2.py
"""
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.interpolate import PchipInterpolator as Pchip

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from pidcore.errors import ParameterError  # noqa: E402
from pidcore.model.sdc_model import SdcModel  # noqa: E402

SHARED = Path("/work/shared/reference/table3.csv")
t = pd.read_csv(SHARED)
P, A, F = [25.0, 50.0, 75.0, 90.0], [1.0, 5.0, 10.0], [50.0, 100.0, 500.0, 1000.0]
V = np.full((4, 3, 4), np.nan)
for _, r in t.iterrows():
    V[P.index(r.fill_percent), A.index(r.acceleration_g), F.index(r.frequency_hz)] = r.sdc_dem
assert np.isnan(V).sum() == 1 and np.isnan(V[3, 0, 3])
V[3, 0, 3] = V[2, 0, 3]  # held at 75 %: 0.8078


def mine(p: float, a: float, f: float, log: bool = False) -> float:
    fx = np.log10(F) if log else np.array(F)
    v = Pchip(fx, V, axis=2)(np.log10(f) if log else f)  # (fill, acc)
    v = Pchip(P, v, axis=0)(p)                              # (acc,)
    return float(Pchip(A, v)(a))


for log in (False, True):
    m = SdcModel.from_table(t, log_frequency=log)
    assert m.values[3, 0, 3] == 0.8078 and m.filled[3, 0, 3] and m.filled.sum() == 1
    rng = np.random.default_rng(14)
    pts = np.column_stack([rng.uniform(25, 90, 300), rng.uniform(1, 10, 300),
                           np.exp(rng.uniform(np.log(50), np.log(1000), 300))])
    ours = m.evaluate(pts[:, 0], pts[:, 1], pts[:, 2])
    ref = np.array([mine(*q, log=log) for q in pts])
    print(f"log_frequency={log}: max |pidcore - scipy| over 300 points "
          f"{np.abs(ours - ref).max():.1e}")
    # no overshoot: inside the min/max of the 8 corners of each point's cell
    for q, v in zip(pts, ours, strict=True):
        i = [min(np.searchsorted(ax, x, side="right") - 1, len(ax) - 2)
             for ax, x in zip((P, A, F), q, strict=True)]
        corners = V[i[0]:i[0] + 2, i[1]:i[1] + 2, i[2]:i[2] + 2]
        assert corners.min() - 1e-12 <= v <= corners.max() + 1e-12, (q, v)
    # the section the response solver uses is the model along acceleration
    sec = m.acceleration_section(60.0, 700.0)
    acc = np.linspace(1, 10, 50)
    print(f"  acceleration section vs model: "
          f"{np.abs(sec(acc) - m.evaluate(60.0, acc, 700.0)).max():.1e}")

m = SdcModel.from_table(t)
refused = 0
for q in [(24.9, 5, 100), (90.1, 5, 100), (50, 0.99, 100), (50, 10.01, 100), (50, 5, 49.9),
          (50, 5, 1000.1), (50, 5, np.nan)]:
    try:
        m.evaluate(*q)
    except ParameterError:
        refused += 1
print(f"points beyond the box refused: {refused} of 7")
clipped = m.evaluate([10, 95], [0.5, 20], [20, 2000], clip_to_range=True)
assert np.array_equal(clipped, [m(25, 1, 50), m(90, 10, 1000)])
print("clip_to_range holds the edge value:", clipped)
