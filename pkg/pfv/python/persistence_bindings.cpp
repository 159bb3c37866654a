// The run state of an engine as numpy arrays, to be saved with a YADE scene and resumed after
// O.load (pfv/_persistence.py).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "pfv/python/shared_engine.hpp"

namespace pfv::python {
namespace {

// Small integer codes per cell (CellConditions) travel as the float64 arrays of the saved state.
template <class Code>
py::array_t<double> codes_to_array(const std::vector<Code>& codes) {
  std::vector<double> v(codes.size());
  for (std::size_t i = 0; i < codes.size(); ++i) v[i] = static_cast<double>(codes[i]);
  return vector_to_array(v);
}

template <class Code>
std::vector<Code> codes_from_array(const Array& a, const char* name, int max_code) {
  const std::vector<double> v = to_vector(a, name);
  std::vector<Code> codes(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!(v[i] >= 0 && v[i] <= max_code && v[i] == static_cast<int>(v[i])))
      throw std::invalid_argument(std::string("saved state: ") + name + " holds " + std::to_string(v[i]) +
                                  ", not a code 0.." + std::to_string(max_code));
    codes[i] = static_cast<Code>(static_cast<int>(v[i]));
  }
  return codes;
}

py::dict to_dict(const FlowEngine::RunState& s) {
  py::dict d;
  d["mesh_centres"] = points_to_array(s.mesh.centres);
  d["mesh_radii"] = vector_to_array(s.mesh.radii);
  d["mesh_walls"] = s.mesh.walls.coord;
  d["previous_centres"] = points_to_array(s.previous_centres);
  d["previous_walls"] = s.previous_walls.coord;
  d["pressure"] = vector_to_array(s.pressure);
  d["cell_pressure"] = codes_to_array(s.cells.pressure);
  d["cell_blocked"] = codes_to_array(s.cells.blocked);
  d["void_volume"] = vector_to_array(s.void_volume);
  d["steps_since_remesh"] = s.steps_since_remesh;
  d["strain"] = s.strain;
  return d;
}

FlowEngine::RunState from_dict(const py::dict& d) {
  FlowEngine::RunState s;
  s.mesh.centres = to_points(d["mesh_centres"].cast<Array>(), "mesh_centres");
  s.mesh.radii = to_vector(d["mesh_radii"].cast<Array>(), "mesh_radii");
  s.mesh.walls = to_walls(d["mesh_walls"].cast<std::array<double, 6>>());
  const Array previous = d["previous_centres"].cast<Array>();
  if (previous.size() > 0) s.previous_centres = to_points(previous, "previous_centres");
  s.previous_walls = to_walls(d["previous_walls"].cast<std::array<double, 6>>());
  s.pressure = to_vector(d["pressure"].cast<Array>(), "pressure");
  // A state saved before cell conditions were carried has none.
  if (d.contains("cell_pressure")) {
    s.cells.pressure = codes_from_array<CellPressure>(d["cell_pressure"].cast<Array>(), "cell_pressure", 2);
    s.cells.blocked = codes_from_array<std::uint8_t>(d["cell_blocked"].cast<Array>(), "cell_blocked", 1);
    s.void_volume = to_vector(d["void_volume"].cast<Array>(), "void_volume");
  }
  s.steps_since_remesh = d["steps_since_remesh"].cast<int>();
  s.strain = d["strain"].cast<double>();
  return s;
}

}  // namespace

void bind_persistence(EngineClass& engine) {
  engine
      .def("run_state", exclusive([](const SharedEngine& e) { return to_dict(e.run_state()); }),
           "The state a run needs to go on after a save (FlowEngine::RunState) as a dict of arrays.")
      .def("resume", exclusive([](SharedEngine& e, const py::dict& state, double dt) {
             const FlowEngine::RunState s = from_dict(state);
             py::gil_scoped_release release;
             e.resume(s, dt);
           }),
           py::arg("state"), py::arg("dt"), "Rebuild the mesh and the history of run_state() (FlowEngine::resume).")
      .def("imposed_pressures", exclusive([](const SharedEngine& e) { return conditions(e.bc.imposed_pressure); }),
           "[((x, y, z), p), ...] of impose_pressure, in index order.")
      .def("imposed_fluxes", exclusive([](const SharedEngine& e) { return conditions(e.bc.imposed_flux); }),
           "[((x, y, z), q), ...] of impose_flux (q positive into the pore), in index order.");
}

}  // namespace pfv::python
