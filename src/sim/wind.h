#pragma once
// The air velocity field (docs/solver.md "Wind and forces", docs/scene.md `wind`): a mean wind
// from the keys (piecewise linear, held before the first and after the last key), gusts along
// it and a turbulent field, one function of world position and time. Gusts and turbulence
// are patterns of plane waves frozen in the air and carried by the mean wind (Taylor), so a
// gust front reaches a point s metres downwind s/U seconds later. Deterministic: everything
// is a function of (seed, position, time), never of the step or thread count. With
// options.loop_period > 0 the whole field is periodic (docs/solver.md "A periodic wind for
// loops"): the keys repeat, and every rate and wave number is rounded to whole cycles.
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "sim/sim_options.h"
#include "sim/wind_keys.h"
#include "sim/wind_volume.h"

namespace treeanim {

constexpr int kMaxModes = 64;    // the scene reader caps wind.turbulence_modes here
constexpr int kGustWaves = 3;    // plane waves summed into the gust pattern
constexpr int kMaxPhases = kMaxModes + kGustWaves;

// The terms of the air that every point shares at one time (WindField::sample_time).
struct AirSample {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();  // m/s, mean wind
  Eigen::Vector3d gust = Eigen::Vector3d::Zero();  // m/s, gust amplitude along the mean wind (0 in calm air)
  double turbulence = 0;                           // m/s, turbulence amplitude I |mean|
  double sin_b[kMaxPhases] = {}, cos_b[kMaxPhases] = {};  // (phases) sin/cos(w_j t - k_j . D(t))
  // (m/s)^2, covariance of the air the window's average left out: the waves' variance within
  // a step, which the step cannot resolve (0 at a window of 0, or in air without waves)
  Eigen::Matrix3d unresolved = Eigen::Matrix3d::Zero();
};

class WindField {
 public:
  explicit WindField(const WindOptions& options);

  int mode_count() const { return mode_turbulence; }
  // Turbulence modes then gust waves: the length of every phase array.
  int phase_count() const { return static_cast<int>(mode_wave.cols()); }
  // t => mean wind vector (m/s), speed*direction interpolated between keys.
  Eigen::Vector3d mean(double t) const;
  // t => true when the air is still everywhere (no mean wind, no gust, hence no turbulence;
  // never with a volume, whose air is not known everywhere without reading it).
  bool calm(double t) const;
  // The velocity volume that replaces the mean wind inside it; null without one.
  const WindVolume* volume() const { return volume_.get(); }
  // t => amplitude of the gusts along the mean wind (m/s), interpolated between keys.
  double gust_amplitude(double t) const;
  // x (m) => the spatial phase terms sin/cos(k_j . x + phi_j) of every phase, into (phases) arrays.
  void spatial_phases(const Eigen::Vector3d& x, double* sin_a, double* cos_a) const;
  // t, window (s) => the terms every point shares at t (mean, gust vector, turbulence
  // amplitude, temporal phases), each wave averaged over the window about t: a step of length
  // `window` feels the waves it resolves and not those it would alias (0: the values at t);
  // what the averages left out, as a covariance (AirSample::unresolved).
  void sample_time(double t, double window, AirSample& air) const;
  // Spatial phases of x + the terms at t => the air velocity at (x, t) (m/s).
  Eigen::Vector3d velocity(const double* sin_a, const double* cos_a, const AirSample& air) const {
    return velocity(sin_a, cos_a, air, air.mean);
  }
  // The same about the mean wind `mean` (a volume's at x) in place of air.mean.
  Eigen::Vector3d velocity(const double* sin_a, const double* cos_a, const AirSample& air,
                           const Eigen::Vector3d& mean) const;
  // Four points' spatial phases (a lane each) + the terms at t => their air velocities about
  // air.mean, each lane the arithmetic of velocity() (lanes.h): v[i][l] is component i of lane l's.
  void velocities(const double* const (&sin_a)[4], const double* const (&cos_a)[4], const AirSample& air,
                  double (&v)[3][4]) const;
  // x (m), t => the air velocity (m/s); the two calls above for a single point.
  Eigen::Vector3d velocity(const Eigen::Vector3d& x, double t) const;

 private:
  Eigen::Vector3d advection(double t) const;
  // t => the time of the keys it reads: t itself, or t wrapped into the loop's first period.
  double key_time_of(double t) const;
  // Integral of the keys' mean wind from the first key to t (no wrapping).
  Eigen::Vector3d key_advection_at(double t) const;
  // Turns the gust rates into wave vectors carried by the mean wind (constructor).
  void make_gust_waves(const double* rates, const double* tilts);
  // Rounds rates and wave numbers to whole cycles per loop period (constructor, loops only).
  void make_periodic();

  WindKeySeries keys;                    // the mean wind and gust amplitude between keys
  std::vector<Eigen::Vector3d> key_advection;  // (K) m, integral of the mean wind up to key k
  double intensity;                      // turbulence rms per component / mean speed
  int mode_turbulence = 0;               // N, turbulence modes; phases N .. N + kGustWaves - 1 are the gust's
  Eigen::Matrix3Xd mode_wave;            // (3 x P) 1/m, wave vectors of the modes, then of the gust waves
  Eigen::Matrix3Xd mode_amplitude;       // (3 x N) unit vectors normal to the wave vectors, pre-scaled
  std::vector<double> mode_phase;        // (P) rad
  std::vector<double> mode_omega;        // (P) rad/s, evolution in place (0 for the gust waves)
  double loop_period = 0;                // s; > 0: the field repeats with this period
  double loop_start = 0;                 // s, start of the first period
  Eigen::Vector3d loop_advection = Eigen::Vector3d::Zero();  // m, advection over one period
  std::shared_ptr<const WindVolume> volume_;  // shared by copies: one cache of frames
};

}  // namespace treeanim
