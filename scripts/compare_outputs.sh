#!/usr/bin/env bash
# Runs the same fourteen scenes with two builds of friction_run and says whether their results are
# byte-identical: the check behind "results unchanged" for a change meant to be speed only.
#
#   scripts/compare_outputs.sh REFERENCE_RUNNER CANDIDATE_RUNNER [WORK_DIR]
#
# The scenes cover the 1D chain (side- and top-driven, tilted, with the torque term) and the 2D lattice (geometric and linear
# springs; one lattice wider than the force sweep's column chunks), Amontons–Coulomb and slip weakening, velocity Verlet and RK4, fast-forward on and off.
# Every results file is compared except the summary's wall-time line. Exit status 0 if all are identical,
# 1 if any differ (the differing files are listed), 2 on a usage error. About 50 s (28 runs).
set -euo pipefail

if [[ $# -lt 2 || $# -gt 3 ]]; then
  sed -n '5p' "$0" | sed 's/^# *//' >&2
  exit 2
fi
reference=$(realpath "$1")
candidate=$(realpath "$2")
work=${3:-$(mktemp -d)}
scenes_dir="$(cd "$(dirname "$0")/.." && pwd)/friction_sim/scenes"

# name | scene file | overrides. Slip weakening needs its ξ_µ (0 would be Amontons–Coulomb again), short
# enough that the weakening is unstable and the events dynamic: longer, the chain creeps in one slow event.
cases=(
  "2d_ac_ff|pmma_2d.yaml|"
  "2d_ac_dyn|pmma_2d.yaml|integrator.fast_forward=false"
  "2d_linearised|pmma_2d.yaml|lattice.spring_form=linearised"
  "2d_sw|pmma_2d.yaml|friction.law=slip_weakening friction.weakening_length=1e-6"
  "2d_rk4|pmma_2d.yaml|integrator.scheme=rk4"
  "2d_mattress|pmma_2d.yaml|load.top=spring_mattress"
  "2d_wide|pmma_2d.yaml|lattice.nodes_x=281 lattice.nodes_z=16 geometry.height=0.0075 integrator.time_step=4e-8 stop.time=0.2"
  "1d_side|pmma_1d_side.yaml|"
  "1d_side_verlet|pmma_1d_side.yaml|integrator.scheme=velocity_verlet integrator.time_step=2e-7 integrator.fast_forward=false"
  "1d_top|pmma_1d_top.yaml|"
  "1d_tilt|pmma_1d_side.yaml|chain.tilt=0.3"
  "1d_torque|pmma_1d_side.yaml|chain.torque_share=1.0"
  "1d_sw|pmma_1d_side.yaml|friction.law=slip_weakening friction.weakening_length=1e-7 integrator.scheme=velocity_verlet integrator.time_step=2e-7"
  "block|single_block.yaml|"
)

status=0
for entry in "${cases[@]}"; do
  IFS='|' read -r name scene overrides <<<"$entry"
  set_args=()
  for assignment in $overrides; do set_args+=(--set "$assignment"); done
  for side in reference candidate; do
    runner=${!side}
    "$runner" "$scenes_dir/$scene" --out "$work/$side/$name" "${set_args[@]}" >/dev/null
    grep -v 'wall time' "$work/$side/$name/summary.txt" >"$work/$side/$name/summary_without_wall_time.txt"
  done
  differing=()
  for file in events.csv event_nodes.csv loading.csv stresses.csv scene.yaml summary_without_wall_time.txt; do
    cmp -s "$work/reference/$name/$file" "$work/candidate/$name/$file" || differing+=("$file")
  done
  if [[ ${#differing[@]} -eq 0 ]]; then
    echo "identical  $name"
  else
    echo "DIFFERENT  $name: ${differing[*]}"
    status=1
  fi
done
echo "outputs in $work"
exit $status
