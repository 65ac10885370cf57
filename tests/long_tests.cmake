# Run by ctest after the discovered tests are declared (TEST_INCLUDE_FILES, appended last): the longest
# seeded drives are labelled `long`. They take minutes under the sanitizers (20 Hz fixes through both
# estimators, Monte Carlo runs), so scripts/test.sh runs them in the Release pass only; the sanitizer pass
# covers the same code through the shorter drives (5 Hz single-point, in motion, reversing, batch, faults).
# A renamed test fails here loudly ("Can not find test").
set_tests_properties(
  CorrelatedGnss.NeesStaysHonestOnGaussMarkovSpp20Hz
  InitializationPaths.InMotionSpp20Hz
  InitializationPaths.SlowRoverSpp
  InitializationPaths.StaticWithoutWheelsGnssVelocityWitness
  BatchEndToEnd.SigmaAgreesWithTheMonteCarloSpread
  PROPERTIES LABELS long)
