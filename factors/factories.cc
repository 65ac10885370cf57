// The AutoDiffCostFunction instantiations of the small factors, kept in one translation unit so the
// Jet templates compile once (the IMU factor's lives in imu_factor.cc).
//
// The CHECKs below are programmer errors, not data (docs/robustness.md, "Faults in the stream"): every σ
// comes from the config (checked > 0 by config_keys.h) or from a record the reader accepted (σ > 0 and
// finite, log_limits); a preintegration is attached only when it spans a positive time (Smoother::AnchorAt
// makes a keyframe instead, and Smoother::IntegrateTo coasts where no sample covers a step); chord and
// random-walk intervals are between keyframes, which are more than kSameEpoch apart.
#include <ceres/autodiff_cost_function.h>
#include <glog/logging.h>

#include "factors/bias_rw_factor.h"
#include "factors/chord_factor.h"
#include "factors/delayed_factor.h"
#include "factors/gnss_factor.h"
#include "factors/gnss_preint_factor.h"
#include "factors/gnss_velocity_factor.h"
#include "factors/odometer_factor.h"
#include "factors/preint_attached_factor.h"
#include "factors/raw_gnss_factor.h"
#include "factors/wheel_yaw_factor.h"
#include "factors/heading_factor.h"
#include "factors/nhc_factor.h"
#include "factors/scale_rw_factor.h"
#include "factors/wheel_factor.h"
#include "factors/zero_motion_factor.h"

namespace gins {

ceres::CostFunction* GnssFactor::Create(const Vec3& z_w, const Vec3& sigma_w, const Vec3& lever_b) {
  CHECK((sigma_w.array() > 0.0).all()) << "GnssFactor: σ must be > 0, got " << sigma_w.transpose();
  return new ceres::AutoDiffCostFunction<GnssFactor, 3, pose::kAmbient>(
      new GnssFactor(z_w, sigma_w, lever_b));
}

ceres::CostFunction* HeadingFactor::Create(double yaw_meas, double sigma_yaw, double mount_yaw) {
  CHECK_GT(sigma_yaw, 0.0) << "HeadingFactor: σ must be > 0";
  return new ceres::AutoDiffCostFunction<HeadingFactor, 1, pose::kAmbient>(
      new HeadingFactor(yaw_meas, sigma_yaw, mount_yaw));
}

ceres::CostFunction* WheelFactor::Create(double speed_meas, double sigma) {
  CHECK_GT(sigma, 0.0) << "WheelFactor: σ must be > 0";
  return new ceres::AutoDiffCostFunction<WheelFactor, 1, pose::kAmbient, 3, 1>(
      new WheelFactor(speed_meas, sigma));
}

ceres::CostFunction* NhcFactor::Create(double sigma, const Vec3& omega_b, const Vec3& lever_b) {
  CHECK_GT(sigma, 0.0) << "NhcFactor: σ must be > 0";
  return new ceres::AutoDiffCostFunction<NhcFactor, 2, pose::kAmbient, 3>(new NhcFactor(sigma, omega_b, lever_b));
}

template <class Measurement>
ceres::CostFunction* PreintAttachedFactor<Measurement>::Create(std::shared_ptr<const Preintegration> preint,
                                                               const ImuEarthTerms& earth, Measurement measurement) {
  // The callers floor every σ and never attach over an empty interval: data cannot reach these.
  CHECK(preint != nullptr && preint->dt() > 0.0) << "PreintAttachedFactor over an empty preintegration";
  return new PreintAttachedCostFunction<Measurement>(std::move(preint), earth, std::move(measurement));
}

template <class Measurement>
ceres::CostFunction* PreintAttachedFactor<Measurement>::CreateAutoDiff(std::shared_ptr<const Preintegration> preint,
                                                                       const ImuEarthTerms& earth,
                                                                       Measurement measurement) {
  CHECK(preint != nullptr && preint->dt() > 0.0) << "PreintAttachedFactor over an empty preintegration";
  return new ceres::AutoDiffCostFunction<PreintAttachedFactor<Measurement>, Measurement::kResidualDim,
                                         pose::kAmbient, 3, 6>(
      new PreintAttachedFactor<Measurement>(std::move(preint), earth, std::move(measurement)));
}
template class PreintAttachedFactor<GnssAtTime>;
template class PreintAttachedFactor<HeadingAtTime>;
template class PreintAttachedFactor<GnssVelocityAtTime>;
template class PreintAttachedFactor<RawRangeAtTime>;
template class PreintAttachedFactor<RawRateAtTime>;

template <class M>
ceres::CostFunction* RawAtKeyframeFactor<M>::Create(M model) {
  return new ceres::AutoDiffCostFunction<RawAtKeyframeFactor<M>, 3, pose::kAmbient, 3>(
      new RawAtKeyframeFactor<M>(std::move(model)));
}
template class RawAtKeyframeFactor<RawRangeAtTime>;
template class RawAtKeyframeFactor<RawRateAtTime>;

ceres::CostFunction* RawDisplacementFactor::Create(const Vec3& d_w, const Mat3& sqrt_info, const Vec3& lever_b) {
  return new ceres::AutoDiffCostFunction<RawDisplacementFactor, 3, pose::kAmbient, pose::kAmbient>(
      new RawDisplacementFactor(d_w, sqrt_info, lever_b));
}

template <class Measurement>
ceres::CostFunction* DelayedAtKeyframeFactor<Measurement>::Create(Delayed<Measurement> delayed) {
  return new DelayedAtKeyframeCostFunction<Measurement>(std::move(delayed));
}

template <class Measurement>
ceres::CostFunction* DelayedAtKeyframeFactor<Measurement>::CreateAutoDiff(Delayed<Measurement> delayed) {
  return new ceres::AutoDiffCostFunction<DelayedAtKeyframeFactor<Measurement>, Measurement::kResidualDim,
                                         pose::kAmbient, 3, 1>(new DelayedAtKeyframeFactor<Measurement>(delayed));
}
template class DelayedAtKeyframeFactor<GnssAtTime>;
template class DelayedAtKeyframeFactor<HeadingAtTime>;
template class DelayedAtKeyframeFactor<GnssVelocityAtTime>;

ceres::CostFunction* GnssPreintFactor::Create(std::shared_ptr<const Preintegration> preint,
                                              const ImuEarthTerms& earth, const Vec3& z_w, const Vec3& sigma_w,
                                              const Vec3& lever_b) {
  CHECK((sigma_w.array() > 0.0).all()) << "GnssPreintFactor: σ must be > 0, got " << sigma_w.transpose();
  return PreintAttachedFactor<GnssAtTime>::Create(std::move(preint), earth,
                                                  GnssAtTime{z_w, sigma_w.cwiseInverse(), lever_b});
}

ceres::CostFunction* GnssVelocityFactor::Create(const Vec3& z_w, const Vec3& sigma_w, const Vec3& omega_b,
                                        const Vec3& lever_b) {
  CHECK((sigma_w.array() > 0.0).all()) << "GvelFactor: σ must be > 0, got " << sigma_w.transpose();
  return new ceres::AutoDiffCostFunction<GnssVelocityFactor, 3, pose::kAmbient, 3>(
      new GnssVelocityFactor(z_w, sigma_w, omega_b, lever_b));
}

ceres::CostFunction* OdometerFactor::CreateAutoDiff(const Vec3& displacement_i, double sigma, const Vec3& lever_b) {
  CHECK_GT(sigma, 0.0) << "OdometerFactor: σ must be > 0";
  return new ceres::AutoDiffCostFunction<OdometerFactor, 1, pose::kAmbient, pose::kAmbient, 1>(
      new OdometerFactor(displacement_i, sigma, lever_b));
}

ceres::CostFunction* ChordFactor::CreateAutoDiff(double dt, double sigma, const Vec3& lever_b, const Vec3& path_i) {
  CHECK(dt > 0.0 && sigma > 0.0) << "ChordFactor: dt and σ must be > 0";
  return new ceres::AutoDiffCostFunction<ChordFactor, 2, pose::kAmbient, pose::kAmbient>(
      new ChordFactor(dt, sigma, lever_b, path_i));
}

ceres::CostFunction* WheelYawFactor::Create(double yaw_change, double sigma) {
  CHECK_GT(sigma, 0.0) << "WheelYawFactor: σ must be > 0";
  return new ceres::AutoDiffCostFunction<WheelYawFactor, 1, pose::kAmbient, pose::kAmbient, 1>(
      new WheelYawFactor(yaw_change, sigma));
}

ceres::CostFunction* BiasRwFactor::Create(double gyro_bias_rw, double acc_bias_rw, double dt) {
  CHECK(gyro_bias_rw > 0.0 && acc_bias_rw > 0.0 && dt > 0.0)
      << "BiasRwFactor: random walks and dt must be > 0 (" << gyro_bias_rw << ", " << acc_bias_rw << ", "
      << dt << ")";
  return new ceres::AutoDiffCostFunction<BiasRwFactor, 6, 6, 6>(
      new BiasRwFactor(gyro_bias_rw, acc_bias_rw, dt));
}

ceres::CostFunction* ScaleRwFactor::Create(double scale_rw, double dt) {
  CHECK(scale_rw > 0.0 && dt > 0.0) << "ScaleRwFactor: random walk and dt must be > 0";
  return new ceres::AutoDiffCostFunction<ScaleRwFactor, 1, 1, 1>(new ScaleRwFactor(scale_rw, dt));
}

ceres::CostFunction* ZeroMotionFactor::Create(double sigma_p, double sigma_theta) {
  CHECK(sigma_p > 0.0 && sigma_theta > 0.0) << "ZeroMotionFactor: sigmas must be > 0";
  return new ceres::AutoDiffCostFunction<ZeroMotionFactor, 6, 7, 7>(new ZeroMotionFactor(sigma_p, sigma_theta));
}

}  // namespace gins
