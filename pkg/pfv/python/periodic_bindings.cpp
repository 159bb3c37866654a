// pfv._core.PeriodicFlow: the step of a periodic cell (engine/periodic_flow.hpp) for Python, with
// numpy arrays in and out. A step releases the GIL while it runs.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "pfv/engine/periodic_flow.hpp"
#include "pfv/python/shared_engine.hpp"

namespace pfv::python {

namespace {

Eigen::Matrix3d to_cell(const Array& h) {
  if (h.ndim() != 2 || h.shape(0) != 3 || h.shape(1) != 3) throw py::value_error("h must have shape (3, 3)");
  Eigen::Matrix3d out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out(i, j) = h.at(i, j);
  return out;
}

py::dict to_dict(const PeriodicFlow::RunState& s) {
  py::dict d;
  d["mesh_centres"] = points_to_array(s.mesh_centres);
  d["mesh_radii"] = vector_to_array(s.mesh_radii);
  d["mesh_h"] = s.mesh_h;
  d["previous_centres"] = points_to_array(s.previous_centres);
  d["previous_h"] = s.previous_h;
  d["periodic_pressure"] = vector_to_array(s.periodic_pressure);
  d["strain"] = s.strain;
  return d;
}

PeriodicFlow::RunState from_dict(const py::dict& d) {
  PeriodicFlow::RunState s;
  s.mesh_centres = to_points(d["mesh_centres"].cast<Array>(), "mesh_centres");
  s.mesh_radii = to_vector(d["mesh_radii"].cast<Array>(), "mesh_radii");
  s.mesh_h = to_cell(d["mesh_h"].cast<Array>());
  const Array previous = d["previous_centres"].cast<Array>();
  if (previous.size() > 0) s.previous_centres = to_points(previous, "previous_centres");
  s.previous_h = to_cell(d["previous_h"].cast<Array>());
  s.periodic_pressure = to_vector(d["periodic_pressure"].cast<Array>(), "periodic_pressure");
  s.strain = d["strain"].cast<double>();
  return s;
}

template <std::size_t N, typename T>
py::array_t<T> rows_to_array(const std::vector<std::array<T, N>>& rows) {
  py::array_t<T> out({rows.size(), N});
  auto o = out.template mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < N; ++j) o(i, j) = rows[i][j];
  return out;
}

// The throats of the current mesh as arrays, one row per facet (the throat-level comparison with
// the Stokes reference in validation/stokes/ reads them).
py::dict throats(const PeriodicFlow& f) {
  const FacetGeometry& g = f.facets();
  py::dict d;
  d["cells"] = rows_to_array(g.cell);
  d["vertices"] = rows_to_array(g.vertex);
  d["translation"] = points_to_array(g.translation);
  d["area_vector"] = points_to_array(g.area_vector);
  d["fluid_area"] = vector_to_array(g.fluid_area);
  d["length"] = vector_to_array(g.length);
  d["hydraulic_radius"] = vector_to_array(g.hydraulic_radius);
  d["sector_area"] = rows_to_array(g.sector_area);
  d["wetted_area"] = rows_to_array(g.wetted_area);
  d["conductance"] = vector_to_array(f.conductances());
  d["flux"] = vector_to_array(f.throat_fluxes());
  d["constriction_radius"] = vector_to_array(f.throat_constrictions());
  return d;
}

SolverKind solver_kind(const std::string& name) {
  for (SolverKind k :
       {SolverKind::kCholesky, SolverKind::kGaussSeidel, SolverKind::kConjugateGradient, SolverKind::kMultigrid})
    if (to_string(k) == name) return k;
  throw py::value_error("solver must be cholesky, gauss_seidel, conjugate_gradient or multigrid, got '" + name + "'");
}

}  // namespace

void bind_periodic(py::module_& m) {
  py::class_<PeriodicFlow>(m, "PeriodicFlow",
                           "The flow through a periodic packing under an imposed mean pressure gradient, one DEM step "
                           "at a time (p = p~ + gradP . x, p~ periodic).")
      .def(py::init<>())
      .def(
          "set_settings",
          [](PeriodicFlow& f, double viscosity, double permeability_factor, const Vec3& gradient, double bulk_modulus,
             const std::string& solver, double tolerance, double relax, double def_tolerance) {
            PeriodicFlowSettings s;
            s.viscosity = viscosity;
            s.permeability_factor = permeability_factor;
            s.gradient = gradient;
            s.bulk_modulus = bulk_modulus;
            s.solver = solver_kind(solver);
            s.tolerance = tolerance;
            s.relax = relax;
            s.def_tolerance = def_tolerance;
            f.set_settings(s);
          },
          py::arg("viscosity"), py::arg("permeability_factor"), py::arg("gradient"), py::arg("bulk_modulus"),
          py::arg("solver") = "cholesky", py::arg("tolerance") = 1e-6, py::arg("relax") = 1.9,
          py::arg("def_tolerance") = 0.0, "solver: cholesky, gauss_seidel, conjugate_gradient or multigrid.")
      .def(
          "step",
          [](PeriodicFlow& f, const Array& centres, const Array& radii, const Array& h, double dt) {
            const auto c = to_points(centres, "centres");
            const auto r = to_vector(radii, "radii");
            const Eigen::Matrix3d cell = to_cell(h);
            py::gil_scoped_release release;
            f.step(c, r, cell, dt);
          },
          py::arg("centres"), py::arg("radii"), py::arg("h"), py::arg("dt"),
          "One step: centres (n, 3), radii (n,), the cell's vectors h (3, 3, columns as YADE's hSize), dt.")
      .def("impose_pressure", &PeriodicFlow::impose_pressure, py::arg("position"), py::arg("pressure"),
           "An imposed pressure at the pore holding position (kept through remeshes); returns its index.")
      .def("set_imposed_pressure", &PeriodicFlow::set_imposed_pressure, py::arg("index"), py::arg("pressure"))
      .def("clear_imposed_pressure", &PeriodicFlow::clear_imposed_pressure)
      .def("impose_flux", &PeriodicFlow::impose_flux, py::arg("position"), py::arg("inflow"),
           "An inflow (volume per time) into the pore holding position (kept through remeshes).")
      .def("clear_imposed_flux", &PeriodicFlow::clear_imposed_flux)
      .def("imposed_pressures", [](const PeriodicFlow& f) { return conditions(f.imposed_pressures()); })
      .def("imposed_fluxes", [](const PeriodicFlow& f) { return conditions(f.imposed_fluxes()); })
      .def("imposed_cells", [](const PeriodicFlow& f) { return vector_to_array(f.imposed_cells()); })
      .def("run_state", [](const PeriodicFlow& f) { return to_dict(f.run_state()); })
      .def(
          "resume", [](PeriodicFlow& f, const py::dict& state) { f.resume(from_dict(state)); }, py::arg("state"),
          "Rebuild the mesh and the history of run_state() (PeriodicFlow::resume).")
      .def("remesh_times", [](const PeriodicFlow& f) { return times_dict(f.remesh_times()); })
      .def("step_times", [](const PeriodicFlow& f) { return times_dict(f.step_times()); })
      .def("request_remesh", &PeriodicFlow::request_remesh)
      .def("forget_motion", &PeriodicFlow::forget_motion)
      .def("has_mesh", &PeriodicFlow::has_mesh)
      .def_property_readonly("remesh_count", &PeriodicFlow::remesh_count)
      .def_property_readonly("strain", &PeriodicFlow::strain)
      .def_property_readonly("n_cells", [](const PeriodicFlow& f) { return f.has_mesh() ? f.mesh().n_cells() : 0; })
      .def("periodic_pressure", [](const PeriodicFlow& f) { return vector_to_array(f.periodic_pressure()); })
      .def("pressure", [](const PeriodicFlow& f) { return vector_to_array(f.pressure()); })
      .def("volume_rates", [](const PeriodicFlow& f) { return vector_to_array(f.volume_rates()); })
      .def("fluid_volumes", [](const PeriodicFlow& f) { return vector_to_array(f.fluid_volumes()); })
      .def("cell_volumes", [](const PeriodicFlow& f) { return vector_to_array(f.cells().volume); })
      .def("cell_vertices", [](const PeriodicFlow& f) { return cell_vertices_array(f.mesh().mesh.cell_vertices); })
      .def("image_spheres", [](const PeriodicFlow& f) { return vector_to_array(f.mesh().image_sphere); })
      .def("image_positions", [](const PeriodicFlow& f) { return points_to_array(f.image_positions()); })
      .def("step_cell", [](const PeriodicFlow& f) { return Eigen::Matrix3d(f.step_cell()); })
      .def("current_cell_volumes", [](const PeriodicFlow& f) { return vector_to_array(f.current_volumes()); })
      .def("forces", [](const PeriodicFlow& f) { return points_to_array(f.forces()); })
      .def("mean_velocity", &PeriodicFlow::mean_velocity)
      .def("throats", &throats,
           "Per facet of the current mesh: cells (m, 2), vertices (image ids), translation of cell 1, area_vector, "
           "fluid_area, length, hydraulic_radius, sector_area, wetted_area, conductance, flux (cell 0 to 1), "
           "constriction_radius.")
      .def("power_centres", [](const PeriodicFlow& f) { return points_to_array(f.cells().power_centre); })
      .def("pressure_at", &PeriodicFlow::pressure_at, py::arg("x"));
}

}  // namespace pfv::python
