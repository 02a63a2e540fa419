#include "sim/wind.h"

#include <Eigen/Geometry>
#include <cmath>

#include <numbers>
#include <random>

namespace treeanim {

namespace {

// A 64-bit generator's raw output => uniform in [0, 1). std::uniform_real_distribution is
// implementation-defined, so it would make bakes differ between standard libraries.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

Eigen::Vector3d random_unit(std::mt19937_64& rng) {
  const double z = 2 * uniform01(rng) - 1;
  const double phi = 2 * std::numbers::pi * uniform01(rng);
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

// Index k of the key interval [k, k+1) holding t, for 0 <= k < K-1; t must lie inside.
size_t interval_of(const std::vector<double>& times, double t) {
  size_t lo = 0, hi = times.size() - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    (times[mid] <= t ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

WindField::WindField(const WindOptions& options)
    : intensity(options.turbulence_intensity), loop_period(options.loop_period), loop_start(options.loop_start) {
  for (const WindKey& k : options.keys) {
    key_time.push_back(k.time);
    key_wind.push_back(k.speed * k.direction);
    key_gust.push_back(k.gust);
  }
  // Exact integral of the piecewise-linear mean wind (trapezoids), for the advection of the
  // frozen turbulence: a function of t alone, so the field does not depend on the step.
  key_advection.assign(key_time.size(), Eigen::Vector3d::Zero());
  for (size_t k = 1; k < key_time.size(); ++k)
    key_advection[k] = key_advection[k - 1] +
                       0.5 * (key_time[k] - key_time[k - 1]) * (key_wind[k - 1] + key_wind[k]);

  std::mt19937_64 rng(options.seed ^ 0x7475726275ull);  // "turbu": the turbulence stream
  const int n = options.turbulence_modes;
  mode_wave.resize(3, n);
  mode_amplitude.resize(3, n);
  mode_phase.resize(n);
  mode_omega.resize(n);
  // Unit amplitudes normal to k (divergence-free modes); the sum of n modes with random
  // directions has a per-component rms of sqrt(n/6), hence the factor sqrt(6/n).
  const double normalise = std::sqrt(6.0 / n);
  for (int m = 0; m < n; ++m) {
    const Eigen::Vector3d dir = random_unit(rng);
    // Wavelengths spread log-uniformly over [L/2, 2L] around the length scale L.
    const double wavelength = options.turbulence_length * std::exp2(2 * uniform01(rng) - 1);
    mode_wave.col(m) = dir * (2 * std::numbers::pi / wavelength);
    Eigen::Vector3d a = dir.cross(random_unit(rng));
    if (a.norm() < 1e-6) a = dir.unitOrthogonal();
    mode_amplitude.col(m) = a.normalized() * normalise;
    mode_phase[m] = 2 * std::numbers::pi * uniform01(rng);
    mode_omega[m] = 2 * std::numbers::pi * options.turbulence_frequency * (0.5 + uniform01(rng));
  }
  // Gusts: three sinusoids at incommensurate multiples of the gust rate, normalised to [-1, 1].
  const double ratios[3] = {1.0, 1.6180339887498949, 2.4142135623730951};
  for (int j = 0; j < 3; ++j) {
    gust_omega[j] = 2 * std::numbers::pi * options.gust_frequency * ratios[j];
    gust_phase[j] = 2 * std::numbers::pi * uniform01(rng);
  }
  if (loop_period > 0) make_periodic();
}

void WindField::make_periodic() {
  loop_advection = key_advection_at(loop_start + loop_period) - key_advection_at(loop_start);
  // A rate of c cycles per period, c >= 1 a whole number: sin(w t) then repeats with the loop.
  auto whole_cycles = [&](double omega) {
    const double cycles = std::max(1.0, std::round(omega * loop_period / (2 * std::numbers::pi)));
    return 2 * std::numbers::pi * cycles / loop_period;
  };
  for (double& omega : gust_omega) omega = whole_cycles(omega);
  const double drift = loop_advection.norm();
  for (int m = 0; m < mode_count(); ++m) {
    mode_omega[m] = whole_cycles(mode_omega[m]);
    if (drift == 0) continue;
    // The frozen field drifts by loop_advection per period: k . drift must be whole cycles too.
    // Only the wave vector's component along the drift changes; the amplitude is kept normal
    // to it, so the field stays divergence-free.
    const Eigen::Vector3d along = loop_advection / drift;
    Eigen::Vector3d k = mode_wave.col(m);
    const double cycles = std::round(k.dot(loop_advection) / (2 * std::numbers::pi));
    k += (2 * std::numbers::pi * cycles / drift - k.dot(along)) * along;
    if (k.norm() < 1e-12) k = mode_wave.col(m).cross(along);  // a mode with no drift component left
    const double scale = mode_amplitude.col(m).norm();
    Eigen::Vector3d a = mode_amplitude.col(m) - mode_amplitude.col(m).dot(k.normalized()) * k.normalized();
    if (a.norm() < 1e-9) a = k.unitOrthogonal();
    mode_wave.col(m) = k;
    mode_amplitude.col(m) = a.normalized() * scale;
  }
}

double WindField::key_time_of(double t) const {
  if (!(loop_period > 0)) return t;
  return loop_start + (t - loop_start) - loop_period * std::floor((t - loop_start) / loop_period);
}

Eigen::Vector3d WindField::mean(double t) const {
  t = key_time_of(t);
  if (key_time.empty()) return Eigen::Vector3d::Zero();
  if (t <= key_time.front()) return key_wind.front();
  if (t >= key_time.back()) return key_wind.back();
  const size_t k = interval_of(key_time, t);
  const double s = (t - key_time[k]) / (key_time[k + 1] - key_time[k]);
  return (1 - s) * key_wind[k] + s * key_wind[k + 1];
}

double WindField::gust_amplitude(double t) const {
  t = key_time_of(t);
  if (key_time.empty()) return 0;
  if (t <= key_time.front()) return key_gust.front();
  if (t >= key_time.back()) return key_gust.back();
  const size_t k = interval_of(key_time, t);
  const double s = (t - key_time[k]) / (key_time[k + 1] - key_time[k]);
  return (1 - s) * key_gust[k] + s * key_gust[k + 1];
}

double WindField::gust_signal(double t) const {
  double sum = 0;
  for (int j = 0; j < 3; ++j) sum += std::sin(gust_omega[j] * t + gust_phase[j]);
  return sum / 3;
}

Eigen::Vector3d WindField::base(double t) const {
  const Eigen::Vector3d m = mean(t);
  const double gust = gust_amplitude(t);
  const double speed = m.norm();
  if (gust == 0 || speed == 0) return m;  // a gust needs a direction: none in still air
  return m * (1 + gust * gust_signal(t) / speed);
}

bool WindField::calm(double t) const { return mean(t).squaredNorm() == 0; }

Eigen::Vector3d WindField::advection(double t) const {
  if (!(loop_period > 0)) return key_advection_at(t);
  // Whole periods drift by loop_advection each; the rest of the way within the first period.
  const double periods = std::floor((t - loop_start) / loop_period);
  return periods * loop_advection + key_advection_at(key_time_of(t)) - key_advection_at(loop_start);
}

Eigen::Vector3d WindField::key_advection_at(double t) const {
  if (key_time.empty()) return Eigen::Vector3d::Zero();
  if (t <= key_time.front()) return (t - key_time.front()) * key_wind.front();
  if (t >= key_time.back()) return key_advection.back() + (t - key_time.back()) * key_wind.back();
  const size_t k = interval_of(key_time, t);
  const double s = (t - key_time[k]) / (key_time[k + 1] - key_time[k]);
  return key_advection[k] + 0.5 * (t - key_time[k]) * (key_wind[k] + ((1 - s) * key_wind[k] + s * key_wind[k + 1]));
}

void WindField::spatial_phases(const Eigen::Vector3d& x, double* sin_a, double* cos_a) const {
  for (int m = 0; m < mode_count(); ++m) {
    const double a = mode_wave.col(m).dot(x) + mode_phase[m];
    sin_a[m] = std::sin(a);
    cos_a[m] = std::cos(a);
  }
}

double WindField::temporal_phases(double t, double* sin_b, double* cos_b) const {
  const Eigen::Vector3d d = advection(t);
  for (int m = 0; m < mode_count(); ++m) {
    const double b = mode_omega[m] * t - mode_wave.col(m).dot(d);
    sin_b[m] = std::sin(b);
    cos_b[m] = std::cos(b);
  }
  return intensity * mean(t).norm();
}

Eigen::Vector3d WindField::turbulence(const double* sin_a, const double* cos_a, const double* sin_b,
                                      const double* cos_b, double scale) const {
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  if (scale == 0) return u;
  for (int m = 0; m < mode_count(); ++m)
    u += mode_amplitude.col(m) * (sin_a[m] * cos_b[m] + cos_a[m] * sin_b[m]);
  return u * scale;
}

}  // namespace treeanim
