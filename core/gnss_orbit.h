// Broadcast-ephemeris satellite models: position, velocity and clock of a satellite from its Keplerian
// ephemeris (GPS, Galileo, BeiDou, QZSS), the group delay of a signal, which ephemeris to use, and the
// signal's travel from satellite to receiver (transmit time, Earth rotation). Values only: the RINEX reader
// (core/io/rinex.h) fills the KeplerEphemeris.
//
// Time: GPS seconds since 1980-01-06 throughout (BeiDou's toe/toc are converted from BDT by the reader).
// Frames: the ECEF frame of each system (WGS 84, GTRF, CGCS2000) taken as one; they agree to a few cm.
#pragma once

#include <vector>

#include "core/conventions.h"
#include "core/gnss_ephemeris.h"

namespace gins {

constexpr double kSpeedOfLight = 299792458.0;  // m/s, all ICDs

// The constants a system's user algorithm is defined with.
struct GnssOrbitConstants {
  double mu_m3_s2;        // Earth's gravitational constant
  double omega_e_rad_s;   // Earth's rotation rate
};
// GPS/QZSS: IS-GPS-200 §20.3.3.4.3 (WGS 84: μ = 3.986005e14, Ω̇e = 7.2921151467e-5); Galileo: OS SIS ICD
// §5.1.1 (μ = 3.986004418e14, same Ω̇e); BeiDou: B1I ICD §5.2.4 (CGCS2000: μ = 3.986004418e14,
// Ω̇e = 7.292115e-5).
GnssOrbitConstants OrbitConstants(GnssSystem system);

// t − t_ref into [−302400, 302400] s: the ICDs' rule for a time difference across the week's end.
double WrapHalfWeek(double dt_s);

// BeiDou GEO satellites (PRN 1-5 and 59-63), whose broadcast orbit is in a frame inclined by 5°.
bool IsBeidouGeo(const SatelliteId& sat);

// Eccentric anomaly E of mean anomaly M (rad): Kepler's equation M = E − e·sin E by Newton's method.
double SolveKepler(double mean_anomaly_rad, double e);

// A satellite at a time, from one ephemeris.
struct SatelliteState {
  Vec3 position_ecef_m = Vec3::Zero();  // antenna phase centre as broadcast, ECEF at that same time
  Vec3 velocity_ecef_m_s = Vec3::Zero();  // in the rotating ECEF frame (analytic derivative)
  // SV clock offset (s, to be added to the satellite's time to get system time: t = t_sv − Δt_sv) for the
  // ephemeris's reference signal (GPS: L1/L2 P(Y) ionosphere-free; Galileo I/NAV: E1/E5b, F/NAV: E1/E5a;
  // BeiDou D1/D2: B3I), relativistic term included, group delay NOT (GroupDelay below).
  double clock_bias_s = 0.0;
  double clock_drift_s_s = 0.0;
  double relativistic_s = 0.0;  // the part F·e·√A·sin E of clock_bias_s
};

// IS-GPS-200 §20.3.3.4.3 Table 20-IV (Galileo OS SIS ICD §5.1.1, BeiDou B1I ICD §5.2.4.12 and, for GEO,
// the −5° rotation of §5.2.4.12's last rows) at `gps_s`; the clock of §20.3.3.3.3.1: af0 + af1·dt + af2·dt²
// + Δt_r with dt = t − toc and Δt_r = F·e·√A·sin E, F = −2√μ/c². The velocity is the analytic time
// derivative of the same equations (tested against a central difference).
SatelliteState KeplerSatelliteState(const KeplerEphemeris& eph, double gps_s);

// The relativistic clock term F·e·√A·sin E (s) of §20.3.3.3.3.1, F = −2√μ/c² (GPS: −4.442807633e-10 s/√m).
double RelativisticClockTerm(GnssSystem system, double e, double sqrt_a_sqrt_m, double eccentric_anomaly_rad);

// The code signals whose group delay the broadcast ephemeris gives.
enum class GnssSignal {
  kGpsL1Ca,     // GPS/QZSS L1 C/A (RINEX C1C)
  kGpsL2,       // L2 P(Y) (C2W); L2C (C2L) has an ISC in CNAV besides, not in the LNAV record
  kGpsL5,       // L5 (C5Q): its ISC is in CNAV only
  kGalileoE1,   // Galileo E1 (C1C, C1X)
  kGalileoE5a,  // C5Q, C5X
  kGalileoE5b,  // C7Q, C7X
  kBeidouB1I,   // C2I
  kBeidouB2I,   // C7I
  kBeidouB3I,   // C6I
  kBeidouB1C,   // C1P, C1X: its ISC is in the CNAV1 message, not in the D1/D2 record
};

// The group delay (s) to subtract from the reference-signal clock for `signal`: the signal's clock is
// clock_bias_s − GroupDelay (equivalently, a pseudorange corrected by + c·clock_bias_s − c·GroupDelay).
//   GPS (IS-GPS-200 §20.3.3.3.3.2): L1 C/A TGD, L2 γ·TGD with γ = (f1/f2)²; L5 not in LNAV.
//   Galileo (OS SIS ICD §5.1.5): E1 with I/NAV (reference E1/E5b) BGD(E1,E5b), with F/NAV (E1/E5a)
//   BGD(E1,E5a); E5a with F/NAV (f1/f5a)²·BGD(E1,E5a); E5b with I/NAV (f1/f5b)²·BGD(E1,E5b).
//   BeiDou D1/D2 (B1I ICD §5.2.4.10, B3I the reference): B1I TGD1, B2I TGD2, B3I 0.
// `*known` false (and 0 returned) where the record gives no delay for the signal (B1C from D1/D2, E5a
// from I/NAV, ...): the receiver clock of the system absorbs the common part; the rest stays an error.
double GroupDelay(const KeplerEphemeris& eph, GnssSignal signal, bool* known = nullptr);

// The carrier frequency (Hz) of a signal.
double SignalFrequency(GnssSignal signal);

// Whether a Galileo record is I/NAV (data sources bit 0 or 2) or F/NAV (bit 1) (RINEX 3.04 §A8).
bool IsGalileoInav(const KeplerEphemeris& eph);

// The longest |t − toe| an ephemeris is used for: GPS/QZSS 2 h (half the 4 h fit interval), Galileo 4 h
// (RTKLIB's choice: records are renewed every 10 min but valid for hours), BeiDou 6 h (RTKLIB's too).
double MaxEphemerisAge(GnssSystem system);

struct EphemerisSelection {
  bool galileo_inav = true;   // I/NAV records (E1/E5b clock, for E1 users); false: F/NAV (E1/E5a)
};
// The ephemeris to use for `sat` at `gps_s`: healthy (health 0), within MaxEphemerisAge of its toe, the
// closest toe; nullptr if none.
const KeplerEphemeris* SelectEphemeris(const std::vector<KeplerEphemeris>& ephemerides, const SatelliteId& sat,
                                       double gps_s, const EphemerisSelection& selection = {});

// A satellite at the transmit time of a pseudorange received at `rx_gps_s`, expressed in the ECEF frame of the
// reception time.
struct TransmitState {
  SatelliteState sat;     // position/velocity rotated into the ECEF of t_rx (Sagnac), clock at t_tx
  double tx_gps_s = 0.0;  // transmit time, system (GPS) time
  double travel_s = 0.0;  // geometric travel time used for the Earth rotation
};
// t_tx = t_rx − P/c − Δt_sv(t_tx), iterated (Δt_sv is a function of t_tx). t_rx − P/c is exactly the
// satellite clock's transmit time (the pseudorange is the receiver's clock reading at reception minus the
// satellite's at transmission, times c): the receiver clock error only dates the reception, which matters
// for the Earth rotation below (1 ms: 0.5 mm). Then the satellite's ECEF position at t_tx is rotated about
// z by Ω̇e·τ, τ = |r_sat − r_rx|/c (the frame turns while the signal travels), τ iterated with it.
// `receiver_ecef_m` may be zero (unknown): τ is then P/c − Δt_sv.
TransmitState SatelliteAtTransmit(const KeplerEphemeris& eph, double rx_gps_s, double pseudorange_m,
                                  const Vec3& receiver_ecef_m);

// Rotation of an ECEF vector of time t into the ECEF frame of time t + τ: Rz(−Ω̇e·τ) applied as a frame
// rotation, x' = x cos θ + y sin θ, y' = −x sin θ + y cos θ, θ = Ω̇e·τ.
Vec3 EarthRotationCorrection(const Vec3& r_ecef, double omega_e_rad_s, double travel_s);

}  // namespace gins
