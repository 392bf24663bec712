#!/usr/bin/env bash
# Runs a command while BUSY_LOOPS (default 2) CPU-bound loops compete with it for the cores:
# the timing contracts (progress cadence, cancel latency) must hold on a busy machine.
# Usage: tests/load/with_busy_cores.sh COMMAND [ARGS...]   Exit status: the command's.
set -u
loops=${BUSY_LOOPS:-2}
pids=()
stop_loops() { for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; done; wait "${pids[@]}" 2>/dev/null; }
trap stop_loops EXIT
trap 'exit 130' INT TERM
for ((i = 0; i < loops; i++)); do
  bash -c 'while :; do :; done' &
  pids+=("$!")
done
echo "with_busy_cores: ${loops} busy loops (pids ${pids[*]}) beside: $*" >&2
"$@"
