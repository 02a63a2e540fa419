// cpfg view files (docs/scene.md "lsystem.view", CPFG manual 8.1) and the funcedit functions
// they name: files written for these tests in cpfg's style, in a folder of their own.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "temp_folder_test.h"
#include "common/errors.h"
#include "lsystem/view_file.h"

namespace treeanim {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, as a vlab object folder holds its .v and the files it names.
class ViewFile : public TempFolderTest {
 protected:
  ViewFile() : TempFolderTest("treeanim_view") {}

  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  // The test surface of tests/data/cpfg (one flat patch), copied in as `name`.
  void write_surface(const std::string& name) const {
    fs::copy_file(fs::path(TREEANIM_SOURCE_DIR) / "tests/data/cpfg/leaf.s", dir_ / name);
  }
  std::string error_of(const std::string& view_text) const {
    try {
      read_view_file(write("plant.v", view_text));
    } catch (const InputError& e) {
      std::string message = e.what();
      const std::string prefix = dir_.string() + "/";
      return message.rfind(prefix, 0) == 0 ? message.substr(prefix.size()) : message;
    }
    return "no error";
  }

};

// A funcedit function: y = x on [0, 1] (control points on a line give a line).
const char* kLinear = "fver 1 1\nname: grow\nsamples: 5\nflip: off\nrange: 0, 1\ntype: bspline\npoints: 4\n"
                      "0 0\n0.333333 0.333333\n0.666667 0.666667\n1 1\n";

TEST_F(ViewFile, ReadsTheSettingsThatShapeTheTreeAndPassesRenderingOnes) {
  write_surface("leaf.s");  // petal.s is missing: cpfg leaves that surface out
  const ViewSettings v = read_view_file(write("plant.v",
                                              "maximum depth: 10\nAngle increment: 22.5\ninitial color: 3\n"
                                              "initial line width: 0.4\nline width increment: 0.05\n"
                                              "viewpoint: 0,0,1\ntropism: T: 0,-1,0 E: 0.2\n"
                                              "surface: l leaf.s 1\nsurface: p petal.s 2 5\nlight: O: 1 1 1\n"));
  EXPECT_EQ(v.angle, 22.5);
  EXPECT_EQ(v.initial_width, 0.4);
  EXPECT_EQ(v.width_increment, 0.05);
  ASSERT_EQ(v.movements.size(), 1u);
  EXPECT_EQ(v.movements[0].direction, Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(v.movements[0].elasticity, 0.2);
  ASSERT_EQ(v.surfaces.size(), 1u);
  EXPECT_EQ(v.surfaces[0].id, 'l');
  EXPECT_EQ(v.surfaces[0].scale, 1.0);
  EXPECT_FALSE(v.surfaces[0].precision);
  EXPECT_EQ(v.surfaces[0].surface.patches.size(), 1u);
  EXPECT_EQ(v.surfaces[0].where, (dir_ / "plant.v").string() + ":8:1");
  EXPECT_TRUE(v.functions.empty());
}

// "surface: id file.s scale [i j] [texture]" (CPFG manual 8.1.5), read as cpfg reads it.
TEST_F(ViewFile, SurfaceLinesTakeScalePrecisionAndTheFirstOfAnId) {
  write_surface("leaf.s");
  const ViewSettings v = read_view_file(write("plant.v", "surface: a leaf.s 2 4 6\nsurface: b leaf.s 0 3\n"
                                                         "surface: c leaf.s 1.5 20 0.5 7\nsurface: a leaf.s 9\n"
                                                         "surface: d leaf.s 1 0 0\n"));
  ASSERT_EQ(v.surfaces.size(), 4u);
  EXPECT_EQ(v.surfaces[0].scale, 2.0);
  EXPECT_EQ(v.surfaces[0].precision, (std::array<int, 2>{4, 6}));
  EXPECT_EQ(v.surfaces[1].scale, 1.0);      // a scale <= 0 is 1, as in cpfg
  EXPECT_FALSE(v.surfaces[1].precision);    // one number after the scale is a texture
  EXPECT_FALSE(v.surfaces[2].precision);    // a count below 1 leaves the precision to the file
  EXPECT_EQ(v.surfaces[3].id, 'd');         // the second 'a' is left out: the first of an id counts
  EXPECT_FALSE(v.surfaces[3].precision);    // "0 0" leaves it to the file
}

// cpfg reads "line: id file.s scale" as a surface of that id (CPFG manual 8.1.5: its line
// type is never drawn); "tsurface:" is refused rather than left out.
TEST_F(ViewFile, LineIsASurfaceAndTsurfaceIsRefused) {
  write_surface("blade.s");
  const ViewSettings v = read_view_file(write("plant.v", "line: L blade.s 0.5\nsurface: L blade.s 9\n"));
  ASSERT_EQ(v.surfaces.size(), 1u);
  EXPECT_EQ(v.surfaces[0].id, 'L');
  EXPECT_EQ(v.surfaces[0].scale, 0.5);
  EXPECT_EQ(error_of("angle factor: 8\ntsurface: t leaf.ray 1\n"),
            "plant.v:2:1: 'tsurface:' (a surface of triangles in rayshade's format, CPFG manual 8.1.5, 8.4) is not "
            "supported; give the surface as a bezieredit '.s' file on a 'surface:' line");
}

TEST_F(ViewFile, AngleFactorDividesTheCircleAndWidthsInPixelsAreLeftOut) {
  const ViewSettings v = read_view_file(write("plant.v", "angle factor: 16\ninitial line width: 3 pixels\n"));
  EXPECT_EQ(v.angle, 22.5);
  EXPECT_FALSE(v.initial_width);
  EXPECT_FALSE(v.width_increment);
  EXPECT_TRUE(v.movements.empty());
}

TEST_F(ViewFile, FunctionFilesInBothFormatsAreFoundBesideTheViewFile) {
  write("grow.func", kLinear);
  write("old.func", std::string("range: 0, 1\npoints: 2\n0 1\n1 3\n"));  // the format before "fver"
  write("pair.fset", std::string("funcgalleryver 1 1\nitems: 2\n") + kLinear + "\n" + kLinear);  // both named "grow"
  const ViewSettings v = read_view_file(write("plant.v", "function: grow.func 5\nfunction: old.func\n"
                                                         "function set: pair.fset\n"));
  ASSERT_EQ(v.functions.size(), 4u);
  for (const SampledFunction& f : v.functions) ASSERT_GE(f.samples.size(), 3u);
  const std::vector<double>& linear = v.functions[0].samples;
  EXPECT_NEAR(linear.front(), 0.0, 1e-9);
  EXPECT_NEAR(linear[linear.size() / 2], 0.5, 1e-3);
  EXPECT_NEAR(linear.back(), 1.0, 1e-9);
  EXPECT_NEAR(v.functions[1].samples.front(), 1.0, 1e-9);
  EXPECT_NEAR(v.functions[1].samples.back(), 3.0, 1e-9);
  EXPECT_EQ(v.functions[2].samples, linear);
  EXPECT_EQ(v.functions[3].samples, linear);
  EXPECT_EQ(v.functions[0].name, "grow");
  EXPECT_EQ(v.functions[1].name, "");
}

TEST_F(ViewFile, ErrorsNameTheFileAndLine) {
  EXPECT_EQ(error_of("viewpoint: 0,0,1\nangle increment: wide\n"), "plant.v:2:1: expected a number after 'angle increment:'");
  EXPECT_EQ(error_of("angle factor: 0\n"), "plant.v:1:1: expected an 'angle factor:' of at least 1 in size (360 / it is the angle)");
  EXPECT_EQ(error_of("line width increment: nan\n"), "plant.v:1:1: expected a number after 'line width increment:'");
  EXPECT_EQ(error_of("\ntropism: T: 0,0,0 E: 1\n"), "plant.v:2:1: 'tropism:' expected a non-zero 'T:' vector (or E: and S: 0, no tropism)");
  EXPECT_EQ(error_of("tropism: T: 0,1,0 E: stiff\n"), "plant.v:1:1: 'tropism:' expected a number after 'E:'");
  EXPECT_EQ(error_of("surface: leaf leaf.s 1\n"), "plant.v:1:1: expected a one-letter surface id after 'surface:'");
  EXPECT_EQ(error_of("surface: l\n"), "plant.v:1:1: expected 'surface: id file.s scale' (the file name after the id)");
  EXPECT_EQ(error_of("surface: l leaf.s big\n"), "plant.v:1:1: expected 'surface: id file.s scale' (a number after the file name)");
  write("broken.s", "0 1 0 1 0 0\nCONTACT POINT X: 0 Y: 0\n");
  EXPECT_EQ(error_of("surface: l broken.s 1\n"),
            "broken.s:2:24: expected 'CONTACT POINT  X: x Y: y Z: z', got the end of the file");
  EXPECT_EQ(error_of("function: none.func\n"), "none.func: cannot read the function file (no such file)");
  write("bad.func", "fver 1 1\nname: f\npoints: 2\n0 0\n1\n");
  EXPECT_EQ(error_of("\n\nfunction: bad.func\n"), "bad.func:5:1: expected a point 'x y'");
  write("empty.func", "\n");
  EXPECT_EQ(error_of("function: empty.func\n"),
            "empty.func:2:1: expected a funcedit function starting with 'fver 1 1' (or 'range:' in the older format)");
  write("short.fset", "funcgalleryver 1 1\nitems: 2\n" + std::string(kLinear));
  EXPECT_EQ(error_of("function set: short.fset\n"),
            "short.fset:14:1: expected a funcedit function starting with 'fver 1 1' (or 'range:' in the older format)");
  write("noitems.fset", "funcgalleryver 1 1\n");
  EXPECT_EQ(error_of("function set: noitems.fset\n"), "noitems.fset:2:1: expected 'items: n' after 'funcgalleryver'");
}

// Several tropisms and torques (CPFG manual 8.1.8) as cpfg computes them: T made unit and scaled
// by the intensity clamp(I / |T|, -1, 1), A: as its cosine and sine (not for a torque), E:, S:.
TEST_F(ViewFile, TropismAndTorqueLinesInOrder) {
  const ViewSettings v = read_view_file(write("plant.v", "tropism: T: 0 2 0 E: 0.1\n"
                                                         "tropism: T: 0.0  0.0 1.0  A:90 I: 0.5 S: 0.05\n"
                                                         "torque: T: 1,0,0 A: 30 E: -0.2\n"
                                                         "tropism: T: 0 3 0 I: 6\n"
                                                         "tropism direction: 0,-2,0\ninitial elasticity: 0.15\n"
                                                         "elasticity increment: -0.06\ninitial scale: 0\nscale multiplier: 2\n"));
  ASSERT_EQ(v.movements.size(), 4u);
  EXPECT_FALSE(v.movements[0].torque);
  EXPECT_EQ(v.movements[0].direction, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(v.movements[0].cos_angle, 1.0);
  EXPECT_EQ(v.movements[0].sin_angle, 0.0);
  EXPECT_EQ(v.movements[0].elasticity, 0.1);
  EXPECT_EQ(v.movements[1].direction, Eigen::Vector3d(0, 0, 0.5));
  EXPECT_NEAR(v.movements[1].cos_angle, 0.0, 1e-15);
  EXPECT_EQ(v.movements[1].sin_angle, 1.0);
  EXPECT_EQ(v.movements[1].elasticity, 0.0);
  EXPECT_EQ(v.movements[1].step, 0.05);
  EXPECT_TRUE(v.movements[2].torque);
  EXPECT_EQ(v.movements[2].cos_angle, 1.0);  // A: means nothing to a torque
  EXPECT_EQ(v.movements[2].elasticity, -0.2);
  EXPECT_EQ(v.movements[3].direction, Eigen::Vector3d(0, 3, 0));  // I / |T| = 2, clamped to 1
  EXPECT_EQ(v.old_tropism, Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(v.initial_elasticity, 0.15);
  EXPECT_EQ(v.elasticity_increment, -0.06);
  EXPECT_EQ(v.initial_scale, 1.0);  // 0 reads as 1, as in cpfg
  EXPECT_EQ(v.scale_multiplier, 2.0);
}

// A subnormal number is a number (stod threw for it, and it was refused as none).
TEST_F(ViewFile, ATinyIntensityIsANumber) {
  const ViewSettings v = read_view_file(write("plant.v", "tropism: T: 0 1 0 I: 1e-320 E: 1\n"));
  ASSERT_EQ(v.movements.size(), 1u);
  EXPECT_GT(v.movements[0].direction.y(), 0.0);
  EXPECT_LT(v.movements[0].direction.y(), 1e-300);
}

// cpfg drops a tropism line it cannot read and goes on; here it is refused with its place.
TEST_F(ViewFile, MalformedTropismLinesAreRefused) {
  EXPECT_EQ(error_of("tropism: E: 0.2\n"), "plant.v:1:1: 'tropism:' expected 'T: x y z' (it is mandatory)");
  EXPECT_EQ(error_of("\ntorque: T: 0 1\n"), "plant.v:2:1: 'torque:' expected three numbers after 'T:'");
  EXPECT_EQ(error_of("tropism: T: 0 1 0 B: 2\n"), "plant.v:1:1: 'tropism:' expected a subcommand T: A: I: E: or S:, got 'B'");
  EXPECT_EQ(error_of("tropism: T: 0 1 0 0.5\n"), "plant.v:1:1: 'tropism:' expected a subcommand T: A: I: E: or S:, got '0.5'");
  EXPECT_EQ(error_of("tropism: T: 0 1 0 E: 1 E: 2\n"), "plant.v:1:1: 'tropism:' gives 'E:' twice");
  EXPECT_EQ(error_of("tropism: T: 0 1 0 A: 9x\n"), "plant.v:1:1: 'tropism:' expected a number after 'A:'");
  EXPECT_EQ(error_of("tropism: T: 0 1 0 I: 0 S: 0.1\n"),
            "plant.v:1:1: 'tropism:' expected a non-zero 'I:' (cpfg drops a line of intensity 0; with E: and S: 0 it bends nothing)");
  EXPECT_EQ(error_of("tropism: I: 2 T: 0 1 0\n"),
            "plant.v:1:1: 'tropism:' expected 'T:' before 'I:' (cpfg reads an intensity before the direction as 0 and drops the line)");
  EXPECT_EQ(error_of("tropism: T: 0 1 0 E:\n"), "plant.v:1:1: 'tropism:' expected a number after 'E:'");
  EXPECT_EQ(error_of("tropism direction: 0,1\n"), "plant.v:1:1: expected 'tropism direction: x,y,z' (three numbers)");
  EXPECT_EQ(error_of("initial elasticity: soft\n"), "plant.v:1:1: expected a number after 'initial elasticity:'");
  EXPECT_EQ(error_of("initial scale: big\n"), "plant.v:1:1: expected a number after 'initial scale:'");
}

// cpfg reads a zero tropism direction, or a tropism line of zero T: or I:, as no tropism while
// nothing makes it elastic: the old-style bend is skipped at elasticity 0 and the line is
// dropped (so the next line keeps cpfg's movement id). With an elasticity it would divide 0 by 0.
TEST_F(ViewFile, ZeroTropismWithoutElasticityIsNoTropism) {
  const ViewSettings v = read_view_file(write("plant.v", "tropism direction: 0.0,0.0,0.0\ninitial elasticity: 0\n"
                                                         "elasticity increment: 0.0\ntropism: T: 0,0,0 E: 0\n"
                                                         "tropism: T: 0 1 0 I: 0\ntorque: T: 0 0 0\n"
                                                         "tropism: T: 0 0 1 E: 0.2\n"));
  EXPECT_EQ(v.old_tropism, Eigen::Vector3d::Zero());
  EXPECT_EQ(v.initial_elasticity, 0.0);
  ASSERT_EQ(v.movements.size(), 1u);
  EXPECT_EQ(v.movements[0].direction, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(v.movements[0].elasticity, 0.2);
  EXPECT_EQ(error_of("tropism direction: 0,0,0\ninitial elasticity: 0.1\n"),
            "plant.v:1:1: expected a non-zero 'tropism direction:' with a non-zero 'initial elasticity:' or "
            "'elasticity increment:' (cpfg divides 0,0,0 by its length; with both 0 it is no tropism)");
  EXPECT_EQ(error_of("elasticity increment: 0.05\n\ntropism direction: 0 0 0\n").substr(0, 11), "plant.v:3:1");
  EXPECT_EQ(error_of("tropism: T: 0 0 0 S: 0.01\n"),
            "plant.v:1:1: 'tropism:' expected a non-zero 'T:' vector (or E: and S: 0, no tropism)");
}

// A cuspy curve file in cpfg's layout: a straight line from (0, 0) to (0, 3) (control points on
// a line, the ends tripled so that the B-spline reaches them).
const char* kLine = "version: 1.4\ncontact: 0 0 0\nheading: 0 1 0\npoints: 4\nrange: 0.0 1.0\ndimension: 4\n"
                    "type: bspline\n0 0 0 3\n0 1 0 1\n0 2 0 1\n0 3 0 3\n";

// curve: files (CPFG manual 5.5) are read by arc length: the line's length and its points.
TEST_F(ViewFile, CurvesAreReadByArcLength) {
  write("line.con", kLine);
  const ViewSettings v = read_view_file(write("plant.v", "curve: line.con\ncurve: line.con 7\n"));
  ASSERT_EQ(v.curves.size(), 2u);
  EXPECT_NEAR(v.curves[0].length, 3.0, 1e-9);
  EXPECT_EQ(v.curves[0].arc.size(), 100u);
  EXPECT_EQ(v.curves[1].arc.size(), 7u);
  for (const double s : {0.0, 0.25, 0.5, 0.9, 1.0}) {
    EXPECT_NEAR(v.curves[0].at(s)[1], 3.0 * s, 2e-3) << s;
    EXPECT_EQ(v.curves[0].at(s)[0], 0.0);
  }
  EXPECT_NEAR(v.curves[0].at(-1)[1], 0.0, 1e-12);  // clamped to the ends
  EXPECT_NEAR(v.curves[0].at(2)[1], 3.0, 1e-12);
  write("closed.con", "points: 4\ntype: bspline-closed\n0 0\n1 0\n1 1\n0 1\n");
  const ViewSettings closed = read_view_file(write("closed.v", "curve: closed.con\n"));
  EXPECT_NEAR(closed.curves[0].at(0)[0], closed.curves[0].at(1)[0], 1e-12);  // a closed curve ends where it starts
  EXPECT_NEAR(closed.curves[0].at(0)[1], closed.curves[0].at(1)[1], 1e-12);
  write("few.con", "points: 2\n0 0\n1 1\n");
  EXPECT_EQ(error_of("curve: few.con\n"), "few.con:1:1: expected at least 4 control points (multiplicities included)");
  write("bezier.con", "points: 4\ntype: bezier\n0 0\n1 0\n1 1\n0 1\n");
  EXPECT_EQ(error_of("curve: bezier.con\n"),
            "bezier.con:1:1: curve type 'bezier' is not supported (expected bspline, bspline-closed or bspline-phantom)");
  write("extra.con", "points: 1\n0 0\n1 1\n");
  EXPECT_EQ(error_of("curve: extra.con\n"), "extra.con:3:1: more points than 'points:' announces");
  EXPECT_EQ(error_of("curve: line.con 1\n"), "plant.v:1:1: expected 2 ... 1000000 samples after the curve file");
}

TEST_F(ViewFile, MissingViewFileIsAnInputError) {
  try {
    read_view_file(dir_ / "none.v");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), (dir_ / "none.v").string() + ": cannot read the view file (no such file)");
  }
}

}  // namespace
}  // namespace treeanim
