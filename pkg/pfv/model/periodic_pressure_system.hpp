// The pressure of a periodic packing under a macroscopic gradient (thesis 3.5 on the infinite
// periodic packing): p(x) = p~(x) + gradP . x with p~ periodic, one value p~_i per stored cell.
//
// A throat f from cell i to the translate of cell j by t_f (FacetGeometry::translation) carries
//   q_f = k_f (p_i - p_j') = k_f (p~_i - p~_j - gradP . (P_j + t_f - P_i)),
// P the power centres, so the balance of each cell, sum_f q_f = -dV_i/dt, reads
//   G p~ = -dV/dt + s,   s_i = sum_f k_f gradP . d_f (d_f = P_j + t_f - P_i, from i's side).
// G over all cells annihilates constants: p~ is defined up to one, and the system has a solution
// only if the sources add up to zero (no net volume change of the pores, the sums of s cancel by
// construction). The constant is fixed by p~ = 0 in one reference cell, which removes that cell's
// row and column; what remains is positive definite (the cells are connected). Pores whose
// pressure is imposed (YADE's imposePressure) fix it instead: they are known values, no pore is
// the reference, and each throat from an unknown to a known pore adds k p~_known to the
// unknown's right-hand side.
//
// Cells whose power centres coincide (a throat of zero length: cospherical spheres, as in the
// regular arrays) are one pore cut by arbitrary facets, and share one unknown: their throats have
// no length, so no finite conductance is right for them (a clamped one leaves the arbitrary split
// of each lattice cube into tetrahedra in the result: doc/periodic.md).
#pragma once
#include <memory>
#include <vector>

#include "pfv/linalg/symmetric_matrix.hpp"
#include "triangulation/mesh.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

struct PeriodicPressureSystem {
  // A throat between an unknown and a known pore: k p~[cell] belongs on the unknown's side.
  struct Coupling {
    int unknown, cell;
    double k;
  };
  int reference_cell = 0;         // p~ = 0 there (and in the cells of its pore); -1: none
  std::vector<int> pore;          // per cell, its pore: the cells joined by zero-length throats
  std::vector<int> unknown;       // per cell, its pore's unknown; -1 for a known pore
  std::vector<int> unknown_cell;  // per unknown, one cell of its pore
  std::vector<Coupling> coupling;
  std::shared_ptr<const SymmetricMatrix> matrix = std::make_shared<const SymmetricMatrix>();

  int n_unknowns() const { return static_cast<int>(unknown_cell.size()); }
  // The right-hand side of the unknowns from per-cell values: the sum over each pore's cells.
  std::vector<double> gather(const std::vector<double>& per_cell) const;
  // Adds the known pores' part to the right-hand side b, from p~ per cell.
  void add_known(const std::vector<double>& periodic_pressure, std::vector<double>& b) const;
  // Per cell, its pore's value of x; the known pores' values are taken from known (per cell).
  std::vector<double> scatter(const std::vector<double>& x, const std::vector<double>& known) const;
};

// facets from compute_facet_geometry of a periodic mesh (translations set); k per facet, the
// zero-length throats' values unused. storage (optional, per cell, > 0): V_f / (K dt) of a
// compressible fluid, added to the diagonal; G is then positive definite and no pore is the
// reference (reference_cell -1). imposed (optional): cells whose pores' pressures are known; no
// pore is the reference then either.
PeriodicPressureSystem assemble_periodic_system(const Mesh& mesh, const FacetGeometry& facets,
                                                const std::vector<double>& k, const std::vector<double>& storage = {},
                                                const std::vector<int>& imposed = {});

// Per cell, s_i of the gradient (above).
std::vector<double> gradient_source(const CellGeometry& cells, const FacetGeometry& facets,
                                    const std::vector<double>& k, const Vec3& gradient);

// Per facet, the flux q_f from cell[f][0] to cell[f][1]'s translate, for the periodic part p~
// per cell.
std::vector<double> periodic_fluxes(const CellGeometry& cells, const FacetGeometry& facets,
                                    const std::vector<double>& k, const std::vector<double>& periodic_pressure,
                                    const Vec3& gradient);

// The superficial (Darcy) velocity of the periodic cell of volume V: (1/V) sum_f q_f d_f, the
// flux through any section of the cell per unit area, averaged over the sections.
Vec3 mean_velocity(const CellGeometry& cells, const FacetGeometry& facets, const std::vector<double>& fluxes,
                   double volume);

}  // namespace pfv
