#include "yade_force_bridge.hpp"

#ifdef PFV_HAVE_BOOST_PYTHON
#include <Eigen/Core>
#include <boost/python/extract.hpp>
#include <boost/python/handle.hpp>
#include <boost/python/object.hpp>
#endif

#include <algorithm>
#include <cmath>

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

}  // namespace

YadeForceBridge::YadeForceBridge(py::object vector3_type, const py::array_t<long long>& ids,
                                 const py::array_t<long long>& rows) {
  const auto id = ids.unchecked<1>();
  const auto row = rows.unchecked<1>();
  if (row.shape(0) != id.shape(0)) throw py::value_error("one force row per body id is needed");
  ids_.reserve(id.shape(0));
  for (py::ssize_t i = 0; i < id.shape(0); ++i) {
    if (row(i) < 0) throw py::value_error("negative force row");
    ids_.push_back(py::int_(id(i)));
    rows_.push_back(row(i));
  }
  std::vector<double*> storage;
  vectors_.reserve(ids_.size());
  for (std::size_t i = 0; i < ids_.size(); ++i) {
    vectors_.push_back(vector3_type(0.0, 0.0, 0.0));
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

void YadeForceBridge::apply(py::handle add, const Forces& forces) const {
  const auto f = forces.unchecked<2>();
  const py::ssize_t n = f.shape(0);
  if (f.ndim() != 2 || f.shape(1) != 3 || std::any_of(rows_.begin(), rows_.end(), [n](py::ssize_t r) { return r >= n; }))
    throw py::value_error("force array does not match the bodies of the bridge");
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
