// Per-sample costs of the core: IMU kernel, preintegration, log parsing.
#include <benchmark/benchmark.h>

#include "core/imu_kernel.h"
#include "core/io/log_reader.h"
#include "core/preintegration.h"
#include "core/so3.h"

namespace gins {
namespace {

void BM_ImuStep(benchmark::State& state) {
  Kinematics x{ExpQuat<double>(Vec3(0.1, 0.2, 0.3)), Vec3(1, 2, 0), Vec3::Zero()};
  const Vec3 omega(0.01, -0.02, 0.1), acc(0.1, 0.2, 9.8), g(0, 0, -9.8);
  ImuStepJacobians J;
  const bool with_jacobians = state.range(0) != 0;
  for (auto _ : state) {
    x = ImuStep(x, omega, acc, g, 0.01, with_jacobians ? &J : nullptr);
    benchmark::DoNotOptimize(x);
    benchmark::DoNotOptimize(J);
  }
}
BENCHMARK(BM_ImuStep)->Arg(0)->Arg(1)->ArgName("jacobians");

void BM_PreintegrationStep(benchmark::State& state) {
  Preintegration p(Vec3::Zero(), Vec3::Zero(), 1e-4, 1e-3);
  const Vec3 gyro(0.01, -0.02, 0.1), acc(0.1, 0.2, 9.8);
  int n = 0;
  for (auto _ : state) {
    if (++n == 1000) {  // keep the stored interval realistic (a few seconds)
      state.PauseTiming();
      p = Preintegration(Vec3::Zero(), Vec3::Zero(), 1e-4, 1e-3);
      n = 0;
      state.ResumeTiming();
    }
    p.Integrate(gyro, acc, 0.01);
    benchmark::DoNotOptimize(p.cov());
  }
}
BENCHMARK(BM_PreintegrationStep);

void BM_ParseLogLine(benchmark::State& state) {
  const std::string_view lines[] = {
      "IMU 1700000000.010000 -1.106300389e-03 3.878863433e-03 1.076968188e-03 -2.346130173e-02 -3.253824781e-02 "
      "9.828179482e+00",
      "ODOM 1700000000.100000 120 118",
      "GNSS 1700000001.000000 31.5081847072 120.4019869031 0.0365 171.01713 1 0.020 0.020 0.030"};
  LogRecord rec;
  InputIssue issue;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ParseLogLine(lines[i++ % 3], &rec, &issue));
  }
}
BENCHMARK(BM_ParseLogLine);

}  // namespace
}  // namespace gins
