// Checks on a scene snapshot (sphere centres, radii, walls) before anything is built from it.
#pragma once
#include <string>
#include <vector>

#include "triangulation/box_walls.hpp"
#include "triangulation/vec3.hpp"

namespace pfv {

// The widest domain accepted, in radii of the largest sphere.
constexpr double kMaxDomainRadii = 1e6;

// Throws std::invalid_argument naming the first problem: sizes, non-finite or non-positive
// values, walls out of order, a centre on or outside a wall, a domain wider than
// kMaxDomainRadii largest radii along some axis.
void validate_snapshot(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls);

// Throws std::invalid_argument if two centres coincide (the triangulation would silently
// drop one sphere).
void check_distinct_centres(const std::vector<Vec3>& centres);

std::string describe(const Vec3& x);  // "(x, y, z)" for messages
std::string describe(double x);       // six significant digits

}  // namespace pfv
