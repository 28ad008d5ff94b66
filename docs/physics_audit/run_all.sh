#!/usr/bin/env bash
# Independent physics audit of pidcore on specimens unlike the paper's (2026-11-30).
# Run from this folder: bash run_all.sh  (uses the checkout two levels up; a few minutes).
set -euo pipefail
export PYTHONPATH=../..
PY=${PYTHON:-python}
for s in paper steel wc pom wc_tiny wc_full; do
  $PY -m pidcore specimen check $s.toml --json > $s.json
done
$PY ref.py paper steel wc pom wc_tiny wc_full      # specimen check vs first principles
$PY dem1.py                                         # restitution vs an ODE of Eq. 2-3
$PY dem2.py                                         # free flight, incline, rolling
rm -rf damper && $PY -m pidcore model damper --out damper >/dev/null && $PY damper_ref.py
$PY pchip_ref.py                                    # tensor-product pchip vs scipy
mkdir -p edges && $PY mkedges.py && for f in edges/*.toml; do
  $PY -m pidcore specimen check "$f" >/dev/null 2>edges/err.txt && echo "$f accepted" || head -c 300 edges/err.txt; echo
done
# round 14: measured numbers, report columns, stored-run damper, pchip beyond the grid
cp ../../data_samples/dem_table3.h5 r14_store.h5
$PY -m pidcore analyze ../../data_samples/exports/* --sidecar ../../data_samples/loadcases.csv --store r14_store.h5 --no-progress >/dev/null
$PY -m pidcore analyze ../../data_samples/exports/* --sidecar ../../data_samples/loadcases.csv --no-store --json --no-progress > r14_an.json
rm -rf r14_rep r14_damp && $PY -m pidcore report --store r14_store.h5 --out r14_rep >/dev/null
$PY -m pidcore model damper --table store --store r14_store.h5 --out r14_damp >/dev/null
$PY measure_ref.py r14_an.json r14_rep/report.csv r14_store.h5
$PY damper_store_ref.py r14_damp r14_store.h5
$PY app_cli_ref.py r14_store.h5 r14_damp r14_rep/report.csv
$PY pchip_ref2.py
