// End to end: the built treeanim binary, its exit codes, messages and outputs.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <cstdlib>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "temp_folder_test.h"

namespace {

namespace fs = std::filesystem;

struct Result {
  int code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class Cli : public TempFolderTest {
 protected:
  Cli() : TempFolderTest("treeanim-cli") {}

  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  Result run(const std::string& args) {
    const std::string command = std::string(TREEANIM_BINARY) + " " + args + " >" +
                                (dir_ / "stdout").string() + " 2>" + (dir_ / "stderr").string();
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir_ / "stdout"), slurp(dir_ / "stderr")};
  }
};

// Three unit segments straight up, one bake output.
const char* kLine = R"({
  "lsystem": {"axiom": "FFF", "iterations": 0},
  "time": {"fps": 24, "frames": 5, "substeps": 2},
  "wind": {"keys": [{"time": 0, "speed": 4, "direction": [1, 0, 0]}]},
  "outputs": [{"format": "hdf5", "path": "bake.h5"}]
})";

TEST_F(Cli, VersionAndHelp) {
  Result r = run("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out.rfind("treeanim ", 0), 0u) << r.out;
  r = run("run --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("Examples:"), std::string::npos) << r.out;
}

TEST_F(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(run("--version extra").code, 2);
  EXPECT_EQ(run("extra --version").code, 2);
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("frobnicate x").code, 2);
  EXPECT_EQ(run("run").code, 2);
  EXPECT_EQ(run("run a.json --threads 0").code, 2);
}

TEST_F(Cli, MissingSceneExitsTwoWithThePath) {
  const Result r = run("run " + (dir_ / "nope.json").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find((dir_ / "nope.json").string() + ": cannot read the scene file (no such file)"),
            std::string::npos) << r.err;
}

TEST_F(Cli, BadSceneExitsTwoAndWritesNothing) {
  const fs::path scene = write("bad.json", R"({"lsystem": {"axiom": "F"}, "time": {"fsp": 3},
    "outputs": [{"format": "hdf5", "path": "bake.h5"}]})");
  const Result r = run("run " + scene.string() + " -o " + (dir_ / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/time/fsp: unknown key (did you mean /time/fps?)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(Cli, InfoJsonGivesExactSkeletonCounts) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("info --json " + scene.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const auto info = nlohmann::json::parse(r.out);
  EXPECT_EQ(info["derivation"]["modules"], 3);
  EXPECT_EQ(info["derivation"]["iterations"], 0);
  EXPECT_EQ(info["skeleton"]["segments"], 3);
  EXPECT_EQ(info["skeleton"]["leaves"], 0);
  EXPECT_NEAR(info["skeleton"]["total_length"].get<double>(), 3.0, 1e-12);
  EXPECT_NEAR(info["skeleton"]["bbox_max"][1].get<double>(), 3.0, 1e-12);
  EXPECT_NEAR(info["skeleton"]["bbox_min"][1].get<double>(), 0.0, 1e-12);
  EXPECT_GT(info["mesh"]["vertices"].get<long long>(), 0);
  EXPECT_EQ(info["estimate"]["bytes_per_frame"], info["mesh"]["vertices"].get<long long>() * 12);
  for (const char* key : {"triangles"}) EXPECT_TRUE(info["mesh"].contains(key));
  for (const char* key : {"clusters", "memberships", "mass_kg"}) EXPECT_TRUE(info["model"].contains(key));
}

// Each output's estimate: 12 bytes a vertex and frame for the HDF5 positions, the USD text's
// ~36 characters a point, ~96 a joint skinned (output/output_formats.cpp).
TEST_F(Cli, InfoEstimatesEachOutput) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("info --json " + scene.string() +
                       R"( --set 'outputs=[{"format": "hdf5", "path": "b.h5"}, {"format": "usd", "path": "t.usda"},)"
                       R"( {"format": "usd", "path": "s.usda", "skinned": true}]')");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto info = nlohmann::json::parse(r.out);
  const auto& outputs = info["estimate"]["outputs"];
  ASSERT_EQ(outputs.size(), 3u);
  const double vertices = info["mesh"]["vertices"].get<double>(), triangles = info["mesh"]["triangles"].get<double>(),
               joints = info["model"]["clusters"].get<double>();
  EXPECT_EQ(outputs[0]["format"], "hdf5");
  EXPECT_EQ(outputs[0]["bytes"].get<double>(), 5 * 12 * vertices + 36 * vertices + 12 * triangles + 32768);
  EXPECT_EQ(outputs[1]["path"], "t.usda");
  const double usd_mesh = 40 * vertices + 36 * triangles;
  EXPECT_EQ(outputs[1]["bytes"].get<double>(), 5 * 36 * vertices + usd_mesh);
  EXPECT_EQ(outputs[2]["bytes"].get<double>(), 5 * 96 * joints + usd_mesh + 24 * vertices + 320 * joints);
}

// validate refuses what run refuses before it simulates, each writer's own limits too (it said
// OK to a VAT narrower than a frame, a page under its max_mib and a GLB past 4 GiB).
TEST_F(Cli, ValidateMeetsTheWritersLimits) {
  const std::string demo = std::string(TREEANIM_SOURCE_DIR) + "/configs/demo.json";
  const struct {
    const char* options;
    int code;
    const char* message;
  } cases[] = {
      {R"(--set 'outputs=[{"format": "vat", "path": "v.exr", "texture_width": 1}]')", 2,
       "/outputs/0/texture_width: 1 texels a row put a frame's 9797 vertices on 9797 rows, over 8192; expected at "
       "least 2 (or 0: as wide as the vertices)"},
      {R"(--set 'outputs=[{"format": "html", "path": "p.html", "max_mib": 2}]' --set tree.ring_sides=64)", 2,
       "/outputs/0/max_mib: the page needs"},
      {R"(--set time.frames=200000 --set 'outputs=[{"format": "glb", "path": "big.glb"}]')", 2,
       "/outputs/0: the animated GLB "},
      {R"(--set time.frames=200000 --set 'outputs=[{"format": "skinned_glb", "path": "big.glb"}]')", 2,
       "/outputs/0: the skinned GLB "},
  };
  for (const auto& c : cases) {
    for (const std::string& command : {std::string("validate "), "run --no-space-check -o " + (dir_ / "out").string() + " "}) {
      const Result r = run(command + demo + " " + c.options);
      EXPECT_EQ(r.code, c.code) << command << c.options << ": " << r.err;
      EXPECT_NE(r.err.find(c.message), std::string::npos) << command << c.options << ": " << r.err;
    }
    EXPECT_FALSE(fs::exists(dir_ / "out")) << c.options;
  }
}

// What the free-space check and farm plan count against what a bake writes, for every format:
// the demo tree for two frames (where what is written once weighs most) and for eight. An
// estimate short of the bytes lets a bake start that its disk cannot hold.
TEST_F(Cli, EstimatesAreCloseToTheBytesWritten) {
  const std::string demo = std::string(TREEANIM_SOURCE_DIR) + "/configs/demo.json";
  for (const char* output : {R"({"format": "hdf5", "path": "o.h5"})", R"({"format": "obj", "path": "f%04d.obj"})",
                             R"({"format": "obj", "path": "n%04d.obj", "normals": true})",
                             R"({"format": "gltf", "path": "g%04d.glb"})", R"({"format": "glb", "path": "o.glb"})",
                             R"({"format": "pc2", "path": "o.pc2"})", R"({"format": "mdd", "path": "o.mdd"})",
                             R"({"format": "vat", "path": "o.exr"})", R"({"format": "skinned_glb", "path": "s.glb"})",
                             R"({"format": "usd", "path": "o.usda"})",
                             R"({"format": "usd", "path": "s.usda", "skinned": true})",
                             R"({"format": "html", "path": "o.html"})"})
    for (int frames : {2, 8}) {
      const std::string options =
          demo + " --set time.frames=" + std::to_string(frames) + " --set 'outputs=[" + output + "]'";
      Result r = run("info --json " + options);
      ASSERT_EQ(r.code, 0) << r.err;
      const double estimate = nlohmann::json::parse(r.out)["estimate"]["outputs"][0]["bytes"].get<double>();
      const fs::path out = dir_ / ("out-" + std::to_string(frames));
      fs::remove_all(out);
      r = run("run " + options + " -o " + out.string() + " --quiet");
      ASSERT_EQ(r.code, 0) << r.err;
      double written = 0;
      for (const auto& file : fs::recursive_directory_iterator(out))
        if (file.is_regular_file()) written += double(file.file_size());
      EXPECT_GE(estimate, 0.95 * written) << output << ", " << frames << " frames";
      EXPECT_LE(estimate, 1.7 * written) << output << ", " << frames << " frames";
    }
}

// A cpfg object (tests/data/cpfg): plant.v names leaf.s for ~l, a 3 x 2-quad patch of 12 points
// and 12 triangles; four leaves on a stem of two segments (25 vertices, 40 triangles).
TEST_F(Cli, ViewFileSurfaceIsTheLeafShapeAndBakes) {
  const std::string object = std::string(TREEANIM_SOURCE_DIR) + "/tests/data/cpfg/";
  const fs::path scene = write("plant.json", R"({"lsystem": {"grammar": ")" + object + R"(plant.l", "view": ")" + object +
                                                 R"(plant.v"}, "time": {"frames": 3, "substeps": 1},
    "wind": {"keys": [{"time": 0, "speed": 6, "direction": [1, 0, 0]}]},
    "outputs": [{"format": "hdf5", "path": "bake.h5"}]})");
  Result r = run("info --json " + scene.string());
  ASSERT_EQ(r.code, 0) << r.err;
  auto info = nlohmann::json::parse(r.out);
  EXPECT_EQ(info["skeleton"]["leaves"], 4);
  EXPECT_EQ(info["model"]["leaf_clusters"], 4);
  EXPECT_EQ(info["mesh"]["vertices"], 25 + 4 * 12);
  EXPECT_EQ(info["mesh"]["triangles"], 40 + 4 * 12);
  r = run("info --json " + scene.string() + " --set lsystem.surface_precision=1");  // one quad a patch
  ASSERT_EQ(r.code, 0) << r.err;
  info = nlohmann::json::parse(r.out);
  EXPECT_EQ(info["mesh"]["vertices"], 25 + 4 * 4);
  r = run("run " + scene.string() + " -o " + (dir_ / "out").string() + " --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out/bake.h5"));
}

// info gives the figures of a bake: of one that run would refuse, it says why instead.
TEST_F(Cli, InfoRefusesOutputsThatValidateRefuses) {
  const fs::path scene = write("line.json", kLine);
  const std::string twice = " --set 'outputs.1={\"format\": \"hdf5\", \"path\": \"bake.h5\"}'";
  for (const char* command : {"validate ", "info ", "info --json "}) {
    const Result r = run(command + scene.string() + twice);
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_NE(r.err.find("bake.h5"), std::string::npos) << command << r.err;
  }
  EXPECT_EQ(run("info " + scene.string()).code, 0);
}

// The job scripts name the scene on comment lines, where a line break would start a command.
TEST_F(Cli, FarmScriptsRefuseALineBreakInAPath) {
  const std::string forest = R"({"lsystem": {"axiom": "F", "iterations": 0}, "time": {"frames": 2},
    "forest": {"trees": [{}]}, "outputs": [{"format": "hdf5", "path": "{tree}.h5"}]})";
  const fs::path scene = write("nl\ntouch injected\n.json", forest);
  const Result r = run("farm submit '" + scene.string() + "' --engine script --tasks 1 -o " + (dir_ / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("nl\\x0atouch injected\\x0a.json holds a control character"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(Cli, SetOverridesASceneValue) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("info --json " + scene.string() + " --set lsystem.axiom=FFFFF");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["skeleton"]["segments"], 5);
}

TEST_F(Cli, ResolvedSceneHasDefaultsAndOverrides) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("info --resolved-scene " + scene.string() + " --set time.fps=30");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto resolved = nlohmann::json::parse(r.out);
  EXPECT_EQ(resolved["time"]["fps"], 30);
  EXPECT_EQ(resolved["time"]["frames"], 5);
  EXPECT_TRUE(resolved["tree"].contains("ring_sides"));
  EXPECT_TRUE(resolved["hsm"].contains("stiffness"));
}

TEST_F(Cli, ValidatePrintsOk) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("validate " + scene.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find(": OK"), std::string::npos) << r.out;
}

TEST_F(Cli, FramesOutsideTheSceneExitTwo) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("run " + scene.string() + " -o " + (dir_ / "out").string() + " --frames 3:9");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--frames '3:9': expected START:END with 0 <= START <= END <= 4"),
            std::string::npos) << r.err;
}

TEST_F(Cli, RunWritesTheBakeAndNoTemporaries) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("run " + scene.string() + " -o " + (dir_ / "out").string() + " --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("baked 5 frames"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "bake.h5"));
  for (const auto& entry : fs::directory_iterator(dir_ / "out"))
    EXPECT_EQ(entry.path().filename(), "bake.h5") << "left over: " << entry.path();
}

TEST_F(Cli, ASampledBakeAndInfoSayHowManySamplesMoveTheMesh) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("run " + scene.string() + " -o " + (dir_ / "out").string() +
                       " --set 'hsm.particles=\"samples\"'");
  ASSERT_EQ(r.code, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex(R"(baked 5 frames: (\d+) vertices simulated as (\d+) samples, )")))
      << r.out;
  EXPECT_LT(std::stoul(m[2]), std::stoul(m[1])) << r.out;
  EXPECT_EQ(run("run " + scene.string() + " -o " + (dir_ / "out2").string()).out.find("samples"), std::string::npos);
  // `info` says the same before a bake.
  const auto info = nlohmann::json::parse(run("info --json " + scene.string() + " --set 'hsm.particles=\"samples\"'").out);
  EXPECT_EQ(info["model"]["samples"].get<unsigned long>(), std::stoul(m[2]));
  EXPECT_FALSE(nlohmann::json::parse(run("info --json " + scene.string()).out)["model"].contains("samples"));
}

TEST_F(Cli, QuietPrintsNothing) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("run " + scene.string() + " -o " + (dir_ / "out").string() + " --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "");
}

TEST_F(Cli, LogModePrintsAboutEveryFivePercent) {
  const fs::path scene = write("line.json", kLine);
  const Result r = run("run " + scene.string() + " -o " + (dir_ / "out").string() +
                       " --set time.frames=40");
  ASSERT_EQ(r.code, 0) << r.err;
  size_t lines = 0;
  for (size_t at = r.err.find("progress:"); at != std::string::npos; at = r.err.find("progress:", at + 1)) ++lines;
  EXPECT_GE(lines, 15u) << r.err;
  EXPECT_LE(lines, 21u) << r.err;
  EXPECT_NE(r.err.find("progress: 100%"), std::string::npos) << r.err;
}

}  // namespace
