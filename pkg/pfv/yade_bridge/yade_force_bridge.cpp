#include "pfv/yade_bridge/yade_force_bridge.hpp"

#ifdef PFV_HAVE_BOOST_PYTHON
#include <dlfcn.h>
#include <Eigen/Core>
#include <boost/python/errors.hpp>
#include <boost/python/extract.hpp>
#include <boost/python/handle.hpp>
#include <boost/python/object.hpp>

namespace yade {
class pyForceContainer {};  // only the name matters (Boost.Python's registry)
}  // namespace yade
#endif

#include <algorithm>
#include <cmath>
#include <string>

namespace py = pybind11;

namespace pfv {
namespace {

// The address of the three doubles inside a YADE Vector3, or nullptr.
double* storage_of(py::handle v) {
#ifdef PFV_HAVE_BOOST_PYTHON
  using Vector3r = Eigen::Matrix<double, 3, 1>;  // yade-double's Vector3r
  boost::python::object o(boost::python::handle<>(boost::python::borrowed(v.ptr())));
  boost::python::extract<Vector3r&> e(o);
  if (!e.check()) return nullptr;
  return e().data();
#else
  (void)v;
  return nullptr;
#endif
}

#ifdef PFV_HAVE_BOOST_PYTHON
// yade::pyForceContainer::force_add(long, Vector3r const&, bool) of yade-double: the Itanium ABI
// passes `this` first and the Vector3r (three doubles) by address, as ForceAdd declares.
constexpr const char* kForceAddSymbol =
    "_ZN4yade16pyForceContainer9force_addElRKN5Eigen6MatrixIdLi3ELi1ELi0ELi3ELi1EEEb";
#endif

}  // namespace

YadeForceBridge::YadeForceBridge(py::object vector3_type, const py::array_t<long long>& ids,
                                 const py::array_t<long long>& rows)
    : vector3_type_(std::move(vector3_type)) {
  const auto id = ids.unchecked<1>();
  const auto row = rows.unchecked<1>();
  if (row.shape(0) != id.shape(0)) throw py::value_error("one force row per body id is needed");
  id_values_.reserve(id.shape(0));
  for (py::ssize_t i = 0; i < id.shape(0); ++i) {
    if (row(i) < 0) throw py::value_error("negative force row");
    id_values_.push_back(static_cast<long>(id(i)));
    rows_.push_back(row(i));
  }
#ifdef PFV_HAVE_BOOST_PYTHON
  // The wrapper module is loaded already (yade.wrapper defines O.forces); RTLD_NOLOAD only
  // takes a reference to it, released by the destructor.
  try {
    const auto path = py::module_::import("yade.wrapper").attr("__file__").cast<std::string>();
    wrapper_module_ = {dlopen(path.c_str(), RTLD_NOW | RTLD_NOLOAD), dlclose};
    if (wrapper_module_) force_add_ = reinterpret_cast<ForceAdd>(dlsym(wrapper_module_.get(), kForceAddSymbol));
  } catch (const std::exception&) {  // no YADE module here, or no file of it: addF calls
    force_add_ = nullptr;
  }
#endif
}

void YadeForceBridge::prepare_fallback() const {
  if (fallback_ready_) return;
  fallback_ready_ = true;
  ids_.reserve(id_values_.size());
  for (long id : id_values_) ids_.push_back(py::int_(id));
  std::vector<double*> storage;
  vectors_.reserve(ids_.size());
  for (std::size_t i = 0; i < ids_.size(); ++i) {
    vectors_.push_back(vector3_type_(0.0, 0.0, 0.0));
    double* s = storage_of(vectors_.back());
    if (!s) return;  // tuples then
    storage.push_back(s);
  }
  // Trust the layout only after reading back through YADE's own accessors.
  if (!storage.empty()) {
    storage[0][0] = 1.5, storage[0][1] = -2.5, storage[0][2] = 3.25;
    const py::object v = vectors_[0];
    if (v[py::int_(0)].cast<double>() != 1.5 || v[py::int_(1)].cast<double>() != -2.5 ||
        v[py::int_(2)].cast<double>() != 3.25)
      return;
  }
  storage_ = std::move(storage);
}

void* YadeForceBridge::direct_target(py::handle add) const {
#ifdef PFV_HAVE_BOOST_PYTHON
  // add must be the bound addF of a yade.wrapper.ForceContainer (a Python method object whose
  // function is the class's addF and whose self holds a yade::pyForceContainer).
  if (!force_add_ || !PyMethod_Check(add.ptr())) return nullptr;
  PyObject* self = PyMethod_GET_SELF(add.ptr());
  PyObject* function = PyMethod_GET_FUNCTION(add.ptr());
  PyObject* unbound = PyObject_GetAttrString(reinterpret_cast<PyObject*>(Py_TYPE(self)), "addF");
  if (!unbound) {
    PyErr_Clear();
    return nullptr;
  }
  const bool is_add_f = unbound == function;
  Py_DECREF(unbound);
  if (!is_add_f) return nullptr;
  boost::python::object o(boost::python::handle<>(boost::python::borrowed(self)));
  boost::python::extract<yade::pyForceContainer&> e(o);
  return e.check() ? static_cast<void*>(&e()) : nullptr;
#else
  (void)add;
  return nullptr;
#endif
}

void YadeForceBridge::apply(py::handle add, const Forces& forces) const {
  if (forces.ndim() != 2 || forces.shape(1) != 3) throw py::value_error("force array must have shape (n, 3)");
  apply(add, forces.data(), static_cast<std::size_t>(forces.shape(0)));
}

void YadeForceBridge::apply(py::handle add, const double* forces, std::size_t count) const {
  const auto n = static_cast<py::ssize_t>(count);
  if (std::any_of(rows_.begin(), rows_.end(), [n](py::ssize_t r) { return r >= n; }))
    throw py::value_error("force array does not match the bodies of the bridge");
  const auto f = [forces](py::ssize_t row, int axis) { return forces[3 * row + axis]; };
#ifdef PFV_HAVE_BOOST_PYTHON
  if (void* container = direct_target(add)) {
    try {
      for (std::size_t i = 0; i < id_values_.size(); ++i) {
        const py::ssize_t row = rows_[i];
        const double value[3] = {f(row, 0), f(row, 1), f(row, 2)};
        force_add_(container, id_values_[i], value, false);
      }
    } catch (const boost::python::error_already_set&) {  // an id out of range: YADE set IndexError
      throw py::error_already_set();
    }
    return;
  }
#endif
  prepare_fallback();
  PyObject* fn = add.ptr();
  for (std::size_t i = 0; i < ids_.size(); ++i) {
    const py::ssize_t row = rows_[i];
    PyObject* result;
    if (!storage_.empty()) {
      double* s = storage_[i];
      s[0] = f(row, 0), s[1] = f(row, 1), s[2] = f(row, 2);
      PyObject* args[2] = {ids_[i].ptr(), vectors_[i].ptr()};
      result = PyObject_Vectorcall(fn, args, 2, nullptr);
    } else {
      PyObject* tuple = Py_BuildValue("(ddd)", f(row, 0), f(row, 1), f(row, 2));
      PyObject* args[2] = {ids_[i].ptr(), tuple};
      result = tuple ? PyObject_Vectorcall(fn, args, 2, nullptr) : nullptr;
      Py_XDECREF(tuple);
    }
    if (!result) throw py::error_already_set();
    Py_DECREF(result);
  }
}

}  // namespace pfv
