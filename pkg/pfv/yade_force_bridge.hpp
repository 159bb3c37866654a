// Hands the fluid forces to YADE: one O.forces.addF(id, force) per body each step, the
// cheapest write YADE's Python interface offers (it has no bulk setter).
//
// addF with a ready-made Vector3 costs about half of addF with a tuple (bridge measurements in
// doc/yade-bridge.md), so the bridge owns one YADE Vector3 per body, made once, and writes the
// force straight into its storage; addF copies the value. The storage is found through
// Boost.Python's converter registry, which YADE's own bindings populate (so this works only
// inside a YADE process and only when PFV was built with Boost.Python); failing that, the
// bridge passes tuples.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <vector>

namespace pfv {

class YadeForceBridge {
 public:
  using Forces = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

  // vector3_type: yade.minieigenHP.Vector3; body ids[i] receives row rows[i] of the forces.
  YadeForceBridge(pybind11::object vector3_type, const pybind11::array_t<long long>& ids,
                  const pybind11::array_t<long long>& rows);
  // add(ids[i], forces[rows[i]]) for every i; add is a bound O.forces.addF.
  void apply(pybind11::handle add, const Forces& forces) const;
  bool writes_in_place() const { return !storage_.empty(); }
  std::size_t size() const { return ids_.size(); }

 private:
  std::vector<pybind11::object> ids_, vectors_;
  std::vector<pybind11::ssize_t> rows_;
  std::vector<double*> storage_;  // x, y, z of vectors_[i]; empty: pass tuples
};

}  // namespace pfv
