// Single cells of the current mesh, by index (valid until the next remesh): their geometry,
// fluxes and stored volumes, and the conditions set on them (YADE's cell methods; the YADE
// names are in pfv/_cell_interface.py).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "pfv/model/cell_queries.hpp"
#include "pfv/python/shared_engine.hpp"

namespace pfv::python {
namespace {

std::array<double, 3> triple(const Vec3& x) { return {x.x(), x.y(), x.z()}; }

// Positions (n, 3) and walls as a Packing needs them.
struct Positions {
  std::vector<Vec3> centres;
  BoxWalls walls;
  Positions(const Array& c, const std::array<double, 6>& w) : centres(to_points(c, "positions")), walls(to_walls(w)) {}
};

}  // namespace

void bind_cells(EngineClass& engine) {
  engine
      .def("cell_barycenter", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             if (e.last_centres().size() != static_cast<std::size_t>(e.mesh().n_spheres))
               throw py::value_error("the mesh has no positions yet (its step did not complete)");
             const std::vector<double> no_radii;
             const Packing packing{e.last_centres(), no_radii, e.walls()};
             return triple(cell_barycenter(e.cells().shape[id], packing));
           }),
           py::arg("id"), "Mean of the cell's vertices at the last step's positions (walls: see cell_queries.hpp).")
      .def("cell_neighbours", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             std::vector<int> out;
             for (int n : e.mesh().cell_neighbours[id])
               if (n >= 0) out.push_back(n);
             return out;
           }),
           py::arg("id"), "The pore cells across the cell's facets (no entry where there is none).")
      .def("cell_vertex_indices", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             return e.mesh().cell_vertices[id];
           }),
           py::arg("id"), "The cell's four vertices: sphere indices, n_spheres + w for wall w.")
      .def("n_spheres", exclusive([](const SharedEngine& e) { return meshed(e).mesh().n_spheres; }))
      .def("cell_flux", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             return cell_flux(e.system(), e.pressure(), e.volume_rates(), id);
           }),
           py::arg("id"), "Flux leaving the cell through its throats plus its volume rate, at the last step.")
      .def("cell_fluxes", exclusive([](const SharedEngine& e) {
             meshed(e);
             std::vector<double> q(e.pressure().size());
             for (std::size_t c = 0; c < q.size(); ++c)
               q[c] = cell_flux(e.system(), e.pressure(), e.volume_rates(), static_cast<int>(c));
             return vector_to_array(q);
           }))
      .def("volume_rates", exclusive([](const SharedEngine& e) { return vector_to_array(meshed(e).volume_rates()); }))
      .def("imposed_pressure_cell", exclusive([](const SharedEngine& e, int cond) {
             meshed(e);
             if (cond < 0 || cond >= static_cast<int>(e.bc.imposed_pressure.size()))
               throw py::index_error("no imposed pressure with index " + std::to_string(cond));
             return e.locate(e.bc.imposed_pressure[cond].position);
           }),
           py::arg("cond"), "The cell of imposed pressure number cond on the current mesh (-1: none).")
      .def("set_cell_imposed", exclusive([](SharedEngine& e, int id, bool imposed) {
             check_cell(e, id);
             e.set_cell_imposed(id, imposed);
           }),
           py::arg("id"), py::arg("imposed"))
      .def("cell_imposed", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             return e.cell_imposed(id);
           }),
           py::arg("id"))
      .def("set_cell_pressure", exclusive([](SharedEngine& e, int id, double p) {
             check_cell(e, id);
             e.set_cell_pressure(id, p);  // std::invalid_argument: ValueError
           }),
           py::arg("id"), py::arg("pressure"))
      .def("block_cell", exclusive([](SharedEngine& e, int id, bool zero_pressure) {
             check_cell(e, id);
             e.block_cell(id, zero_pressure);
           }),
           py::arg("id"), py::arg("zero_pressure"))
      .def("cell_blocked", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             return e.cell_conditions().is_blocked(id);
           }),
           py::arg("id"))
      .def("void_volumes", exclusive([](const SharedEngine& e) { return vector_to_array(meshed(e).void_volumes()); }),
           "The pore volume each cell stores (V_f, at least minimum_porosity V).")
      .def("initialize_volumes",
           exclusive([](SharedEngine& e, const Array& centres, const std::array<double, 6>& walls) {
             meshed(e);
             const Positions x(centres, walls);
             e.initialize_volumes(x.centres, x.walls);
           }),
           py::arg("positions"), py::arg("walls"))
      .def("update_volumes",
           exclusive([](SharedEngine& e, const Array& centres, const std::array<double, 6>& walls, double dt) {
             meshed(e);
             const Positions x(centres, walls);
             e.update_volumes(x.centres, x.walls, dt);
           }),
           py::arg("positions"), py::arg("walls"), py::arg("dt"));
}

}  // namespace pfv::python
