#include "formats/usd_forest.h"

#include <set>

#include "files/text_output.h"
#include "formats/usd_text.h"

namespace treeanim {

std::string forest_usda(const std::vector<ForestStageTree>& trees, const ForestStageTime& time) {
  std::string out = "#usda 1.0\n(\n    defaultPrim = \"Forest\"\n    endTimeCode = " + std::to_string(time.end) +
                    "\n    framesPerSecond = ";
  append_usd_number(out, time.fps);
  out += "\n    metersPerUnit = 1\n    startTimeCode = " + std::to_string(time.start) + "\n    timeCodesPerSecond = ";
  append_usd_number(out, time.fps);
  out += "\n    upAxis = \"Y\"\n)\n\ndef Xform \"Forest\" (\n    kind = \"assembly\"\n)\n{\n";
  std::set<std::string> names;
  for (size_t t = 0; t < trees.size(); ++t) {
    const ForestStageTree& tree = trees[t];
    // Ids may hold '-' and '.', which prim names may not; a clash takes the tree's place in the list.
    std::string name = usd_prim_name(tree.id);
    if (!names.insert(name).second) names.insert(name += "_" + std::to_string(t));
    const bool relative = !std::filesystem::path(tree.layer).is_absolute();
    out += "    def \"" + name + "\" (\n        customData = {\n            string treeanim_id = " +
           usd_quoted(tree.id) + "\n        }\n        prepend references = " +
           usd_asset_path((relative ? "./" : "") + tree.layer) + "\n    )\n    {\n        double3 xformOp:translate = (";
    for (int a = 0; a < 3; ++a) {
      if (a > 0) out += ", ";
      append_usd_number(out, tree.translation[a]);
    }
    out += ")\n        double xformOp:rotateY = ";
    append_usd_number(out, tree.rotation_degrees);
    out += "\n        uniform token[] xformOpOrder = [\"xformOp:translate\", \"xformOp:rotateY\"]\n    }\n";
  }
  return out + "}\n";
}

void write_forest_usda(const std::filesystem::path& path, const std::vector<ForestStageTree>& trees,
                       const ForestStageTime& time) {
  write_text_output(path, forest_usda(trees, time));
}

}  // namespace treeanim
