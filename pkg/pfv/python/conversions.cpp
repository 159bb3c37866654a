// Results shared by the walled and the periodic engines' bindings, as Python objects.
#include <cstring>

#include "pfv/python/shared_engine.hpp"

namespace pfv::python {

py::dict times_dict(const StageTimes& t) {
  py::dict d;
  d["triangulation"] = t.triangulation;
  d["geometry"] = t.geometry;
  d["conductance"] = t.conductance;
  d["assembly"] = t.assembly;
  d["analysis"] = t.analysis;
  d["factorization"] = t.factorization;
  d["force_cache"] = t.force_cache;
  d["volumes"] = t.volumes;
  d["solve"] = t.solve;
  d["forces"] = t.forces;
  d["shear_geometry"] = t.shear_geometry;
  d["shear_forces"] = t.shear_forces;
  d["pressure_field"] = t.pressure_field;
  d["carry_over"] = t.carry_over;
  d["total"] = t.total;
  return d;
}

py::list conditions(const std::vector<PointCondition>& list) {
  py::list out;
  for (const PointCondition& c : list)
    out.append(py::make_tuple(py::make_tuple(c.position.x(), c.position.y(), c.position.z()), c.value));
  return out;
}

py::array_t<int> cell_vertices_array(const std::vector<std::array<int, 4>>& cells) {
  py::array_t<int> out({static_cast<py::ssize_t>(cells.size()), py::ssize_t{4}});
  if (!cells.empty()) std::memcpy(out.mutable_data(), cells.data(), cells.size() * sizeof(cells[0]));
  return out;
}

}  // namespace pfv::python
