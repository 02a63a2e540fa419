// /hsm and /wind readers (scene/sim_sections.h), the wind CSV and the wind field.
#include <unistd.h>

#include <gtest/gtest.h>

#include <fstream>

#include "common/errors.h"
#include "scene/sim_sections.h"
#include "sim/wind.h"
#include "input_error_of.h"

namespace treeanim {
namespace {

HsmOptions read_hsm(Json document) {
  SceneReader reader(document, "/scenes", "s.json");
  HsmOptions o = read_hsm_options(reader.root().object("hsm"));
  reader.check_unknown_keys();
  return o;
}

WindOptions read_wind(Json document, const std::filesystem::path& dir = "/scenes") {
  SceneReader reader(document, dir, "s.json");
  WindOptions o = read_wind_options(reader.root().object("wind"), 42);
  reader.check_unknown_keys();
  return o;
}

TEST(HsmOptions, DefaultsAreFilledIn) {
  Json document = Json::object();
  SceneReader reader(document, "/scenes", "s.json");
  const HsmOptions o = read_hsm_options(reader.root().object("hsm"));
  EXPECT_EQ(o.stiffness, StiffnessMode::kPhysical);
  EXPECT_TRUE(o.global_matching);
  EXPECT_TRUE(o.sleep);
  EXPECT_EQ(o.leaf_detach_force, 0);
  EXPECT_EQ(document["hsm"]["stiffness"], "physical");
  EXPECT_EQ(document["hsm"]["youngs_modulus"], 8e9);
  EXPECT_EQ(o.precision, Precision::kDouble);
  EXPECT_EQ(document["hsm"]["precision"], "double");
}

TEST(HsmOptions, ReadsPrecision) {
  EXPECT_EQ(read_hsm(Json::parse(R"({"hsm": {"precision": "float"}})")).precision, Precision::kFloat);
  EXPECT_EQ(read_hsm(Json::parse(R"({"hsm": {"precision": "double"}})")).precision, Precision::kDouble);
  const std::string error = input_error_of([] { read_hsm(Json::parse(R"({"hsm": {"precision": "half"}})")); });
  EXPECT_NE(error.find("/hsm/precision"), std::string::npos) << error;
  EXPECT_NE(error.find("\"float\""), std::string::npos) << error;
}

TEST(HsmOptions, ReadsParticles) {
  EXPECT_EQ(read_hsm(Json::parse(R"({"hsm": {}})")).particles, ParticleMode::kVertices);
  EXPECT_EQ(read_hsm(Json::parse(R"({"hsm": {"particles": "samples"}})")).particles, ParticleMode::kSamples);
  EXPECT_EQ(read_hsm(Json::parse(R"({"hsm": {"particles": "vertices"}})")).particles, ParticleMode::kVertices);
  const std::string error = input_error_of([] { read_hsm(Json::parse(R"({"hsm": {"particles": "foo"}})")); });
  EXPECT_NE(error.find("/hsm/particles: expected one of \"vertices\", \"samples\", got \"foo\""), std::string::npos)
      << error;
}

TEST(HsmOptions, ACapBelowTheDefaultFloorTakesTheFloorDown) {
  Json document = Json::parse(R"({"hsm": {"max_limb_frequency": 1}})");
  SceneReader reader(document, "/scenes", "s.json");
  const HsmOptions o = read_hsm_options(reader.root().object("hsm"));
  EXPECT_EQ(o.max_limb_frequency, 1);
  EXPECT_EQ(o.min_limb_frequency, 1);
  EXPECT_EQ(document["hsm"]["min_limb_frequency"], 1);  // the resolved scene reads back
  EXPECT_EQ(read_hsm(Json::parse(R"({"hsm": {"max_limb_frequency": 30}})")).min_limb_frequency, 1.25);
  EXPECT_EQ(
      input_error_of([] { read_hsm(Json::parse(R"({"hsm": {"max_limb_frequency": 1, "min_limb_frequency": 2}})")); }),
      "s.json: /hsm/min_limb_frequency: the floor 2 rad/s is above max_limb_frequency, 1 rad/s: expected a "
      "floor at or below the cap");
}

TEST(HsmOptions, RefusesTheKeysOfTheOtherStiffnessMode) {
  EXPECT_EQ(input_error_of([] { read_hsm(Json::parse(R"({"hsm": {"alpha": 0.3}})")); }),
            "s.json: /hsm/alpha: expected no alpha where stiffness is \"physical\" (alpha is read by "
            "\"stiffness\": \"per_step\" alone), got 0.3");
  EXPECT_EQ(
      input_error_of([] { read_hsm(Json::parse(R"({"hsm": {"stiffness": "per_step", "min_limb_frequency": 2}})")); }),
      "s.json: /hsm/min_limb_frequency: expected no min_limb_frequency where stiffness is \"per_step\" "
      "(min_limb_frequency is read by \"stiffness\": \"physical\" alone), got 2");
  for (const std::string mode : {"physical", "per_step"})
    for (const std::string key : {"k_d", "global_scale", "max_frequency", "max_limb_frequency"}) {
      const bool physical_key = key != "k_d";
      if (physical_key == (mode == "physical")) continue;
      const std::string error = input_error_of(
          [&] { read_hsm(Json::parse(R"({"hsm": {"stiffness": ")" + mode + R"(", ")" + key + R"(": 0.5}})")); });
      EXPECT_NE(error.find("/hsm/" + key + ": expected no " + key), std::string::npos) << error;
    }
  // null takes the default, as anywhere; the resolved scene holds its own mode's keys alone, so
  // it reads back.
  Json document = Json::parse(R"({"hsm": {"stiffness": "per_step", "global_scale": null}})");
  SceneReader reader(document, "/scenes", "s.json");
  EXPECT_EQ(read_hsm_options(reader.root().object("hsm")).stiffness, StiffnessMode::kPerStep);
  EXPECT_TRUE(document["hsm"].contains("alpha"));
  EXPECT_FALSE(document["hsm"].contains("max_frequency"));
  Json physical = Json::parse(R"({"hsm": {}})");
  SceneReader physical_reader(physical, "/scenes", "s.json");
  (void)read_hsm_options(physical_reader.root().object("hsm"));
  EXPECT_TRUE(physical["hsm"].contains("max_frequency"));
  EXPECT_FALSE(physical["hsm"].contains("alpha"));
  EXPECT_FALSE(physical["hsm"].contains("k_d"));
}

TEST(HsmOptions, ReadsPerStepStiffness) {
  const HsmOptions o = read_hsm(Json::parse(R"({"hsm": {"stiffness": "per_step", "alpha": 0.3, "k_d": 0.05,
                                                       "global_matching": false, "sleep": false}})"));
  EXPECT_EQ(o.stiffness, StiffnessMode::kPerStep);
  EXPECT_EQ(o.alpha, 0.3);
  EXPECT_EQ(o.k_d, 0.05);
  EXPECT_FALSE(o.global_matching);
  EXPECT_FALSE(o.sleep);
}

TEST(HsmOptions, RejectsOutOfRangeAndUnknownKeys) {
  EXPECT_EQ(input_error_of([] { read_hsm(Json::parse(R"({"hsm": {"stiffness": "per_step", "alpha": 1.5}})")); }),
            "s.json: /hsm/alpha: expected a number in [0, 1], got 1.5");
  EXPECT_NE(input_error_of([] {
              read_hsm(Json::parse(R"({"hsm": {"stifness": "physical"}})"));
            }).find("did you mean /hsm/stiffness"),
            std::string::npos);
  EXPECT_NE(input_error_of([] { read_hsm(Json::parse(R"({"hsm": {"stiffness": "soft"}})")); }).find("\"per_step\""),
            std::string::npos);
}

TEST(WindOptions, ReadsKeysAndNormalisesDirections) {
  const WindOptions o = read_wind(Json::parse(R"({"wind": {"keys": [
      {"time": 0, "speed": 5, "direction": [2, 0, 0]},
      {"time": 2, "speed": 10, "direction": [0, 0, 3], "gust": 2}]}})"));
  ASSERT_EQ(o.keys.size(), 2u);
  EXPECT_EQ(o.keys[0].direction, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(o.keys[1].direction, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(o.keys[1].gust, 2);
  EXPECT_EQ(o.seed, 42u);  // the scene seed by default
}

TEST(WindOptions, RejectsBadKeys) {
  EXPECT_EQ(input_error_of([] { read_wind(Json::parse(R"({"wind": {"keys": [{"time": 1}, {"time": 1}]}})")); }),
            "s.json: /wind/keys/1/time: time 1 must be greater than the previous key's time 1");
  EXPECT_EQ(input_error_of([] { read_wind(Json::parse(R"({"wind": {"keys": [{"direction": [0, 0, 0]}]}})")); }),
            "s.json: /wind/keys/0/direction: expected a non-zero vector");
  EXPECT_EQ(input_error_of([] { read_wind(Json::parse(R"({"wind": {"keys": [{"speed": -1}]}})")); }),
            "s.json: /wind/keys/0/speed: expected a number in [0, 113], got -1");
}

TEST(WindOptions, ReadsCsvFileRelativeToTheScene) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("treeanim_test_wind-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "gale.csv") << "time,speed,dx,dy,dz,gust\n# calm start\n0,0,1,0,0,0\n1.5, 12, 0,0,2, 3\n";
  const WindOptions o = read_wind(Json::parse(R"({"wind": {"file": "gale.csv"}})"), dir);
  ASSERT_EQ(o.keys.size(), 2u);
  EXPECT_EQ(o.keys[1].time, 1.5);
  EXPECT_EQ(o.keys[1].speed, 12);
  EXPECT_EQ(o.keys[1].direction, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(o.keys[1].gust, 3);
  EXPECT_NE(input_error_of([&] {
              read_wind(Json::parse(R"({"wind": {"file": "missing.csv"}})"), dir);
            }).find("cannot open wind file"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(WindCsv, ErrorsNameFileAndLine) {
  EXPECT_EQ(input_error_of([] { parse_wind_csv("t,speed,dx,dy,dz\n", "w.csv"); }),
            "w.csv:1: expected the header 'time,speed,dx,dy,dz' or 'time,speed,dx,dy,dz,gust', got 't,speed,dx,dy,dz'");
  EXPECT_EQ(input_error_of([] { parse_wind_csv("time,speed,dx,dy,dz\n0,1,1,0,0\n1,x,1,0,0\n", "w.csv"); }),
            "w.csv:3: column 'speed': expected a finite number, got 'x'");
  EXPECT_EQ(input_error_of([] { parse_wind_csv("time,speed,dx,dy,dz\n0,1,1,0\n", "w.csv"); }),
            "w.csv:2: expected 5 comma-separated values, got 4");
  EXPECT_EQ(input_error_of([] { parse_wind_csv("time,speed,dx,dy,dz\n0,1,0,0,0\n", "w.csv"); }),
            "w.csv:2: columns 'dx,dy,dz': the direction must not be zero");
  EXPECT_EQ(input_error_of([] { parse_wind_csv("time,speed,dx,dy,dz\n2,1,1,0,0\n\n1,1,1,0,0\n", "w.csv"); }),
            "w.csv:4: time 1 must be greater than the previous key's time 2");
  EXPECT_EQ(input_error_of([] { parse_wind_csv("time,speed,dx,dy,dz\n", "w.csv"); }),
            "w.csv:1: expected at least one data line after the header");
}

// A direction whose norm overflows or underflows is still a direction, and a subnormal is a
// number; infinity is not.
TEST(WindCsv, DirectionsAndNumbersAtTheEndsOfTheDoubles) {
  const std::vector<WindKey> keys =
      parse_wind_csv("time,speed,dx,dy,dz\n0,5,1e300,1e300,0\n1,4e-320,0,1e-310,0\n", "w.csv");
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_TRUE(keys[0].direction.isApprox(Eigen::Vector3d(1, 1, 0).normalized()));
  EXPECT_EQ(keys[1].direction, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(keys[1].speed, 4e-320);
  EXPECT_EQ(input_error_of([] { parse_wind_csv("time,speed,dx,dy,dz\n0,1e999,1,0,0\n", "w.csv"); }),
            "w.csv:2: column 'speed': expected a finite number, got '1e999'");
}

TEST(WindField, InterpolatesAndHoldsAtTheEnds) {
  WindOptions o;
  o.keys = {{1, 2, {1, 0, 0}, 0}, {3, 6, {0, 1, 0}, 0}};
  const WindField wind(o);
  EXPECT_EQ(wind.mean(0), Eigen::Vector3d(2, 0, 0));
  EXPECT_EQ(wind.mean(1), Eigen::Vector3d(2, 0, 0));
  EXPECT_TRUE(wind.mean(2).isApprox(Eigen::Vector3d(1, 3, 0)));
  EXPECT_EQ(wind.mean(3), Eigen::Vector3d(0, 6, 0));
  EXPECT_EQ(wind.mean(10), Eigen::Vector3d(0, 6, 0));
  EXPECT_FALSE(wind.calm(10));
  EXPECT_TRUE(WindField(WindOptions{}).calm(0));
}

TEST(WindField, GustsStayWithinTheirAmplitude) {
  WindOptions o;
  o.keys = {{0, 10, {0, 0, 1}, 4}};
  o.turbulence_intensity = 0;
  const WindField wind(o);
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i < 10000; ++i) {
    const Eigen::Vector3d b = wind.velocity(Eigen::Vector3d(0, 1, 0), i * 0.01);
    EXPECT_EQ(b.x(), 0);
    lo = std::min(lo, b.z());
    hi = std::max(hi, b.z());
  }
  EXPECT_GE(lo, 6.0);
  EXPECT_LE(hi, 14.0);
  EXPECT_GT(hi - lo, 4.0);  // it does gust
}

TEST(WindField, TurbulenceIsSeededCoherentAndScaled) {
  WindOptions o;
  o.keys = {{0, 10, {1, 0, 0}, 0}};
  o.turbulence_intensity = 0.2;
  o.turbulence_length = 4;
  const WindField a(o), b(o);
  o.seed = 2;
  const WindField c(o);
  // Without gusts the air is the mean wind plus the turbulence.
  auto sample = [](const WindField& w, const Eigen::Vector3d& x, double t) {
    return Eigen::Vector3d(w.velocity(x, t) - w.mean(t));
  };
  const Eigen::Vector3d x(1, 2, 3);
  EXPECT_EQ(sample(a, x, 1.5), sample(b, x, 1.5));      // deterministic
  EXPECT_NE(sample(a, x, 1.5), sample(c, x, 1.5));      // seeded
  // Coherent: 5 cm apart the air moves alike; the rms over space is near intensity * speed.
  EXPECT_LT((sample(a, x, 1.5) - sample(a, x + Eigen::Vector3d(0.05, 0, 0), 1.5)).norm(), 0.2);
  double sum2 = 0;
  int n = 0;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      sum2 += sample(a, Eigen::Vector3d(i * 3.1, j * 2.3, i * 0.7), 0.3 * j).squaredNorm();
      ++n;
    }
  const double rms_per_component = std::sqrt(sum2 / n / 3);
  EXPECT_NEAR(rms_per_component, 0.2 * 10, 0.6);
  // Calm air has no turbulence.
  WindOptions still;
  EXPECT_EQ(sample(WindField(still), x, 1), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace treeanim
