#include "pfv/model/boundary_conditions.hpp"

#include <algorithm>
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
  const PressureProfile& pr = bc.profile;
  if (pr.wall < 0 || pr.wall >= kWallCount || pr.axis < 0 || pr.axis > 2 || pr.axis == wall_axis(pr.wall))
    throw std::invalid_argument("the pressure profile must lie on a wall, along another axis");
  if (pr.empty() && pr.pressure.empty()) return;
  if (pr.position.size() != pr.pressure.size() || pr.position.size() < 2)
    throw std::invalid_argument("boundaryXPos and boundaryPressure must have the same length, at least 2 (got " +
                                std::to_string(pr.position.size()) + " and " + std::to_string(pr.pressure.size()) +
                                ")");
  for (std::size_t i = 0; i < pr.position.size(); ++i) {
    if (!std::isfinite(pr.position[i]) || !std::isfinite(pr.pressure[i]))
      throw std::invalid_argument("boundaryXPos[" + std::to_string(i) + "] and boundaryPressure[" + std::to_string(i) +
                                  "] must be finite");
    if (i > 0 && !(pr.position[i] > pr.position[i - 1]))
      throw std::invalid_argument("boundaryXPos must increase (entry " + std::to_string(i) + ")");
  }
}

double profile_pressure(const PressureProfile& pr, double x, double outside) {
  const auto& xs = pr.position;
  if (xs.size() < 2 || x < xs.front() || x > xs.back()) return outside;
  const std::size_t i = std::min<std::size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin(), xs.size() - 1);
  const double t = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
  return pr.pressure[i - 1] + t * (pr.pressure[i] - pr.pressure[i - 1]);
}

}  // namespace pfv
