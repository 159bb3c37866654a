// Throat conductances k_ij = g_ij / L_ij of the hydraulic-radius model (thesis 3.4-3.5):
//   g = alpha * A_f * R_h^2 / mu,   alpha = permeability_factor / 2,
// which is Poiseuille's pi r^4 / (8 mu) for a tube of radius r (R_h = r/2).
#pragma once
#include <vector>

#include "triangulation/pore_geometry.hpp"

namespace pfv {

struct ConductanceModel {
  double viscosity = 1.0;
  double permeability_factor = 1.0;
  // beta of an orifice in series with the duct (Dagan, Weinberg & Tamir 1982: a tube of radius a
  // and length L conducts pi a^4 / (8 mu (L + 3 pi a / 8))): k = g / (L + beta a), a the facet's
  // equivalent radius sqrt(A_f / pi). 0: the thesis' duct alone. Under study against the Stokes
  // reference (doc/validation.md section 7.7); not a user setting.
  double entrance = 0.0;
  // Optional clamping of k to [min_ratio, max_ratio] times the median k (YADE's clampKValues,
  // minKdivKmean, maxKdivKmean, with a different reference; see doc/yade.md). It
  // also keeps flat (L = 0) and closed (A_f = 0) throats from making G singular.
  bool clamp = true;
  double min_ratio = 1e-4;
  double max_ratio = 100.0;
};

// One value per facet; one-sided facets (no pore cell beyond) get 0.
std::vector<double> throat_conductances(const FacetGeometry& facets, const ConductanceModel& model);

}  // namespace pfv
