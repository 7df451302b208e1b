#!/usr/bin/env bash
# Builds the ROS-free core and its unit tests with plain CMake and GoogleTest, no catkin and no ROS on
# PATH, under AddressSanitizer and UndefinedBehaviorSanitizer with warnings as errors, and runs the tests.
# CI runs it before the test command. Ends with one line "N passed, N failed" (GoogleTest's cases).
#   scripts/check_core.sh [BUILD_DIR]      (default .build/core-sanitize; about 5 min on 2 cores)
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/.build/core-sanitize}"
# Only the system's tools: no /opt/ros, no pyenv.
export PATH=/usr/bin:/bin
# Under the sanitizers the cases run about ten times slower than in Release. The twenty-five longest
# (4.5 to 38 s each, most of the sanitized run) repeat at larger sizes or over longer runs what others
# test; the Release build runs them all.
slow=(
  SliderRun.TwoDimensionalEnergyBudgetClosesWithEverythingOn
  ShippedScenes/PinnedScene.EndsInThePinnedStateWithThePinnedEvents/pmma_1d_top
  HardCases.PusherAtTheBottomCornerAndAtTheTop
  HardCases.LargeLatticeTakesAFewSteps
  HardCases.FastForwardAgreesWithFullDynamics
  HardCases.EqualStaticAndKineticFrictionAndZeroKineticFriction
  HardCases.HundredStickSlipCyclesWithoutDrift
  HardCases.NoDampingAndAStiffFoundation
  SimulationStrips.GroupedStepsGiveTheRunOfSingleStepsThroughEvents
  SimulationStrips.GroupedStepsOfALatticeOfSeveralStripsGiveTheSingleStepsThroughEvents
  Determinism.SameSceneTwiceGivesIdenticalEventsAndState
  Determinism.AStopConditionSetDuringTheRunEndsItOnTheSameStepAsTheScenes
  FastForward.GoesOnWithTheTrailingEdgeLiftedAndAgreesWithFullDynamics
  FastForward.StaticJumpAgreesWithALongDampedDynamicRelaxation
  FastForward.AgreesWithFullDynamicsOnPrecursorsAndFirstGlobalEvent
  SlipEvents.AnInterfaceThatCreepsGivesWayAtItsPeakForceNotAtItsFirstUnsticking
  RateStateResults.TheFilesHoldEachContactsAgeingStrengthAndWhenEachNodeLastSlipped
  SlipWeakening.EnergyBudgetClosesToRoundOffForASingleBlockAndClosely2D
  BothIntegratorsBothDirections/SingleBlockStickSlip.MatchesTheClosedFormCycle/2
  BothIntegratorsBothDirections/SingleBlockStickSlip.MatchesTheClosedFormCycle/3
  BothIntegratorsBothDirections/SingleBlockStickSlip.MatchesTheClosedFormCycle/5
  RateStateBlock.SteadySlidingFollowsTheSteadyStateCurveOverSixDecadesOfSpeed
  RateStateBlock.VelocityStepJumpsByTheDirectEffectThenEvolvesOverTheCharacteristicSlip
  FrameEventDetector.RateStateEventsEndOnTheirSlipSpeedWhileTheInterfaceCreeps
  QuasiStaticCreep.CreepingSliderHasTheFullDynamicsPrecursors
)
filter="-$(IFS=:; echo "${slow[*]}")"
# -O1 with line tables: a quick build, and reports that name the line.
mkdir -p "$build"
cmake -S "$root/friction_sim" -B "$build" -DFRICTION_SIM_CORE_ONLY=ON -DFRICTION_SIM_SANITIZE=ON \
  -DFRICTION_WERROR=ON -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS="-O1 -g1" >"$build.log" 2>&1 &&
  cmake --build "$build" -j2 >>"$build.log" 2>&1 || {
  tail -n 40 "$build.log"
  echo "0 passed, 1 failed"
  exit 1
}
cd "$root/friction_sim" || exit 1
report="$build/test_friction_core.xml"
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  "$build/test_friction_core" --gtest_filter="$filter" --gtest_output="xml:$report" >"$build/tests.log" 2>&1
status=$?
grep -E "^\[  FAILED|ERROR: AddressSanitizer|runtime error:" "$build/tests.log" | head -n 40
/usr/bin/python3 - "$report" "$status" <<'PY'
import sys, xml.etree.ElementTree as ET
try:
    suites = ET.parse(sys.argv[1]).getroot()
    tests, failures, errors = (int(suites.get(k, 0)) for k in ("tests", "failures", "errors"))
except (OSError, ET.ParseError):
    tests, failures, errors = 0, 1, 0  # the run died before writing its report (a sanitizer abort)
failed = failures + errors or (1 if sys.argv[2] != "0" else 0)
print("%d passed, %d failed" % (tests - failed, failed))
sys.exit(1 if failed else 0)
PY
