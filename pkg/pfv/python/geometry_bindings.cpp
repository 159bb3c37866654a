// Geometry of the current mesh, for tests and post-processing (numpy copies).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "pfv/model/cell_velocity.hpp"
#include "pfv/python/shared_engine.hpp"

namespace pfv::python {

void bind_geometry(EngineClass& engine) {
  engine
      .def("cell_vertices",
           exclusive([](const SharedEngine& e) { return cell_vertices_array(meshed(e).mesh().cell_vertices); }))
      .def("cell_volumes", exclusive([](const SharedEngine& e) { return vector_to_array(meshed(e).cells().volume); }))
      .def("cell_fluid_volumes",
           exclusive([](const SharedEngine& e) { return vector_to_array(meshed(e).cells().fluid_volume); }))
      .def("cell_centers",
           exclusive([](const SharedEngine& e) { return points_to_array(meshed(e).cells().power_centre); }))
      .def("conductances", exclusive([](const SharedEngine& e) { return vector_to_array(meshed(e).conductances()); }))
      .def("facet_cells", exclusive([](const SharedEngine& e) { return meshed(e).facets().cell; }))
      .def("cell_velocities", exclusive([](const SharedEngine& e) {
             const CellConditions& blocked = meshed(e).cell_conditions();
             const int n = e.mesh().n_spheres;
             if (e.positions().size() != static_cast<std::size_t>(n))
               throw py::value_error("the mesh has no positions yet (its step did not complete)");
             std::vector<double> k = e.conductances();
             if (!blocked.blocked.empty())  // no flux through a blocked cell's throats
               for (int f = 0; f < e.facets().size(); ++f)
                 for (int c : e.facets().cell[f])
                   if (c >= 0 && blocked.is_blocked(c)) k[f] = 0;
             return points_to_array(mean_cell_velocities(e.cells(), e.facets(), k, e.pressure(), e.positions(), n));
           }),
           "Mean fluid velocity of every cell from the throat fluxes of the last step (cell_velocity.hpp).");
}

}  // namespace pfv::python
