#pragma once
// The air velocity field (docs/scene.md, docs/solver.md "Wind"): a mean wind from the
// keys (piecewise linear, held before the first and after the last key), gusts along it, and
// a frozen-turbulence field of sinusoidal modes advected with the mean wind. Deterministic:
// everything is a function of (seed, position, time), never of the step or thread count.
// With options.loop_period > 0 the whole field is periodic (docs/solver.md "Wind"): the keys
// repeat, and every rate and wave number is rounded to whole cycles per period.
#include <Eigen/Core>
#include <vector>

#include "sim/sim_options.h"

namespace treeanim {

class WindField {
 public:
  explicit WindField(const WindOptions& options);

  int mode_count() const { return static_cast<int>(mode_wave.cols()); }
  // t => mean wind vector (m/s), speed*direction interpolated between keys.
  Eigen::Vector3d mean(double t) const;
  // t => mean wind plus the gust along it (m/s): the air velocity without turbulence.
  Eigen::Vector3d base(double t) const;
  // t => true when the air is still everywhere (no mean wind, no gust, hence no turbulence).
  bool calm(double t) const;
  // t => amplitude of the gusts along the mean wind (m/s), interpolated between keys.
  double gust_amplitude(double t) const;
  // x (m) => the spatial phase terms sin/cos(k_m . x + phi_m) of every mode, into (modes) arrays.
  void spatial_phases(const Eigen::Vector3d& x, double* sin_a, double* cos_a) const;
  // t => the temporal phase terms sin/cos(-k_m . D(t) + w_m t) (D: advection of the frozen
  // field) into (modes) arrays; returns the amplitude factor of the turbulence at t (m/s).
  double temporal_phases(double t, double* sin_b, double* cos_b) const;
  // phases + amplitude => turbulent velocity (m/s) = scale * sum_m a_m sin(a_m + b_m).
  Eigen::Vector3d turbulence(const double* sin_a, const double* cos_a, const double* sin_b,
                             const double* cos_b, double scale) const;

 private:
  double gust_signal(double t) const;
  Eigen::Vector3d advection(double t) const;
  // t => the time of the keys it reads: t itself, or t wrapped into the loop's first period.
  double key_time_of(double t) const;
  // Integral of the keys' mean wind from the first key to t (no wrapping).
  Eigen::Vector3d key_advection_at(double t) const;
  // Rounds rates and wave numbers to whole cycles per loop period (constructor, loops only).
  void make_periodic();

  std::vector<double> key_time;          // (K) s
  std::vector<Eigen::Vector3d> key_wind; // (K) m/s, speed * direction
  std::vector<double> key_gust;          // (K) m/s
  std::vector<Eigen::Vector3d> key_advection;  // (K) m, integral of the mean wind up to key k
  double intensity;                      // turbulence rms per component / mean speed
  Eigen::Matrix3Xd mode_wave;            // (3 x N) 1/m, wave vectors
  Eigen::Matrix3Xd mode_amplitude;       // (3 x N) unit vectors normal to the wave vectors, pre-scaled
  std::vector<double> mode_phase;        // (N) rad
  std::vector<double> mode_omega;        // (N) rad/s, evolution of the frozen field in place
  double gust_omega[3];                  // rad/s, three incommensurate gust rates
  double gust_phase[3];                  // rad
  double loop_period = 0;                // s; > 0: the field repeats with this period
  double loop_start = 0;                 // s, start of the first period
  Eigen::Vector3d loop_advection = Eigen::Vector3d::Zero();  // m, advection over one period
};

}  // namespace treeanim
