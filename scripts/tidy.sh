#!/usr/bin/env bash
# Runs clang-tidy (the checks of .clang-tidy) over the ROS-free core and friction_run, with the compile
# database of a plain CMake configuration of the core. Extra arguments go to clang-tidy, e.g.
#   scripts/tidy.sh --checks='-*,readability-function-cognitive-complexity'
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/.build/core-tidy"
PATH=/usr/bin:/bin cmake -S "$root/friction_sim" -B "$build" -DFRICTION_SIM_CORE_ONLY=ON \
  -DCMAKE_EXPORT_COMPILE_COMMANDS=ON >/dev/null
# clang refuses GCC's -fno-tree-loop-distribute-patterns (core.cmake, contact_interface.cpp) and would
# skip that file.
sed -i 's/ -fno-tree-loop-distribute-patterns//' "$build/compile_commands.json"
cd "$root/friction_sim"
find src/core src/tools -name '*.cpp' | sort | xargs -P 2 -n 4 clang-tidy -p "$build" --quiet "$@" 2>/dev/null
