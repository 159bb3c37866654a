// Single cells of the current mesh, by index (valid until the next remesh): their geometry,
// fluxes and stored volumes, and the conditions set on them (YADE's cell methods; the YADE
// names are in pfv/_cell_geometry.py, _flow_queries.py and _cell_conditions.py).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <string>

#include "pfv/engine/flow_queries.hpp"
#include "pfv/linalg/cholmod_solver.hpp"
#include "pfv/model/cell_queries.hpp"
#include "pfv/python/shared_engine.hpp"
#include "triangulation/constriction.hpp"
#include "triangulation/power_cells.hpp"

namespace pfv::python {
namespace {

std::array<double, 3> triple(const Vec3& x) { return {x.x(), x.y(), x.z()}; }

// Positions (n, 3) and walls as a Packing needs them.
struct Positions {
  std::vector<Vec3> centres;
  BoxWalls walls;
  Positions(const Array& c, const std::array<double, 6>& w) : centres(to_points(c, "positions")), walls(to_walls(w)) {}
};

// The last step's positions with the scan's radii, as a Packing (the radii must match the mesh).
struct LastPacking {
  std::vector<double> radii;
  Packing packing;
  LastPacking(const SharedEngine& e, const Array& r)
      : radii(to_vector(r, "radii")), packing{e.positions(), radii, e.walls()} {
    if (e.positions().size() != static_cast<std::size_t>(e.mesh().n_spheres))
      throw py::value_error("the mesh has no positions yet (its step did not complete)");
    if (radii.size() != e.positions().size())
      throw py::value_error("radii: one per sphere of the mesh (" + std::to_string(e.mesh().n_spheres) + ")");
  }
};

// The facet opposite local vertex 'local' of a checked cell, or -1; IndexError for local outside 0..3.
int throat_of(const SharedEngine& e, int cell, int local) {
  check_cell(e, cell);
  if (local < 0 || local > 3) throw py::index_error("throat index must be in 0..3");
  return find_facet(e.facets(), e.mesh(), cell, local);
}

bool open_throat(const SharedEngine& e, int f) {
  if (f < 0) return false;
  const auto& c = e.facets().cell[f];
  return c[1] >= 0 && !e.cell_conditions().is_blocked(c[0]) && !e.cell_conditions().is_blocked(c[1]);
}

}  // namespace

void bind_cells(EngineClass& engine) {
  engine
      .def("cell_barycenter", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             if (e.positions().size() != static_cast<std::size_t>(e.mesh().n_spheres))
               throw py::value_error("the mesh has no positions yet (its step did not complete)");
             const std::vector<double> no_radii;
             const Packing packing{e.positions(), no_radii, e.walls()};
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
      .def("cell_neighbour_array", exclusive([](const SharedEngine& e) {
             const auto& cn = meshed(e).mesh().cell_neighbours;
             py::array_t<int> out({static_cast<py::ssize_t>(cn.size()), py::ssize_t{4}});
             if (!cn.empty()) std::memcpy(out.mutable_data(), cn.data(), cn.size() * sizeof(cn[0]));
             return out;
           }),
           "(n_cells, 4): the cell across the facet opposite each local vertex, -1 for none.")
      .def("last_positions", exclusive([](const SharedEngine& e) { return points_to_array(meshed(e).positions()); }),
           "The sphere centres of the last step.")
      .def("system_times", exclusive([](const SharedEngine& e) {
             const StageTimes& t = system_times(meshed(e));
             py::dict d;
             d["assembly"] = t.assembly;
             d["analysis"] = t.analysis;
             d["factorization"] = t.factorization;
             return d;
           }),
           "Seconds to assemble, analyse and factorise the current linear system.")
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
             return locate(e, e.bc.imposed_pressure[cond].position);
           }),
           py::arg("cond"), "The cell of imposed pressure number cond on the current mesh (-1: none).")
      .def("set_cell_imposed", exclusive([](SharedEngine& e, int id, bool imposed) {
             check_cell(e, id);
             e.set_cell_imposed(id, imposed);
           }),
           py::arg("id"), py::arg("imposed"))
      .def("cell_imposed", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             return cell_imposed(e, id);
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
           py::arg("positions"), py::arg("walls"), py::arg("dt"))
      .def("throat_conductance", exclusive([](const SharedEngine& e, int cell, int local) {
             const int f = throat_of(e, cell, local);
             return open_throat(e, f) ? e.conductances()[f] : 0.0;
           }),
           py::arg("cell"), py::arg("local"),
           "k of the throat opposite local vertex 'local' (0 towards no cell or through a blocked cell).")
      .def("throat_fluid_area", exclusive([](const SharedEngine& e, int cell, int local) {
             const int f = throat_of(e, cell, local);
             return f < 0 ? 0.0 : e.facets().fluid_area[f];
           }),
           py::arg("cell"), py::arg("local"), "Fluid area of the throat opposite local vertex 'local'.")
      .def("throat_diffusion", exclusive([](const SharedEngine& e, int cell, int local) {
             const int f = throat_of(e, cell, local);
             if (f < 0 || e.facets().cell[f][1] < 0 || !(e.facets().length[f] > 0)) return 0.0;
             return e.facets().area_vector[f].norm() / e.facets().length[f];
           }),
           py::arg("cell"), py::arg("local"), "Area of the throat's facet over the distance of the two power centres.")
      .def("throat_solid_area", exclusive([](const SharedEngine& e, int cell, int local, const Array& radii) {
             throat_of(e, cell, local);
             const LastPacking last(e, radii);
             std::array<bool, kWallCount> solid{};
             for (int w = 0; w < kWallCount; ++w) solid[w] = !e.bc.is_pressure[w];
             const auto a = half_throat_wetted_area(e.mesh(), e.cells(), last.packing, cell, local, solid);
             return a[0] + a[1] + a[2];
           }),
           py::arg("cell"), py::arg("local"), py::arg("radii"),
           "Solid surface of the half throat in the cell (no-flux walls included), at the last step's positions.")
      .def("constrictions", exclusive([](const SharedEngine& e, const Array& radii) {
             meshed(e);
             const LastPacking last(e, radii);
             const FacetGeometry& g = e.facets();
             std::vector<int> a, b;
             std::vector<double> radius;
             std::vector<Vec3> normal;
             std::vector<std::uint8_t> wall;
             for (int f = 0; f < g.size(); ++f) {
               if (g.cell[f][1] < 0) continue;
               a.push_back(g.cell[f][0]);
               b.push_back(g.cell[f][1]);
               radius.push_back(throat_constriction(e.mesh(), g.vertex[f], last.packing).radius);
               normal.push_back(-g.area_vector[f]);  // from the second cell towards the first
               bool any = false;
               for (int v : g.vertex[f]) any |= e.mesh().is_wall(v);
               wall.push_back(any);
             }
             py::dict d;
             d["cells"] = py::make_tuple(vector_to_array(a), vector_to_array(b));
             d["radius"] = vector_to_array(radius);
             d["normal"] = points_to_array(normal);
             d["wall"] = vector_to_array(wall);
             return d;
           }),
           py::arg("radii"),
           "Every throat between two cells: its cells, inscribed radius (throat_constriction), area vector\n"
           "(from the second cell to the first) and whether a wall is one of its vertices.")
      .def("power_cell_volumes", exclusive([](const SharedEngine& e, const Array& radii) {
             meshed(e);
             const LastPacking last(e, radii);
             const PowerCellVolumes v = power_cell_volumes(e.mesh(), e.cells(), last.packing);
             return py::make_tuple(vector_to_array(v.volume), v.incomplete);
           }),
           py::arg("radii"), "(volume per sphere, spheres whose power cell is incomplete): power_cells.hpp.")
      .def("system_matrix", exclusive([](const SharedEngine& e) {
             const PressureSystem& s = meshed(e).system();
             const SymmetricMatrix& g = *s.matrix;
             py::dict d;
             d["col_start"] = vector_to_array(g.col_start);
             d["row"] = vector_to_array(g.row);
             d["value"] = vector_to_array(g.value);
             d["unknown_cell"] = vector_to_array(s.unknown_cell);
             return d;
           }),
           "G of the last step: upper triangle by column over the unknowns, and the cell of each unknown.")
      .def("print_cholmod_statistics", exclusive([](const SharedEngine& e, const std::string& title) {
             if (!e.cholesky()) return false;
             py::gil_scoped_release release;
             e.cholmod().print_statistics(title.c_str());
             return true;
           }),
           py::arg("title"), "CHOLMOD's report on the current factor (stdout); False without one.");
}

}  // namespace pfv::python
