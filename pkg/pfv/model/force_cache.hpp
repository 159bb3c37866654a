// Fluid forces as a fixed linear map of the cell pressures, F = S p (thesis 4.6, 5.1.4).
//
// Built once per remesh: for each (vertex, cell) pair the force per unit pressure in that
// cell, gathering the sector pressure force (3.10), the viscous share of the facet's fluid
// area split by wetted area (3.13 with the corrected sign, 3.14), and for walls the
// projected footprint of the cell. Applying it is one pass, grouped by vertex so that
// threads never write the same force.
#pragma once
#include <span>
#include <vector>

#include "triangulation/mesh.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

class ForceCache {
 public:
  void build(const Mesh& mesh, const FacetGeometry& facets, const Packing& packing);
  // force[v] for every mesh vertex (spheres, then the six walls).
  // team: on the OpenMP team (the same bits as on one thread).
  void apply(const std::vector<double>& cell_pressure, std::vector<Vec3>& force, bool team = true) const;
  // bound[v][a] = sum over cells c of |S(v, c)[a]| cell_value[c]: with nonnegative values, a
  // bound on |force[v][a]| for any pressures of magnitude at most cell_value (the row sums of
  // |S| that the collective time-step bound needs, viscous_stability.cpp).
  void apply_magnitude(const std::vector<double>& cell_value, std::vector<Vec3>& bound) const;
  int n_vertices() const { return static_cast<int>(start_.size()) - 1; }
  // The (sphere, incident cell) terms apply() sums.
  int n_terms() const { return start_.empty() ? 0 : start_.back(); }
  // Vertex v's terms: force[v] = sum over k of cell_pressure[cells(v)[k]] * units(v)[k].
  std::span<const int> cells(int v) const { return {cell_.data() + start_[v], cell_.data() + start_[v + 1]}; }
  std::span<const Vec3> units(int v) const { return {unit_.data() + start_[v], unit_.data() + start_[v + 1]}; }

 private:
  std::vector<int> start_;  // per vertex, into cell_/unit_
  std::vector<int> cell_;
  std::vector<Vec3> unit_;
};

}  // namespace pfv
