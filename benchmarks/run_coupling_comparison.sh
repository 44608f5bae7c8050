#!/usr/bin/env bash
# Runs the Antoci gate for every coupling x solid model x resolution and charts RMS error against wall time:
#   bash benchmarks/run_coupling_comparison.sh [build/release/examples/antoci_gate] [out/coupling]
# then /usr/bin/python3 benchmarks/coupling_chart.py out/coupling docs   (writes the chart and the table)
# Each run uses 2 OpenMP threads and writes <out>/<coupling>_<solid>_<resolution>/{summary.csv,gate_tip.csv,...}.
set -uo pipefail
exe=${1:-build/release/examples/antoci_gate}
out=${2:-out/coupling}
resolutions=${RESOLUTIONS:-"60 80 100"}
couplings=${COUPLINGS:-"repulsive interface stress"}  # interface-mirror: eqs 10-16 as printed (--interface-form)
solids=${SOLIDS:-"tl ul"}
for res in $resolutions; do
  for coupling in $couplings; do
    for solid in $solids; do
      dir="$out/${coupling}_${solid}_${res}"
      [ -f "$dir/summary.csv" ] && continue
      mkdir -p "$dir"
      flags=(--coupling "$coupling")
      [ "$coupling" = interface-mirror ] && flags=(--coupling interface --interface-form surface-mirror)
      OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive "$exe" "${flags[@]}" --solid "$solid" --resolution "$res" \
        --snapshot-interval 0.1 --output "$dir" > "$dir/log.txt" 2>&1
      echo "$coupling $solid $res: exit $? $(grep -E 'RMS error' "$dir/log.txt")"
    done
  done
done
