// The ESKF's tightly coupled GNSS rows (solver/eskf_raw_gnss.cc), exposed for their Jacobian's test.
#pragma once

#include <vector>

#include "core/gnss_raw.h"
#include "core/nav_state.h"

namespace gins {

// One epoch's pseudoranges (rates false) or range rates of the satellites `sats`, at the nominal state x
// with the antenna at lever_b and the body turning at omega_b: residuals predicted − measured, their
// Jacobian in the ESKF's error state (eskf_state.h: δp, δv, δθ; the rest zero), variances, and each row's
// clock group (the system for ranges, one group for range rates). The antenna's velocity is
// v_w + R_wb·(ω_b × lever_b); the line of sight's own change with the position is neglected (|v|/ρ).
NuisanceRows RawGnssRows(const NavState& x, const Vec3& lever_b, const Vec3& omega_b, const RawGnssMeasurement& m,
                         const std::vector<const RawSatellite*>& sats, bool rates);

}  // namespace gins
