// WindField: a looping wind repeats exactly with its period, everywhere (mean, gusts and the
// advected turbulence); without a loop the field is what it was.
#include <gtest/gtest.h>

#include <vector>

#include "sim/wind.h"

namespace treeanim {
namespace {

WindOptions gusty_wind() {
  WindOptions wind;
  wind.keys = {{0.0, 8.0, Eigen::Vector3d(1, 0, 0.3).normalized(), 3.0},
               {4.0, 5.0, Eigen::Vector3d(1, 0, -0.2).normalized(), 2.0},
               {10.0, 8.0, Eigen::Vector3d(1, 0, 0.3).normalized(), 3.0}};
  wind.seed = 11;
  return wind;
}

// The air velocity at x and t: mean and gust, plus turbulence.
Eigen::Vector3d air(const WindField& field, const Eigen::Vector3d& x, double t) {
  std::vector<double> sa(size_t(field.mode_count())), ca(sa.size()), sb(sa.size()), cb(sa.size());
  field.spatial_phases(x, sa.data(), ca.data());
  const double scale = field.temporal_phases(t, sb.data(), cb.data());
  return field.base(t) + field.turbulence(sa.data(), ca.data(), sb.data(), cb.data(), scale);
}

TEST(Wind, ALoopRepeatsWithItsPeriodEverywhere) {
  WindOptions options = gusty_wind();
  options.loop_start = 0.5;
  options.loop_period = 9.5;  // the keys' wind at 0.5 s and 10 s differ: the loop still wraps
  const WindField field(options);
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(3.3, 7.1, -2.4)}) {
    for (const double t : {0.5, 1.37, 6.02, 9.99}) {
      const Eigen::Vector3d once = air(field, x, t);
      for (const int periods : {1, 3, 40}) {
        const Eigen::Vector3d later = air(field, x, t + periods * options.loop_period);
        EXPECT_LT((later - once).norm(), 1e-9 * (1 + periods)) << "t " << t << " periods " << periods;
      }
    }
  }
  // Not a constant: the loop still has gusts and turbulence.
  EXPECT_GT((air(field, Eigen::Vector3d(0, 1, 0), 1.0) - air(field, Eigen::Vector3d(0, 1, 0), 2.0)).norm(), 0.1);
}

TEST(Wind, WithoutALoopTheFieldDoesNotRepeat) {
  const WindField field(gusty_wind());
  const Eigen::Vector3d x(0, 1, 0);
  EXPECT_GT((air(field, x, 1.0) - air(field, x, 1.0 + 9.5)).norm(), 1e-3);
}

}  // namespace
}  // namespace treeanim
