#include "pfv/snapshot/snapshot.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace pfv {
namespace {

[[noreturn]] void bad_input(const std::string& what) { throw std::invalid_argument(what); }

}  // namespace

std::string describe(const Vec3& x) {
  std::ostringstream s;
  s << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return s.str();
}

std::string describe(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

void validate_snapshot(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls) {
  if (centres.size() != radii.size()) bad_input("positions and radii differ in length");
  if (centres.empty()) bad_input("no spheres to couple with the fluid");
  for (int w = 0; w < kWallCount; ++w)
    if (!std::isfinite(walls.coord[w])) bad_input("wall " + std::to_string(w) + " position is not finite");
  for (int a = 0; a < 3; ++a)
    if (!(walls.extent(a) > 0))
      bad_input("walls " + std::to_string(2 * a) + " and " + std::to_string(2 * a + 1) +
                " are not in increasing order (min wall at or beyond max wall)");
  for (std::size_t k = 0; k < centres.size(); ++k) {
    if (!centres[k].allFinite())
      bad_input("sphere " + std::to_string(k) + " has a non-finite position " + describe(centres[k]));
    if (!(std::isfinite(radii[k]) && radii[k] > 0))
      bad_input("sphere " + std::to_string(k) + " has a non-positive or non-finite radius");
    for (int w = 0; w < kWallCount; ++w)
      if (!(walls.height(w, centres[k]) > 0))
        bad_input("sphere " + std::to_string(k) + " centre " + describe(centres[k]) + " is outside wall " +
                  std::to_string(w) + " (at " + describe(walls.coord[w]) + ")");
  }
  // A domain that many radii across cannot be meshed (and its coordinates no longer resolve a
  // radius): a sphere or a wall has gone far astray.
  const double largest = *std::max_element(radii.begin(), radii.end());
  for (int a = 0; a < 3; ++a)
    if (walls.extent(a) > kMaxDomainRadii * largest)
      bad_input("walls " + std::to_string(2 * a) + " and " + std::to_string(2 * a + 1) + " are " +
                describe(walls.extent(a)) + " apart, more than " + describe(kMaxDomainRadii) +
                " times the largest sphere radius " + describe(largest) +
                ": a sphere or a wall is far outside the packing");
}

void check_distinct_centres(const std::vector<Vec3>& centres) {
  std::vector<int> order(centres.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return std::lexicographical_compare(centres[a].data(), centres[a].data() + 3, centres[b].data(),
                                        centres[b].data() + 3);
  });
  for (std::size_t i = 1; i < order.size(); ++i)
    if (centres[order[i]] == centres[order[i - 1]])
      bad_input("sphere " + std::to_string(order[i - 1]) + " and sphere " + std::to_string(order[i]) +
                " have coincident centres " + describe(centres[order[i]]));
}

}  // namespace pfv
