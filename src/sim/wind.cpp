#include "sim/wind.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <numbers>

#include "common/random.h"
#include "sim/kernel_isa.h"
#include "sim/lanes.h"

namespace treeanim {

namespace {

Eigen::Vector3d random_unit(RandomSequence& rng) {
  const double z = 2 * rng.uniform() - 1;
  const double phi = 2 * std::numbers::pi * rng.uniform();
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

// Wave vector k, drift per period D (non-zero) => k with its component along D rounded to a
// whole number of cycles over D, so that sin(k . (x - D(t)) + ...) repeats with the loop.
Eigen::Vector3d whole_cycles_along(const Eigen::Vector3d& k, const Eigen::Vector3d& drift) {
  const Eigen::Vector3d along = drift.normalized();
  const double cycles = std::round(k.dot(drift) / (2 * std::numbers::pi));
  return k + (2 * std::numbers::pi * cycles / drift.norm() - k.dot(along)) * along;
}

}  // namespace

WindField::WindField(const WindOptions& options)
    : keys(wind_key_series(options.keys)),
      intensity(options.turbulence_intensity),
      loop_period(options.loop_period),
      loop_start(options.loop_start),
      volume_(options.volume ? std::make_shared<const WindVolume>(*options.volume) : nullptr) {
  // Exact integral of the piecewise-linear mean wind (trapezoids), for the advection of the
  // frozen patterns: a function of t alone, so the field does not depend on the step.
  key_advection.assign(keys.time.size(), Eigen::Vector3d::Zero());
  for (size_t k = 1; k < keys.time.size(); ++k)
    key_advection[k] = key_advection[k - 1] +
                       0.5 * (keys.time[k] - keys.time[k - 1]) * (keys.wind[k - 1] + keys.wind[k]);

  RandomSequence rng(options.seed ^ 0x7475726275ull);  // "turbu": the turbulence stream
  const int n = options.turbulence_modes;
  mode_turbulence = n;
  mode_wave.resize(3, n + kGustWaves);
  mode_amplitude.resize(3, n);
  mode_phase.resize(n + kGustWaves);
  mode_omega.resize(n + kGustWaves);
  // Unit amplitudes normal to k (divergence-free modes); the sum of n modes with random
  // directions has a per-component rms of sqrt(n/6), hence the factor sqrt(6/n).
  const double normalise = std::sqrt(6.0 / n);
  for (int m = 0; m < n; ++m) {
    const Eigen::Vector3d dir = random_unit(rng);
    // Wavelengths spread log-uniformly over [L/2, 2L] around the length scale L.
    const double wavelength = options.turbulence_length * std::exp2(2 * rng.uniform() - 1);
    mode_wave.col(m) = dir * (2 * std::numbers::pi / wavelength);
    Eigen::Vector3d a = dir.cross(random_unit(rng));
    if (a.norm() < 1e-6) a = dir.unitOrthogonal();
    mode_amplitude.col(m) = a.normalized() * normalise;
    mode_phase[m] = 2 * std::numbers::pi * rng.uniform();
    mode_omega[m] = 2 * std::numbers::pi * options.turbulence_frequency * (0.5 + rng.uniform());
  }
  // Gusts: three waves at incommensurate multiples of the gust rate, summed and normalised to
  // [-1, 1]; their fronts are tilted by up to 45 degrees about the up axis (gusts of finite width).
  const double ratios[kGustWaves] = {1.0, 1.6180339887498949, 2.4142135623730951};
  double rates[kGustWaves], tilts[kGustWaves];
  for (int j = 0; j < kGustWaves; ++j) {
    rates[j] = 2 * std::numbers::pi * options.gust_frequency * ratios[j];
    mode_phase[n + j] = 2 * std::numbers::pi * rng.uniform();
    mode_omega[n + j] = 0;
  }
  for (double& tilt : tilts) tilt = std::numbers::pi / 4 * (2 * rng.uniform() - 1);
  make_gust_waves(rates, tilts);
  if (loop_period > 0) make_periodic();
}

void WindField::make_gust_waves(const double* rates, const double* tilts) {
  // The gust pattern is frozen in the air like the turbulence, so at a point it changes at
  // k . mean: its wave numbers along the wind are the rates over the fastest key's speed,
  // which gives the asked rates in that wind and slower gusts in weaker wind. The wave
  // vectors point upwind: in a steady wind from the first key on, each wave at the origin is
  // sin(w (t - t_first) + phi), the gust signal of a single point.
  size_t fastest = 0;
  for (size_t k = 1; k < keys.wind.size(); ++k)
    if (keys.wind[k].norm() > keys.wind[fastest].norm()) fastest = k;
  const double speed = keys.wind.empty() ? 0.0 : keys.wind[fastest].norm();
  const int n = mode_turbulence;
  if (!(speed > 0)) {  // calm throughout: there are no gusts to carry
    mode_wave.rightCols(kGustWaves).setZero();
    return;
  }
  const Eigen::Vector3d along = keys.wind[fastest] / speed;
  Eigen::Vector3d across = along.cross(Eigen::Vector3d::UnitY());
  across = across.norm() > 1e-6 ? across.normalized() : along.unitOrthogonal();  // a vertical wind
  for (int j = 0; j < kGustWaves; ++j)
    mode_wave.col(n + j) = -rates[j] / speed * (along + std::tan(tilts[j]) * across);
}

void WindField::make_periodic() {
  loop_advection = key_advection_at(loop_start + loop_period) - key_advection_at(loop_start);
  // A rate of c cycles per period, c >= 1 a whole number: sin(w t) then repeats with the loop.
  auto whole_cycles = [&](double omega) {
    const double cycles = std::max(1.0, std::round(omega * loop_period / (2 * std::numbers::pi)));
    return 2 * std::numbers::pi * cycles / loop_period;
  };
  for (int m = 0; m < mode_count(); ++m) mode_omega[m] = whole_cycles(mode_omega[m]);
  const double drift = loop_advection.norm();
  if (drift == 0) return;  // D(t) itself repeats: every wave does
  // The frozen patterns drift by loop_advection per period: k . drift must be whole cycles too.
  // Only the wave vector's component along the drift changes.
  for (int j = mode_count(); j < phase_count(); ++j)
    mode_wave.col(j) = whole_cycles_along(mode_wave.col(j), loop_advection);
  // A turbulence mode keeps its amplitude normal to the new wave vector (divergence-free).
  const Eigen::Vector3d along = loop_advection / drift;
  for (int m = 0; m < mode_count(); ++m) {
    Eigen::Vector3d k = whole_cycles_along(mode_wave.col(m), loop_advection);
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

Eigen::Vector3d WindField::mean(double t) const { return key_mean_wind(keys, key_time_of(t)); }

double WindField::gust_amplitude(double t) const { return key_gust_amplitude(keys, key_time_of(t)); }

bool WindField::calm(double t) const { return !volume_ && mean(t).squaredNorm() == 0; }

Eigen::Vector3d WindField::advection(double t) const {
  if (!(loop_period > 0)) return key_advection_at(t);
  // Whole periods drift by loop_advection each; the rest of the way within the first period.
  const double periods = std::floor((t - loop_start) / loop_period);
  return periods * loop_advection + key_advection_at(key_time_of(t)) - key_advection_at(loop_start);
}

Eigen::Vector3d WindField::key_advection_at(double t) const {
  if (keys.time.empty()) return Eigen::Vector3d::Zero();
  if (t <= keys.time.front()) return (t - keys.time.front()) * keys.wind.front();
  if (t >= keys.time.back()) return key_advection.back() + (t - keys.time.back()) * keys.wind.back();
  const size_t k = key_interval(keys.time, t);
  const double s = (t - keys.time[k]) / (keys.time[k + 1] - keys.time[k]);
  return key_advection[k] + 0.5 * (t - keys.time[k]) * (keys.wind[k] + ((1 - s) * keys.wind[k] + s * keys.wind[k + 1]));
}

void WindField::spatial_phases(const Eigen::Vector3d& x, double* sin_a, double* cos_a) const {
  for (int m = 0; m < phase_count(); ++m) {
    const double a = mode_wave.col(m).dot(x) + mode_phase[m];
    sin_a[m] = std::sin(a);
    cos_a[m] = std::cos(a);
  }
}

void WindField::sample_time(double t, double window, AirSample& air) const {
  air.mean = mean(t);
  const double speed = air.mean.norm();
  // A gust needs a direction: none in still air.
  air.gust = speed > 0 ? Eigen::Vector3d(air.mean * (gust_amplitude(t) / speed)) : Eigen::Vector3d::Zero();
  air.turbulence = intensity * speed;
  const Eigen::Vector3d d = advection(t);
  air.unresolved.setZero();
  for (int j = 0; j < phase_count(); ++j) {
    const double b = mode_omega[j] * t - mode_wave.col(j).dot(d);
    // The wave's rate here, db/dt, and its mean over the window: a box filter's response
    // 1 - (rate window)^2 / 24 to second order, as a Gaussian without the box's negative lobes.
    const double rate = (mode_omega[j] - mode_wave.col(j).dot(air.mean)) * window;
    const double kept = std::exp(-rate * rate / 24);
    air.sin_b[j] = kept * std::sin(b);
    air.cos_b[j] = kept * std::cos(b);
    // A unit wave's variance 1/2 splits into its windows' means (kept^2 / 2) and what varies
    // within a window: the rest, along the wave's amplitude vector.
    const Eigen::Vector3d amplitude =
        j < mode_count() ? Eigen::Vector3d(mode_amplitude.col(j) * air.turbulence) : Eigen::Vector3d(air.gust / kGustWaves);
    air.unresolved += (0.5 * (1 - kept * kept)) * (amplitude * amplitude.transpose());
  }
}

// sin(a + b) = sin(k . (x - D(t)) + w t + phi) for each phase: the turbulence modes along
// their amplitude vectors, the gust waves averaged into a signal in [-1, 1] along the wind.
Eigen::Vector3d WindField::velocity(const double* sin_a, const double* cos_a, const AirSample& air,
                                    const Eigen::Vector3d& mean) const {
  Eigen::Vector3d v = mean;
  if ((air.gust.array() != 0).any()) {
    double gust = 0;
    for (int j = mode_count(); j < phase_count(); ++j) gust += sin_a[j] * air.cos_b[j] + cos_a[j] * air.sin_b[j];
    v += air.gust * (gust / kGustWaves);
  }
  if (air.turbulence != 0) {
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (int m = 0; m < mode_count(); ++m)
      u += mode_amplitude.col(m) * (sin_a[m] * air.cos_b[m] + cos_a[m] * air.sin_b[m]);
    v += u * air.turbulence;
  }
  return v;
}

void WindField::velocities(const double* const (&sin_a)[4], const double* const (&cos_a)[4], const AirSample& air,
                           double (&v)[3][4]) const {
  with_kernel_isa([&] {
    // Phase j of the four points as one vector (written lane by lane, then loaded; by
    // reference: lanes.h).
    auto lanes = [](const double* const (&a)[4], int j, Double4& x) {
      const double lane[4] = {a[0][j], a[1][j], a[2][j], a[3][j]};
      std::memcpy(&x, lane, sizeof x);
    };
    Double4 sin_j, cos_j;
    Double4 sum[3];
    for (int i = 0; i < 3; ++i) sum[i] = Double4{} + air.mean[i];
    if ((air.gust.array() != 0).any()) {
      Double4 gust = {};
      for (int j = mode_count(); j < phase_count(); ++j) {
        lanes(sin_a, j, sin_j), lanes(cos_a, j, cos_j);
        gust += sin_j * air.cos_b[j] + cos_j * air.sin_b[j];
      }
      for (int i = 0; i < 3; ++i) sum[i] += air.gust[i] * (gust / kGustWaves);
    }
    if (air.turbulence != 0) {
      Double4 u[3] = {};
      for (int m = 0; m < mode_count(); ++m) {
        lanes(sin_a, m, sin_j), lanes(cos_a, m, cos_j);
        const Double4 wave = sin_j * air.cos_b[m] + cos_j * air.sin_b[m];
        for (int i = 0; i < 3; ++i) u[i] += mode_amplitude(i, m) * wave;
      }
      for (int i = 0; i < 3; ++i) sum[i] += u[i] * air.turbulence;
    }
    std::memcpy(v, sum, sizeof v);
  });
}

Eigen::Vector3d WindField::velocity(const Eigen::Vector3d& x, double t) const {
  double sin_a[kMaxPhases], cos_a[kMaxPhases];
  spatial_phases(x, sin_a, cos_a);
  AirSample air;
  sample_time(t, 0, air);
  if (volume_) return velocity(sin_a, cos_a, air, volume_->mean(volume_->at(t), x, air.mean));
  return velocity(sin_a, cos_a, air);
}

}  // namespace treeanim
