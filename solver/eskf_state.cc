#include "solver/eskf_state.h"

#include <cmath>

namespace gins {

using eskf::kBlocks;
using eskf::kNumBlocks;

EskfNominal::Additive EskfNominal::Start() {
  Additive a;
  for (int i = 0; i < kNumBlocks; ++i) {
    const int offset = eskf::Offset(kBlocks[i].block) - nav::kDim;
    if (offset < 0) continue;
    a.segment(offset, kBlocks[i].dim).setConstant(kBlocks[i].start);
  }
  return a;
}

EskfNominal EskfNominal::Plus(const Vec& d) const {
  EskfNominal b = *this;
  b.PlusInPlace(d);
  return b;
}

void EskfNominal::PlusInPlace(const Vec& d) {
  x = x.Boxplus(d.head<nav::kDim>());
  additive += d.tail<eskf::kAdditiveDim>();
}

EskfNominal::Vec EskfNominal::Minus(const EskfNominal& a) const {
  Vec d;
  d.head<nav::kDim>() = x.Boxminus(a.x);
  d.tail<eskf::kAdditiveDim>() = additive - a.additive;
  return d;
}

bool EskfNominal::AllFinite() const { return x.AllFinite() && additive.allFinite(); }

void EskfNominal::ResetNonFinite() {
  const Additive start = Start();
  for (int i = 0; i < kNumBlocks; ++i) {
    const int offset = eskf::Offset(kBlocks[i].block) - nav::kDim;
    if (offset < 0 || additive.segment(offset, kBlocks[i].dim).allFinite()) continue;
    additive.segment(offset, kBlocks[i].dim) = start.segment(offset, kBlocks[i].dim);
  }
}

void EskfNominal::Pack(double* out) const {
  Vec3::Map(out) = x.p_wb;
  Vec3::Map(out + 3) = x.v_w;
  out[6] = x.q_wb.w(), out[7] = x.q_wb.x(), out[8] = x.q_wb.y(), out[9] = x.q_wb.z();
  Vec3::Map(out + 10) = x.bg;
  Vec3::Map(out + 13) = x.ba;
  Additive::Map(out + 16) = additive;
}

EskfNominal EskfNominal::Unpack(const double* in, double t) {
  EskfNominal n;
  n.x.t = t;
  n.x.p_wb = Eigen::Map<const Vec3>(in);
  n.x.v_w = Eigen::Map<const Vec3>(in + 3);
  n.x.q_wb = Quat(in[6], in[7], in[8], in[9]);
  n.x.bg = Eigen::Map<const Vec3>(in + 10);
  n.x.ba = Eigen::Map<const Vec3>(in + 13);
  n.additive = Eigen::Map<const Additive>(in + 16);
  return n;
}

}  // namespace gins
