#include "pfv/model/pressure_rhs.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "pfv/snapshot/snapshot.hpp"

namespace pfv {

DirichletCouplings dirichlet_couplings(const PressureSystem& s) {
  DirichletCouplings d;
  for (int u = 0; u < s.n_unknowns(); ++u) {
    const int c = s.unknown_cell[u];
    for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e)
      if (s.unknown[s.adj_cell[e]] < 0 && s.adj_k[e] != 0) {  // no coupling through a blocked cell
        d.unknown.push_back(u);
        d.cell.push_back(s.adj_cell[e]);
        d.k.push_back(s.adj_k[e]);
      }
  }
  return d;
}

bool apply_pressure_field(const PressureField& field, const PressureSystem& s, const std::vector<Vec3>& power_centre,
                          FieldCells& f, std::vector<double>& values, std::vector<double>& pressure) {
  if (!field.active()) return false;
  if (f.wall != field.wall) {
    // The wall's Dirichlet cells stay those of this system until it is rebuilt (which drops
    // this list with it): gathered once, not at every step.
    f.cells.clear();
    f.at.clear();
    for (std::size_t c = 0; c < s.source.size(); ++c)
      if (s.source[c].is_wall(field.wall)) {
        f.cells.push_back(static_cast<int>(c));
        f.at.push_back(power_centre[c]);
      }
    f.wall = field.wall;
  }
  if (f.cells.empty()) return false;
  values.clear();
  field.evaluate(f.at, values);
  if (values.size() != f.cells.size())
    throw std::invalid_argument("the pressure field of wall " + std::to_string(field.wall) + " gave " +
                                std::to_string(values.size()) + " values for " + std::to_string(f.cells.size()) +
                                " cells");
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]))
      throw std::invalid_argument("the pressure field of wall " + std::to_string(field.wall) + " is not finite at " +
                                  describe(f.at[i]));
    pressure[f.cells[i]] = values[i];
  }
  return true;
}

void assemble_rhs(const PressureSystem& s, const RhsTerms& t, const std::vector<double>& boundary_pressure,
                  std::vector<double>& rhs) {
  const int nu = s.n_unknowns();
  rhs.resize(nu);
  for (int u = 0; u < nu; ++u) rhs[u] = -t.volume_rate[s.unknown_cell[u]];
  if (!t.storage.empty())
    for (int u = 0; u < nu; ++u) rhs[u] += t.storage[s.unknown_cell[u]] * t.pressure[s.unknown_cell[u]];
  for (std::size_t i = 0; i < t.imposed_flux_cells.size(); ++i) {
    const int c = t.imposed_flux_cells[i];
    if (c >= 0 && s.unknown[c] >= 0) rhs[s.unknown[c]] += t.imposed_flux[i].value;
  }
  const DirichletCouplings& d = t.couplings;
  for (std::size_t i = 0; i < d.k.size(); ++i) rhs[d.unknown[i]] += d.k[i] * boundary_pressure[d.cell[i]];
}

}  // namespace pfv
