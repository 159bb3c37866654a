#include "pfv/model/boundary_conditions.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "pfv/snapshot/snapshot.hpp"

namespace pfv {
namespace {

void check_points(const std::vector<PointCondition>& conditions, const char* what) {
  for (std::size_t i = 0; i < conditions.size(); ++i) {
    const PointCondition& c = conditions[i];
    if (!c.position.allFinite())
      throw std::invalid_argument(std::string(what) + " " + std::to_string(i) + " is at a non-finite point " +
                                  describe(c.position));
    if (!std::isfinite(c.value))
      throw std::invalid_argument(std::string(what) + " " + std::to_string(i) + " at " + describe(c.position) +
                                  " has a non-finite value");
  }
}

}  // namespace

void validate(const BoundaryConditions& bc) {
  for (int w = 0; w < kWallCount; ++w)
    if (!std::isfinite(bc.value[w]))
      throw std::invalid_argument("bndCondValue[" + std::to_string(w) + "] is not finite");
  check_points(bc.imposed_pressure, "imposed pressure");
  check_points(bc.imposed_flux, "imposed flux");
}

}  // namespace pfv
