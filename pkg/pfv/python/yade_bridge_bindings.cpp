// pfv._core's bindings of the YADE bridge (pfv/yade_bridge/): the force bridge, the SpherePack
// reader and the YADE version they are pinned to, which the package checks at import.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <vector>

#include "pfv/python/shared_engine.hpp"
#include "pfv/yade_bridge/yade_force_bridge.hpp"
#include "pfv/yade_bridge/yade_sphere_pack.hpp"
#include "pfv/yade_bridge/yade_version.hpp"

namespace pfv::python {

void bind_yade_bridge(py::module_& m) {
  m.attr("PINNED_YADE_VERSION") = kPinnedYadeVersion;

  // The per-step bridge to YADE (yade_force_bridge.hpp).
  py::class_<YadeForceBridge>(m, "YadeForceBridge")
      .def(py::init<py::object, const py::array_t<long long>&, const py::array_t<long long>&>(),
           py::arg("vector3_type"), py::arg("ids"), py::arg("rows"))
      .def(
          "apply",
          [](const YadeForceBridge& b, py::handle add, const SharedEngine& engine) {
            const EngineLock lock(engine);
            const std::vector<Vec3>& f = engine.forces();
            static_assert(sizeof(Vec3) == 3 * sizeof(double), "rows of three doubles");
            b.apply(add, f.empty() ? nullptr : f.front().data(), f.size());
          },
          py::arg("add"), py::arg("engine"), "The forces of an Engine (its forces(), without the copy).")
      .def("apply", py::overload_cast<py::handle, const YadeForceBridge::Forces&>(&YadeForceBridge::apply, py::const_),
           py::arg("add"), py::arg("forces"))
      .def_property_readonly("writes_in_place", &YadeForceBridge::writes_in_place)
      .def_property_readonly("calls_yade_directly", &YadeForceBridge::calls_yade_directly)
      .def("__len__", &YadeForceBridge::size);

  // The sphere centres from a yade.pack.SpherePack after fromSimulation() (yade_sphere_pack.hpp).
  m.def(
      "sphere_pack_size", [](py::handle pack) { return sphere_pack_size(pack); }, py::arg("pack"));
  m.def("gather_sphere_pack", &gather_sphere_pack, py::arg("pack"), py::arg("index"), py::arg("centres"),
        py::arg("radii") = py::none(), py::arg("expected_size") = -1);
}

}  // namespace pfv::python
