#pragma once
// The 3D turtle (lpfg conventions, docs/design.md): module string => Skeleton.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "lsystem/leaf_shapes.h"
#include "lsystem/module_string.h"
#include "lsystem/skeleton.h"
#include "lsystem/tropism.h"

namespace treeanim {

struct TurtleSettings {
  double step = 1.0;                          // length of F/G/f/g without a parameter
  double angle_degrees = 90.0;                // δ of + - & ^ \ / without a parameter
  double width_factor = 0.707;                // '!' without a parameter multiplies the width by this
  double initial_width = 1.0;                 // diameter before the first '!(w)' when the word uses '!' or '#' at all
  std::optional<double> width_increment;      // cpfg view file: '#' adds it, '!' without a parameter subtracts it
  Eigen::Vector3d tropism{0, -1, 0};          // T of "tropism:" (direction of the bending force)
  double tropism_elasticity = 0.0;            // e; 0 = no tropism
  std::vector<Movement> movements;            // cpfg view file's "tropism:"/"torque:" lines, before every F G f g
  Eigen::Vector3d old_tropism{0, 1, 0};       // cpfg's unit "tropism direction:" (8.1.10), after every F G f g
  double initial_elasticity = 0.0;            // cpfg's "initial elasticity:" of that tropism ('_' changes it)
  double elasticity_increment = 0.0;          // cpfg's "elasticity increment:": what '_' adds
  double initial_scale = 1.0;                 // cpfg's "initial scale:": lengths, widths and surfaces (@D changes it)
  double scale_multiplier = 1.0;              // cpfg's "scale multiplier:": @Di multiplies, @Dd divides by it
  std::vector<LeafShape> surfaces;            // the view file's surfaces: ~id draws the one of its letter
  bool calls = false;                         // the grammar calls sub-L-systems: '?(label, s)' scales until '$'
};

// Initial frame H=(0,1,0) L=(-1,0,0) U=(0,0,1) at the origin; +(90)F(1) ends at (-1,0,0),
// &(90)F(1) at (0,0,-1). word => skeleton (scene units). The symbol table is docs/turtle.md;
// symbols the turtle does not know are structural and ignored. Accepts any word: a ']'
// without its '[' and an unclosed '{' are ignored (the grammar checks brackets).
Skeleton interpret(const ModuleString& word, const TurtleSettings& settings);

// The turtle interprets word and its query modules (CPFG manual 6.9) take the values they ask
// for: ?P(x, y[, z]) the position, ?H the heading, ?U the up and ?L the left vector.
void answer_queries(ModuleString* word, const TurtleSettings& settings);

}  // namespace treeanim
