// What the VTK output (pfv/_vtk_output.py) reads of the current mesh besides the geometry
// bindings: the positions the last step ran at, the cell volumes at those positions and the
// pressure source of every cell (numpy copies).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <vector>

#include "pfv/linalg/system_io.hpp"
#include "pfv/python/shared_engine.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv::python {
namespace {

// The integer Python reads for a cell's pressure source (cell_sources below). A new kind of
// BoundarySource needs a code here.
int source_code(const BoundarySource& source) {
  switch (source.kind) {
    case BoundarySource::Kind::kWall:
      return source.index;
    case BoundarySource::Kind::kImposedPoint:
      return kWallCount + source.index;
    case BoundarySource::Kind::kCellImposed:
      return -2;
    case BoundarySource::Kind::kBlocked:
      return -3;
    case BoundarySource::Kind::kUnknown:
      break;
  }
  return -1;
}

}  // namespace

void bind_output(EngineClass& engine) {
  engine
      .def("positions", exclusive([](const SharedEngine& e) { return points_to_array(meshed(e).positions()); }),
           "Sphere centres of the last step (input order): the positions walls(), pressure() and forces() belong to.")
      .def("current_cell_volumes", exclusive([](const SharedEngine& e) {
             const CellGeometry& cells = meshed(e).cells();
             const std::vector<Vec3>& centres = e.positions();
             if (centres.size() != static_cast<std::size_t>(e.mesh().n_spheres))
               throw py::value_error("the last step's positions do not belong to the current mesh");
             std::vector<double> volume(cells.shape.size());
             for (std::size_t c = 0; c < volume.size(); ++c)
               volume[c] = cell_volume(cells.shape[c], centres, e.walls());
             return vector_to_array(volume);
           }),
           "Total volume of every cell (tetrahedron or wall prism) at positions() and walls(); cell_volumes() is\n"
           "the volume at the last remesh.")
      .def("cell_sources", exclusive([](const SharedEngine& e) {
             const std::vector<BoundarySource>& source = meshed(e).system().source;
             if (source.size() != static_cast<std::size_t>(e.mesh().n_cells()))
               throw py::value_error("the linear system does not belong to the current mesh (run a step first)");
             std::vector<int> code(source.size());
             for (std::size_t c = 0; c < source.size(); ++c) code[c] = source_code(source[c]);
             return vector_to_array(code);
           }),
           "Pressure source of every cell: wall w (0..5) or 6 + k (imposed pressure k) for a cell whose pressure\n"
           "is imposed (a Dirichlet cell of the system), -1 for a cell whose pressure is solved for.")
      .def("save_system", exclusive([](const SharedEngine& e, const std::string& folder) {
             const FlowEngine& m = meshed(e);
             if (m.last_rhs().size() != static_cast<std::size_t>(m.system().n_unknowns()) ||
                 m.last_solution().size() != m.last_rhs().size())
               throw py::value_error("no solve on the current system yet (run a step first)");
             try {
               write_system(folder, *m.system().matrix, m.last_rhs(), m.last_solution());
             } catch (const std::runtime_error& error) {
               throw py::value_error(error.what());
             }
           }),
           py::arg("folder"),
           "Writes the last step's system G p = b into an existing folder: G.mtx (Matrix Market, symmetric),\n"
           "b.mtx and the solution x.mtx, for a solver run outside the engine (build/pfv_amg_solve, over MPI).");
}

}  // namespace pfv::python
