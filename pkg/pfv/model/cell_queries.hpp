// Quantities of single pore cells asked for after a step (YADE's getCellBarycenter,
// getCellFluxFromId, getCellInvVoidVolume, ...); computed on demand, never by the step.
#pragma once
#include <vector>

#include "pfv/model/pressure_system.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

// The mean of the cell's four vertices. A wall vertex, whose fictitious centre lies at infinity,
// counts as the point of its wall plane nearest the mean of the cell's sphere centres, so that
// the barycentre of a boundary cell lies inside it.
Vec3 cell_barycenter(const CellShape& shape, const Packing& packing);

// What the cell's own condition must supply to hold it as it is: the flux leaving it through
// its throats plus the rate at which its volume grows (volume per time; negative: the cell takes
// fluid in). Zero to solver accuracy for an unknown cell of an incompressible fluid; for a
// Dirichlet cell, the influx of its pressure source with the opposite sign.
double cell_flux(const PressureSystem& system, const std::vector<double>& pressure,
                 const std::vector<double>& volume_rate, int cell);

// The pore volume a cell stores: its fluid volume, at least minimum_porosity times its total
// volume (YADE's minimumPorosity, which keeps near-solid cells from a vanishing volume).
inline double void_volume(double volume, double fluid_volume, double minimum_porosity) {
  const double floor = minimum_porosity * volume;
  return fluid_volume > floor ? fluid_volume : floor;
}

}  // namespace pfv
