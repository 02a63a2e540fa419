// cpfg surface files (.s): the header (bounding box, optional precision, contact point, end
// point, heading, up, size), then patches of a name, a colour line, three neighbour lines and
// 16 control points. Read as a stream of whitespace-separated tokens that know their line and
// column, so that any error names the token where the format stops.
#include "lsystem/surface_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>
#include <string_view>
#include <utility>

#include "common/errors.h"
#include "common/message_text.h"
#include "common/read_text_file.h"

namespace treeanim {
namespace {

constexpr double kParallel = 1e-9;  // |H x U| below this: UP gives no frame

struct Token {
  std::string_view text;
  int line = 0;    // 1-based
  int column = 0;  // 1-based
};

class SurfaceReader {
 public:
  SurfaceReader(std::string name, const std::string& text) : name_(std::move(name)) { tokenize(text); }

  BezierSurface read() {
    BezierSurface s;
    if (word_is("VERSION")) skip_line();  // stedit's first line
    for (int i = 0; i < 6; ++i) number("the bounding box 'xmin xmax ymin ymax zmin zmax'");
    if (word_is("PRECISION")) s.precision = precision();
    s.contact = labelled_point({"CONTACT", "POINT"});
    s.end = labelled_point({"END", "POINT"});
    const Token* at_heading = peek();
    s.heading = labelled_point({"HEADING"});
    const Token* at_up = peek();
    s.up = labelled_point({"UP"});
    if (s.heading.norm() == 0) fail(at_heading, "expected a non-zero HEADING");
    s.heading.normalize();
    s.up -= s.up.dot(s.heading) * s.heading;
    if (s.up.norm() < kParallel) fail(at_up, "expected an UP vector that is not parallel to the HEADING");
    s.up.normalize();
    expect("SIZE:", "'SIZE: s'");
    const Token* at_size = peek();
    s.size = number("the size after 'SIZE:'");
    if (!(s.size > 0)) fail(at_size, "expected a SIZE > 0");
    while (peek()) s.patches.push_back(patch());
    if (s.patches.empty()) fail(nullptr, "expected a patch (a name, 'TOP COLOR: ...', 'AL: ...', 'L: ...', 'BL: ...' and 16 points)");
    return s;
  }

 private:
  void tokenize(const std::string& text) {
    int line = 1, column = 1;
    size_t start = std::string::npos;
    for (size_t k = 0; k <= text.size(); ++k) {
      const char c = k < text.size() ? text[k] : ' ';  // a blank past the end closes the last token
      const bool blank = c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
      if (!blank && start == std::string::npos) {
        start = k;
        tokens_.push_back({std::string_view(text).substr(k, 0), line, column});
      }
      if (blank && start != std::string::npos) {
        tokens_.back().text = std::string_view(text).substr(start, k - start);
        start = std::string::npos;
      }
      if (!continues_character(c)) ++column;
      if (c == '\n') {
        ++line;
        column = 1;
      }
    }
  }

  const Token* peek() const { return next_ < tokens_.size() ? &tokens_[next_] : nullptr; }
  bool word_is(std::string_view word) const { return peek() && peek()->text == word; }

  // Error at token t (null: the end of the file), naming what stands there.
  [[noreturn]] void fail(const Token* t, const std::string& message) const {
    // The end of the file is reported just after its last token.
    const Token* last = tokens_.empty() ? nullptr : &tokens_.back();
    const int line = t ? t->line : last ? last->line : 1;
    const auto characters = [](std::string_view text) {
      return static_cast<int>(std::count_if(text.begin(), text.end(), [](char c) { return !continues_character(c); }));
    };
    const int column = t ? t->column : last ? last->column + characters(last->text) : 1;
    std::string got = t ? "'" + excerpt(t->text, 27) + "'" : "the end of the file";
    throw InputError(name_ + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message + ", got " + got);
  }

  void expect(std::string_view word, const std::string& what) {
    if (!word_is(word)) fail(peek(), "expected " + what);
    ++next_;
  }

  void skip_line() {
    const int line = peek()->line;
    while (peek() && peek()->line == line) ++next_;
  }

  double number(const std::string& what) {
    const Token* t = peek();
    double v = 0;
    if (t) {
      std::string_view text = t->text;
      if (text.size() > 1 && text[0] == '+') text.remove_prefix(1);
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
      if (ec == std::errc() && end == text.data() + text.size() && std::isfinite(v)) {
        ++next_;
        return v;
      }
    }
    fail(t, "expected a number: " + what);
  }

  // "PRECISION S: s T: t" => the two counts, clamped to cpfg's 1 ... 10.
  std::array<int, 2> precision() {
    ++next_;
    std::array<int, 2> out{};
    for (int k = 0; k < 2; ++k) {
      expect(k == 0 ? "S:" : "T:", k == 0 ? "'PRECISION S: s T: t'" : "'T: t' after 'PRECISION S: s'");
      const Token* at = peek();
      const double v = number("a count of quads");
      if (v != std::floor(v)) fail(at, "expected a whole number of quads");
      out[static_cast<size_t>(k)] = static_cast<int>(std::clamp(v, 1.0, 10.0));
    }
    return out;
  }

  // "WORD [WORD] X: x Y: y Z: z" => (x, y, z).
  Eigen::Vector3d labelled_point(std::initializer_list<std::string_view> words) {
    std::string label;
    for (std::string_view w : words) label += (label.empty() ? "" : " ") + std::string(w);
    const std::string what = "'" + label + "  X: x Y: y Z: z'";
    for (std::string_view w : words) expect(w, what);
    Eigen::Vector3d p;
    const char* axes[] = {"X:", "Y:", "Z:"};
    for (int k = 0; k < 3; ++k) {
      expect(axes[k], what);
      p[k] = number(std::string(axes[k], 1) + " of " + label);
    }
    return p;
  }

  // name, "TOP COLOR: ...", "AL: ...", "L: ...", "BL: ...", 16 points => the control points.
  // Colours and neighbour names are rendering and are read past.
  std::array<Eigen::Vector3d, 16> patch() {
    const std::string name(peek()->text);
    skip_line();
    for (const char* word : {"TOP", "AL:", "L:", "BL:"}) {
      if (!word_is(word))
        fail(peek(), std::string("expected the line '") + word + " ...' of patch '" + name + "'");
      skip_line();
    }
    std::array<Eigen::Vector3d, 16> points;
    for (int i = 0; i < 16; ++i)
      for (int k = 0; k < 3; ++k)
        points[static_cast<size_t>(i)][k] = number("control point " + std::to_string(i + 1) + " of 16 (x y z) of patch '" + name + "'");
    return points;
  }

  std::string name_;
  std::vector<Token> tokens_;
  size_t next_ = 0;
};

}  // namespace

BezierSurface read_surface_file(const std::filesystem::path& path) {
  std::string text, reason;
  if (!read_text_file(path, text, reason))
    throw InputError(path.string() + ": cannot read the surface file (" + reason + ")");
  return SurfaceReader(path.string(), text).read();
}

}  // namespace treeanim
