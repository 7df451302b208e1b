# The ROS-free core: the library friction_sim_core, the offline runner and the core's tests' sources.
# Included by CMakeLists.txt both in a catkin build and in a plain CMake build (FRICTION_SIM_CORE_ONLY).
find_package(Eigen3 REQUIRED)
find_package(yaml-cpp REQUIRED)
# Threads for the large lattices' force sweeps (Lattice2D::setThreads).
find_package(OpenMP REQUIRED COMPONENTS CXX)
# AMD (SuiteSparse): the fill-reducing ordering of the static solver's Cholesky factor (its numeric
# factorisation is the core's own). Only AMD is linked: CHOLMOD and the BLAS it pulls in cost 2 ms of
# loading per process, a tenth of a small run's start-up.
find_path(AMD_INCLUDE_DIR amd.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(AMD_LIBRARY amd REQUIRED)
# Eigen's and AMD's headers for every target from here on (the core's solvers and their tests use both).
include_directories(SYSTEM ${EIGEN3_INCLUDE_DIR} ${AMD_INCLUDE_DIR})

# The core compiled once: into the library, and into friction_run, which links it statically (below).
add_library(friction_sim_core_objects OBJECT
  src/core/contact/contact_interface.cpp
  src/core/contact/friction_law.cpp
  src/core/instruments/frame_event_detector.cpp
  src/core/instruments/instruments.cpp
  src/core/instruments/readouts.cpp
  src/core/instruments/results_io.cpp
  src/core/instruments/slip_events.cpp
  src/core/model/chain_1d.cpp
  src/core/model/lattice_2d.cpp
  src/core/model/model.cpp
  src/core/run/command_schedule.cpp
  src/core/run/fast_forward.cpp
  src/core/run/quasi_static_creep.cpp
  src/core/run/run_driver.cpp
  src/core/run/simulation.cpp
  src/core/run/simulation_commands.cpp
  src/core/run/step_group.cpp
  src/core/scene/config_error.cpp
  src/core/scene/loading_protocol.cpp
  src/core/scene/scene_io.cpp
  src/core/scene/scene_validation.cpp
  src/core/solvers/cholesky_factor.cpp
  src/core/solvers/grid_multigrid.cpp
  src/core/solvers/integrator.cpp
  src/core/solvers/static_solver.cpp
  src/core/stage/stage.cpp
)
set_target_properties(friction_sim_core_objects PROPERTIES POSITION_INDEPENDENT_CODE ON)
# What compiling against the core needs: its public headers in include/friction_sim/<room>/ (the core's
# own are next to its sources, src/core/<room>/), yaml-cpp's, and the flags below.
add_library(friction_sim_core_interface INTERFACE)
target_include_directories(friction_sim_core_interface INTERFACE include ${YAML_CPP_INCLUDE_DIR})
target_link_libraries(friction_sim_core_objects PUBLIC friction_sim_core_interface)
target_include_directories(friction_sim_core_objects PRIVATE src/core)
# errno from sqrt is never read: without it the bond loops vectorise. No FMA contraction: a vector
# loop's peeled and main parts would otherwise round differently depending on where a buffer happens
# to be aligned, and two runs of one scene would drift apart (determinism is tested). No semantic
# interposition: calls within a source file (the step's small calls) need not go through the PLT and
# can be inlined; nobody replaces the core's functions at load time.
target_compile_options(friction_sim_core_objects PRIVATE -fno-math-errno -ffp-contract=off
  -fno-semantic-interposition ${OpenMP_CXX_FLAGS})
# The rig is built where it runs: use the machine's full SIMD width (AVX2/AVX-512 halves the step time).
# AVX-512 rounds Eigen's sums and dense products otherwise than AVX2 (another packet width), so the pinned
# results hold bit for bit on AVX2 builds only (test_determinism.cpp); it is kept for its speed: without
# it, 12000 steps of 449 x 241 took 10.8 s instead of 7.0 s on an AVX-512 host (2026-11-28, side by side).
option(FRICTION_SIM_NATIVE "Compile the physics core for the building machine's CPU (-march=native)" ON)
if(FRICTION_SIM_NATIVE)
  target_compile_options(friction_sim_core_interface INTERFACE -march=native)
  # GCC before 12.3 initialises a register from itself in its AVX-512 headers (GCC bug 105593): on an
  # AVX-512 machine every Eigen reduction and transpose inlined from them warns that it "may be" or "is"
  # used uninitialized (the latter in the sanitizers' build). Off there, for everything the core's
  # headers reach (its nodes and tests too).
  include(CheckCXXSourceCompiles)
  include(CMakePushCheckState)
  cmake_push_check_state(RESET)
  set(CMAKE_REQUIRED_FLAGS -march=native)
  check_cxx_source_compiles("#ifndef __AVX512F__\n#error no AVX-512\n#endif\nint main() {}" FRICTION_SIM_NATIVE_AVX512)
  cmake_pop_check_state()
  if(FRICTION_SIM_NATIVE_AVX512 AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 12.3)
    target_compile_options(friction_sim_core_interface INTERFACE -Wno-maybe-uninitialized -Wno-uninitialized)
  endif()
endif()
# The friction loop records each node's force as it turns it into an acceleration; GCC would split
# that record off into a memcpy call, a second pass over the forces and a call per strip.
set_source_files_properties(src/core/contact/contact_interface.cpp PROPERTIES COMPILE_OPTIONS -fno-tree-loop-distribute-patterns)
# OpenMP is for the lattice's own threads: Eigen's dense products (the factorisation's updates) stay on
# the calling thread, whatever OMP_NUM_THREADS says (two threads cost more than they gave on panels this small).
target_compile_definitions(friction_sim_core_interface INTERFACE EIGEN_DONT_PARALLELIZE)

add_library(friction_sim_core $<TARGET_OBJECTS:friction_sim_core_objects>)
target_link_libraries(friction_sim_core PUBLIC friction_sim_core_interface yaml-cpp ${AMD_LIBRARY}
  PRIVATE OpenMP::OpenMP_CXX)
# Calls between the core's own source files bind inside the library too, without the PLT.
target_link_options(friction_sim_core PRIVATE -Wl,-Bsymbolic-functions)

# friction_run starts a process per run, and loading shared libraries was a tenth of a 57 × 31 run's
# time before its first step: `friction_run --help` took 2.1 ms linked to the core's library, 1.1 ms
# with the core, libstdc++, libgcc, libgomp, yaml-cpp and AMD linked in (an empty C program 0.7 ms;
# 2026-11-28, AMD EPYC family 25). Only the C library and libm stay shared. Where a static archive is
# missing, or under the sanitizers (whose runtimes want the shared C++ library), it links as the nodes do.
# How the processes that run simulations take their memory (glibc's settings): theirs, not the core's.
add_library(friction_sim_process_memory OBJECT src/tools/process_memory.cpp)
target_include_directories(friction_sim_process_memory PUBLIC src/tools)
add_executable(friction_run src/tools/friction_run.cpp)
target_link_libraries(friction_run friction_sim_process_memory)
find_library(YAML_CPP_ARCHIVE libyaml-cpp.a)
find_library(AMD_ARCHIVE libamd.a)
find_library(SUITESPARSECONFIG_ARCHIVE libsuitesparseconfig.a)
# The compiler's own archive of libgomp (it answers the bare name when it has none).
execute_process(COMMAND ${CMAKE_CXX_COMPILER} -print-file-name=libgomp.a OUTPUT_VARIABLE GOMP_ARCHIVE
  OUTPUT_STRIP_TRAILING_WHITESPACE)
find_package(Threads REQUIRED)
if(YAML_CPP_ARCHIVE AND AMD_ARCHIVE AND SUITESPARSECONFIG_ARCHIVE AND IS_ABSOLUTE "${GOMP_ARCHIVE}"
   AND NOT FRICTION_SIM_SANITIZE)
  target_sources(friction_run PRIVATE $<TARGET_OBJECTS:friction_sim_core_objects>)
  target_link_libraries(friction_run friction_sim_core_interface ${YAML_CPP_ARCHIVE} ${AMD_ARCHIVE}
    ${SUITESPARSECONFIG_ARCHIVE} ${GOMP_ARCHIVE} Threads::Threads ${CMAKE_DL_LIBS} -static-libstdc++ -static-libgcc)
  set(FRICTION_RUN_LINKAGE static)
else()
  target_link_libraries(friction_run friction_sim_core)
  set(FRICTION_RUN_LINKAGE shared)
endif()

# The core's unit tests (GoogleTest), run by catkin or by CTest.
set(FRICTION_SIM_CORE_TESTS
  test/test_analysis.cpp
  test/test_cholesky_factor.cpp
  test/test_closed_forms.cpp
  test/test_determinism.cpp
  test/test_run_driver.cpp
  test/test_fast_forward.cpp
  test/test_hard_cases.cpp
  test/test_friction_laws.cpp
  test/test_rate_state.cpp
  test/test_lattice.cpp
  test/test_scene.cpp
  test/test_static_solver.cpp
  test/test_strips.cpp
  test/test_runs.cpp
)
# The core's tests reach its own headers too (src/core/<room>/).
set(FRICTION_SIM_CORE_TEST_INCLUDES "${CMAKE_CURRENT_SOURCE_DIR}/src/core")
# Where the core's tests find the shipped scenes and the pinned results.
set(FRICTION_SIM_CORE_TEST_DEFINITIONS
  SCENE_DIR="${CMAKE_CURRENT_SOURCE_DIR}/scenes"
  PINNED_DIR="${CMAKE_CURRENT_SOURCE_DIR}/test/pinned")
