#!/usr/bin/env bash
# Regenerates the throughput table of docs/performance.md:
#   REPEATS=3 bash benchmarks/run_dam_break_throughput.sh build/release/benchmarks/bench_dam_break_throughput
# (build first: cmake --preset release -DSPHFSI_BUILD_BENCHMARKS=ON && cmake --build build/release -j2)
# Each configuration runs REPEATS times (default 1), the repeats interleaved with the other configurations so that
# a burst of load from other processes does not hit all repeats of one configuration; report the best and spread.
set -euo pipefail
bench=${1:-build/release/benchmarks/bench_dam_break_throughput}
repeats=${REPEATS:-1}
echo "precision,threads,particles,steps,seconds,million_particle_steps_per_s,cpu_seconds,million_particle_steps_per_cpu_s"
for ((k = 0; k < repeats; ++k)); do
  for res in 90 190 390; do
    steps=$(( res == 90 ? 400 : (res == 190 ? 100 : 25) ))
    for precision in float double; do
      for threads in 1 2; do
        OMP_WAIT_POLICY=passive "$bench" --resolution "$res" --threads "$threads" --precision "$precision" --steps "$steps"
      done
    done
  done
done
