// WindField as one field over a forest: neighbours feel nearly the same air, a gust reaches a
// point downwind distance / speed later, points far apart across the wind differ; the field
// is finite in calm air and through reversals; a looping wind repeats exactly with its
// period, everywhere (mean, gusts and the advected turbulence).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "correlation.h"
#include "sim/wind.h"
#include "sim/wind_keys.h"

namespace treeanim {
namespace {

using testing::best_lag;
using testing::correlation;

WindOptions gusty_wind() {
  WindOptions wind;
  wind.keys = {{0.0, 8.0, Eigen::Vector3d(1, 0, 0.3).normalized(), 3.0},
               {4.0, 5.0, Eigen::Vector3d(1, 0, -0.2).normalized(), 2.0},
               {10.0, 8.0, Eigen::Vector3d(1, 0, 0.3).normalized(), 3.0}};
  wind.seed = 11;
  return wind;
}

// A forest's wind: 8 m/s along x with 3 m/s gusts and the default turbulence, except its length.
WindOptions forest_wind(double turbulence_length) {
  WindOptions wind;
  wind.keys = {{0.0, 8.0, Eigen::Vector3d(1, 0, 0), 3.0}};
  wind.turbulence_length = turbulence_length;
  wind.seed = 5;
  return wind;
}

// Air velocity at x sampled every dt from t = 0, n samples (m/s).
std::vector<Eigen::Vector3d> air_series(const WindField& field, const Eigen::Vector3d& x, double dt, int n) {
  std::vector<Eigen::Vector3d> series;
  for (int i = 0; i < n; ++i) series.push_back(field.velocity(x, i * dt));
  return series;
}

TEST(Wind, PointsOneMetreApartFeelNearlyTheSameAir) {
  // Over 60 s, with eddies of a forest's size (turbulence_length 16 m: an integral length of
  // 4.3 m, docs/solver.md "Wind and forces"), along and across the wind, as trees stand.
  const WindField field(forest_wind(16));
  const double dt = 1.0 / 24;
  const Eigen::Vector3d x(30, 4, -20);
  const std::vector<Eigen::Vector3d> here = air_series(field, x, dt, 60 * 24);
  for (const Eigen::Vector3d& step : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1)}) {
    const double r = correlation(here, air_series(field, x + step, dt, 60 * 24));
    EXPECT_GT(r, 0.95) << "1 m along " << step.transpose();
    RecordProperty(step.x() > 0 ? "correlation_1m_along" : "correlation_1m_across", std::to_string(r));
  }
}

TEST(Wind, FourPointsInLanesGetEachPointsOwnBits) {
  // The step samples its clusters' air four at a time (WindField::velocities): each lane must be
  // velocity()'s value for that point to the bit, in gusts, turbulence, calm and a step's averages.
  for (const WindOptions& options : {gusty_wind(), forest_wind(4), WindOptions{}}) {
    const WindField field(options);
    const int P = field.phase_count();
    std::vector<double> sin_a(4 * size_t(P) + 1), cos_a(4 * size_t(P) + 1);
    for (int l = 0; l < 4; ++l)
      field.spatial_phases(Eigen::Vector3d(3.7 * l - 5, 0.9 * l, 11.0 - 6.3 * l), &sin_a[size_t(l * P)],
                           &cos_a[size_t(l * P)]);
    const double* sin_lanes[4] = {&sin_a[0], &sin_a[size_t(P)], &sin_a[size_t(2 * P)], &sin_a[size_t(3 * P)]};
    const double* cos_lanes[4] = {&cos_a[0], &cos_a[size_t(P)], &cos_a[size_t(2 * P)], &cos_a[size_t(3 * P)]};
    for (const double t : {0.0, 0.37, 2.5, 7.125}) {
      for (const double window : {0.0, 1.0 / 48}) {
        AirSample air;
        field.sample_time(t, window, air);
        double v[3][4];
        field.velocities(sin_lanes, cos_lanes, air, v);
        for (int l = 0; l < 4; ++l) {
          const Eigen::Vector3d one = field.velocity(sin_lanes[l], cos_lanes[l], air);
          for (int i = 0; i < 3; ++i)
            EXPECT_EQ(std::memcmp(&v[i][l], &one[i], sizeof(double)), 0)
                << "t " << t << ", lane " << l << ", component " << i << ": " << v[i][l] << " against " << one[i];
        }
      }
    }
  }
}

TEST(Wind, AGustReachesAPointDownwindDistanceOverSpeedLater) {
  // Without turbulence the air is the mean wind plus the gust along it: 100 m downwind the
  // gust signal is the upwind one 100 m / 8 m/s = 12.5 s later, whatever the wind's heading.
  WindOptions options = forest_wind(4);
  options.turbulence_intensity = 0;
  const Eigen::Vector3d heading = Eigen::Vector3d(1, 0, 0.6).normalized();
  options.keys = {{0.0, 8.0, heading, 3.0}};
  const WindField field(options);
  const double dt = 1.0 / 24, lag = 100 / 8.0;
  const Eigen::Vector3d upwind(-40, 5, 12), downwind = upwind + 100 * heading;
  for (const double t : {0.0, 3.7, 61.0, 1e4})
    EXPECT_NEAR((field.velocity(downwind, t + lag) - field.velocity(upwind, t)).norm(), 0, 1e-9) << "t " << t;
  // The cross-correlation over 120 s peaks at the lag, to the sample.
  const std::vector<Eigen::Vector3d> a = air_series(field, upwind, dt, 120 * 24),
                                     b = air_series(field, downwind, dt, 120 * 24);
  const size_t best = best_lag(a, b, 0, 30 * 24);
  EXPECT_EQ(best, size_t(std::lround(lag / dt)));
  EXPECT_GT(correlation(a, b, 0, best), 0.999);
  EXPECT_LT(correlation(a, b), 0.9);  // not simply the same gust everywhere
  RecordProperty("lag_s", std::to_string(double(best) * dt));
}

TEST(Wind, PointsAHundredMetresApartAcrossTheWindDiffer) {
  // Eddies of the default 4 m and gust fronts tilted by up to 45 degrees: across the wind
  // 100 m apart, the air velocities are uncorrelated, averaged over seeds.
  double sum = 0;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    WindOptions options = forest_wind(4);
    options.seed = seed;
    const WindField field(options);
    const Eigen::Vector3d x(10, 3, 0);
    const double r = correlation(air_series(field, x, 1.0 / 24, 60 * 24),
                                 air_series(field, x + Eigen::Vector3d(0, 0, 100), 1.0 / 24, 60 * 24));
    EXPECT_LT(std::fabs(r), 0.5) << "seed " << seed;
    sum += r;
  }
  EXPECT_LT(std::fabs(sum / 8), 0.15);
  RecordProperty("correlation_100m_across", std::to_string(sum / 8));
}

TEST(Wind, FiniteAndContinuousInCalmAirAndThroughAReversal) {
  // Calm before, a gale that turns round through still air, calm after; far from the origin.
  WindOptions options;
  options.keys = {{1.0, 0.0, Eigen::Vector3d(1, 0, 0), 0.0},
                  {3.0, 20.0, Eigen::Vector3d(1, 0, 0), 6.0},
                  {5.0, 20.0, Eigen::Vector3d(-1, 0, 0.1).normalized(), 6.0},
                  {7.0, 0.0, Eigen::Vector3d(0, 0, 1), 0.0}};
  const WindField field(options);
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(5e3, 10, -7e3)}) {
    EXPECT_EQ(field.velocity(x, 0.5), Eigen::Vector3d::Zero());
    EXPECT_EQ(field.velocity(x, 1e6), Eigen::Vector3d::Zero());
    Eigen::Vector3d previous = field.velocity(x, 0);
    for (int i = 1; i <= 80000; ++i) {
      const Eigen::Vector3d v = field.velocity(x, i * 1e-4);
      ASSERT_TRUE(v.allFinite()) << "t " << i * 1e-4;
      // Continuous but where the mean wind is still (t = 4 s: the gust's direction turns round).
      if (std::fabs(i * 1e-4 - 4) > 0.01) {
        EXPECT_LT((v - previous).norm(), 0.5) << "t " << i * 1e-4;
      }
      previous = v;
    }
  }
}

TEST(Wind, ALoopRepeatsWithItsPeriodEverywhere) {
  WindOptions options = gusty_wind();
  options.loop_start = 0.5;
  options.loop_period = 9.5;  // the keys' wind at 0.5 s and 10 s differ: the loop still wraps
  const WindField field(options);
  for (const Eigen::Vector3d& x :
       {Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(3.3, 7.1, -2.4), Eigen::Vector3d(-250, 4, 310)}) {
    for (const double t : {0.5, 1.37, 6.02, 9.99}) {
      const Eigen::Vector3d once = field.velocity(x, t);
      for (const int periods : {1, 3, 40}) {
        const Eigen::Vector3d later = field.velocity(x, t + periods * options.loop_period);
        EXPECT_LT((later - once).norm(), 1e-9 * (1 + periods)) << "t " << t << " periods " << periods;
      }
    }
  }
  // Not a constant: the loop still has gusts and turbulence.
  const Eigen::Vector3d x(0, 1, 0);
  EXPECT_GT((field.velocity(x, 1.0) - field.velocity(x, 2.0)).norm(), 0.1);
}

// Windows of length h about t_k => (mean over windows of the variance of the air within a
// window (m/s)^2, summed over the axes; mean over windows of trace(AirSample::unresolved)).
std::pair<double, double> within_window_variance(const WindField& field, const Eigen::Vector3d& x, double h) {
  double measured = 0, modelled = 0;
  const int windows = 400, samples = 64;
  for (int k = 0; k < windows; ++k) {
    const double t = 0.37 * k + 1;
    std::vector<Eigen::Vector3d> air;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i = 0; i < samples; ++i) air.push_back(field.velocity(x, t + h * ((i + 0.5) / samples - 0.5)));
    for (const Eigen::Vector3d& a : air) mean += a / samples;
    for (const Eigen::Vector3d& a : air) measured += (a - mean).squaredNorm() / samples / windows;
    AirSample sample;
    field.sample_time(t, h, sample);
    modelled += sample.unresolved.trace() / windows;
  }
  return {measured, modelled};
}

TEST(Wind, WhatAStepAveragesOutIsTheVarianceWithinIt) {
  // The air's variance within a step, which the step's averages leave out (docs/solver.md,
  // "What a step cannot resolve"): none at a window of 0, all of the turbulence's at a window
  // far longer than its waves, and close to it between (the model is a Gaussian filter, the
  // step a box).
  WindOptions wind = forest_wind(4);
  wind.keys[0].gust = 0;
  wind.turbulence_intensity = 0.5;
  const WindField field(wind);
  const Eigen::Vector3d x(3, -2, 5);
  AirSample point;
  field.sample_time(2.0, 0, point);
  EXPECT_EQ(point.unresolved.trace(), 0);
  // The whole turbulent variance, from a long series at the point.
  const std::vector<Eigen::Vector3d> series = air_series(field, x, 0.01, 60000);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& a : series) mean += a / double(series.size());
  double total = 0;
  for (const Eigen::Vector3d& a : series) total += (a - mean).squaredNorm() / double(series.size());
  field.sample_time(2.0, 30, point);
  EXPECT_NEAR(point.unresolved.trace(), total, 0.1 * total);
  for (const double h : {0.1, 0.5}) {
    const auto [measured, modelled] = within_window_variance(field, x, h);
    EXPECT_GT(measured, 0.02 * total) << h;
    EXPECT_NEAR(modelled, measured, 0.2 * measured) << "window " << h << " s";
    RecordProperty("unresolved_at_" + std::to_string(h), std::to_string(modelled / measured));
  }
}

TEST(Wind, WithoutALoopTheFieldDoesNotRepeat) {
  const WindField field(gusty_wind());
  const Eigen::Vector3d x(0, 1, 0);
  EXPECT_GT((field.velocity(x, 1.0) - field.velocity(x, 1.0 + 9.5)).norm(), 1e-3);
}

// The loop check as scene/ made it on the field: mean wind and gusts of a WindField (not yet
// periodic) at both ends of the loop, equal within 1e-9 of the wind's size.
bool field_is_periodic(const WindOptions& wind, double start, double period) {
  const WindField field(wind);
  const Eigen::Vector3d first = field.mean(start), last = field.mean(start + period);
  const double first_gust = field.gust_amplitude(start), last_gust = field.gust_amplitude(start + period);
  const double tolerance = 1e-9 * std::max(1.0, first.norm() + first_gust);
  return !((first - last).norm() > tolerance || std::fabs(first_gust - last_gust) > tolerance);
}

TEST(Wind, TheLoopSeamOfTheKeysAgreesWithTheField) {
  const Eigen::Vector3d x(1, 0, 0), slanted = Eigen::Vector3d(1, 0, 0.3).normalized();
  struct Case {
    const char* name;
    std::vector<WindKey> keys;
    double start, period;
    bool periodic;
  };
  const Case cases[] = {
      {"calm", {}, 0.0, 5.0, true},
      {"one key", {{0.0, 6.0, x, 2.0}}, -3.0, 5.0, true},
      {"the same wind at both ends", gusty_wind().keys, 0.0, 10.0, true},
      {"a key between the ends", gusty_wind().keys, 0.0, 4.0, false},
      {"ends held past the keys", gusty_wind().keys, -2.0, 14.0, true},
      {"only the gusts differ", {{0.0, 6.0, x, 2.0}, {5.0, 6.0, x, 2.5}}, 0.0, 5.0, false},
      {"only the direction differs", {{0.0, 6.0, x, 0.0}, {5.0, 6.0, slanted, 0.0}}, 0.0, 5.0, false},
      {"within the tolerance", {{0.0, 6.0, x, 2.0}, {5.0, 6.0 + 1e-12, x, 2.0}}, 0.0, 5.0, true},
      {"just past the tolerance", {{0.0, 6.0, x, 2.0}, {5.0, 6.0 + 1e-7, x, 2.0}}, 0.0, 5.0, false},
      {"ends inside intervals", {{0.0, 4.0, x, 1.0}, {2.0, 8.0, x, 1.0}, {4.0, 4.0, x, 1.0}, {6.0, 8.0, x, 1.0}}, 1.0,
       4.0, true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    WindOptions wind;
    wind.keys = c.keys;
    const WindSeam seam = wind_loop_seam(wind, c.start, c.period);
    EXPECT_EQ(seam.periodic, c.periodic);
    EXPECT_EQ(seam.periodic, field_is_periodic(wind, c.start, c.period));
    const WindField field(wind);
    EXPECT_EQ(seam.first, field.mean(c.start));
    EXPECT_EQ(seam.last, field.mean(c.start + c.period));
    EXPECT_EQ(seam.first_gust, field.gust_amplitude(c.start));
    EXPECT_EQ(seam.last_gust, field.gust_amplitude(c.start + c.period));
  }
}

}  // namespace
}  // namespace treeanim
