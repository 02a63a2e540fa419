#pragma once
// The wind's keys as time series (docs/scene.md `wind`): the mean wind speed * direction and
// the gust amplitude, linear between keys and held before the first and after the last key.
// WindField reads them; so does the scene's loop check, which needs no field.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "sim/sim_options.h"

namespace treeanim {

struct WindKeySeries {
  std::vector<double> time;           // (K) s, strictly increasing
  std::vector<Eigen::Vector3d> wind;  // (K) m/s, speed * direction
  std::vector<double> gust;           // (K) m/s, gust amplitude along the wind
};

// keys => their series.
WindKeySeries wind_key_series(const std::vector<WindKey>& keys);
// times (K >= 2), t within them => k of the key interval [k, k+1) holding t.
size_t key_interval(const std::vector<double>& times, double t);
// series, t (s) => the mean wind at t (m/s); zero without keys.
Eigen::Vector3d key_mean_wind(const WindKeySeries& keys, double t);
// series, t (s) => the gust amplitude at t (m/s); 0 without keys.
double key_gust_amplitude(const WindKeySeries& keys, double t);

// The keys' wind at both ends of a loop (time.loop), before it is made periodic.
struct WindSeam {
  Eigen::Vector3d first = Eigen::Vector3d::Zero();  // m/s, mean wind at the loop's start
  Eigen::Vector3d last = Eigen::Vector3d::Zero();   // m/s, mean wind at its end
  double first_gust = 0, last_gust = 0;             // m/s, gust amplitudes there
  bool periodic = false;  // both equal within 1e-9 of the wind's size: the wind can repeat
};

// wind options, loop start and period (s) => the wind at the seam and whether it can be made
// periodic over the loop.
WindSeam wind_loop_seam(const WindOptions& wind, double start, double period);

}  // namespace treeanim
