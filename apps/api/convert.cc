#include "apps/api/convert.h"

#include <string>
#include <variant>

namespace gins::api {
namespace {

Vec3 V(const double* a) { return Vec3(a[0], a[1], a[2]); }

void Copy(const Vec3& v, double* out) {
  out[0] = v.x();
  out[1] = v.y();
  out[2] = v.z();
}

// The public record of each type: its type and member.
void ToRecord(const ImuSample& m, Record* out) {
  out->type = Record::Type::kImu;
  out->imu.t = m.t;
  Copy(m.gyro, out->imu.gyro);
  Copy(m.acc, out->imu.acc);
}

void ToRecord(const WheelRecord& m, Record* out) {
  out->type = Record::Type::kWheel;
  out->wheel = {m.t, m.left_pulses, m.right_pulses};
}

void ToRecord(const GnssRecord& g, Record* out) {
  out->type = Record::Type::kGnss;
  out->gnss = {g.t, g.lat_deg, g.lon_deg, g.alt_m, g.heading_deg, g.heading_valid, g.has_sigma, {}};
  Copy(g.sigma_enu, out->gnss.sigma_enu);
}

void ToRecord(const GnssVelocityRecord& g, Record* out) {
  out->type = Record::Type::kGnssVelocity;
  out->gnss_velocity.t = g.t;
  Copy(g.v_enu, out->gnss_velocity.v_enu);
  out->gnss_velocity.has_sigma = g.has_sigma;
  Copy(g.sigma_enu, out->gnss_velocity.sigma_enu);
}

// A measurement module's record (core/measurement_module.h): its token and numbers.
template <typename R>
void ToRecord(const R& m, Record* out) {
  out->type = Record::Type::kOther;
  out->other.type = RecordTraits<R>::kInfo.token;
  double v[RecordTraits<R>::kInfo.max_fields];
  out->other.values.assign(v, v + R::Values(m, v));
}

// The module record of r's token, filled from its numbers; false if no module has that token.
template <size_t I = 0>
bool FromOther(const OtherRecord& r, LogRecord* out) {
  if constexpr (I == kNumRecordTypes) {
    return false;
  } else {
    using R = std::variant_alternative_t<I, LogRecordData>;
    if constexpr (MeasurementModules::kHasRecord<R>) {
      const RecordTypeInfo& info = RecordTraits<R>::kInfo;
      if (r.type == info.token) {
        const size_t n = r.values.size();
        if (n != info.min_fields && n != info.max_fields) {
          throw Error(Error::Kind::kInput, "a " + r.type + " record has " + std::to_string(n) + " values, needs " +
                                               std::to_string(info.min_fields) + " or " +
                                               std::to_string(info.max_fields) + " (the time first)");
        }
        R::Fill(r.values.data(), n, &out->data.emplace<R>());
        return true;
      }
    }
    return FromOther<I + 1>(r, out);
  }
}

}  // namespace

LogRecord ToLogRecord(const Imu& m) { return {ImuSample{m.t, V(m.gyro), V(m.acc)}}; }

LogRecord ToLogRecord(const Wheel& m) { return {WheelRecord{m.t, m.left_pulses, m.right_pulses}}; }

LogRecord ToLogRecord(const Gnss& m) {
  return {GnssRecord{m.t, m.lat_deg, m.lon_deg, m.alt_m, m.heading_deg, m.heading_valid, m.has_sigma, V(m.sigma_enu)}};
}

LogRecord ToLogRecord(const GnssVelocity& m) {
  return {GnssVelocityRecord{m.t, V(m.v_enu), m.has_sigma, V(m.sigma_enu)}};
}

LogRecord ToLogRecord(const Record& r) {
  LogRecord out;
  switch (r.type) {
    case Record::Type::kImu:
      out = ToLogRecord(r.imu);
      break;
    case Record::Type::kWheel:
      out = ToLogRecord(r.wheel);
      break;
    case Record::Type::kGnss:
      out = ToLogRecord(r.gnss);
      break;
    case Record::Type::kGnssVelocity:
      out = ToLogRecord(r.gnss_velocity);
      break;
    case Record::Type::kOther:
      if (!FromOther(r.other, &out)) throw Error(Error::Kind::kInput, "unknown record type '" + r.other.type + "'");
      break;
  }
  out.line = r.line;
  return out;
}

Record ToRecord(const LogRecord& r) {
  Record out;
  out.line = r.line;
  std::visit([&out](const auto& m) { ToRecord(m, &out); }, r.data);
  return out;
}

void ToState(Stream stream, const StateEstimate& e, State* out) {
  out->stream = stream;
  out->t = e.x.t;
  Copy(e.x.p_wb, out->p_enu);
  Copy(e.x.v_w, out->v_enu);
  out->q_wb[0] = e.x.q_wb.w();
  out->q_wb[1] = e.x.q_wb.x();
  out->q_wb[2] = e.x.q_wb.y();
  out->q_wb[3] = e.x.q_wb.z();
  Copy(e.x.bg, out->gyro_bias);
  Copy(e.x.ba, out->acc_bias);
  Copy(e.sigma_p, out->sigma_p);
  Copy(e.sigma_v, out->sigma_v);
  Copy(e.sigma_att, out->sigma_att);
  out->odom_scale = e.odom_scale;
}

StateEstimate ToStateEstimate(const State& s) {
  StateEstimate e;
  e.x.t = s.t;
  e.x.p_wb = V(s.p_enu);
  e.x.v_w = V(s.v_enu);
  e.x.q_wb = Quat(s.q_wb[0], s.q_wb[1], s.q_wb[2], s.q_wb[3]);
  e.x.bg = V(s.gyro_bias);
  e.x.ba = V(s.acc_bias);
  e.sigma_p = V(s.sigma_p);
  e.sigma_v = V(s.sigma_v);
  e.sigma_att = V(s.sigma_att);
  e.odom_scale = s.odom_scale;
  return e;
}

}  // namespace gins::api
