// The ESKF's update for every measurement module (core/measurement_module.h): the module's model of the
// kinematic state at its time, linearised with Jets at the nominal state in (δp, δθ, δv) and handed to
// Eskf::Update, gated at the module's gate_probability. A module needs no ESKF code of its own.
#include "core/chi2.h"
#include "core/linearize.h"
#include "core/so3.h"
#include "solver/eskf.h"

namespace gins {

using eskf::Block;
using eskf::EmbedJacobian;

void Eskf::SetModuleGates() {
  MeasurementModules::ForEach([&](auto tag) {
    using Mod = typename decltype(tag)::type;
    module_gates_[MeasurementModules::IndexOf<Mod>()] =
        Chi2Gate(std::get<typename Mod::Options>(sensors_.modules).gate_probability, Mod::Model::kResidualDim);
  });
}

void Eskf::UseModule(const Measurement& measurement) {
  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (MeasurementModules::kHasMeasurement<M>) {
          constexpr size_t i = MeasurementModules::IndexOfMeasurement<M>();
          using Mod = MeasurementModules::At<i>;
          constexpr int D = Mod::Model::kResidualDim;
          static_assert(D >= 1 && D <= 3, "a module's residual has 1 to 3 rows (Eskf::Update's sizes)");
          if (!initialized_ || m.t < nom_.x.t) return;
          Propagate(m.t);
          const typename Mod::Model model = Mod::ModelOf(m, std::get<typename Mod::Options>(sensors_.modules));
          const Model<D> linearized = [&] {
            Eigen::Matrix<double, D, 1> r;
            Eigen::Matrix<double, D, 9> H;  // (δp, δθ, δv)
            Linearize<D, 9>(
                [&](const auto& d) {
                  using T = typename std::decay_t<decltype(d)>::Scalar;
                  const PredictedKinematics<T> k{nom_.x.p_wb.cast<T>() + d.template head<3>(),
                                                 nom_.x.v_w.cast<T>() + d.template tail<3>(),
                                                 nom_.x.q_wb.cast<T>() * ExpQuat<T>(d.template segment<3>(3))};
                  Eigen::Matrix<T, D, 1> res;
                  model(k, res.data());
                  return res;
                },
                &r, &H);
            return Linearized<D>{r, EmbedJacobian<D>({{Block::kP, H.template leftCols<3>()},
                                                      {Block::kTheta, H.template middleCols<3>(3)},
                                                      {Block::kV, H.template rightCols<3>()}})};
          };
          // The model is whitened: unit noise.
          Update<D>(linearized, Eigen::Matrix<double, D, D>::Identity(), module_gates_[i], &module_counts_[i], m.t);
        }
      },
      measurement);
}

void Eskf::AddModuleStats(nlohmann::json* stats) const {
  MeasurementModules::ForEach([&](auto tag) {
    using Mod = typename decltype(tag)::type;
    (*stats)[Mod::kName] = module_counts_[MeasurementModules::IndexOf<Mod>()].ToJson();
  });
}

}  // namespace gins
