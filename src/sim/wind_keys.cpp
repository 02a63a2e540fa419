#include "sim/wind_keys.h"

#include <algorithm>
#include <cmath>

namespace treeanim {

namespace {

// The value of `values` at t, linear between keys, held outside them; `none` without keys.
template <typename T>
T value_at(const std::vector<double>& times, const std::vector<T>& values, double t, const T& none) {
  if (times.empty()) return none;
  if (t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  const size_t k = key_interval(times, t);
  const double s = (t - times[k]) / (times[k + 1] - times[k]);
  return (1 - s) * values[k] + s * values[k + 1];
}

}  // namespace

WindKeySeries wind_key_series(const std::vector<WindKey>& keys) {
  WindKeySeries series;
  for (const WindKey& k : keys) {
    series.time.push_back(k.time);
    series.wind.push_back(k.speed * k.direction);
    series.gust.push_back(k.gust);
  }
  return series;
}

size_t key_interval(const std::vector<double>& times, double t) {
  size_t lo = 0, hi = times.size() - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    (times[mid] <= t ? lo : hi) = mid;
  }
  return lo;
}

Eigen::Vector3d key_mean_wind(const WindKeySeries& keys, double t) {
  return value_at<Eigen::Vector3d>(keys.time, keys.wind, t, Eigen::Vector3d::Zero());
}

double key_gust_amplitude(const WindKeySeries& keys, double t) { return value_at(keys.time, keys.gust, t, 0.0); }

WindSeam wind_loop_seam(const WindOptions& wind, double start, double period) {
  const WindKeySeries keys = wind_key_series(wind.keys);
  WindSeam seam;
  seam.first = key_mean_wind(keys, start);
  seam.last = key_mean_wind(keys, start + period);
  seam.first_gust = key_gust_amplitude(keys, start);
  seam.last_gust = key_gust_amplitude(keys, start + period);
  const double tolerance = 1e-9 * std::max(1.0, seam.first.norm() + seam.first_gust);
  seam.periodic = !((seam.first - seam.last).norm() > tolerance || std::fabs(seam.first_gust - seam.last_gust) > tolerance);
  return seam;
}

}  // namespace treeanim
