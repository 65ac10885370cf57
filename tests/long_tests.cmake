# The longest seeded drives, labelled `long`. They take minutes under the sanitizers (10-20 Hz fixes through
# both estimators, Monte Carlo runs), so scripts/test_sanitizers.sh leaves them out (scripts/test.sh runs
# them); it covers the same code through the shorter drives (5 Hz single-point, in motion, reversing, batch,
# faults). Read twice: by tests/CMakeLists.txt for the list (the test Tests.LongLabelNamesEveryListedTest
# checks that ctest finds each name: set_tests_properties ignores one it does not know), and by ctest
# (TEST_INCLUDE_FILES, after the discovered tests are declared), which applies the label.
set(GINS_LONG_TESTS
  CorrelatedGnss.NeesStaysHonestOnGaussMarkovSpp20Hz
  InitializationPaths.InMotionSpp20Hz
  InitializationPaths.SlowRoverSpp
  InitializationPaths.StaticWithoutWheelsGnssVelocityWitness
  BatchEndToEnd.SigmaAgreesWithTheMonteCarloSpread
  VehicleSetups.TenHzFixesAreAllUsed)
if(NOT DEFINED CMAKE_PROJECT_NAME)  # in ctest
  set_tests_properties(${GINS_LONG_TESTS} PROPERTIES LABELS long)
endif()
