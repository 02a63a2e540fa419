// treeanim species [--json]: the species library, each grown at its default height.
#include <cstdio>
#include <iostream>

#include "bake/prepare_tree.h"
#include "cli/commands.h"
#include "scene/species.h"

namespace treeanim {

namespace {

Json species_row(const Species& species) {
  const Scene scene = load_scene_text(Json{{"species", species.name}}.dump(), "species " + species.name, "", {});
  const PreparedTree tree = prepare_tree(scene);
  return {{"name", species.name},
          {"common", species.common},
          {"latin", species.latin},
          {"habit", species.habit},
          {"height", {{"default", species.default_height}, {"min", species.min_height}, {"max", species.max_height}}},
          {"vertices", tree.model.vertex_count()},
          {"clusters", tree.model.cluster_count()},
          {"leaves", tree.model.leaf_count()},
          {"sway_frequency_hz", species.sway_frequency},
          {"youngs_modulus", scene.hsm.youngs_modulus},
          {"wood_density", scene.tree.wood_density},
          {"sources", species.sources}};
}

}  // namespace

int species_command(bool json) {
  Json rows = Json::array();
  for (const Species& species : species_library()) rows.push_back(species_row(species));
  if (json) {
    std::cout << rows.dump(2) << "\n";
    return 0;
  }
  std::printf("%-18s %-52s %-18s %8s %8s %9s\n", "name", "species", "height m (default)", "vertices", "clusters",
              "sway Hz");
  for (const Json& row : rows) {
    const std::string name = row["common"].get<std::string>() + " (" + row["latin"].get<std::string>() + ")";
    char height[96];
    std::snprintf(height, sizeof height, "%g-%g (%g)", row["height"]["min"].get<double>(),
                  row["height"]["max"].get<double>(), row["height"]["default"].get<double>());
    std::printf("%-18s %-52s %-18s %8lld %8lld %9.2f\n", row["name"].get<std::string>().c_str(), name.c_str(), height,
                row["vertices"].get<long long>(), row["clusters"].get<long long>(),
                row["sway_frequency_hz"].get<double>());
  }
  std::printf("Use one: {\"species\": \"%s\"} or {\"species\": {\"name\": \"%s\", \"height\": %g}} in a scene "
              "(docs/species.md).\n",
              rows[0]["name"].get<std::string>().c_str(), rows[0]["name"].get<std::string>().c_str(),
              rows[0]["height"]["max"].get<double>());
  return 0;
}

}  // namespace treeanim
