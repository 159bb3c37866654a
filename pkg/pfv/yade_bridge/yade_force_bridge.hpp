// Hands the fluid forces to YADE: O.forces.addF(id, force) for every body each step (YADE's
// Python interface has no bulk setter).
//
// Most of an addF call is Boost.Python's argument conversion, so the bridge calls the C++
// function addF is bound to, yade::pyForceContainer::force_add(id, f, permanent=false), itself:
// the symbol is exported by YADE's wrapper module and found by its mangled name (which spells
// out the argument types), and the container is the object behind the bound method, found
// through Boost.Python's converter registry, which YADE's bindings populate. Same function, same
// arguments as addF, about a fifth of the cost (doc/yade.md). Failing that (another
// YADE, PFV built without Boost.Python), one addF call per body with a YADE Vector3 owned by the
// bridge and written in place (half the cost of a tuple), or with tuples. The fallback's Python
// objects (one Vector3 and one int per body, made on the first step of an engine) are made on its
// first use only: the direct call needs none of them.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
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
  // The same from count rows of three doubles (the engine's own force array: no copy to numpy).
  void apply(pybind11::handle add, const double* forces, std::size_t count) const;
  bool writes_in_place() const {
    prepare_fallback();
    return !storage_.empty();
  }
  // Whether apply(O.forces.addF, ...) calls YADE's force_add directly.
  bool calls_yade_directly() const { return force_add_ != nullptr; }
  std::size_t size() const { return id_values_.size(); }

 private:
  using ForceAdd = void (*)(void* container, long id, const double (&f)[3], bool permanent);
  // The target of a bound O.forces.addF, or nullptr if it cannot be called directly.
  void* direct_target(pybind11::handle add) const;
  // Makes ids_, vectors_ and storage_ once (the fallback of apply; see the top of the file).
  // Mutable state behind const: the bridge is used under the engine's lock, never concurrently.
  void prepare_fallback() const;

  std::unique_ptr<void, int (*)(void*)> wrapper_module_{nullptr, nullptr};  // dlopen handle
  ForceAdd force_add_ = nullptr;
  std::vector<long> id_values_;
  std::vector<pybind11::ssize_t> rows_;
  pybind11::object vector3_type_;
  mutable bool fallback_ready_ = false;
  mutable std::vector<pybind11::object> ids_, vectors_;
  mutable std::vector<double*> storage_;  // x, y, z of vectors_[i]; empty: pass tuples
};

}  // namespace pfv
